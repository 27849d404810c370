/* The RP2040 port's USB device stack (firmware/ports/rp2040_ice40/usbd.c,
 * usb_desc.c, usb_link.c) on the host with the controller port mocked,
 * TinyUSB style: setup packets in, endpoint 0 responses checked byte by byte
 * (descriptors against docs/protocol.md and docs/board.md); malformed and
 * out-of-state requests are STALLed and the device still enumerates after;
 * frames through the bulk and HID links reach the firmware core (with the
 * model's register map) and their replies come back whole; an oversized
 * flood is NAKed, never overrun; a host that stops reading mid-reply costs a
 * bounded wait and the next request is served. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cbvh_fw/fw.h"
#include "cbvh_fw/payload.h"
#include "cbvh_sim.h"
#include "usb_link.h"
#include "usbd.h"

/* ---- mock controller ---- */
typedef struct {
    int open, armed, stalled, type;
    uint8_t *dst;
    uint16_t len;
    uint8_t data[64];
} mock_ep;
static mock_ep eps[16][2]; /* [n][out] */
static int addr_now, addr_calls, aborts;

static mock_ep *ep_of(uint8_t ep) { return &eps[ep & 0xF][!(ep & 0x80)]; }
static void m_set_address(void *c, uint8_t a) { (void)c, addr_now = a, addr_calls++; }
static void m_ep_open(void *c, uint8_t ep, uint8_t type, uint16_t mps) {
    (void)c;
    assert_int_equal(mps, 64);
    mock_ep *e = ep_of(ep);
    memset(e, 0, sizeof *e);
    e->open = 1;
    e->type = type;
}
static void m_close_all(void *c) {
    (void)c;
    for (int n = 1; n < 16; n++) memset(eps[n], 0, sizeof eps[n]);
}
static void m_xfer(void *c, uint8_t ep, uint8_t *data, uint16_t len) {
    (void)c;
    mock_ep *e = ep_of(ep);
    assert_false(e->armed); /* never armed twice */
    assert_true(len <= 64);
    assert_true((ep & 0xF) == 0 || e->open);
    e->armed = 1;
    e->len = len;
    e->dst = data;
    if ((ep & 0x80) && len) memcpy(e->data, data, len);
}
static void m_abort(void *c, uint8_t ep) {
    (void)c;
    ep_of(ep)->armed = 0;
    aborts++;
}
static void m_stall(void *c, uint8_t ep, int on) {
    (void)c;
    if ((ep & 0xF) == 0) {
        eps[0][0].stalled = eps[0][1].stalled = on;
        eps[0][0].armed = eps[0][1].armed = 0;
    } else {
        ep_of(ep)->stalled = on;
        ep_of(ep)->armed = 0;
    }
}
static const usbd_port mport = {0, m_set_address, m_ep_open, m_close_all, m_xfer, m_abort, m_stall};

/* ---- device under test: stack + link + firmware core on the model ---- */
static usbd_dev dev;
static usb_link lnk;
static cbvh_fw fw;
static cbvh_regmap_model regs;
static cbvh_fw_hal hal;
static uint32_t now;
static int host_reading = 1;
static uint8_t host_in[3 * CBVH_FRAME_MAX];
static size_t host_in_len;
static int zlps;

/* The host side of the IN endpoints, as the port's poll would deliver it. */
static void collect_in(void) {
    for (int n = 1; n <= 2; n++) {
        mock_ep *e = &eps[n][0];
        if (!e->armed || !host_reading) continue;
        e->armed = 0;
        if (n == 2) { /* HID report: [count][bytes] */
            assert_int_equal(e->len, 64);
            assert_true(e->data[0] >= 1 && e->data[0] <= 63);
            memcpy(host_in + host_in_len, e->data + 1, e->data[0]);
            host_in_len += e->data[0];
        } else {
            if (e->len == 0) zlps++;
            memcpy(host_in + host_in_len, e->data, e->len);
            host_in_len += e->len;
        }
        usbd_xfer_done(&dev, (uint8_t)(0x80 | n), e->len);
    }
}
static void poll(void *c) {
    (void)c;
    now += 10;
    collect_in();
}
static uint32_t now_us(void *c) { return (void)c, now; }

