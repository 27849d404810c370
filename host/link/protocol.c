/* Host side of the board protocol: see protocol.h and docs/protocol.md. */
#include "link/protocol.h"
#include "util/parse_int.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* What a request- or session-class error code means, for the one-line
 * message (docs/protocol.md, "Error replies"). */
static const char *request_error_meaning(unsigned code) {
    switch (code) {
    case CBVH_E_HEADER: return "the request's status byte was not 0";
    case CBVH_E_COMMAND: return "the board does not know the command";
    case CBVH_E_PAYLOAD: return "payload size or fields wrong for the command";
    case CBVH_E_UNIT: return "the board's datapath has no such unit";
    case CBVH_E_SHAPE: return "the board's unit has another number of input or output words";
    case CBVH_E_TOO_BIG: return "the reply would not fit one frame";
    case CBVH_E_DATAPATH: return "the datapath did not finish or flagged an error";
    case CBVH_E_CONFIG: return "the board's unit is not built for this N, min_scale or encoding";
    case CBVH_E_BUSY: return "another host is connected";
    default: return "unknown code";
    }
}

static long now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long)ts.tv_sec * 1000L + ts.tv_nsec / 1000000L;
}

void cbvh_link_init(cbvh_link *l, const cbvh_link_io *io) {
    memset(l, 0, sizeof *l);
    l->io = *io;
    l->timeout_ms = CBVH_LINK_TIMEOUT_MS_DEFAULT;
    l->max_retries = CBVH_LINK_RETRIES_DEFAULT;
    l->seq = (uint16_t)(now_ms() & 0xFFFF); /* a new session does not reuse the last one's numbers */
    cbvh_parser_init(&l->rx);
}

/* One integer setting from the environment: unset or empty keeps *v; anything
 * but a plain decimal in lo..hi is an error (atoi took "5x" as 5). */
static int env_int(const char *name, long lo, long hi, int *v, char *err, size_t errlen) {
    const char *s = getenv(name);
    if (!s || !*s) return 0;
    long x;
    if (cbvh_parse_long(s, lo, hi, &x)) {
        snprintf(err, errlen, "%s='%.40s' is not valid (expected an integer in %ld..%ld)", name, s, lo, hi);
        return -1;
    }
    *v = (int)x;
    return 0;
}

int cbvh_link_env_options(cbvh_link *l, char *err, size_t errlen) {
    int t = CBVH_LINK_TIMEOUT_MS_DEFAULT, r = CBVH_LINK_RETRIES_DEFAULT;
    if (env_int("CBVH_LINK_TIMEOUT_MS", 1, CBVH_LINK_TIMEOUT_MS_MAX, &t, err, errlen) ||
        env_int("CBVH_LINK_RETRIES", 0, CBVH_LINK_RETRIES_MAX, &r, err, errlen))
        return -1;
    if (l) {
        l->timeout_ms = t;
        l->max_retries = r;
    }
    return 0;
}

void cbvh_link_flush(cbvh_link *l, int quiet_ms) {
    uint8_t buf[4096];
    char err[64];
    long r;
    cbvh_parser_init(&l->rx);
    while (!l->broken && (r = l->io.read(l->io.ctx, buf, sizeof buf, quiet_ms, err, sizeof err)) > 0)
        for (size_t off = 0; off < (size_t)r || cbvh_parser_busy(&l->rx);) { /* dropped, but a refusal is kept */
            size_t used = 0;
            cbvh_frame f;
            cbvh_parse_error e;
            if (cbvh_parser_push(&l->rx, buf + off, (size_t)r - off, &used, &f, &e) == CBVH_PARSE_FRAME &&
                f.status == CBVH_E_BUSY)
                l->refused = 1;
            off += used;
        }
    cbvh_parser_init(&l->rx);
    l->pend_len = 0;
}

/* The board refused the connection (busy): final, and the connection is
 * gone; the next request connects again. */
static int fail_refused(cbvh_link *l, char *err, size_t errlen) {
    l->refused = 0;
    l->broken = 1;
    l->st.failures++;
    snprintf(err, errlen, "%s: %s", cbvh_error_name(CBVH_E_BUSY), request_error_meaning(CBVH_E_BUSY));
    return -1;
}

/* Reopens a broken link, trying again after a short, growing pause until the
 * per-attempt timeout has passed: a board that resets or re-enumerates on USB
 * is gone for about a second, far longer than one failed open takes. */
