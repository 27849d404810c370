/* Firmware core with its HAL mocked (cmocka, TinyUSB style): the register
 * traffic of a RUN is checked access by access; the reply frames are decoded
 * and checked field by field; every kind of malformed frame gets exactly its
 * error reply and the core keeps answering. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "cbvh_fw/fw.h"
#include "cbvh_fw/payload.h"
#include "cbvh_fw/regmap.h"
#include "cbvh_sim.h"

/* ---- strict mock HAL ---- */
static uint32_t mock_read(void *ctx, uint32_t addr) {
    (void)ctx;
    check_expected(addr);
    return mock_type(uint32_t);
}
static void mock_write(void *ctx, uint32_t addr, uint32_t value) {
    (void)ctx;
    check_expected(addr);
    check_expected(value);
}

/* Replies are captured for inspection. */
static uint8_t sent[16][CBVH_FRAME_MAX];
static size_t sent_len[16];
static int n_sent;
static void capture_send(void *ctx, const uint8_t *frame, size_t len) {
    (void)ctx;
    assert_true(len <= CBVH_FRAME_MAX);
    if (n_sent < 16) {
        memcpy(sent[n_sent], frame, len);
        sent_len[n_sent] = len;
    }
    n_sent++;
}

static const cbvh_fw_hal mock_hal = {NULL, mock_read, mock_write, capture_send, "mockboard"};
static cbvh_fw fw;

static void expect_write(uint32_t addr, uint32_t value) {
    expect_value(mock_write, addr, addr);
    expect_value(mock_write, value, value);
}
static void expect_read(uint32_t addr, uint32_t ret) {
    expect_value(mock_read, addr, addr);
    will_return(mock_read, ret);
}

static int setup(void **s) {
    (void)s;
    n_sent = 0;
    expect_write(CBVH_REG_CTRL, CBVH_CTRL_RESET);
    cbvh_fw_init(&fw, &mock_hal);
    return 0;
}

static void send_frame(uint8_t cmd, uint16_t seq, const uint8_t *payload, uint16_t len) {
    static uint8_t buf[CBVH_FRAME_MAX];
    if (len) memcpy(buf + CBVH_FRAME_HDR, payload, len);
    size_t n = cbvh_frame_seal(buf, cmd, 0, seq, len);
    cbvh_fw_rx(&fw, buf, n);
}

static cbvh_frame reply_at(int i) {
    cbvh_frame f;
    assert_true(i < n_sent);
    assert_int_equal(cbvh_frame_decode(sent[i], sent_len[i], &f), CBVH_E_OK);
    return f;
}

static void identify(void **s) {
    (void)s;
    expect_read(CBVH_REG_VERSION, 7);
    expect_read(CBVH_REG_UNITS, 0x3E);
    expect_read(CBVH_REG_ID, CBVH_REG_ID_VALUE);
    send_frame(CBVH_CMD_IDENTIFY, 42, NULL, 0);
    assert_int_equal(n_sent, 1);
    cbvh_frame f = reply_at(0);
    assert_int_equal(f.cmd, CBVH_CMD_IDENTIFY | CBVH_REPLY);
    assert_int_equal(f.status, CBVH_E_OK);
    assert_int_equal(f.seq, 42);
    assert_int_equal(f.len, CBVH_IDENTITY_BYTES);
    assert_int_equal(f.payload[0], CBVH_PROTO_VERSION);
    assert_int_equal(cbvh_get32(f.payload + 4), 7);
    assert_int_equal(cbvh_get32(f.payload + 8), 0x3E);
    assert_int_equal(cbvh_get16(f.payload + 12), CBVH_FRAME_MAX_PAYLOAD);
    assert_string_equal((const char *)f.payload + 20, "mockboard");
}

static void run_header(uint8_t *p, uint8_t unit, int8_t n, int16_t min, uint8_t enc, uint8_t nin, uint8_t nout,
                       uint16_t count) {
    memset(p, 0, 12);
    p[0] = unit;
    p[1] = (uint8_t)n;
    cbvh_put16(p + 2, (uint16_t)min);
    p[4] = enc;
    p[5] = nin;
    p[6] = nout;
    cbvh_put16(p + 8, count);
}

