/* hidapi HID transport to the board: the board protocol's byte stream cut
 * into 64-byte reports, each [n][n frame bytes, zero padded] (n <= 63).  The
 * board uses no report IDs, so hid_write gets a leading 0 report-ID byte
 * (65 bytes) and hid_read returns the bare 64-byte report.
 * Spec: "hid" or "hid:SERIAL". */
#include <hidapi.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>

#include "link/board_link.h"

#define HID_REPORT 64
#define HID_DATA (HID_REPORT - 1)

typedef struct {
    cbvh_link link; /* first: see board_link.h */
    hid_device *dev;
    wchar_t serial[64];
    int use_serial;
    uint16_t vid, pid; /* from the environment, checked once at open */
} hid_state;

static int hid_attach(hid_state *s, char *err, size_t errlen, int *none) {
    uint16_t vid = s->vid, pid = s->pid;
    struct hid_device_info *devs = hid_enumerate(vid, pid);
    *none = devs == NULL;
    hid_free_enumeration(devs);
    if (*none) {
        snprintf(err, errlen, "no HID device %04x:%04x", vid, pid);
        return -1;
    }
    s->dev = hid_open(vid, pid, s->use_serial ? s->serial : NULL);
    if (!s->dev) {
        snprintf(err, errlen, "HID device %04x:%04x found but cannot be opened (%ls); %s", vid, pid,
                 hid_error(NULL) ? hid_error(NULL) : L"no reason given", CBVH_UDEV_HINT);
        return -1;
    }
    return 0;
}

static int hidt_write(void *ctx, const uint8_t *buf, size_t n, char *err, size_t errlen) {
    hid_state *s = ctx;
    while (n > 0) {
        uint8_t rep[HID_REPORT + 1] = {0};
        size_t k = n < HID_DATA ? n : HID_DATA;
        rep[1] = (uint8_t)k;
        memcpy(rep + 2, buf, k);
        if (!s->dev || hid_write(s->dev, rep, sizeof rep) < 0) {
            snprintf(err, errlen, "hid write failed");
            return -1;
        }
        buf += k;
        n -= k;
    }
    return 0;
}

static long hidt_read(void *ctx, uint8_t *buf, size_t cap, int timeout_ms, char *err, size_t errlen) {
    hid_state *s = ctx;
    uint8_t rep[HID_REPORT];
    if (!s->dev || cap < HID_DATA) return -1;
    int r = hid_read_timeout(s->dev, rep, sizeof rep, timeout_ms);
    if (r < 0) {
        snprintf(err, errlen, "hid read failed");
        return -1;
    }
    if (r == 0) return 0;
    size_t k = rep[0];
    if (k > HID_DATA || (int)k > r - 1) k = 0; /* malformed report: drop it, the CRC/timeout logic recovers */
    memcpy(buf, rep + 1, k);
    return (long)k;
}

static int hidt_reopen(void *ctx, char *err, size_t errlen) {
    hid_state *s = ctx;
    int none;
    if (s->dev) hid_close(s->dev);
    s->dev = NULL;
    return hid_attach(s, err, errlen, &none);
}

static int hid_open_board(cbvh_backend *b, const char *arg, char *err, size_t errlen) {
    hid_state *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return CBVH_BACKEND_ERROR;
    }
    cbvh_link_io io = {s, hidt_write, hidt_read, hidt_reopen, NULL};
    cbvh_link_init(&s->link, &io);
    /* Bad settings fail the open before any device is looked for. */
    if (cbvh_usb_identity(&s->vid, &s->pid, err, errlen) || cbvh_link_env_options(&s->link, err, errlen)) {
        free(s);
        return CBVH_BACKEND_ERROR;
    }
    if (hid_init() != 0) {
        snprintf(err, errlen, "hid_init failed");
        free(s);
        return CBVH_BACKEND_NONE;
    }
    if (arg && *arg) {
        mbstowcs(s->serial, arg, sizeof s->serial / sizeof s->serial[0] - 1);
        s->use_serial = 1;
    }
    int none = 1;
    if (hid_attach(s, err, errlen, &none)) {
        free(s);
        hid_exit();
        return none ? CBVH_BACKEND_NONE : CBVH_BACKEND_ERROR;
    }
    cbvh_link_flush(&s->link, 20);
    char why[200];
    if (cbvh_link_identify(&s->link, why, sizeof why)) {
        snprintf(err, errlen, "hid board: %s", why);
        hid_close(s->dev);
        free(s);
        hid_exit();
        return CBVH_BACKEND_ERROR;
    }
    const cbvh_identity *id = &s->link.ident;
    snprintf(b->label, sizeof b->label, "hid %04x:%04x %s (fw %u.%u.%u, datapath v%u)", s->vid, s->pid, id->board_name,
             id->fw_major, id->fw_minor, id->fw_patch, (unsigned)id->datapath_version);
    b->state = s;
    return CBVH_BACKEND_OK;
}

static void hid_close_board(cbvh_backend *b) {
    hid_state *s = b->state;
    if (!s) return;
    if (s->dev) hid_close(s->dev);
    free(s);
    b->state = NULL;
    hid_exit();
}

static int hid_run(cbvh_backend *b, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in,
                   uint32_t *out, size_t count, char *err, size_t errlen) {
    hid_state *s = b->state;
    if (!s) {
        snprintf(err, errlen, "hid backend not open");
        return CBVH_BACKEND_ERROR;
    }
    return cbvh_link_run(&s->link, unit, cfg, in, out, count, err, errlen) ? CBVH_BACKEND_ERROR : CBVH_BACKEND_OK;
}

static int hid_list(const char *arg, FILE *out) {
    (void)arg; /* every board is listed, whatever its serial */
    uint16_t vid, pid;
    char why[200];
    if (cbvh_usb_identity(&vid, &pid, why, sizeof why)) {
        cbvh_backend_list_line(out, &cbvh_backend_hid, "not probed (%s)", why);
        return 0;
    }
    if (hid_init() != 0) {
        cbvh_backend_list_line(out, &cbvh_backend_hid, "none (hid_init failed)");
        return 0;
    }
    struct hid_device_info *devs = hid_enumerate(vid, pid);
    int found = 0;
    for (struct hid_device_info *d = devs; d; d = d->next) {
        found++;
        cbvh_backend_list_line(out, &cbvh_backend_hid, "%04x:%04x %s \"%ls\" serial %ls", d->vendor_id, d->product_id,
                               d->path, d->product_string ? d->product_string : L"?",
                               d->serial_number ? d->serial_number : L"?");
    }
    hid_free_enumeration(devs);
    if (!found)
        cbvh_backend_list_line(out, &cbvh_backend_hid,
                               "none (no HID device %04x:%04x; without permission on /dev/hidraw* or /dev/bus/usb "
                               "boards are invisible: %s)",
                               vid, pid, CBVH_UDEV_HINT);
    hid_exit();
    return found;
}

const cbvh_backend_ops cbvh_backend_hid = {"hid", NULL, hid_open_board, hid_close_board, hid_run, hid_list};