/* hal.ctx is send's (the link), as in main.c; the register map is the model's. */
static uint32_t rd(void *c, uint32_t a) { return (void)c, cbvh_regmap_model_read(&regs, a); }
static void wr(void *c, uint32_t a, uint32_t v) { (void)c, cbvh_regmap_model_write(&regs, a, v); }

static int setup(void **s) {
    (void)s;
    memset(eps, 0, sizeof eps);
    addr_now = addr_calls = aborts = zlps = 0;
    host_reading = 1;
    host_in_len = 0;
    now = 0;
    usb_link_init(&lnk, &dev, poll, now_us, 0, 250000);
    usbd_init(&dev, &mport, &lnk.cls);
    cbvh_regmap_model_init(&regs);
    hal = (cbvh_fw_hal){&lnk, rd, wr, usb_link_send, "cbvh-rp2040"};
    cbvh_fw_init(&fw, &hal);
    return 0;
}

/* One control transfer as a host does it: returns the bytes of the data
 * stage, or -1 for a STALL. */
static int ctl(uint8_t bm, uint8_t req, uint16_t wvalue, uint16_t windex, uint16_t wlength, uint8_t *in) {
    uint8_t s[8] = {bm, req, (uint8_t)wvalue, (uint8_t)(wvalue >> 8), (uint8_t)windex, (uint8_t)(windex >> 8),
                    (uint8_t)wlength, (uint8_t)(wlength >> 8)};
    eps[0][0].stalled = eps[0][1].stalled = 0; /* the controller clears a stall on SETUP */
    usbd_setup(&dev, s);
    int got = 0;
    for (int guard = 0; guard < 100; guard++) {
        if (eps[0][0].stalled || eps[0][1].stalled) return -1;
        if (eps[0][0].armed) { /* IN: data or status */
            eps[0][0].armed = 0;
            assert_true(got + eps[0][0].len <= wlength || eps[0][0].len == 0);
            if (in) memcpy(in + got, eps[0][0].data, eps[0][0].len);
            got += eps[0][0].len;
            usbd_xfer_done(&dev, 0x80, eps[0][0].len);
        } else if (eps[0][1].armed) { /* OUT status stage */
            eps[0][1].armed = 0;
            usbd_xfer_done(&dev, 0x00, 0);
        } else {
            assert_int_equal(dev.ctl_stage, USBD_CTL_IDLE);
            return got;
        }
    }
    fail_msg("control transfer did not end");
    return -2;
}

/* The fixture of the tests that start from a bus reset, before enumeration. */
static int setup_reset(void **s) {
    setup(s);
    usbd_bus_reset(&dev);
    return 0;
}

static void enumerate(void) {
    usbd_bus_reset(&dev);
    uint8_t b[256];
    assert_int_equal(ctl(0x80, 6, 0x0100, 0, 64, b), 18);
    assert_int_equal(ctl(0x00, 5, 7, 0, 0, NULL), 0);
    assert_int_equal(addr_now, 7);
    assert_int_equal(ctl(0x00, 9, 1, 0, 0, NULL), 0);
}

/* The fixture of the tests that start from an enumerated, configured device. */
static int setup_configured(void **s) {
    setup(s);
    enumerate();
    return 0;
}

static void test_device_descriptor(void **s) {
    (void)s;
    uint8_t b[256];
    assert_int_equal(ctl(0x80, 6, 0x0100, 0, 8, b), 8); /* first 8 bytes, as Linux asks */
    assert_int_equal(ctl(0x80, 6, 0x0100, 0, 255, b), 18);
    assert_int_equal(ctl(0x80, 6, 0x0100, 0, 0, b), 0); /* wLength 0: no data stage, status IN */
    static const uint8_t want[18] = {18, 1, 0x00, 0x02, 0, 0, 0, 64, 0x09, 0x12, 0xB1, 0xC0, 0x10, 0x00, 1, 2, 3, 1};
    assert_memory_equal(b, want, 18);
}

