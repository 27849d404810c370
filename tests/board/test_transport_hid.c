/* The hidapi transport against the firmware core, with hidapi itself mocked
 * (TinyUSB style: the test defines the hid_* functions the transport calls, so
 * they take precedence over libhidapi).  The fake device carries the frame
 * stream in 64-byte reports exactly as docs/protocol.md says, into an
 * in-process firmware core whose FPGA is the model.  Checks: report format on
 * the wire, `--backend hid` results equal the model for every unit,
 * `--backend auto` picks hid when there is no usb board, malformed reports
 * are survived, a bad CBVH_USB_VID/PID fails the open (and the listing)
 * with one line instead of looking for another device. */
#include <hidapi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "link/board_link.h"
#include "cbvh_sim.h"
#include "gen_inputs.h"
#include "test_util.h"

#define REPORTS 4096
static struct {
    int present, opened;
    cbvh_regmap_model regs;
    cbvh_fw fw;
    uint8_t q[REPORTS][64];
    size_t head, tail;
    unsigned long writes, bad_writes, reports_in, enumerates;
    int inject_bad_report;
} dev;
static struct hid_device_info info;
static int fake_handle;

static void fw_send(void *ctx, const uint8_t *frame, size_t len) {
    (void)ctx;
    for (size_t off = 0; off < len; off += 63) {
        size_t k = len - off < 63 ? len - off : 63;
        uint8_t *r = dev.q[dev.head++ % REPORTS];
        memset(r, 0, 64);
        r[0] = (uint8_t)k;
        memcpy(r + 1, frame + off, k);
    }
}
static const cbvh_fw_hal hal = {&dev.regs, cbvh_regmap_model_read, cbvh_regmap_model_write, fw_send, "hid-fake"};

int hid_init(void) { return 0; }
int hid_exit(void) { return 0; }
struct hid_device_info *hid_enumerate(unsigned short vid, unsigned short pid) {
    dev.enumerates++;
    if (!dev.present || vid != CBVH_USB_VID_DEFAULT || pid != CBVH_USB_PID_DEFAULT) return NULL;
    memset(&info, 0, sizeof info);
    info.vendor_id = vid;
    info.product_id = pid;
    info.path = (char *)"fake-hidraw0";
    return &info;
}
void hid_free_enumeration(struct hid_device_info *devs) { (void)devs; }
hid_device *hid_open(unsigned short vid, unsigned short pid, const wchar_t *serial) {
    (void)vid, (void)pid, (void)serial;
    if (!dev.present) return NULL;
    dev.opened = 1;
    return (hid_device *)&fake_handle;
}
void hid_close(hid_device *d) {
    (void)d;
    dev.opened = 0;
}
const wchar_t *hid_error(hid_device *d) {
    (void)d;
    return L"fake";
}
int hid_write(hid_device *d, const unsigned char *data, size_t length) {
    dev.writes++;
    /* 65 bytes: report ID 0, then the 64-byte report [n][n bytes] */
    if (d != (hid_device *)&fake_handle || length != 65 || data[0] != 0 || data[1] == 0 || data[1] > 63) {
        dev.bad_writes++;
        return -1;
    }
    cbvh_fw_rx(&dev.fw, data + 2, data[1]);
    return (int)length;
}
int hid_read_timeout(hid_device *d, unsigned char *data, size_t length, int ms) {
    (void)ms;
    if (d != (hid_device *)&fake_handle || length != 64) return -1;
    if (dev.inject_bad_report) { /* a report claiming more bytes than it can hold */
        dev.inject_bad_report = 0;
        memset(data, 0xCB, 64);
        data[0] = 200;
        return 64;
    }
    if (dev.tail == dev.head) return 0;
    memcpy(data, dev.q[dev.tail++ % REPORTS], 64);
    dev.reports_in++;
    return 64;
}

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stderr, c, __VA_ARGS__)