static int reopen_within_timeout(cbvh_link *l, char *why, size_t whylen) {
    long deadline = now_ms() + l->timeout_ms;
    long pause_ms = 10;
    char last[200] = "";
    for (;;) {
        if (l->io.reopen(l->io.ctx, last, sizeof last) == 0) return 0;
        long left = deadline - now_ms();
        if (left <= 0) break;
        long nap = pause_ms < left ? pause_ms : left;
        struct timespec ts = {nap / 1000, (nap % 1000) * 1000000L};
        nanosleep(&ts, NULL);
        if (pause_ms < 100) pause_ms *= 2;
    }
    snprintf(why, whylen, "link lost and not back within %d ms (%s)", l->timeout_ms, last);
    return -1;
}

/* What one attempt received besides its reply: a timeout must say what did
 * arrive (garbage, another protocol version, a damaged or cut-off frame),
 * not only that the reply did not. */
typedef struct {
    unsigned long bytes, frame_bytes; /* all bytes read; bytes of intact frames among them */
    uint8_t head[2];                  /* the first two bytes: a reply's magic and version */
    size_t head_n;
    unsigned crc_errors, stale_frames;
} attempt_rx;

static void attempt_rx_add(attempt_rx *a, const uint8_t *buf, long r) {
    for (long i = 0; i < r && a->head_n < sizeof a->head; i++) a->head[a->head_n++] = buf[i];
    a->bytes += (unsigned long)r;
}

static void describe_no_reply(const cbvh_link *l, const attempt_rx *a, char *why, size_t whylen) {
    size_t partial = l->rx.have; /* bytes of a frame still incomplete */
    /* Rescans after a damaged frame can re-count bytes: clamp, never wrap. */
    unsigned long rest = a->bytes > a->frame_bytes ? a->bytes - a->frame_bytes : 0;
    unsigned long garbage = rest > partial ? rest - partial : 0;
    if (a->head_n == 2 && a->head[0] == CBVH_FRAME_MAGIC && a->head[1] != CBVH_PROTO_VERSION)
        snprintf(why, whylen, "reply from protocol version %u (this host speaks version %u)", a->head[1],
                 CBVH_PROTO_VERSION);
    else if (a->crc_errors)
        snprintf(why, whylen, "reply damaged: bad CRC");
    else if (garbage)
        snprintf(why, whylen, "%lu bytes that are not a frame arrived instead of a reply", garbage);
    else if (partial >= CBVH_FRAME_HDR)
        snprintf(why, whylen, "reply cut short: %zu of its %zu bytes arrived", partial,
                 (size_t)(CBVH_FRAME_HDR + cbvh_get16(l->rx.buf + 6) + CBVH_FRAME_CRC));
    else if (partial)
        snprintf(why, whylen, "reply cut short: %zu bytes of its header arrived", partial);
    else if (a->stale_frames)
        snprintf(why, whylen, "no reply within %d ms, only %u stale frame%s (other sequence number or command)",
                 l->timeout_ms, a->stale_frames, a->stale_frames == 1 ? "" : "s");
    else
        snprintf(why, whylen, "no reply within %d ms", l->timeout_ms);
}