static void test_config_descriptor(void **s) {
    (void)s;
    uint8_t b[512];
    assert_int_equal(ctl(0x80, 6, 0x0200, 0, 9, b), 9);
    assert_int_equal(b[2] | b[3] << 8, 64);
    assert_int_equal(b[4], 2); /* interfaces */
    zlps = 0;
    /* exactly 64 bytes asked with 255: one full packet then a zero-length one */
    assert_int_equal(ctl(0x80, 6, 0x0200, 0, 255, b), 64);
    static const struct {
        int at, n;
        uint8_t d[9];
    } want[] = {
        {9, 9, {9, 4, 0, 0, 2, 0xFF, 0, 0, 4}}, /* interface 0: vendor, 2 endpoints */
        {18, 7, {7, 5, 0x01, 2, 64, 0, 0}},      /* bulk OUT */
        {25, 7, {7, 5, 0x81, 2, 64, 0, 0}},      /* bulk IN */
        {32, 9, {9, 4, 1, 0, 2, 3, 0, 0, 5}},    /* interface 1: HID */
        {41, 2, {9, 0x21}},                      /* HID descriptor */
        {50, 7, {7, 5, 0x82, 3, 64, 0, 1}},      /* interrupt IN, 1 ms */
        {57, 7, {7, 5, 0x02, 3, 64, 0, 1}},      /* interrupt OUT, 1 ms */
    };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) assert_memory_equal(b + want[i].at, want[i].d, want[i].n);
    assert_int_equal(ctl(0x81, 6, 0x2200, 1, 255, b), -1); /* interface requests: only once configured */
}

static void string_is(int index, const char *want) {
    uint8_t b[256];
    int n = ctl(0x80, 6, (uint16_t)(0x0300 | index), 0x0409, 255, b);
    assert_int_equal(n, 2 + 2 * (int)strlen(want));
    assert_int_equal(b[0], n);
    assert_int_equal(b[1], 3);
    for (size_t i = 0; i < strlen(want); i++) {
        assert_int_equal(b[2 + 2 * i], want[i]);
        assert_int_equal(b[3 + 2 * i], 0);
    }
}

static void test_strings(void **s) {
    (void)s;
    uint8_t b[8];
    assert_int_equal(ctl(0x80, 6, 0x0300, 0, 255, b), 4);
    assert_int_equal(b[2] | b[3] << 8, 0x0409);
    string_is(1, "cbvh");
    string_is(2, "cbvh board"); /* docs/protocol.md */
    string_is(3, "0001");
    string_is(4, "cbvh bulk link");
    string_is(5, "cbvh hid link");
    assert_int_equal(ctl(0x80, 6, 0x0306, 0x0409, 255, b), -1);
}

static void test_address_after_status(void **s) {
    (void)s;
    uint8_t st[8] = {0x00, 5, 42, 0, 0, 0, 0, 0};
    usbd_setup(&dev, st);
    assert_int_equal(addr_now, 0); /* not before the status stage */
    assert_true(eps[0][0].armed && eps[0][0].len == 0);
    eps[0][0].armed = 0;
    usbd_xfer_done(&dev, 0x80, 0);
    assert_int_equal(addr_now, 42);
    usbd_bus_reset(&dev);
    assert_int_equal(addr_now, 0);
}

static void test_configuration_and_status(void **s) {
    (void)s;
    uint8_t b[8];
    assert_int_equal(ctl(0x80, 8, 0, 0, 1, b), 1);
    assert_int_equal(b[0], 1);
    assert_true(eps[1][0].open && eps[1][1].open && eps[2][0].open && eps[2][1].open);
    assert_int_equal(eps[1][1].type, USBD_XFER_BULK);
    assert_int_equal(eps[2][0].type, USBD_XFER_INTERRUPT);
    assert_true(eps[1][1].armed && eps[2][1].armed); /* OUT endpoints ready for the host */
    assert_int_equal(ctl(0x80, 0, 0, 0, 2, b), 2);
    assert_int_equal(b[0] | b[1], 0);
    assert_int_equal(ctl(0x81, 0, 0, 1, 2, b), 2);
    assert_int_equal(ctl(0x81, 10, 0, 0, 1, b), 1);
    assert_int_equal(ctl(0x01, 11, 0, 1, 0, NULL), 0);
    assert_int_equal(ctl(0x01, 11, 1, 1, 0, NULL), -1); /* no alternate settings */
    /* HID descriptor and report descriptor through the HID interface */
    uint8_t r[256];
    assert_int_equal(ctl(0x81, 6, 0x2100, 1, 255, r), 9);
    int rl = r[7];
    assert_int_equal(ctl(0x81, 6, 0x2200, 1, 255, r), rl);
    assert_int_equal(r[0], 0x06); /* vendor usage page */
    assert_int_equal(ctl(0x81, 6, 0x2200, 0, 255, r), -1); /* not the vendor interface */
    assert_int_equal(ctl(0x21, 10, 0, 1, 0, NULL), 0);      /* SET_IDLE */
    assert_int_equal(ctl(0xA1, 1, 0x0100, 1, 64, r), -1);   /* GET_REPORT: reports go on the interrupt pipe */
    /* SET_CONFIGURATION(0) closes the data endpoints */
    assert_int_equal(ctl(0x00, 9, 0, 0, 0, NULL), 0);
    assert_false(eps[1][1].open);
    assert_int_equal(ctl(0x82, 0, 0, 0x81, 2, b), -1); /* data endpoints only exist when configured */
}