/* Two vectors of a 3-in/2-out unit: exact register sequence. */
static void run_register_sequence(void **s) {
    (void)s;
    uint8_t p[12 + 2 * 3 * 4];
    run_header(p, 2, 6, -30, 1, 3, 2, 2);
    for (int i = 0; i < 6; i++) cbvh_put32(p + 12 + 4 * i, 0x100u + (uint32_t)i);
    cbvh_fw_config c = {6, -30, 1};
    expect_read(CBVH_REG_UNITS, 1u << 2);
    expect_write(CBVH_REG_CONFIG, cbvh_dp_config_word(&c));
    expect_write(CBVH_REG_UNIT_SEL, 2);
    expect_read(CBVH_REG_SHAPE, 3 | 2 << 8);
    for (int v = 0; v < 2; v++) {
        for (int i = 0; i < 3; i++) expect_write(CBVH_REG_IN(i), 0x100u + (uint32_t)(3 * v + i));
        expect_write(CBVH_REG_CTRL, CBVH_CTRL_START);
        expect_read(CBVH_REG_STATUS, CBVH_STAT_BUSY); /* one busy poll, then done */
        expect_read(CBVH_REG_STATUS, CBVH_STAT_DONE);
        expect_read(CBVH_REG_OUT(0), 0xA0u + (uint32_t)v);
        expect_read(CBVH_REG_OUT(1), 0xB0u + (uint32_t)v);
    }
    send_frame(CBVH_CMD_RUN, 7, p, sizeof p);
    cbvh_frame f = reply_at(0);
    assert_int_equal(f.status, CBVH_E_OK);
    assert_int_equal(f.seq, 7);
    assert_int_equal(f.len, 4 + 2 * 2 * 4);
    assert_int_equal(cbvh_get16(f.payload), 2);
    assert_int_equal(f.payload[2], 2);
    assert_int_equal(f.payload[3], 2);
    assert_int_equal(cbvh_get32(f.payload + 4), 0xA0);
    assert_int_equal(cbvh_get32(f.payload + 8), 0xB0);
    assert_int_equal(cbvh_get32(f.payload + 12), 0xA1);
    assert_int_equal(cbvh_get32(f.payload + 16), 0xB1);
    assert_int_equal(fw.n.vectors, 2);
}

static void datapath_hang(void **s) {
    (void)s;
    uint8_t p[12 + 4] = {0};
    run_header(p, 1, 6, -30, 0, 1, 1, 1);
    cbvh_fw_config c = {6, -30, 0};
    expect_read(CBVH_REG_UNITS, 1u << 1);
    expect_write(CBVH_REG_CONFIG, cbvh_dp_config_word(&c));
    expect_write(CBVH_REG_UNIT_SEL, 1);
    expect_read(CBVH_REG_SHAPE, 1 | 1 << 8);
    expect_write(CBVH_REG_IN(0), 0);
    expect_write(CBVH_REG_CTRL, CBVH_CTRL_START);
    expect_value_count(mock_read, addr, CBVH_REG_STATUS, CBVH_DATAPATH_POLL_LIMIT);
    will_return_count(mock_read, CBVH_STAT_BUSY, CBVH_DATAPATH_POLL_LIMIT);
    expect_write(CBVH_REG_CTRL, CBVH_CTRL_RESET); /* the core resets a hung datapath */
    send_frame(CBVH_CMD_RUN, 9, p, sizeof p);
    cbvh_frame f = reply_at(0);
    assert_int_equal(f.status, CBVH_E_DATAPATH);
    assert_int_equal(f.seq, 9);
    assert_int_equal(f.len, 0);
    assert_int_equal(fw.n.datapath_errors, 1);
}

static void absent_unit(void **s) {
    (void)s;
    uint8_t p[12];
    run_header(p, 9, 6, -30, 0, 1, 1, 0);
    expect_read(CBVH_REG_UNITS, 0x3E);
    send_frame(CBVH_CMD_RUN, 3, p, sizeof p);
    assert_int_equal(reply_at(0).status, CBVH_E_UNIT);
}

/* A datapath that has the unit but not for this configuration (gateware built
 * for another N): SHAPE reads 0 after the select, and the reply is config,
 * not unit, with no vector run. */
static void unit_not_built_for_config(void **s) {
    (void)s;
    uint8_t p[12];
    run_header(p, 2, 7, -30, 0, 3, 6, 0);
    expect_read(CBVH_REG_UNITS, 0x10Eu);
    expect_write(CBVH_REG_CONFIG, 7u | (uint32_t)(uint16_t)-30 << 8);
    expect_write(CBVH_REG_UNIT_SEL, 2);
    expect_read(CBVH_REG_SHAPE, 0);
    send_frame(CBVH_CMD_RUN, 4, p, sizeof p);
    cbvh_frame f = reply_at(0);
    assert_int_equal(f.status, CBVH_E_CONFIG);
    assert_int_equal(f.seq, 4);
    assert_int_equal(f.len, 0);
    assert_string_equal(cbvh_error_name(CBVH_E_CONFIG), "config");
}

