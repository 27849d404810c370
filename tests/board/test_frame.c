/* Frame codec (firmware/core/frame.c): CRC, sealing, one-shot decode and the
 * streaming parser's resynchronisation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "cbvh_fw/frame.h"

static size_t make(uint8_t *buf, uint8_t cmd, uint16_t seq, const char *payload) {
    size_t n = strlen(payload);
    memcpy(buf + CBVH_FRAME_HDR, payload, n);
    return cbvh_frame_seal(buf, cmd, 0, seq, (uint16_t)n);
}

static void crc_check_value(void **s) {
    (void)s;
    assert_int_equal(cbvh_crc32(0, (const uint8_t *)"123456789", 9), 0xCBF43926u);
    /* incremental = one shot */
    uint32_t c = cbvh_crc32(0, (const uint8_t *)"1234", 4);
    assert_int_equal(cbvh_crc32(c, (const uint8_t *)"56789", 5), 0xCBF43926u);
}

static void seal_and_decode(void **s) {
    (void)s;
    static uint8_t buf[CBVH_FRAME_MAX];
    size_t n = make(buf, CBVH_CMD_LOOPBACK, 0xBEEF, "hello");
    assert_int_equal(n, CBVH_FRAME_HDR + 5 + CBVH_FRAME_CRC);
    assert_int_equal(buf[0], 0xCB);
    cbvh_frame f;
    assert_int_equal(cbvh_frame_decode(buf, n, &f), CBVH_E_OK);
    assert_int_equal(f.cmd, CBVH_CMD_LOOPBACK);
    assert_int_equal(f.seq, 0xBEEF);
    assert_int_equal(f.len, 5);
    assert_memory_equal(f.payload, "hello", 5);
    assert_int_equal(cbvh_frame_decode(buf, n - 1, &f), CBVH_E_LENGTH);
    buf[9] ^= 4;
    assert_int_equal(cbvh_frame_decode(buf, n, &f), CBVH_E_CRC);
    buf[9] ^= 4;
    buf[1] = 2;
    assert_int_equal(cbvh_frame_decode(buf, n, &f), CBVH_E_VERSION);
    assert_int_equal(cbvh_frame_seal(buf, 1, 0, 0, CBVH_FRAME_MAX_PAYLOAD + 1), 0);
}

/* Pushes bytes one at a time; collects events. */
typedef struct {
    int frames, errors;
    uint8_t codes[16];
    uint16_t seqs[16];
    char last_payload[64];
} events;

static void feed(cbvh_parser *p, const uint8_t *d, size_t n, size_t chunk, events *ev) {
    while (n || cbvh_parser_busy(p)) {
        size_t k = n < chunk ? n : chunk, used = 0;
        cbvh_frame f;
        cbvh_parse_error e;
        int r = cbvh_parser_push(p, d, k, &used, &f, &e);
        assert_true(used <= k);
        if (r == CBVH_PARSE_MORE) assert_int_equal(used, k);
        d += used;
        n -= used;
        if (r == CBVH_PARSE_FRAME) {
            ev->seqs[ev->frames % 16] = f.seq;
            memcpy(ev->last_payload, f.payload, f.len < 63 ? f.len : 63);
            ev->last_payload[f.len < 63 ? f.len : 63] = 0;
            ev->frames++;
        } else if (r == CBVH_PARSE_ERROR) {
            ev->codes[ev->errors % 16] = e.code;
            ev->errors++;
        }
    }
}

static void parser_chunking(void **s) {
    (void)s;
    static cbvh_parser p;
    static uint8_t buf[3 * 64];
    size_t n = make(buf, 1, 1, "a");
    n += make(buf + n, 1, 2, "bcd");
    n += make(buf + n, 1, 3, "");
    for (size_t chunk = 1; chunk <= n; chunk++) {
        events ev = {0};
        cbvh_parser_init(&p);
        feed(&p, buf, n, chunk, &ev);
        assert_int_equal(ev.frames, 3);
        assert_int_equal(ev.errors, 0);
        assert_int_equal(ev.seqs[0], 1);
        assert_int_equal(ev.seqs[1], 2);
        assert_int_equal(ev.seqs[2], 3);
    }
}