static void test_halt_and_clear(void **s) {
    (void)s;
    uint8_t b[2];
    assert_int_equal(ctl(0x82, 0, 0, 0x81, 2, b), 2);
    assert_int_equal(b[0], 0);
    assert_int_equal(ctl(0x02, 3, 0, 0x81, 0, NULL), 0); /* SET_FEATURE(ENDPOINT_HALT) */
    assert_true(eps[1][0].stalled);
    assert_int_equal(ctl(0x82, 0, 0, 0x81, 2, b), 2);
    assert_int_equal(b[0], 1);
    assert_false(usbd_tx_ready(&dev));
    assert_int_equal(ctl(0x02, 1, 0, 0x81, 0, NULL), 0); /* CLEAR_FEATURE(ENDPOINT_HALT) */
    assert_false(eps[1][0].stalled);
    assert_int_equal(ctl(0x82, 0, 0, 0x81, 2, b), 2);
    assert_int_equal(b[0], 0);
    assert_true(usbd_tx_ready(&dev));
    /* OUT: halting takes the armed buffer back; clearing re-arms it */
    assert_int_equal(ctl(0x02, 3, 0, 0x01, 0, NULL), 0);
    assert_false(eps[1][1].armed);
    assert_int_equal(ctl(0x02, 1, 0, 0x01, 0, NULL), 0);
    assert_true(eps[1][1].armed);
    assert_int_equal(ctl(0x02, 1, 0, 0x00, 0, NULL), 0);  /* clearing endpoint 0: a no-op */
    assert_int_equal(ctl(0x02, 3, 0, 0x80, 0, NULL), -1); /* halting it: a request error */
    assert_int_equal(ctl(0x02, 1, 1, 0x81, 0, NULL), -1); /* unknown endpoint feature */
}

static void test_malformed_setups(void **s) {
    (void)s;
    uint8_t b[256];
    assert_int_equal(ctl(0x80, 0xFF, 0, 0, 64, b), -1);         /* unknown request */
    assert_int_equal(ctl(0xC0, 1, 0, 0, 64, b), -1);            /* vendor */
    assert_int_equal(ctl(0xE0, 1, 0, 0, 64, b), -1);            /* reserved type */
    assert_int_equal(ctl(0x00, 7, 0x0100, 0, 18, NULL), -1);    /* SET_DESCRIPTOR, with data */
    assert_int_equal(ctl(0x00, 5, 200, 0, 0, NULL), -1);        /* address > 127 */
    assert_int_equal(ctl(0x00, 5, 3, 0, 0, NULL), -1);          /* SET_ADDRESS while configured */
    assert_int_equal(ctl(0x00, 9, 2, 0, 0, NULL), -1);          /* no configuration 2 */
    assert_int_equal(ctl(0x80, 6, 0x0600, 0, 10, b), -1);       /* device qualifier: full speed only */
    assert_int_equal(ctl(0x80, 6, 0x0101, 0, 18, b), -1);       /* device descriptor index 1 */
    assert_int_equal(ctl(0x80, 6, 0x2200, 0, 64, b), -1);       /* report descriptor from the device */
    assert_int_equal(ctl(0x82, 0, 0, 0x85, 2, b), -1);          /* no endpoint 5 */
    assert_int_equal(ctl(0x82, 0, 0, 0x0181, 2, b), -1);        /* high byte of wIndex set */
    assert_int_equal(ctl(0x81, 0, 0, 7, 2, b), -1);             /* no interface 7 */
    assert_int_equal(ctl(0x00, 3, 1, 0, 0, NULL), -1);          /* remote wakeup: not offered */
    assert_int_equal(ctl(0x00, 3, 2, 0, 0, NULL), -1);          /* test mode */
    assert_int_equal(ctl(0x80, 0, 1, 0, 2, b), -1);             /* GET_STATUS with wValue */
    assert_int_equal(ctl(0x21, 9, 0x0200, 1, 64, NULL), -1);    /* SET_REPORT with data */
    assert_int_equal(ctl(0x21, 10, 0, 0, 0, NULL), -1);         /* SET_IDLE to the vendor interface */
    /* a SETUP in the middle of a data stage starts over */
    uint8_t st[8] = {0x80, 6, 0, 2, 0, 0, 255, 0};
    usbd_setup(&dev, st);
    assert_true(eps[0][0].armed);
    eps[0][0].armed = 0; /* the host never took it: lost */
    assert_int_equal(ctl(0x80, 6, 0x0100, 0, 18, b), 18);
    assert_int_equal(b[8], 0x09);
    /* stale completions on endpoint 0 change nothing */
    usbd_xfer_done(&dev, 0x80, 64);
    usbd_xfer_done(&dev, 0x00, 0);
    assert_int_equal(dev.ctl_stage, USBD_CTL_IDLE);
    assert_int_equal(dev.n.stalls, 18);
    /* still a working device */
    assert_int_equal(ctl(0x80, 8, 0, 0, 1, b), 1);
    assert_int_equal(b[0], 1);
}