/* ---- fake HAL: the model-backed register map, for the malformed-frame storm ---- */
static cbvh_regmap_model regs;
static const cbvh_fw_hal fake_hal = {&regs, cbvh_regmap_model_read, cbvh_regmap_model_write, capture_send, "fake"};

static int setup_fake(void **s) {
    (void)s;
    n_sent = 0;
    cbvh_regmap_model_init(&regs);
    cbvh_fw_init(&fw, &fake_hal);
    return 0;
}

typedef struct {
    const char *what;
    uint8_t expect;
} bad_case;

static void malformed_frames_each_get_an_error(void **s) {
    (void)s;
    static uint8_t b[CBVH_FRAME_MAX];
    uint8_t p[64];
    struct {
        const char *what;
        uint8_t code;
        size_t n;
    } cases[12];
    int nc = 0;
    size_t n;
#define CASE(label, code_)                                                                                             \
    do {                                                                                                               \
        n_sent = 0;                                                                                                    \
        cbvh_fw_rx(&fw, b, n);                                                                                         \
        assert_int_equal(n_sent, 1);                                                                                   \
        cbvh_frame f_ = reply_at(0);                                                                                   \
        if (f_.status != (code_)) fail_msg("%s: got %s, want %s", label, cbvh_error_name(f_.status),                 \
                                           cbvh_error_name(code_));                                                    \
        assert_true(f_.cmd & CBVH_REPLY);                                                                              \
        nc++;                                                                                                          \
    } while (0)
    (void)cases;
    /* bad CRC */
    n = cbvh_frame_seal(b, CBVH_CMD_IDENTIFY, 0, 1, 0);
    b[n - 1] ^= 1;
    CASE("crc", CBVH_E_CRC);
    /* unknown version: header rejected, the rest rescanned (no magic in it) */
    n = cbvh_frame_seal(b, CBVH_CMD_IDENTIFY, 0, 2, 0);
    b[1] = 7;
    n = 8; /* only the header: its CRC bytes would count as garbage before the next frame */
    CASE("version", CBVH_E_VERSION);
    /* length over the limit */
    n = cbvh_frame_seal(b, CBVH_CMD_IDENTIFY, 0, 3, 0);
    cbvh_put16(b + 6, CBVH_FRAME_MAX_PAYLOAD + 1);
    n = 8;
    CASE("length", CBVH_E_LENGTH);
    /* unknown command */
    n = cbvh_frame_seal(b, 0x55, 0, 4, 0);
    CASE("command", CBVH_E_COMMAND);
    /* status byte set in a request */
    n = cbvh_frame_seal(b, CBVH_CMD_IDENTIFY, 3, 5, 0);
    CASE("status byte", CBVH_E_HEADER);
    /* a reply sent to the board */
    n = cbvh_frame_seal(b, CBVH_CMD_IDENTIFY | CBVH_REPLY, 0, 6, 0);
    CASE("reply bit", CBVH_E_HEADER);
    /* payload where none belongs */
    b[8] = 1;
    n = cbvh_frame_seal(b, CBVH_CMD_STATUS, 0, 7, 1);
    CASE("status payload", CBVH_E_PAYLOAD);
    /* RUN too short */
    b[8] = 2;
    n = cbvh_frame_seal(b, CBVH_CMD_RUN, 0, 8, 1);
    CASE("run short", CBVH_E_PAYLOAD);
    /* RUN shape disagrees (scale_estimate is 2 -> 2) */
    run_header(p, 1, 6, -30, 0, 3, 2, 0);
    memcpy(b + 8, p, 12);
    n = cbvh_frame_seal(b, CBVH_CMD_RUN, 0, 9, 12);
    CASE("shape", CBVH_E_SHAPE);
    /* RUN count whose reply would not fit */
    run_header(p, 1, 6, -30, 0, 2, 2, 600);
    memcpy(b + 8, p, 12);
    n = cbvh_frame_seal(b, CBVH_CMD_RUN, 0, 10, 12);
    CASE("too big", CBVH_E_TOO_BIG);
    /* RUN count disagrees with the payload size */
    run_header(p, 1, 6, -30, 0, 2, 2, 3);
    memcpy(b + 8, p, 12);
    n = cbvh_frame_seal(b, CBVH_CMD_RUN, 0, 11, 12 + 8);
    CASE("count", CBVH_E_PAYLOAD);
    /* encoding out of range */
    run_header(p, 1, 6, -30, 2, 2, 2, 0);
    memcpy(b + 8, p, 12);
    n = cbvh_frame_seal(b, CBVH_CMD_RUN, 0, 12, 12);
    CASE("encoding", CBVH_E_PAYLOAD);
    /* garbage: reported when the next frame starts */
    memset(b, 0x11, 5);
    n = 5 + cbvh_frame_seal(b + 5, CBVH_CMD_LOOPBACK, 0, 13, 0);
    n_sent = 0;
    cbvh_fw_rx(&fw, b, n);
    assert_int_equal(n_sent, 2);
    assert_int_equal(reply_at(0).status, CBVH_E_SYNC);
    assert_int_equal(reply_at(1).status, CBVH_E_OK);
    /* truncated frame + inter-byte timeout */
    n = cbvh_frame_seal(b, CBVH_CMD_LOOPBACK, 0, 14, 0) - 2;
    n_sent = 0;
    cbvh_fw_rx(&fw, b, n);
    assert_int_equal(n_sent, 0);
    cbvh_fw_rx_idle(&fw);
    assert_int_equal(n_sent, 1);
    cbvh_frame t = reply_at(0);
    assert_int_equal(t.status, CBVH_E_TIMEOUT);
    assert_int_equal(t.seq, 14);
    assert_int_equal(nc, 12);
    /* still alive: loopback and counters */
    n_sent = 0;
    memcpy(b + 8, "ping", 4);
    n = cbvh_frame_seal(b, CBVH_CMD_LOOPBACK, 0, 15, 4);
    cbvh_fw_rx(&fw, b, n);
    cbvh_frame l = reply_at(0);
    assert_int_equal(l.status, CBVH_E_OK);
    assert_memory_equal(l.payload, "ping", 4);
    n_sent = 0;
    n = cbvh_frame_seal(b, CBVH_CMD_STATUS, 0, 16, 0);
    cbvh_fw_rx(&fw, b, n);
    cbvh_frame st = reply_at(0);
    assert_int_equal(st.len, 4 * CBVH_FW_COUNTERS);
    assert_int_equal(cbvh_get32(st.payload + 4), 14); /* error replies: 12 cases + sync + timeout */
    assert_int_equal(cbvh_get32(st.payload + 8), 1);  /* crc */
    assert_int_equal(cbvh_get32(st.payload + 12), 1); /* sync */
    assert_int_equal(cbvh_get32(st.payload + 20), 1); /* rx timeouts */
}

