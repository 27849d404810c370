/* Payload layouts of the board protocol's commands (docs/protocol.md,
 * "Commands"): the RUN request and reply headers and the IDENTIFY reply.
 * The one definition of where each field sits, used by the firmware core to
 * read requests and write replies and by the host to do the reverse.
 * Freestanding: only <stdint.h>/<stddef.h>, no malloc. */
#ifndef CBVH_FW_PAYLOAD_H
#define CBVH_FW_PAYLOAD_H

#include <stddef.h>
#include <stdint.h>

/* RUN request payload: this header, then count * n_in words (u32 LE).
 *   0 u8 unit id     1 i8 N (quant_bits)    2 i16 min_scale
 *   4 u8 encoding    5 u8 n_in   6 u8 n_out   7 u8 0
 *   8 u16 count     10 u16 0 */
#define CBVH_RUN_HDR 12u
typedef struct {
    uint8_t unit;
    int8_t quant_bits;
    int16_t min_scale;
    uint8_t encoding, n_in, n_out;
    uint16_t count;
} cbvh_run_hdr;

/* RUN reply payload: this header, then count * n_out words (u32 LE).
 *   0 u16 count   2 u8 n_out   3 u8 unit id */
#define CBVH_RUN_REPLY_HDR 4u
typedef struct {
    uint16_t count;
    uint8_t n_out, unit;
} cbvh_run_reply_hdr;

/* IDENTIFY reply payload, CBVH_IDENTITY_BYTES bytes:
 *  0 u8  protocol version      1 u8 fw major   2 u8 fw minor   3 u8 fw patch
 *  4 u32 datapath version      8 u32 unit bitmask
 * 12 u16 max payload          14 u8 register window words      15 u8 0
 * 16 u32 REG_ID               20 char[16] board name (at most 15 characters, NUL padded)
 * 36 u32 0 */
#define CBVH_IDENTITY_BYTES 40u
typedef struct {
    uint8_t proto_version, fw_major, fw_minor, fw_patch;
    uint32_t datapath_version, units;
    uint16_t max_payload;
    uint8_t reg_words;
    uint32_t reg_id;
    char board_name[16]; /* NUL-terminated */
} cbvh_identity;

/* Writers fill every byte of their layout (reserved ones with 0). */
void cbvh_run_hdr_put(uint8_t *p, const cbvh_run_hdr *h);
void cbvh_run_reply_hdr_put(uint8_t *p, const cbvh_run_reply_hdr *h);
void cbvh_identity_put(uint8_t *p, const cbvh_identity *id);

/* Readers take the payload and its length: 0, or -1 when it is shorter than
 * the header (RUN) or not exactly CBVH_IDENTITY_BYTES (IDENTIFY), or a
 * reserved field of the RUN request is not 0.  They check nothing else:
 * what the fields may hold is the caller's rule.  The board name is copied
 * as sent, up to its first NUL (at most 15 characters). */
int cbvh_run_hdr_get(const uint8_t *p, size_t len, cbvh_run_hdr *h);
int cbvh_run_reply_hdr_get(const uint8_t *p, size_t len, cbvh_run_reply_hdr *h);
int cbvh_identity_get(const uint8_t *p, size_t len, cbvh_identity *id);

/* Vectors of n_in input and n_out output words in one RUN frame whose
 * request and reply payloads may not exceed max_payload bytes. */
static inline size_t cbvh_run_max_batch(size_t max_payload, unsigned n_in, unsigned n_out) {
    size_t a = (max_payload - CBVH_RUN_HDR) / (4u * (size_t)n_in);
    size_t b = (max_payload - CBVH_RUN_REPLY_HDR) / (4u * (size_t)n_out);
    return a < b ? a : b;
}

#endif