/* Random setup packets and events: no crash, no write out of bounds, and
 * the device enumerates afterwards. */
static void test_setup_fuzz(void **s) {
    (void)s;
    srand(12345);
    uint8_t b[4096];
    for (int i = 0; i < 20000; i++) {
        uint8_t st[8];
        for (int k = 0; k < 8; k++) st[k] = (uint8_t)rand();
        if (i % 3 == 0) st[0] &= 0x83; /* standard requests more often */
        if (i % 5 == 0) st[1] &= 0x0F;
        if (i % 7 == 0) { /* the host wanders off mid-transfer */
            eps[0][0].stalled = eps[0][1].stalled = 0;
            usbd_setup(&dev, st);
            eps[0][0].armed = eps[0][1].armed = 0;
            continue;
        }
        int n = ctl(st[0], st[1], (uint16_t)(st[2] | st[3] << 8), (uint16_t)(st[4] | st[5] << 8),
                    (uint16_t)(st[6] | st[7] << 8), b);
        assert_true(n >= -1 && n <= (st[6] | st[7] << 8));
        if (i % 11 == 0) usbd_xfer_done(&dev, (uint8_t)rand(), (uint16_t)rand()); /* spurious completions */
        if (i % 997 == 0) usbd_bus_reset(&dev);
    }
    enumerate();
    assert_int_equal(ctl(0x80, 6, 0x0100, 0, 18, b), 18);
}

/* ---- the links ---- */

static void device_step(void) {
    uint8_t buf[64];
    size_t n;
    while ((n = usb_link_take(&lnk, buf, sizeof buf)) > 0) cbvh_fw_rx(&fw, buf, n);
    for (int i = 0; i < 3; i++) collect_in(); /* the reply's last packet, and a zero-length one after it */
}

/* Writes bytes to an OUT endpoint in packets, as the host controller would;
 * returns the packets the device NAKed (not armed) and left unsent. */
static size_t host_out(uint8_t ep, const uint8_t *data, size_t n, int drain) {
    mock_ep *e = &eps[ep][1];
    while (n) {
        if (!e->armed) {
            if (!drain) return n;
            device_step();
            assert_true(e->armed);
        }
        size_t k = n < 64 ? n : 64;
        e->armed = 0;
        memcpy(e->dst, data, k);
        usbd_xfer_done(&dev, ep, (uint16_t)k);
        data += k;
        n -= k;
    }
    return 0;
}

static void host_out_hid(const uint8_t *data, size_t n) {
    while (n) {
        uint8_t rep[64] = {0};
        size_t k = n < 63 ? n : 63;
        rep[0] = (uint8_t)k;
        memcpy(rep + 1, data, k);
        assert_int_equal(host_out(2, rep, 64, 1), 0);
        data += k;
        n -= k;
    }
}

