/* The board protocol's frame (docs/protocol.md), shared by the firmware and
 * the host.  Freestanding: only <stdint.h>/<stddef.h>, no malloc.
 *
 *   offset size  field
 *   0      1     magic 0xCB
 *   1      1     protocol version (CBVH_PROTO_VERSION)
 *   2      1     command; replies set bit 7 (CBVH_REPLY)
 *   3      1     status: 0 in requests; 0 or a CBVH_E_* code in replies
 *   4      2     sequence number, little-endian (replies echo the request's)
 *   6      2     payload length, little-endian, <= CBVH_FRAME_MAX_PAYLOAD
 *   8      len   payload
 *   8+len  4     CRC-32 (IEEE 802.3, reflected) of bytes 0..8+len-1, LE */
#ifndef CBVH_FW_FRAME_H
#define CBVH_FW_FRAME_H

#include <stddef.h>
#include <stdint.h>

#define CBVH_FRAME_MAGIC 0xCBu
#define CBVH_PROTO_VERSION 1u
#define CBVH_FRAME_HDR 8u
#define CBVH_FRAME_CRC 4u
#define CBVH_FRAME_MAX_PAYLOAD 4096u
#define CBVH_FRAME_MAX (CBVH_FRAME_HDR + CBVH_FRAME_MAX_PAYLOAD + CBVH_FRAME_CRC)
#define CBVH_REPLY 0x80u

enum {
    CBVH_CMD_IDENTIFY = 0x01, /* -> cbvh_identity payload (payload.h) */
    CBVH_CMD_RESET = 0x02,    /* reset datapath and counters */
    CBVH_CMD_RUN = 0x03,      /* run a batch of vectors on one unit (payload.h) */
    CBVH_CMD_LOOPBACK = 0x04, /* echo the payload */
    CBVH_CMD_STATUS = 0x05,   /* counters */
};

/* Reply status codes.  LINK errors mean "the frame did not arrive intact":
 * the host retries them; the others are answers about a good frame. */
enum {
    CBVH_E_OK = 0,
    CBVH_E_CRC = 1,        /* link: CRC mismatch */
    CBVH_E_SYNC = 2,       /* link: bytes before a magic were skipped */
    CBVH_E_VERSION = 3,    /* link: unknown protocol version */
    CBVH_E_LENGTH = 4,     /* link: length field > CBVH_FRAME_MAX_PAYLOAD */
    CBVH_E_TIMEOUT = 5,    /* link: frame incomplete when the inter-byte timeout hit */
    CBVH_E_HEADER = 6,     /* status byte of a request not 0 */
    CBVH_E_COMMAND = 7,    /* unknown command */
    CBVH_E_PAYLOAD = 8,    /* payload size/fields wrong for the command */
    CBVH_E_UNIT = 9,       /* unit id not present in the datapath */
    CBVH_E_SHAPE = 10,     /* host's n_in/n_out differ from the datapath's */
    CBVH_E_TOO_BIG = 11,   /* batch exceeds one frame */
    CBVH_E_DATAPATH = 12,  /* datapath did not finish / flagged an error */
    CBVH_E_CONFIG = 13,    /* unit present but not built for this N / min_scale / encoding */
    CBVH_E_BUSY = 14,      /* session: the virtual board serves another host; sent unprompted
                              (command 0x80, sequence number 0) on a connection it then closes */
};

static inline int cbvh_error_is_link(unsigned code) { return code >= CBVH_E_CRC && code <= CBVH_E_TIMEOUT; }
const char *cbvh_error_name(unsigned code);

typedef struct {
    uint8_t version, cmd, status;
    uint16_t seq, len;
    const uint8_t *payload; /* points into the parser's buffer */
} cbvh_frame;

uint32_t cbvh_crc32(uint32_t crc, const uint8_t *p, size_t n); /* start with crc = 0 */

static inline void cbvh_put16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8); }
static inline void cbvh_put32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8), p[2] = (uint8_t)(v >> 16), p[3] = (uint8_t)(v >> 24);
}
static inline uint16_t cbvh_get16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }
static inline uint32_t cbvh_get32(const uint8_t *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Writes header and CRC around a payload already placed at buf + CBVH_FRAME_HDR.
 * Returns the frame size, or 0 when len is too large. */
size_t cbvh_frame_seal(uint8_t *buf, uint8_t cmd, uint8_t status, uint16_t seq, uint16_t len);

/* Streaming parser: bytes in, whole frames or error events out.  After a bad
 * header, a CRC mismatch or a timeout it rescans the dropped frame's bytes
 * (from its second byte) for the next magic, so a truncated frame does not
 * take the frame behind it down too. */
typedef struct {
    uint8_t buf[CBVH_FRAME_MAX];
    size_t have;       /* bytes of the current frame in buf[0..have) */
    size_t rp, rend;   /* bytes still to rescan: buf[rp..rend), always rp >= have */
    uint32_t skipped;  /* garbage bytes skipped since the last event */
} cbvh_parser;

enum { CBVH_PARSE_MORE = 0, CBVH_PARSE_FRAME = 1, CBVH_PARSE_ERROR = 2 };

typedef struct {
    uint8_t code;   /* CBVH_E_* */
    uint16_t seq;   /* sequence number of the bad frame, when known */
    int seq_known;
    uint8_t cmd;    /* command byte of the bad frame, when known (else 0) */
} cbvh_parse_error;

void cbvh_parser_init(cbvh_parser *p);
/* Rescans pending bytes, then consumes data[0..n) until one event; *used says
 * how many bytes of data were taken (0 is possible when the event came from
 * the rescan).  Call again while n > 0 or cbvh_parser_busy(p).  On
 * CBVH_PARSE_FRAME, *f is valid until the next call. */
int cbvh_parser_push(cbvh_parser *p, const uint8_t *data, size_t n, size_t *used, cbvh_frame *f, cbvh_parse_error *e);
static inline int cbvh_parser_busy(const cbvh_parser *p) { return p->rp < p->rend; }
/* Inter-byte timeout: drops a partial frame.  Returns 1 (and fills *e with
 * CBVH_E_TIMEOUT) when something was dropped; then push with n = 0 while
 * cbvh_parser_busy() to rescan its bytes. */
int cbvh_parser_timeout(cbvh_parser *p, cbvh_parse_error *e);
static inline int cbvh_parser_partial(const cbvh_parser *p) { return p->have > 0 || p->rp < p->rend; }

/* One-shot decode of exactly one frame in buf[0..n): 0 or a CBVH_E_* code. */
int cbvh_frame_decode(const uint8_t *buf, size_t n, cbvh_frame *f);

#endif
