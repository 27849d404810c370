/* The libusb bulk transport against the firmware core, with libusb mocked
 * (the test defines the libusb_* functions the transport calls; they take
 * precedence over libusb-1.0).  The fake device has one vendor interface with
 * bulk OUT 0x01 / IN 0x81 wired to an in-process firmware core (model FPGA).
 * Checks: results equal the model for every unit, a device that vanishes in
 * the middle of a batch is reopened and the batch completes, "permission
 * denied" names the udev rule, no device is reported as none, bad
 * CBVH_USB_VID/PID or CBVH_LINK_* settings fail the open before any device is
 * touched, and a board reporting a small max payload in IDENTIFY only gets
 * frames that fit it. */
#include <libusb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "link/board_link.h"
#include "cbvh_sim.h"
#include "gen_inputs.h"
#include "test_util.h"

static struct {
    int present, deny, opened, claimed, vanish_after; /* vanish_after: OUT transfers until a NO_DEVICE */
    uint16_t max_payload; /* non-zero: what the board's IDENTIFY reply claims instead of 4096 */
    size_t max_out;       /* largest OUT transfer seen */
    cbvh_regmap_model regs;
    cbvh_fw fw;
    uint8_t in[1 << 16];
    size_t head, tail;
    unsigned long outs, opens;
} dev;
static int dummy_dev, dummy_handle, dummy_ctx;
static libusb_device *list[2];

static void fw_send(void *ctx, const uint8_t *frame, size_t len) {
    (void)ctx;
    static uint8_t patched[CBVH_FRAME_MAX];
    if (dev.max_payload && frame[2] == (CBVH_CMD_IDENTIFY | CBVH_REPLY) && len <= sizeof patched) {
        /* a board with smaller frames: same identity, max payload field (offset 12) changed, CRC redone */
        memcpy(patched, frame, len);
        cbvh_put16(patched + CBVH_FRAME_HDR + 12, dev.max_payload);
        len = cbvh_frame_seal(patched, frame[2], frame[3], cbvh_get16(frame + 4), cbvh_get16(frame + 6));
        frame = patched;
    }
    for (size_t i = 0; i < len; i++) dev.in[dev.head++ % sizeof dev.in] = frame[i];
}
static const cbvh_fw_hal hal = {&dev.regs, cbvh_regmap_model_read, cbvh_regmap_model_write, fw_send, "usb-fake"};