static size_t request(uint8_t *buf, uint8_t cmd, uint16_t seq, const uint8_t *payload, uint16_t len) {
    if (len) memcpy(buf + CBVH_FRAME_HDR, payload, len);
    return cbvh_frame_seal(buf, cmd, 0, seq, len);
}

static void expect_reply(uint8_t cmd, uint16_t seq, uint8_t status, uint16_t len) {
    cbvh_frame f;
    if (host_in_len < 12) fail_msg("no reply (%zu bytes back; link %d, config %d)", host_in_len, dev.link, dev.config);
    assert_int_equal(cbvh_frame_decode(host_in, host_in_len, &f), 0);
    assert_int_equal(f.cmd, cmd | CBVH_REPLY);
    assert_int_equal(f.seq, seq);
    assert_int_equal(f.status, status);
    assert_int_equal(f.len, len);
}

static void test_bulk_identify_and_loopback(void **s) {
    (void)s;
    static uint8_t req[CBVH_FRAME_MAX], payload[CBVH_FRAME_MAX_PAYLOAD];
    size_t n = request(req, CBVH_CMD_IDENTIFY, 1, NULL, 0);
    host_out(1, req, n, 1);
    device_step();
    expect_reply(CBVH_CMD_IDENTIFY, 1, 0, CBVH_IDENTITY_BYTES);
    assert_string_equal((const char *)host_in + CBVH_FRAME_HDR + 20, "cbvh-rp2040");
    assert_int_equal(cbvh_get32(host_in + CBVH_FRAME_HDR + 16), 0x48564243u);
    /* the largest frame: 4108 bytes, 64 full packets and a short one */
    for (unsigned i = 0; i < sizeof payload; i++) payload[i] = (uint8_t)(i * 7 + 3);
    host_in_len = 0;
    n = request(req, CBVH_CMD_LOOPBACK, 2, payload, CBVH_FRAME_MAX_PAYLOAD);
    host_out(1, req, n, 1);
    device_step();
    expect_reply(CBVH_CMD_LOOPBACK, 2, 0, CBVH_FRAME_MAX_PAYLOAD);
    assert_memory_equal(host_in + CBVH_FRAME_HDR, payload, CBVH_FRAME_MAX_PAYLOAD);
    /* a reply of exactly 64 bytes ends with a zero-length packet */
    host_in_len = 0;
    zlps = 0;
    n = request(req, CBVH_CMD_LOOPBACK, 3, payload, 64 - 12);
    host_out(1, req, n, 1);
    device_step();
    expect_reply(CBVH_CMD_LOOPBACK, 3, 0, 52);
    assert_int_equal(zlps, 1);
}

static void test_hid_link(void **s) {
    (void)s;
    static uint8_t req[CBVH_FRAME_MAX], payload[300];
    for (unsigned i = 0; i < sizeof payload; i++) payload[i] = (uint8_t)(255 - i);
    size_t n = request(req, CBVH_CMD_LOOPBACK, 9, payload, sizeof payload);
    host_out_hid(req, n);
    device_step();
    expect_reply(CBVH_CMD_LOOPBACK, 9, 0, sizeof payload); /* the reply came back as HID reports */
    assert_memory_equal(host_in + CBVH_FRAME_HDR, payload, sizeof payload);
    assert_int_equal(dev.link, USBD_LINK_HID);
    /* malformed reports are dropped and counted */
    uint8_t bad[64] = {0};
    host_out(2, bad, 64, 1); /* count 0 */
    bad[0] = 64;
    host_out(2, bad, 64, 1); /* count past the report */
    bad[0] = 10;
    host_out(2, bad, 5, 1); /* short report claiming 10 bytes */
    assert_int_equal(dev.n.hid_bad_reports, 3);
    /* a RUN through HID on the model's register map: scale_estimate */
    host_in_len = 0;
    uint8_t run[12 + 8] = {1, 6, (uint8_t)-30, 0xFF, 0, 0, 0, 0, 1, 0, 0, 0};
    cbvh_layout lay;
    cbvh_unit_config c = cbvh_regmap_config(6u | (uint32_t)(uint16_t)-30 << 8);
    cbvh_unit_by_id(1)->layout(&c, &lay);
    run[5] = (uint8_t)lay.n_in;
    run[6] = (uint8_t)lay.n_out;
    n = request(req, CBVH_CMD_RUN, 10, run, (uint16_t)(12 + 4 * lay.n_in));
    host_out_hid(req, n);
    device_step();
    expect_reply(CBVH_CMD_RUN, 10, 0, (uint16_t)(4 + 4 * lay.n_out));
}

