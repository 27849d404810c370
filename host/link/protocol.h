/* Host side of the board protocol (docs/protocol.md): requests with sequence
 * numbers, reply validation, timeouts, retries and resynchronisation, over any
 * byte link (socket, libusb bulk, hidapi reports). */
#ifndef CBVH_HOST_PROTOCOL_H
#define CBVH_HOST_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/unit_table.h"
#include "cbvh_fw/frame.h"
#include "cbvh_fw/payload.h"

/* One transport's byte I/O. */
typedef struct {
    void *ctx;
    /* Sends a whole frame: 0, or -1 when the link broke (err says why). */
    int (*write)(void *ctx, const uint8_t *buf, size_t n, char *err, size_t errlen);
    /* Reads what is there (up to cap), waiting at most timeout_ms: bytes read,
     * 0 on timeout, -1 when the link broke. */
    long (*read)(void *ctx, uint8_t *buf, size_t cap, int timeout_ms, char *err, size_t errlen);
    /* Re-establishes a broken link (NULL: cannot). 0 or -1. */
    int (*reopen)(void *ctx, char *err, size_t errlen);
    /* 1 when the other end has closed the link (the virtual board lets an
     * idle host go), checked before each request so that it is reopened
     * without spending an attempt; NULL: never known in advance. */
    int (*hung_up)(void *ctx);
} cbvh_link_io;

typedef struct {
    uint64_t requests, attempts, replies_ok;
    uint64_t crc_errors, sync_errors, other_parse_errors; /* detected in replies */
    uint64_t stale_replies;                               /* wrong sequence number or command */
    uint64_t timeouts, link_errors_reported;              /* board said our request arrived broken */
    uint64_t link_breaks, reopens, retries, failures;
    uint64_t bad_replies; /* CRC fine but fields inconsistent */
} cbvh_link_stats;

typedef struct {
    cbvh_link_io io;
    int timeout_ms;  /* per attempt: for the reply, or for a broken link to reopen */
    int max_retries; /* attempts = 1 + max_retries */
    uint16_t seq;
    int broken;
    int refused; /* the board refused this connection: another host has it (CBVH_E_BUSY) */
    cbvh_link_stats st;
    cbvh_parser rx;
    uint8_t tx[CBVH_FRAME_MAX];
    uint8_t req[CBVH_FRAME_MAX_PAYLOAD];
    uint8_t reply[CBVH_FRAME_MAX_PAYLOAD];
    uint8_t pend[4096]; /* bytes read after an accepted reply, parsed next time */
    size_t pend_len;
    cbvh_identity ident;
} cbvh_link;

#define CBVH_LINK_TIMEOUT_MS_DEFAULT 1000
#define CBVH_LINK_RETRIES_DEFAULT 8
#define CBVH_LINK_TIMEOUT_MS_MAX 600000
#define CBVH_LINK_RETRIES_MAX 1000

void cbvh_link_init(cbvh_link *l, const cbvh_link_io *io);
/* Drops whatever the board still has in flight (after open/reopen), except
 * a refusal (status busy), which the next request reports at once. */
void cbvh_link_flush(cbvh_link *l, int quiet_ms);

/* One request/reply exchange with retries.  On success returns 0 and the
 * reply payload is in l->reply[0..*reply_len).  Error replies that are not
 * link errors are final (no retry).  A broken link is reopened, tried again
 * with a short back-off for up to timeout_ms per attempt (a board reset or
 * USB re-enumeration takes about a second).  A refusal (status busy: the
 * virtual board serves another host) fails at once with "busy: another host
 * is connected", before or instead of any reply.  On failure err ends with what
 * the last attempt saw: nothing, garbage, another protocol version, a frame
 * cut short or damaged, only stale frames, or a link that did not come back. */
int cbvh_link_transact(cbvh_link *l, uint8_t cmd, const uint8_t *payload, uint16_t len, uint16_t *reply_len,
                       char *err, size_t errlen);

int cbvh_link_identify(cbvh_link *l, char *err, size_t errlen);
/* Largest number of vectors of this shape in one RUN frame of the protocol's
 * largest size (a board may report less: cbvh_link_run honours that). */
size_t cbvh_link_max_batch(int n_in, int n_out);
/* Runs count vectors, split into as many frames as needed (no larger than
 * the max payload the board reported in IDENTIFY).  out is written
 * only from validated replies; 0 or -1 with err set. */
int cbvh_link_run(cbvh_link *l, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out,
                  size_t count, char *err, size_t errlen);

/* Validates a RUN reply payload against the request: 0 or -1 (fuzzed). */
int cbvh_run_reply_check(const uint8_t *p, size_t len, uint8_t unit, unsigned count, unsigned n_out);
/* Parses an IDENTIFY reply payload: 0 or -1 (fuzzed). */
int cbvh_identity_parse(const uint8_t *p, size_t len, cbvh_identity *id);

/* Timeout and retries from CBVH_LINK_TIMEOUT_MS (1..CBVH_LINK_TIMEOUT_MS_MAX)
 * and CBVH_LINK_RETRIES (0..CBVH_LINK_RETRIES_MAX); unset or empty keeps the
 * defaults.  0, or -1 with err naming the variable and the accepted form (l is
 * then untouched).  l may be NULL: only check the variables. */
int cbvh_link_env_options(cbvh_link *l, char *err, size_t errlen);

#endif