int LIBUSB_CALL libusb_init(libusb_context **ctx) {
    *ctx = (libusb_context *)&dummy_ctx;
    return 0;
}
void LIBUSB_CALL libusb_exit(libusb_context *ctx) { (void)ctx; }
ssize_t LIBUSB_CALL libusb_get_device_list(libusb_context *ctx, libusb_device ***l) {
    (void)ctx;
    list[0] = dev.present ? (libusb_device *)&dummy_dev : NULL;
    list[1] = NULL;
    *l = list;
    return dev.present ? 1 : 0;
}
void LIBUSB_CALL libusb_free_device_list(libusb_device **l, int unref) { (void)l, (void)unref; }
int LIBUSB_CALL libusb_get_device_descriptor(libusb_device *d, struct libusb_device_descriptor *desc) {
    (void)d;
    memset(desc, 0, sizeof *desc);
    desc->idVendor = CBVH_USB_VID_DEFAULT;
    desc->idProduct = CBVH_USB_PID_DEFAULT;
    desc->iProduct = 2;
    desc->iSerialNumber = 3;
    return 0;
}
int LIBUSB_CALL libusb_open(libusb_device *d, libusb_device_handle **h) {
    (void)d;
    if (dev.deny) return LIBUSB_ERROR_ACCESS;
    *h = (libusb_device_handle *)&dummy_handle;
    dev.opened++;
    dev.opens++;
    return 0;
}
void LIBUSB_CALL libusb_close(libusb_device_handle *h) {
    (void)h;
    dev.opened--;
}
int LIBUSB_CALL libusb_get_string_descriptor_ascii(libusb_device_handle *h, uint8_t idx, unsigned char *s, int n) {
    (void)h;
    const char *v = idx == 2 ? "cbvh board" : "FAKE0001";
    snprintf((char *)s, (size_t)n, "%s", v);
    return (int)strlen((char *)s);
}
static struct libusb_endpoint_descriptor eps[2];
static struct libusb_interface_descriptor alt;
static struct libusb_interface iface;
static struct libusb_config_descriptor cfgd;
int LIBUSB_CALL libusb_get_active_config_descriptor(libusb_device *d, struct libusb_config_descriptor **c) {
    (void)d;
    eps[0].bEndpointAddress = 0x01;
    eps[0].bmAttributes = LIBUSB_TRANSFER_TYPE_BULK;
    eps[1].bEndpointAddress = 0x81;
    eps[1].bmAttributes = LIBUSB_TRANSFER_TYPE_BULK;
    alt.bNumEndpoints = 2;
    alt.endpoint = eps;
    iface.altsetting = &alt;
    iface.num_altsetting = 1;
    cfgd.bNumInterfaces = 1;
    cfgd.interface = &iface;
    *c = &cfgd;
    return 0;
}
void LIBUSB_CALL libusb_free_config_descriptor(struct libusb_config_descriptor *c) { (void)c; }
int LIBUSB_CALL libusb_set_auto_detach_kernel_driver(libusb_device_handle *h, int e) {
    (void)h, (void)e;
    return 0;
}
int LIBUSB_CALL libusb_claim_interface(libusb_device_handle *h, int i) {
    (void)h;
    dev.claimed += i == 0;
    return i == 0 ? 0 : LIBUSB_ERROR_NOT_FOUND;
}
int LIBUSB_CALL libusb_release_interface(libusb_device_handle *h, int i) {
    (void)h, (void)i;
    dev.claimed--;
    return 0;
}
uint8_t LIBUSB_CALL libusb_get_bus_number(libusb_device *d) {
    (void)d;
    return 1;
}
uint8_t LIBUSB_CALL libusb_get_device_address(libusb_device *d) {
    (void)d;
    return 7;
}
int LIBUSB_CALL libusb_bulk_transfer(libusb_device_handle *h, unsigned char ep, unsigned char *data, int length,
                                     int *transferred, unsigned int timeout) {
    (void)timeout;
    *transferred = 0;
    if (h != (libusb_device_handle *)&dummy_handle) return LIBUSB_ERROR_INVALID_PARAM;
    if (ep == 0x01) {
        if (dev.vanish_after > 0 && --dev.vanish_after == 0) {
            /* the device disappears: this frame is cut after 10 bytes */
            cbvh_fw_rx(&dev.fw, data, 10);
            return LIBUSB_ERROR_NO_DEVICE;
        }
        dev.outs++;
        if ((size_t)length > dev.max_out) dev.max_out = (size_t)length;
        cbvh_fw_rx(&dev.fw, data, (size_t)length);
        *transferred = length;
        return 0;
    }
    if (ep == 0x81) {
        int n = 0;
        while (n < length && dev.tail != dev.head) data[n++] = dev.in[dev.tail++ % sizeof dev.in];
        *transferred = n;
        return n ? 0 : LIBUSB_ERROR_TIMEOUT;
    }
    return LIBUSB_ERROR_INVALID_PARAM;
}
const char *LIBUSB_CALL libusb_strerror(int code) {
    return code == LIBUSB_ERROR_ACCESS ? "Access denied (insufficient permissions)" : "fake libusb error";
}

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stderr, c, __VA_ARGS__)

