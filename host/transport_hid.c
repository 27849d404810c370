/* hidapi HID transport to the board.  Probing only for now: the report
 * framing arrives with the board issue (docs/protocol.md). */
#include <hidapi.h>

#include "backend.h"

static int hid_open_board(cbvh_backend *b, const char *arg, char *err, size_t errlen) {
    (void)arg;
    (void)b;
    uint16_t vid, pid;
    cbvh_usb_identity(&vid, &pid);
    if (hid_init() != 0) {
        snprintf(err, errlen, "hid_init failed");
        return CBVH_BACKEND_NONE;
    }
    struct hid_device_info *devs = hid_enumerate(vid, pid);
    int found = devs != NULL;
    hid_free_enumeration(devs);
    hid_exit();
    if (!found) {
        snprintf(err, errlen, "no HID device %04x:%04x", vid, pid);
        return CBVH_BACKEND_NONE;
    }
    snprintf(err, errlen, "HID device %04x:%04x found but the report protocol is not implemented yet", vid, pid);
    return CBVH_BACKEND_ERROR;
}

static void hid_close_board(cbvh_backend *b) { (void)b; }

static int hid_run(cbvh_backend *b, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in,
                   uint32_t *out, size_t count, char *err, size_t errlen) {
    (void)b, (void)unit, (void)cfg, (void)in, (void)out, (void)count;
    snprintf(err, errlen, "hid backend not open");
    return CBVH_BACKEND_ERROR;
}

const cbvh_backend_ops cbvh_backend_hid = {"hid", hid_open_board, hid_close_board, hid_run};
