/* libusb bulk transport to the board: the board protocol's frames go over a
 * vendor-class interface (0) with one bulk OUT and one bulk IN endpoint.
 * Spec: "usb" or "usb:SERIAL".  Identity: backend.h (CBVH_USB_VID/PID). */
#include <libusb.h>
#include <stdlib.h>
#include <string.h>

#include "link/board_link.h"

#define USB_IFACE 0
#define USB_TIMEOUT_CHUNK_MS 1000

typedef struct {
    cbvh_link link; /* first: see board_link.h */
    libusb_context *ctx;
    libusb_device_handle *h;
    uint8_t ep_in, ep_out;
    uint16_t vid, pid; /* from the environment, checked once at open */
    char serial[64];
} usb_state;

/* Finds the board (optionally by serial) and opens and claims it. */
static int usb_attach(usb_state *s, char *err, size_t errlen, int *none) {
    uint16_t vid = s->vid, pid = s->pid;
    libusb_device **list = NULL;
    ssize_t n = libusb_get_device_list(s->ctx, &list);
    int rc = -1;
    *none = 1;
    snprintf(err, errlen, "no device %04x:%04x on the USB bus (%ld devices seen)", vid, pid, (long)(n < 0 ? 0 : n));
    for (ssize_t i = 0; i < n && rc != 0; i++) {
        struct libusb_device_descriptor d;
        if (libusb_get_device_descriptor(list[i], &d) != 0 || d.idVendor != vid || d.idProduct != pid) continue;
        *none = 0;
        libusb_device_handle *h = NULL;
        int o = libusb_open(list[i], &h);
        if (o != 0) {
            snprintf(err, errlen, "device %04x:%04x found but cannot be opened: %s%s%s", vid, pid, libusb_strerror(o),
                     o == LIBUSB_ERROR_ACCESS ? "; " : "", o == LIBUSB_ERROR_ACCESS ? CBVH_UDEV_HINT : "");
            continue;
        }
        if (s->serial[0]) {
            unsigned char sn[64] = {0};
            if (d.iSerialNumber == 0 ||
                libusb_get_string_descriptor_ascii(h, d.iSerialNumber, sn, sizeof sn) <= 0 ||
                strcmp((char *)sn, s->serial) != 0) {
                libusb_close(h);
                snprintf(err, errlen, "no device %04x:%04x with serial %s", vid, pid, s->serial);
                continue;
            }
        }
        struct libusb_config_descriptor *cfg = NULL;
        uint8_t in = 0, out = 0;
        int crc = libusb_get_active_config_descriptor(list[i], &cfg);
        if (crc != 0) { /* e.g. unplugged between the listing and here: not a wrong device */
            libusb_close(h);
            snprintf(err, errlen, "device %04x:%04x: cannot read its configuration (%s)", vid, pid,
                     libusb_strerror(crc));
            continue;
        }
        if (cfg->bNumInterfaces > USB_IFACE) {
            const struct libusb_interface_descriptor *id = &cfg->interface[USB_IFACE].altsetting[0];
            for (int e = 0; e < id->bNumEndpoints; e++) {
                const struct libusb_endpoint_descriptor *ep = &id->endpoint[e];
                if ((ep->bmAttributes & 3) != LIBUSB_TRANSFER_TYPE_BULK) continue;
                if (ep->bEndpointAddress & LIBUSB_ENDPOINT_IN) in = ep->bEndpointAddress;
                else out = ep->bEndpointAddress;
            }
        }
        if (cfg) libusb_free_config_descriptor(cfg);
        if (!in || !out) {
            snprintf(err, errlen, "device %04x:%04x has no bulk IN/OUT pair on interface %d", vid, pid, USB_IFACE);
            libusb_close(h);
            continue;
        }
        libusb_set_auto_detach_kernel_driver(h, 1);
        int c = libusb_claim_interface(h, USB_IFACE);
        if (c != 0) {
            snprintf(err, errlen, "device %04x:%04x: cannot claim interface %d: %s", vid, pid, USB_IFACE,
                     libusb_strerror(c));
            libusb_close(h);
            continue;
        }
        s->h = h;
        s->ep_in = in;
        s->ep_out = out;
        rc = 0;
    }
    if (list) libusb_free_device_list(list, 1);
    return rc;
}

static int usb_write(void *ctx, const uint8_t *buf, size_t n, char *err, size_t errlen) {
    usb_state *s = ctx;
    int done = 0;
    int r = s->h ? libusb_bulk_transfer(s->h, s->ep_out, (unsigned char *)buf, (int)n, &done, USB_TIMEOUT_CHUNK_MS)
                 : LIBUSB_ERROR_NO_DEVICE;
    if (r != 0 || (size_t)done != n) {
        snprintf(err, errlen, "usb write failed: %s", libusb_strerror(r));
        return -1;
    }
    return 0;
}

static long usb_read(void *ctx, uint8_t *buf, size_t cap, int timeout_ms, char *err, size_t errlen) {
    usb_state *s = ctx;
    if (!s->h) return -1;
    int got = 0;
    int r = libusb_bulk_transfer(s->h, s->ep_in, buf, (int)cap, &got, (unsigned)(timeout_ms > 0 ? timeout_ms : 1));
    if (r == 0 || r == LIBUSB_ERROR_TIMEOUT) return got;
    snprintf(err, errlen, "usb read failed: %s", libusb_strerror(r));
    return -1;
}

static void usb_detach(usb_state *s) {
    if (s->h) {
        libusb_release_interface(s->h, USB_IFACE);
        libusb_close(s->h);
        s->h = NULL;
    }
}