int main(void) {
    char err[512];
    cbvh_backend b, model;
    unsetenv("CBVH_USB_VID");
    unsetenv("CBVH_USB_PID");
    CHECK(cbvh_backend_open("usb", &b, NULL, err, sizeof err) != 0 && strstr(err, "no device 1209:c0b1"),
          "absent: '%s'", err);
    dev.present = 1;
    dev.deny = 1;
    CHECK(cbvh_backend_open("usb", &b, NULL, err, sizeof err) != 0 && strstr(err, "60-cbvh.rules"),
          "no permission must point at the udev rule: '%s'", err);
    dev.deny = 0;
    /* Bad settings: one line naming the variable and the accepted form, and
     * the (present) device is not even opened under a wrong identity. */
    static const struct {
        const char *var, *val, *want;
    } bad[] = {
        {"CBVH_USB_VID", "zzzz", "CBVH_USB_VID='zzzz' is not a USB ID (expected 1 to 4 hex digits, optional 0x"},
        {"CBVH_USB_VID", "123456", "CBVH_USB_VID='123456' is not a USB ID"},
        {"CBVH_USB_PID", "-1", "CBVH_USB_PID='-1' is not a USB ID"},
        {"CBVH_USB_PID", "0x", "CBVH_USB_PID='0x' is not a USB ID"},
        {"CBVH_LINK_TIMEOUT_MS", "5x", "CBVH_LINK_TIMEOUT_MS='5x' is not valid (expected an integer in 1..600000)"},
        {"CBVH_LINK_TIMEOUT_MS", "0", "CBVH_LINK_TIMEOUT_MS='0' is not valid"},
        {"CBVH_LINK_RETRIES", "99999999999", "CBVH_LINK_RETRIES='99999999999' is not valid (expected an integer in 0..1000)"},
        {"CBVH_LINK_RETRIES", "-1", "CBVH_LINK_RETRIES='-1' is not valid"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        setenv(bad[i].var, bad[i].val, 1);
        unsigned long opens = dev.opens;
        int rc = cbvh_backend_open("usb", &b, NULL, err, sizeof err);
        CHECK(rc != 0 && strstr(err, bad[i].want) && !strchr(err, '\n') && dev.opens == opens,
              "%s=%s: open gave %d, '%s'", bad[i].var, bad[i].val, rc, err);
        /* auto must not fall back to the model over it either */
        rc = cbvh_backend_open("auto", &b, NULL, err, sizeof err);
        CHECK(rc != 0 && strstr(err, bad[i].want), "auto with %s=%s: %d, '%s'", bad[i].var, bad[i].val, rc, err);
        if (rc == 0) cbvh_backend_close(&b);
        unsetenv(bad[i].var);
    }
    /* The accepted forms: 0x prefix, either case; empty means unset. */
    setenv("CBVH_USB_VID", "0x1209", 1);
    setenv("CBVH_USB_PID", "C0B1", 1);
    setenv("CBVH_LINK_RETRIES", "", 1);
    cbvh_regmap_model_init(&dev.regs);
    cbvh_fw_init(&dev.fw, &hal);
    if (cbvh_backend_open("usb", &b, NULL, err, sizeof err)) {
        fprintf(stderr, "FAIL: open usb: %s\n", err);
        return 1;
    }
    printf("opened: %s\n", b.label);
    CHECK(cbvh_backend_link(&b)->max_retries == CBVH_LINK_RETRIES_DEFAULT, "empty CBVH_LINK_RETRIES is not the default");
    unsetenv("CBVH_USB_VID");
    unsetenv("CBVH_USB_PID");
    unsetenv("CBVH_LINK_RETRIES");
    if (cbvh_backend_open("model", &model, NULL, err, sizeof err)) return 1;
    uint64_t rng = 11;
    size_t total = 0;
    for (int u = 0; u < cbvh_unit_count; u++) {
        const cbvh_unit *unit = cbvh_units[u];
        cbvh_unit_config cfg = {{6, -30}, u % 2 ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO};
        cbvh_layout lay;
        unit->layout(&cfg, &lay);
        size_t count = 1000;
        uint32_t *in = malloc(count * (size_t)lay.n_in * 4), *a = malloc(count * (size_t)lay.n_out * 4),
                 *o = malloc(count * (size_t)lay.n_out * 4);
        cbvh_gen_inputs(&rng, &cfg, &lay, in, count);
        model.ops->run(&model, unit, &cfg, in, a, count, err, sizeof err);
        if (u == 1) dev.vanish_after = 3; /* third frame of this batch: device gone mid-batch */
        int rc = b.ops->run(&b, unit, &cfg, in, o, count, err, sizeof err);
        CHECK(rc == 0, "%s: %s", unit->name, err);
        CHECK(rc != 0 || memcmp(a, o, count * (size_t)lay.n_out * 4) == 0, "%s: usb differs from model", unit->name);
        total += count;
        free(in), free(a), free(o);
    }
    cbvh_link *l = cbvh_backend_link(&b);
    char line[512];
    cbvh_link_stats_line(&l->st, line, sizeof line);
    printf("%zu vectors over bulk equal the model; %lu OUT transfers, %lu opens; link: %s\n", total, dev.outs,
           dev.opens, line);
    CHECK(l->st.link_breaks == 1 && l->st.reopens == 1, "vanished device: %llu breaks, %llu reopens",
          (unsigned long long)l->st.link_breaks, (unsigned long long)l->st.reopens);
    cbvh_backend_close(&b);
    CHECK(dev.opened == 0 && dev.claimed == 0, "handle left open (%d) or interface claimed (%d)", dev.opened,
          dev.claimed);
    /* devices listing */
    FILE *f = tmpfile();
    CHECK(cbvh_backend_usb.list(NULL, f) == 1, "the listing should name one board");
    rewind(f);
    char buf[256] = "";
    CHECK(fgets(buf, sizeof buf, f) && strncmp(buf, "usb:   1209:c0b1 bus ", 21) == 0 &&
              strstr(buf, "\"cbvh board\" serial FAKE0001"),
          "listing: '%s'", buf);
    fclose(f);

    /* A board that takes 64-byte payloads (IDENTIFY) gets no larger frame:
     * batches are cut to fit, results unchanged; a unit whose single vector
     * does not fit is refused by name, not sent. */
    dev.max_payload = 64;
    if (cbvh_backend_open("usb", &b, NULL, err, sizeof err)) {
        fprintf(stderr, "FAIL: open usb (64-byte board): %s\n", err);
        return 1;
    }
    l = cbvh_backend_link(&b);
    CHECK(l->ident.max_payload == 64, "IDENTIFY max payload read as %u", l->ident.max_payload);
    const cbvh_unit *ac = cbvh_unit_find("axis_compress");
    cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
    cbvh_layout lay;
    ac->layout(&cfg, &lay);
    size_t count = 200;
    uint32_t *in = malloc(count * (size_t)lay.n_in * 4), *a = malloc(count * (size_t)lay.n_out * 4),
             *o = malloc(count * (size_t)lay.n_out * 4);
    cbvh_gen_inputs(&rng, &cfg, &lay, in, count);
    model.ops->run(&model, ac, &cfg, in, a, count, err, sizeof err);
    dev.max_out = 0;
    unsigned long outs = dev.outs;
    int rc = b.ops->run(&b, ac, &cfg, in, o, count, err, sizeof err);
    CHECK(rc == 0, "axis_compress on a 64-byte board: %s", err);
    CHECK(rc != 0 || memcmp(a, o, count * (size_t)lay.n_out * 4) == 0, "axis_compress on a 64-byte board differs");
    CHECK(dev.max_out <= CBVH_FRAME_HDR + 64 + CBVH_FRAME_CRC, "a %zu-byte frame was sent to a 64-byte board",
          dev.max_out);
    printf("64-byte board: %zu axis_compress vectors in %lu frames of at most %zu bytes\n", count, dev.outs - outs,
           dev.max_out);
    free(in), free(a), free(o);
    const cbvh_unit *big = NULL; /* a unit whose one vector needs more than 64 bytes */
    for (int u = 0; u < cbvh_unit_count && !big; u++) {
        cbvh_units[u]->layout(&cfg, &lay);
        if (12 + 4 * lay.n_in > 64 || 4 + 4 * lay.n_out > 64) big = cbvh_units[u];
    }
    if (big) {
        big->layout(&cfg, &lay);
        uint32_t one_in[64] = {0}, one_out[64];
        outs = dev.outs;
        rc = b.ops->run(&b, big, &cfg, one_in, one_out, 1, err, sizeof err);
        CHECK(rc != 0 && strstr(err, big->name) && strstr(err, "does not fit the board's 64-byte frames") &&
                  dev.outs == outs,
              "%s on a 64-byte board: rc %d, '%s', %lu frames sent", big->name, rc, err, dev.outs - outs);
    } else {
        CHECK(0, "no unit needs more than a 64-byte frame at N=6; pick another case");
    }
    cbvh_backend_close(&b);
    dev.max_payload = 0;
    cbvh_backend_close(&model);
    return fails ? 1 : 0;
}