int cbvh_link_transact(cbvh_link *l, uint8_t cmd, const uint8_t *payload, uint16_t len, uint16_t *reply_len,
                       char *err, size_t errlen) {
    if (len > CBVH_FRAME_MAX_PAYLOAD) {
        snprintf(err, errlen, "request payload of %u bytes exceeds the %u-byte frame limit", len,
                 CBVH_FRAME_MAX_PAYLOAD);
        return -1;
    }
    l->st.requests++;
    uint16_t seq = ++l->seq;
    if (len) memcpy(l->tx + CBVH_FRAME_HDR, payload, len);
    size_t n = cbvh_frame_seal(l->tx, cmd, 0, seq, len);
    char why[300] = "no attempt made";
    for (int attempt = 0; attempt <= l->max_retries; attempt++) {
        if (attempt) l->st.retries++;
        if (!l->broken && l->io.hung_up && l->io.hung_up(l->io.ctx)) {
            /* The board closed the link: it let this host go after an idle
             * time, or it went away.  Reconnect at once, without spending an
             * attempt; a board that is not there spends this one, as the
             * write that finds the link broken would. */
            cbvh_link_flush(l, 0); /* what it said before it hung up: a refusal? */
            if (l->refused) return fail_refused(l, err, errlen);
            l->st.link_breaks++;
            if (!l->io.reopen || l->io.reopen(l->io.ctx, why, sizeof why) != 0) {
                l->broken = 1;
                l->st.attempts++;
                continue;
            }
            l->st.reopens++;
            cbvh_link_flush(l, 5);
        }
        if (l->refused) return fail_refused(l, err, errlen);
        if (l->broken) {
            if (!l->io.reopen) break; /* nothing can bring the link back */
            if (reopen_within_timeout(l, why, sizeof why) != 0) continue;
            l->broken = 0;
            l->st.reopens++;
            cbvh_link_flush(l, 5);
            if (l->refused) return fail_refused(l, err, errlen);
        }
        l->st.attempts++;
        if (l->io.write(l->io.ctx, l->tx, n, why, sizeof why) != 0) {
            l->st.link_breaks++;
            l->broken = 1;
            continue;
        }
        long deadline = now_ms() + l->timeout_ms;
        int retry_now = 0;
        attempt_rx got = {0};
        while (!retry_now) {
            long left = deadline - now_ms();
            if (left <= 0) {
                l->st.timeouts++;
                describe_no_reply(l, &got, why, sizeof why);
                cbvh_parser_init(&l->rx); /* a partial reply must not glue onto the next */
                break;
            }
            uint8_t buf[4096];
            long r;
            if (l->pend_len) {
                memcpy(buf, l->pend, l->pend_len);
                r = (long)l->pend_len;
                l->pend_len = 0;
            } else {
                r = l->io.read(l->io.ctx, buf, sizeof buf, (int)left, why, sizeof why);
            }
            if (r < 0) {
                l->st.link_breaks++;
                l->broken = 1;
                break;
            }
            attempt_rx_add(&got, buf, r);
            size_t off = 0;
            while ((off < (size_t)r || cbvh_parser_busy(&l->rx)) && !retry_now) {
                size_t used = 0;
                cbvh_frame f;
                cbvh_parse_error e;
                int ev = cbvh_parser_push(&l->rx, buf + off, (size_t)r - off, &used, &f, &e);
                off += used;
                if (ev == CBVH_PARSE_ERROR) {
                    if (e.code == CBVH_E_CRC) got.crc_errors++, l->st.crc_errors++;
                    else if (e.code == CBVH_E_SYNC) l->st.sync_errors++;
                    else l->st.other_parse_errors++;
                    if (e.code == CBVH_E_CRC && e.seq_known && e.seq == seq) {
                        snprintf(why, sizeof why, "reply damaged: bad CRC");
                        retry_now = 1;
                    }
                } else if (ev == CBVH_PARSE_FRAME) {
                    got.frame_bytes += CBVH_FRAME_HDR + f.len + CBVH_FRAME_CRC;
                    if (f.status == CBVH_E_BUSY) return fail_refused(l, err, errlen); /* whatever it answers */
                    if (f.cmd != (cmd | CBVH_REPLY) || f.seq != seq) {
                        l->st.stale_replies++;
                        got.stale_frames++;
                        continue;
                    }
                    if (f.status != CBVH_E_OK) {
                        if (cbvh_error_is_link(f.status)) {
                            l->st.link_errors_reported++;
                            snprintf(why, sizeof why, "board received a damaged request (%s)",
                                     cbvh_error_name(f.status));
                            retry_now = 1;
                            continue;
                        }
                        l->st.failures++;
                        snprintf(err, errlen, "board rejected command 0x%02x: %s error (%s)", cmd,
                                 cbvh_error_name(f.status), request_error_meaning(f.status));
                        return -1;
                    }
                    memcpy(l->reply, f.payload, f.len);
                    *reply_len = f.len;
                    l->st.replies_ok++;
                    /* Bytes after the reply (duplicates, replies to earlier
                     * attempts) are parsed, and counted as stale, next time. */
                    memcpy(l->pend, buf + off, (size_t)r - off);
                    l->pend_len = (size_t)r - off;
                    return 0;
                }
            }
        }
    }
    l->st.failures++;
    snprintf(err, errlen, "no valid reply to command 0x%02x (seq %u) after %d attempts: %s", cmd, seq,
             l->max_retries + 1, why);
    return -1;
}

int cbvh_identity_parse(const uint8_t *p, size_t len, cbvh_identity *id) {
    if (cbvh_identity_get(p, len, id)) return -1;
    for (char *c = id->board_name; *c; c++)
        if (*c < 32 || *c >= 127) *c = '?';
    if (id->proto_version != CBVH_PROTO_VERSION || id->max_payload < 64 || id->max_payload > CBVH_FRAME_MAX_PAYLOAD)
        return -1;
    return 0;
}