int main(void) {
    char err[512];
    cbvh_backend b, model;
    unsetenv("CBVH_USB_VID");
    unsetenv("CBVH_USB_PID");
    /* No device: hid reports none, auto falls back to the model. */
    CHECK(cbvh_backend_open("hid", &b, NULL, err, sizeof err) != 0 && strstr(err, "no HID device"), "absent: '%s'", err);

    dev.present = 1;
    /* Bad identity settings: one line naming the variable, no enumeration
     * (strtoul took "zzzz" as 0000, "123456" as 3456, "-1" as ffff). */
    static const char *const bad[][2] = {{"CBVH_USB_VID", "zzzz"}, {"CBVH_USB_VID", "123456"}, {"CBVH_USB_PID", "-1"},
                                         {"CBVH_USB_PID", "0xc0b1 "}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char want[128];
        snprintf(want, sizeof want, "%s='%s' is not a USB ID (expected 1 to 4 hex digits", bad[i][0], bad[i][1]);
        setenv(bad[i][0], bad[i][1], 1);
        unsigned long en = dev.enumerates;
        int rc = cbvh_backend_open("hid", &b, NULL, err, sizeof err);
        CHECK(rc != 0 && strstr(err, want) && !strchr(err, '\n') && dev.enumerates == en && !dev.opened,
              "%s=%s: open gave %d, '%s'", bad[i][0], bad[i][1], rc, err);
        FILE *f = tmpfile();
        CHECK(cbvh_backend_hid.list(NULL, f) == 0 && dev.enumerates == en, "%s=%s: listing probed anyway", bad[i][0],
              bad[i][1]);
        char line[300] = "";
        rewind(f);
        CHECK(fgets(line, sizeof line, f) && strncmp(line, "hid:   not probed (", 19) == 0 && strstr(line, want),
              "%s=%s: listing said '%s'", bad[i][0], bad[i][1], line);
        fclose(f);
        unsetenv(bad[i][0]);
    }
    cbvh_regmap_model_init(&dev.regs);
    cbvh_fw_init(&dev.fw, &hal);
    if (cbvh_backend_open("hid", &b, NULL, err, sizeof err)) {
        fprintf(stderr, "FAIL: open hid: %s\n", err);
        return 1;
    }
    printf("opened: %s\n", b.label);
    CHECK(strstr(b.label, "hid-fake") != NULL, "label '%s'", b.label);
    if (cbvh_backend_open("model", &model, NULL, err, sizeof err)) return 1;
    uint64_t rng = 5;
    size_t total = 0;
    for (int u = 0; u < cbvh_unit_count; u++)
        for (int n = 3; n <= 10; n += 7) {
            const cbvh_unit *unit = cbvh_units[u];
            cbvh_unit_config cfg = {{n, -30}, u % 2 ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO};
            cbvh_layout lay;
            unit->layout(&cfg, &lay);
            size_t count = 300;
            uint32_t *in = malloc(count * (size_t)lay.n_in * 4), *a = malloc(count * (size_t)lay.n_out * 4),
                     *o = malloc(count * (size_t)lay.n_out * 4);
            cbvh_gen_inputs(&rng, &cfg, &lay, in, count);
            model.ops->run(&model, unit, &cfg, in, a, count, err, sizeof err);
            int rc = b.ops->run(&b, unit, &cfg, in, o, count, err, sizeof err);
            CHECK(rc == 0, "%s: %s", unit->name, err);
            CHECK(rc != 0 || memcmp(a, o, count * (size_t)lay.n_out * 4) == 0, "%s N=%d: hid differs from model",
                  unit->name, n);
            total += count;
            free(in), free(a), free(o);
        }
    cbvh_link *l = cbvh_backend_link(&b);
    /* A malformed report on the way in is dropped and the exchange recovers. */
    dev.inject_bad_report = 1;
    l->timeout_ms = 50;
    CHECK(cbvh_link_identify(l, err, sizeof err) == 0, "after a bad report: %s", err);
    char line[512];
    cbvh_link_stats_line(&l->st, line, sizeof line);
    printf("%zu vectors through 64-byte reports equal the model; %lu reports out, %lu in; link: %s\n", total,
           dev.writes, dev.reports_in, line);
    CHECK(dev.bad_writes == 0, "%lu malformed reports written", dev.bad_writes);
    cbvh_backend_close(&b);
    CHECK(!dev.opened, "device left open");

    /* auto: no usb bus here (or no usb board), the hid board is taken. */
    if (cbvh_backend_open("auto", &b, stderr, err, sizeof err) == 0) {
        CHECK(b.ops == &cbvh_backend_hid || b.ops == &cbvh_backend_usb, "auto chose %s", b.label);
        printf("auto: %s\n", b.label);
        cbvh_backend_close(&b);
    } else {
        CHECK(0, "auto: %s", err);
    }
    cbvh_backend_close(&model);
    return fails ? 1 : 0;
}
