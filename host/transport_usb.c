/* libusb bulk transport to the board.  Probing only for now: the framing and
 * batch protocol arrive with the board issue (docs/protocol.md). */
#include <libusb.h>

#include "backend.h"

static int usb_open(cbvh_backend *b, const char *arg, char *err, size_t errlen) {
    (void)arg;
    uint16_t vid, pid;
    cbvh_usb_identity(&vid, &pid);
    libusb_context *ctx = NULL;
    int rc = libusb_init(&ctx);
    if (rc != 0) {
        snprintf(err, errlen, "libusb_init failed: %s", libusb_strerror(rc));
        return CBVH_BACKEND_NONE;
    }
    libusb_device **list = NULL;
    ssize_t n = libusb_get_device_list(ctx, &list);
    int found = 0;
    for (ssize_t i = 0; i < n; i++) {
        struct libusb_device_descriptor d;
        if (libusb_get_device_descriptor(list[i], &d) == 0 && d.idVendor == vid && d.idProduct == pid) found++;
    }
    if (list) libusb_free_device_list(list, 1);
    libusb_exit(ctx);
    if (!found) {
        snprintf(err, errlen, "no device %04x:%04x on the USB bus (%ld devices seen)", vid, pid, (long)(n < 0 ? 0 : n));
        return CBVH_BACKEND_NONE;
    }
    (void)b;
    snprintf(err, errlen, "device %04x:%04x found but the bulk protocol is not implemented yet", vid, pid);
    return CBVH_BACKEND_ERROR;
}

static void usb_close(cbvh_backend *b) { (void)b; }

static int usb_run(cbvh_backend *b, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in,
                   uint32_t *out, size_t count, char *err, size_t errlen) {
    (void)b, (void)unit, (void)cfg, (void)in, (void)out, (void)count;
    snprintf(err, errlen, "usb backend not open");
    return CBVH_BACKEND_ERROR;
}

const cbvh_backend_ops cbvh_backend_usb = {"usb", usb_open, usb_close, usb_run};