static void test_oversized_flood_is_nacked(void **s) {
    (void)s;
    static uint8_t junk[20000];
    for (unsigned i = 0; i < sizeof junk; i++) junk[i] = (uint8_t)(i * 13 + 1);
    junk[0] = CBVH_FRAME_MAGIC; /* looks like a frame with a length past 4096 */
    junk[1] = 1;
    junk[6] = 0xFF;
    junk[7] = 0xFF;
    /* without the main loop draining, the ring fills and OUT stops being armed */
    size_t left = host_out(1, junk, sizeof junk, 0);
    assert_int_equal(left, sizeof junk - USB_LINK_RING);
    assert_true(dev.n.rx_held > 0);
    assert_true(lnk.head - lnk.tail <= USB_LINK_RING);
    /* draining re-arms it: the rest goes through and the core answers with errors */
    host_out(1, junk + sizeof junk - left, left, 1);
    device_step();
    assert_true(host_in_len > 0);
    assert_true(fw.n.header_errors + fw.n.sync_errors > 0);
    /* a proper frame after the flood is answered */
    now += 30000;
    cbvh_fw_rx_idle(&fw);
    host_in_len = 0;
    static uint8_t req[64];
    size_t n = request(req, CBVH_CMD_STATUS, 77, NULL, 0);
    host_out(1, req, n, 1);
    device_step();
    cbvh_frame f;
    size_t off = 0; /* skip error replies that drained the flood */
    int found = 0;
    while (off + 12 <= host_in_len) {
        size_t flen = 12 + (size_t)cbvh_get16(host_in + off + 6);
        if (off + flen > host_in_len) break;
        if (cbvh_frame_decode(host_in + off, flen, &f) == 0 && f.seq == 77 && f.status == 0) found = 1;
        off += flen;
    }
    assert_true(found);
}

static void test_vanished_host(void **s) {
    (void)s;
    static uint8_t req[CBVH_FRAME_MAX], payload[2000];
    size_t n = request(req, CBVH_CMD_LOOPBACK, 5, payload, sizeof payload);
    host_out(1, req, n, 1);
    host_reading = 0; /* the host process died: nobody takes IN packets */
    uint32_t t0 = now;
    device_step();
    assert_true(now - t0 >= 250000 && now - t0 < 300000); /* bounded wait */
    assert_int_equal(lnk.tx_dropped, 1);
    assert_int_equal(aborts, 1);
    assert_false(eps[1][0].armed);
    /* a new host: the next request is served in full */
    host_reading = 1;
    host_in_len = 0;
    n = request(req, CBVH_CMD_IDENTIFY, 6, NULL, 0);
    host_out(1, req, n, 1);
    device_step();
    expect_reply(CBVH_CMD_IDENTIFY, 6, 0, CBVH_IDENTITY_BYTES);
    /* a bus reset in the middle of a reply drops it at once */
    host_reading = 0;
    host_in_len = 0;
    n = request(req, CBVH_CMD_LOOPBACK, 7, payload, sizeof payload);
    host_out(1, req, n, 1);
    usbd_bus_reset(&dev);
    t0 = now;
    device_step();
    assert_true(now - t0 < 1000);
    assert_int_equal(lnk.tx_dropped, 2);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_device_descriptor, setup_reset),
        cmocka_unit_test_setup(test_config_descriptor, setup_reset),
        cmocka_unit_test_setup(test_strings, setup_reset),
        cmocka_unit_test_setup(test_address_after_status, setup_reset),
        cmocka_unit_test_setup(test_configuration_and_status, setup_configured),
        cmocka_unit_test_setup(test_halt_and_clear, setup_configured),
        cmocka_unit_test_setup(test_malformed_setups, setup_configured),
        cmocka_unit_test_setup(test_setup_fuzz, setup_configured),
        cmocka_unit_test_setup(test_bulk_identify_and_loopback, setup_configured),
        cmocka_unit_test_setup(test_hid_link, setup_configured),
        cmocka_unit_test_setup(test_oversized_flood_is_nacked, setup_configured),
        cmocka_unit_test_setup(test_vanished_host, setup_configured),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
