/* Frame codec shared by firmware and host (see cbvh_fw/frame.h). */
#include "cbvh_fw/frame.h"

/* Bitwise CRC-32: no 1 KiB table, so it fits the MCU's flash budget; the
 * link is slower than the CRC by orders of magnitude. */
uint32_t cbvh_crc32(uint32_t crc, const uint8_t *p, size_t n) {
    crc = ~crc;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

const char *cbvh_error_name(unsigned code) {
    static const char *const names[] = {"ok",       "crc",     "sync",    "version", "length",
                                        "timeout",  "header",  "command", "payload", "unit",
                                        "shape",    "too-big", "datapath", "config",
                                        "busy"};
    return code < sizeof names / sizeof names[0] ? names[code] : "unknown";
}

size_t cbvh_frame_seal(uint8_t *buf, uint8_t cmd, uint8_t status, uint16_t seq, uint16_t len) {
    if (len > CBVH_FRAME_MAX_PAYLOAD) return 0;
    buf[0] = CBVH_FRAME_MAGIC;
    buf[1] = CBVH_PROTO_VERSION;
    buf[2] = cmd;
    buf[3] = status;
    cbvh_put16(buf + 4, seq);
    cbvh_put16(buf + 6, len);
    size_t body = CBVH_FRAME_HDR + len;
    cbvh_put32(buf + body, cbvh_crc32(0, buf, body));
    return body + CBVH_FRAME_CRC;
}

void cbvh_parser_init(cbvh_parser *p) {
    p->have = 0;
    p->rp = p->rend = 0;
    p->skipped = 0;
}

static void error_from(const cbvh_parser *p, uint8_t code, cbvh_parse_error *e) {
    e->code = code;
    e->seq_known = p->have >= 6;
    e->seq = e->seq_known ? cbvh_get16(p->buf + 4) : 0;
    e->cmd = p->have >= 3 ? p->buf[2] : 0;
}

/* Drops the current frame's first byte and queues the rest (followed by any
 * bytes still queued) for rescanning.  Writes never overtake reads: have <= rp. */
static void drop_and_rescan(cbvh_parser *p) {
    size_t tail = p->rend - p->rp;
    if (p->have + tail > sizeof p->buf) tail = sizeof p->buf - p->have; /* cannot happen: have <= rp */
    for (size_t i = 0; i < tail; i++) p->buf[p->have + i] = p->buf[p->rp + i];
    p->rp = p->have > 0 ? 1 : 0;
    p->rend = p->have + tail;
    if (p->rp > p->rend) p->rp = p->rend;
    p->have = 0;
}

/* fresh = 0 for rescanned bytes: they belong to a frame already reported. */
static int step(cbvh_parser *p, uint8_t b, int fresh, cbvh_frame *f, cbvh_parse_error *e) {
    if (p->have == 0) {
        if (b != CBVH_FRAME_MAGIC) {
            p->skipped += (uint32_t)fresh;
            return CBVH_PARSE_MORE;
        }
        p->buf[p->have++] = b;
        if (p->skipped) { /* report the garbage once, when the next frame starts */
            p->skipped = 0;
            e->code = CBVH_E_SYNC;
            e->seq = 0;
            e->seq_known = 0;
            e->cmd = 0;
            return CBVH_PARSE_ERROR;
        }
        return CBVH_PARSE_MORE;
    }
    p->buf[p->have++] = b;
    if (p->have == CBVH_FRAME_HDR) {
        uint8_t code = 0;
        if (p->buf[1] != CBVH_PROTO_VERSION) code = CBVH_E_VERSION;
        else if (cbvh_get16(p->buf + 6) > CBVH_FRAME_MAX_PAYLOAD) code = CBVH_E_LENGTH;
        if (code) {
            error_from(p, code, e);
            drop_and_rescan(p);
            return CBVH_PARSE_ERROR;
        }
    }
    if (p->have < CBVH_FRAME_HDR) return CBVH_PARSE_MORE;
    size_t len = cbvh_get16(p->buf + 6);
    if (p->have < CBVH_FRAME_HDR + len + CBVH_FRAME_CRC) return CBVH_PARSE_MORE;
    if (cbvh_crc32(0, p->buf, CBVH_FRAME_HDR + len) != cbvh_get32(p->buf + CBVH_FRAME_HDR + len)) {
        error_from(p, CBVH_E_CRC, e);
        drop_and_rescan(p);
        return CBVH_PARSE_ERROR;
    }
    f->version = p->buf[1];
    f->cmd = p->buf[2];
    f->status = p->buf[3];
    f->seq = cbvh_get16(p->buf + 4);
    f->len = (uint16_t)len;
    f->payload = p->buf + CBVH_FRAME_HDR;
    p->have = 0;
    return CBVH_PARSE_FRAME;
}

int cbvh_parser_push(cbvh_parser *p, const uint8_t *data, size_t n, size_t *used, cbvh_frame *f, cbvh_parse_error *e) {
    *used = 0;
    while (p->rp < p->rend) {
        int ev = step(p, p->buf[p->rp++], 0, f, e);
        if (ev != CBVH_PARSE_MORE) return ev;
    }
    p->rp = p->rend = 0;
    for (size_t i = 0; i < n; i++) {
        int ev = step(p, data[i], 1, f, e);
        if (ev != CBVH_PARSE_MORE) {
            *used = i + 1;
            return ev;
        }
    }
    *used = n;
    return CBVH_PARSE_MORE;
}

int cbvh_parser_timeout(cbvh_parser *p, cbvh_parse_error *e) {
    if (p->have == 0) return 0;
    error_from(p, CBVH_E_TIMEOUT, e);
    drop_and_rescan(p);
    return 1;
}

int cbvh_frame_decode(const uint8_t *buf, size_t n, cbvh_frame *f) {
    if (n < CBVH_FRAME_HDR + CBVH_FRAME_CRC) return CBVH_E_LENGTH;
    if (buf[0] != CBVH_FRAME_MAGIC) return CBVH_E_SYNC;
    if (buf[1] != CBVH_PROTO_VERSION) return CBVH_E_VERSION;
    size_t len = cbvh_get16(buf + 6);
    if (len > CBVH_FRAME_MAX_PAYLOAD || n != CBVH_FRAME_HDR + len + CBVH_FRAME_CRC) return CBVH_E_LENGTH;
    if (cbvh_crc32(0, buf, CBVH_FRAME_HDR + len) != cbvh_get32(buf + CBVH_FRAME_HDR + len)) return CBVH_E_CRC;
    f->version = buf[1];
    f->cmd = buf[2];
    f->status = buf[3];
    f->seq = cbvh_get16(buf + 4);
    f->len = (uint16_t)len;
    f->payload = buf + CBVH_FRAME_HDR;
    return CBVH_E_OK;
}