static int usb_reopen(void *ctx, char *err, size_t errlen) {
    usb_state *s = ctx;
    int none;
    usb_detach(s);
    return usb_attach(s, err, errlen, &none);
}

static int usb_open(cbvh_backend *b, const char *arg, char *err, size_t errlen) {
    usb_state *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return CBVH_BACKEND_ERROR;
    }
    if (arg) snprintf(s->serial, sizeof s->serial, "%s", arg);
    cbvh_link_io io = {s, usb_write, usb_read, usb_reopen, NULL};
    cbvh_link_init(&s->link, &io);
    /* Bad settings fail the open before any device is looked for. */
    if (cbvh_usb_identity(&s->vid, &s->pid, err, errlen) || cbvh_link_env_options(&s->link, err, errlen)) {
        free(s);
        return CBVH_BACKEND_ERROR;
    }
    int rc = libusb_init(&s->ctx);
    if (rc != 0) {
        snprintf(err, errlen, "libusb_init failed: %s", libusb_strerror(rc));
        free(s);
        return CBVH_BACKEND_NONE;
    }
    int none = 1;
    if (usb_attach(s, err, errlen, &none)) {
        libusb_exit(s->ctx);
        free(s);
        return none ? CBVH_BACKEND_NONE : CBVH_BACKEND_ERROR;
    }
    cbvh_link_flush(&s->link, 20); /* stale IN packets from an earlier session */
    char why[200];
    if (cbvh_link_identify(&s->link, why, sizeof why)) {
        snprintf(err, errlen, "usb board: %s", why);
        usb_detach(s);
        libusb_exit(s->ctx);
        free(s);
        return CBVH_BACKEND_ERROR;
    }
    const cbvh_identity *id = &s->link.ident;
    snprintf(b->label, sizeof b->label, "usb %04x:%04x %s (fw %u.%u.%u, datapath v%u)", s->vid, s->pid, id->board_name,
             id->fw_major, id->fw_minor, id->fw_patch, (unsigned)id->datapath_version);
    b->state = s;
    return CBVH_BACKEND_OK;
}

static void usb_close(cbvh_backend *b) {
    usb_state *s = b->state;
    if (!s) return;
    usb_detach(s);
    libusb_exit(s->ctx);
    free(s);
    b->state = NULL;
}

static int usb_run(cbvh_backend *b, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in,
                   uint32_t *out, size_t count, char *err, size_t errlen) {
    usb_state *s = b->state;
    if (!s) {
        snprintf(err, errlen, "usb backend not open");
        return CBVH_BACKEND_ERROR;
    }
    return cbvh_link_run(&s->link, unit, cfg, in, out, count, err, errlen) ? CBVH_BACKEND_ERROR : CBVH_BACKEND_OK;
}

static int usb_list(const char *arg, FILE *out) {
    (void)arg; /* every board is listed, whatever its serial */
    uint16_t vid, pid;
    char why[200];
    if (cbvh_usb_identity(&vid, &pid, why, sizeof why)) {
        cbvh_backend_list_line(out, &cbvh_backend_usb, "not probed (%s)", why);
        return 0;
    }
    libusb_context *ctx = NULL;
    int rc = libusb_init(&ctx);
    if (rc != 0) {
        cbvh_backend_list_line(out, &cbvh_backend_usb, "none (libusb_init failed: %s; no USB bus?)", libusb_strerror(rc));
        return 0;
    }
    libusb_device **list = NULL;
    ssize_t n = libusb_get_device_list(ctx, &list);
    int found = 0;
    for (ssize_t i = 0; i < n; i++) {
        struct libusb_device_descriptor d;
        if (libusb_get_device_descriptor(list[i], &d) != 0 || d.idVendor != vid || d.idProduct != pid) continue;
        found++;
        libusb_device_handle *h = NULL;
        int o = libusb_open(list[i], &h);
        unsigned char prod[64] = "?", sn[64] = "?";
        if (o == 0) {
            if (d.iProduct) libusb_get_string_descriptor_ascii(h, d.iProduct, prod, sizeof prod);
            if (d.iSerialNumber) libusb_get_string_descriptor_ascii(h, d.iSerialNumber, sn, sizeof sn);
            libusb_close(h);
            cbvh_backend_list_line(out, &cbvh_backend_usb, "%04x:%04x bus %u addr %u \"%s\" serial %s", vid, pid,
                                   libusb_get_bus_number(list[i]), libusb_get_device_address(list[i]), prod, sn);
        } else {
            cbvh_backend_list_line(out, &cbvh_backend_usb, "%04x:%04x bus %u addr %u: cannot open (%s)%s%s", vid, pid,
                                   libusb_get_bus_number(list[i]), libusb_get_device_address(list[i]),
                                   libusb_strerror(o), o == LIBUSB_ERROR_ACCESS ? "; " : "",
                                   o == LIBUSB_ERROR_ACCESS ? CBVH_UDEV_HINT : "");
        }
    }
    if (!found)
        cbvh_backend_list_line(out, &cbvh_backend_usb, "none (%ld USB devices visible, none is %04x:%04x%s)",
                               (long)(n < 0 ? 0 : n), vid, pid, n <= 0 ? "; no USB bus or no access to /dev/bus/usb" : "");
    if (list) libusb_free_device_list(list, 1);
    libusb_exit(ctx);
    return found;
}

const cbvh_backend_ops cbvh_backend_usb = {"usb", NULL, usb_open, usb_close, usb_run, usb_list};