int cbvh_link_identify(cbvh_link *l, char *err, size_t errlen) {
    uint16_t n = 0;
    if (cbvh_link_transact(l, CBVH_CMD_IDENTIFY, NULL, 0, &n, err, errlen)) return -1;
    if (cbvh_identity_parse(l->reply, n, &l->ident)) {
        snprintf(err, errlen, "board sent a malformed or incompatible IDENTIFY reply (%u bytes)", n);
        return -1;
    }
    return 0;
}

size_t cbvh_link_max_batch(int n_in, int n_out) {
    return cbvh_run_max_batch(CBVH_FRAME_MAX_PAYLOAD, (unsigned)n_in, (unsigned)n_out);
}

int cbvh_run_reply_check(const uint8_t *p, size_t len, uint8_t unit, unsigned count, unsigned n_out) {
    cbvh_run_reply_hdr h;
    if (cbvh_run_reply_hdr_get(p, len, &h)) return -1;
    if (h.count != count || h.n_out != n_out || h.unit != unit) return -1;
    return len == CBVH_RUN_REPLY_HDR + 4ul * n_out * count ? 0 : -1;
}

int cbvh_link_run(cbvh_link *l, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out,
                  size_t count, char *err, size_t errlen) {
    cbvh_layout lay;
    unit->layout(cfg, &lay);
    if (lay.n_in <= 0 || lay.n_out <= 0 || lay.n_in > 64 || lay.n_out > 64) {
        snprintf(err, errlen, "unit %s (%d->%d words) does not fit the board's register windows", unit->name,
                 lay.n_in, lay.n_out);
        return -1;
    }
    if (cfg->params.quant_bits < -128 || cfg->params.quant_bits > 127 || cfg->params.min_scale < -32768 ||
        cfg->params.min_scale > 32767 || (cfg->enc != CBVH_ENC_MODULO && cfg->enc != CBVH_ENC_RELATIVE)) {
        snprintf(err, errlen, "configuration (N=%d, min_scale=%d) cannot be sent to the board",
                 cfg->params.quant_bits, cfg->params.min_scale);
        return -1;
    }
    /* The board may take smaller frames than the protocol allows (IDENTIFY's
     * max payload, at least 64): batches are cut to what it said. */
    size_t cap = l->ident.max_payload ? l->ident.max_payload : CBVH_FRAME_MAX_PAYLOAD;
    size_t max = cbvh_run_max_batch(cap, (unsigned)lay.n_in, (unsigned)lay.n_out);
    if (max == 0) {
        snprintf(err, errlen, "unit %s (%d->%d words) does not fit the board's %zu-byte frames", unit->name,
                 lay.n_in, lay.n_out, cap);
        return -1;
    }
    uint8_t *payload = l->req;
    for (size_t done = 0; done < count;) {
        size_t k = count - done < max ? count - done : max;
        cbvh_run_hdr h = {.unit = unit->id,
                          .quant_bits = (int8_t)cfg->params.quant_bits,
                          .min_scale = (int16_t)cfg->params.min_scale,
                          .encoding = (uint8_t)cfg->enc,
                          .n_in = (uint8_t)lay.n_in,
                          .n_out = (uint8_t)lay.n_out,
                          .count = (uint16_t)k};
        cbvh_run_hdr_put(payload, &h);
        const uint32_t *src = in + done * (size_t)lay.n_in;
        for (size_t i = 0; i < k * (size_t)lay.n_in; i++) cbvh_put32(payload + CBVH_RUN_HDR + 4 * i, src[i]);
        uint16_t rlen = 0;
        char why[400];
        if (cbvh_link_transact(l, CBVH_CMD_RUN, payload, (uint16_t)(CBVH_RUN_HDR + 4 * k * (size_t)lay.n_in), &rlen, why,
                               sizeof why)) {
            snprintf(err, errlen, "%s: vectors %zu..%zu not run: %s", unit->name, done, done + k - 1, why);
            return -1;
        }
        if (cbvh_run_reply_check(l->reply, rlen, unit->id, (unsigned)k, (unsigned)lay.n_out)) {
            l->st.bad_replies++;
            snprintf(err, errlen, "%s: board reply to vectors %zu..%zu is inconsistent (%u bytes)", unit->name, done,
                     done + k - 1, rlen);
            return -1;
        }
        uint32_t *dst = out + done * (size_t)lay.n_out;
        for (size_t i = 0; i < k * (size_t)lay.n_out; i++) dst[i] = cbvh_get32(l->reply + CBVH_RUN_REPLY_HDR + 4 * i);
        done += k;
    }
    return 0;
}