/* A real batch through the fake register map equals the model. */
static void run_matches_model(void **s) {
    (void)s;
    const cbvh_unit *u = cbvh_unit_find("axis_compress");
    assert_non_null(u);
    cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
    cbvh_layout lay;
    u->layout(&cfg, &lay);
    enum { NIN = 4 }; /* lb ub scale node_clb */
    assert_int_equal(lay.n_in, NIN);
    uint32_t in[4 * NIN], want[4 * 8];
    const float lb[4] = {0.f, -1.5f, 3.25f, 100.f}, ub[4] = {1.f, 2.f, 3.5f, 1e6f};
    for (int v = 0; v < 4; v++) {
        in[NIN * v] = cbvh_f32_of(lb[v]);
        in[NIN * v + 1] = cbvh_f32_of(ub[v]);
        in[NIN * v + 2] = cbvh_scale_to_word(-2 + v);
        in[NIN * v + 3] = cbvh_f32_of(lb[v] - 1.0f); /* the node's lower bound */
        u->eval(&cfg, in + NIN * v, want + lay.n_out * v);
    }
    uint8_t p[12 + sizeof in];
    run_header(p, u->id, 6, -30, 0, (uint8_t)lay.n_in, (uint8_t)lay.n_out, 4);
    for (int i = 0; i < 4 * NIN; i++) cbvh_put32(p + 12 + 4 * i, in[i]);
    send_frame(CBVH_CMD_RUN, 77, p, sizeof p);
    cbvh_frame f = reply_at(0);
    assert_int_equal(f.status, CBVH_E_OK);
    for (int i = 0; i < 4 * lay.n_out; i++) assert_int_equal(cbvh_get32(f.payload + 4 + 4 * i), want[i]);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(identify, setup),
        cmocka_unit_test_setup(run_register_sequence, setup),
        cmocka_unit_test_setup(datapath_hang, setup),
        cmocka_unit_test_setup(absent_unit, setup),
        cmocka_unit_test_setup(unit_not_built_for_config, setup),
        cmocka_unit_test_setup(malformed_frames_each_get_an_error, setup_fake),
        cmocka_unit_test_setup(run_matches_model, setup_fake),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