static void parser_resync(void **s) {
    (void)s;
    static cbvh_parser p;
    static uint8_t buf[512];
    size_t n = 0;
    memcpy(buf, "garbage", 7), n = 7;                  /* -> SYNC */
    n += make(buf + n, 1, 10, "ok1");                  /* -> frame */
    size_t bad = n;
    n += make(buf + n, 1, 11, "crc");
    buf[bad + CBVH_FRAME_HDR] ^= 0x10;                 /* -> CRC with seq 11 */
    size_t ver = n;
    n += make(buf + n, 1, 12, "v");
    buf[ver + 1] = 9;                                  /* -> VERSION; rest of the frame is garbage */
    n += make(buf + n, 1, 13, "ok2");                  /* -> SYNC then frame */
    size_t len = n;
    n += make(buf + n, 1, 14, "");
    cbvh_put16(buf + len + 6, CBVH_FRAME_MAX_PAYLOAD + 1); /* -> LENGTH */
    n += make(buf + n, 1, 15, "ok3");                  /* rest of bad frame is CRC bytes: SYNC, then frame */
    events ev = {0};
    cbvh_parser_init(&p);
    feed(&p, buf, n, 5, &ev);
    for (int i = 0; i < ev.errors && i < 16; i++) print_message("error %d: %s\n", i, cbvh_error_name(ev.codes[i]));
    assert_int_equal(ev.frames, 3);
    assert_string_equal(ev.last_payload, "ok3");
    assert_int_equal(ev.seqs[0], 10);
    assert_int_equal(ev.seqs[1], 13);
    assert_int_equal(ev.seqs[2], 15);
    /* Which extra events a bad frame's leftover bytes cause depends on their
     * values (a 0xCB in a CRC starts a candidate frame); what must hold: the
     * good frames all come through and each fault class is reported. */
    int seen[16] = {0};
    for (int i = 0; i < ev.errors && i < 16; i++) seen[ev.codes[i]]++;
    assert_int_equal(ev.codes[0], CBVH_E_SYNC);
    assert_true(seen[CBVH_E_CRC] >= 1);
    assert_true(seen[CBVH_E_VERSION] >= 1);
    assert_true(seen[CBVH_E_LENGTH] >= 1);
    assert_true(ev.errors >= 5 && ev.errors <= 12);
}

static void parser_timeout(void **s) {
    (void)s;
    static cbvh_parser p;
    static uint8_t buf[64];
    size_t n = make(buf, 1, 0x1234, "abc");
    events ev = {0};
    cbvh_parser_init(&p);
    cbvh_parse_error e;
    assert_int_equal(cbvh_parser_timeout(&p, &e), 0); /* nothing pending: no event */
    feed(&p, buf, n - 2, 3, &ev);
    assert_true(cbvh_parser_partial(&p));
    assert_int_equal(cbvh_parser_timeout(&p, &e), 1);
    assert_int_equal(e.code, CBVH_E_TIMEOUT);
    assert_true(e.seq_known);
    assert_int_equal(e.seq, 0x1234);
    feed(&p, buf, n, 1, &ev); /* whole frame after the timeout parses */
    assert_int_equal(ev.frames, 1);
    assert_int_equal(ev.errors, 0);
}

/* A cut frame followed by a whole one: the CRC fails, the rescan finds the
 * whole frame inside the buffered bytes, no timeout needed. */
static void parser_truncated_then_whole(void **s) {
    (void)s;
    static cbvh_parser p;
    static uint8_t buf[128];
    size_t cut = make(buf, 1, 1, "0123456789") - 5;
    size_t n = cut + make(buf + cut, 1, 2, "xyz");
    events ev = {0};
    cbvh_parser_init(&p);
    feed(&p, buf, n, 7, &ev);
    assert_int_equal(ev.frames, 1);
    assert_int_equal(ev.seqs[0], 2);
    assert_string_equal(ev.last_payload, "xyz");
    assert_int_equal(ev.codes[0], CBVH_E_CRC);
}

static void error_classes(void **s) {
    (void)s;
    assert_true(cbvh_error_is_link(CBVH_E_CRC));
    assert_true(cbvh_error_is_link(CBVH_E_TIMEOUT));
    assert_false(cbvh_error_is_link(CBVH_E_UNIT));
    assert_false(cbvh_error_is_link(CBVH_E_OK));
    assert_string_equal(cbvh_error_name(CBVH_E_SHAPE), "shape");
    assert_string_equal(cbvh_error_name(200), "unknown");
    /* the virtual board's refusal (docs/protocol.md): code 14, final, not retried */
    assert_int_equal(CBVH_E_BUSY, 14);
    assert_false(cbvh_error_is_link(CBVH_E_BUSY));
    assert_string_equal(cbvh_error_name(CBVH_E_BUSY), "busy");
    assert_string_equal(cbvh_error_name(CBVH_E_BUSY + 1), "unknown");
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(crc_check_value), cmocka_unit_test(seal_and_decode), cmocka_unit_test(parser_chunking),
        cmocka_unit_test(parser_resync),   cmocka_unit_test(parser_timeout),  cmocka_unit_test(error_classes), cmocka_unit_test(parser_truncated_then_whole),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
