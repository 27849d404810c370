#include "link/backend.h"
#include "link/protocol.h"
#include "link/sim_addr.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* One 16-bit USB ID from the environment: 1 to 4 hex digits, optional 0x.
 * strtoul took "zzzz" as 0, "123456" as 0x3456 (cast) and "-1" as ffff. */
static int env_usb_id(const char *name, uint16_t def, uint16_t *id, char *err, size_t errlen) {
    const char *s = getenv(name);
    *id = def;
    if (!s || !*s) return 0;
    const char *h = s[0] == '0' && (s[1] == 'x' || s[1] == 'X') ? s + 2 : s;
    size_t n = strspn(h, "0123456789abcdefABCDEF");
    if (n < 1 || n > 4 || h[n]) {
        snprintf(err, errlen, "%s='%.40s' is not a USB ID (expected 1 to 4 hex digits, optional 0x, e.g. %04x)", name,
                 s, def);
        return -1;
    }
    *id = (uint16_t)strtoul(h, NULL, 16);
    return 0;
}

int cbvh_usb_identity(uint16_t *vid, uint16_t *pid, char *err, size_t errlen) {
    if (env_usb_id("CBVH_USB_VID", CBVH_USB_VID_DEFAULT, vid, err, errlen) ||
        env_usb_id("CBVH_USB_PID", CBVH_USB_PID_DEFAULT, pid, err, errlen)) {
        *vid = CBVH_USB_VID_DEFAULT;
        *pid = CBVH_USB_PID_DEFAULT;
        return -1;
    }
    return 0;
}

const cbvh_backend_ops *const cbvh_backends[] = {&cbvh_backend_usb, &cbvh_backend_hid, &cbvh_backend_sim,
                                                &cbvh_backend_model, NULL};

void cbvh_backend_list_line(FILE *out, const cbvh_backend_ops *ops, const char *fmt, ...) {
    char name[16];
    snprintf(name, sizeof name, "%s:", ops->name);
    fprintf(out, "%-7s", name);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(out, fmt, ap);
    va_end(ap);
    fputc('\n', out);
}

static int open_one(const cbvh_backend_ops *ops, const char *arg, cbvh_backend *b, char *err, size_t errlen) {
    memset(b, 0, sizeof *b);
    b->ops = ops;
    snprintf(b->label, sizeof b->label, "%s", ops->name);
    int rc = ops->open(b, arg, err, errlen);
    if (rc != CBVH_BACKEND_OK) b->ops = NULL;
    return rc;
}

/* auto: the boards `cbvh devices` lists, in its order (usb, hid, then the
 * virtual board at CBVH_SIM_ADDR when that is set), else the model. */
static int open_auto(cbvh_backend *b, FILE *log, char *err, size_t errlen) {
    /* Bad settings are an error, not a reason to fall back to the model. */
    uint16_t vid, pid;
    if (cbvh_usb_identity(&vid, &pid, err, errlen) || cbvh_link_env_options(NULL, err, errlen)) return -1;
    const char *sim = getenv("CBVH_SIM_ADDR"); /* empty means unset, as for `cbvh devices` */
    char why_sim[220];
    if (sim && *sim && cbvh_sim_addr_check(sim, why_sim, sizeof why_sim)) {
        snprintf(err, errlen, "CBVH_SIM_ADDR: %s", why_sim);
        return -1;
    }
    char why[3][240] = {"", "", ""};
    if (open_one(&cbvh_backend_usb, NULL, b, why[0], sizeof why[0]) == CBVH_BACKEND_OK) return 0;
    if (open_one(&cbvh_backend_hid, NULL, b, why[1], sizeof why[1]) == CBVH_BACKEND_OK) return 0;
    if (sim && *sim) {
        int rc = open_one(&cbvh_backend_sim, sim, b, why[2], sizeof why[2]);
        if (rc == CBVH_BACKEND_OK) return 0;
        if (rc == CBVH_BACKEND_BAD_INPUT) { /* e.g. a bad CBVH_LINK_FAULTS: an error, as for usb's settings */
            snprintf(err, errlen, "sim backend at CBVH_SIM_ADDR=%.100s: %s", sim, why[2]);
            return -1;
        }
    }
    if (log) {
        if (sim && *sim)
            fprintf(log, "cbvh: no board found (usb: %s; hid: %s; sim: %s); using the software model\n", why[0], why[1],
                    why[2]);
        else
            fprintf(log, "cbvh: no board found (usb: %s; hid: %s); using the software model\n", why[0], why[1]);
    }
    return open_one(&cbvh_backend_model, NULL, b, err, errlen) == CBVH_BACKEND_OK ? 0 : -1;
}

/* The backend a spec names ("name" or "name:arg"); *arg gets the text after
 * the colon, or NULL.  NULL with err set for an unknown name. */
static const cbvh_backend_ops *find_backend(const char *spec, const char **arg, char *err, size_t errlen) {
    size_t n = strcspn(spec, ":");
    *arg = spec[n] == ':' ? spec + n + 1 : NULL;
    for (const cbvh_backend_ops *const *o = cbvh_backends; *o; o++)
        if (strlen((*o)->name) == n && strncmp((*o)->name, spec, n) == 0) return *o;
    snprintf(err, errlen, "unknown backend '%s' (expected auto, model, usb, hid or sim:ADDR)", spec);
    return NULL;
}

int cbvh_backend_spec_check(const char *spec, char *err, size_t errlen) {
    if (strcmp(spec, "auto") == 0) return 0;
    const char *arg;
    const cbvh_backend_ops *ops = find_backend(spec, &arg, err, errlen);
    if (!ops) return -1;
    return ops->check_arg && ops->check_arg(arg, err, errlen) ? -1 : 0;
}

int cbvh_backend_open(const char *spec, cbvh_backend *b, FILE *log, char *err, size_t errlen) {
    if (strcmp(spec, "auto") == 0) return open_auto(b, log, err, errlen);
    if (cbvh_backend_spec_check(spec, err, errlen)) return -1;
    const char *arg;
    const cbvh_backend_ops *ops = find_backend(spec, &arg, err, errlen);
    int rc = open_one(ops, arg, b, err, errlen);
    if (rc == CBVH_BACKEND_NONE && err[0] == '\0') snprintf(err, errlen, "no %s board found", ops->name);
    return rc == CBVH_BACKEND_OK ? 0 : -1;
}

void cbvh_backend_close(cbvh_backend *b) {
    if (b->ops && b->ops->close) b->ops->close(b);
    b->ops = NULL;
}
