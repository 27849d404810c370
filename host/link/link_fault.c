/* Fault injector for the socket link (see link_fault.h). */
#define _GNU_SOURCE
#include "link/link_fault.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>

const char *const cbvh_fault_names[CBVH_FAULT_KINDS] = {"drop", "corrupt", "dup", "trunc", "delay", "disconnect"};

void cbvh_link_fault_init(cbvh_link_fault *f, uint64_t seed) {
    memset(f, 0, sizeof *f);
    f->delay_ms = 150;
    f->rng = seed ? seed : 0x9E3779B97F4A7C15ull;
}

static uint64_t next(cbvh_link_fault *f) { /* xorshift64* */
    f->rng ^= f->rng >> 12;
    f->rng ^= f->rng << 25;
    f->rng ^= f->rng >> 27;
    return f->rng * 2685821657736338717ull;
}
static double uniform(cbvh_link_fault *f) { return (double)(next(f) >> 11) / 9007199254740992.0; }

/* One "name=value" item's value: a probability, finite and in [0,1]. */
static int parse_rate(const char *s, double *v) {
    char *end;
    errno = 0;
    double x = strtod(s, &end);
    if (!*s || isspace((unsigned char)*s) || *end || errno || !isfinite(x) || x < 0 || x > 1) return -1;
    *v = x;
    return 0;
}

/* An unsigned decimal integer, digits only (strtoull alone would take "-1"
 * as 2^64-1 and skip leading blanks), at most hi. */
static int parse_uint(const char *s, unsigned long long hi, unsigned long long *v) {
    if (*s < '0' || *s > '9') return -1;
    char *end;
    errno = 0;
    unsigned long long x = strtoull(s, &end, 10);
    if (*end || errno == ERANGE || x > hi) return -1;
    *v = x;
    return 0;
}

int cbvh_link_fault_parse(cbvh_link_fault *f, const char *spec, char *err, size_t errlen) {
    cbvh_link_fault_init(f, 1);
    char buf[256];
    if (strlen(spec) >= sizeof buf) {
        snprintf(err, errlen, "fault spec too long (at most %zu bytes)", sizeof buf - 1);
        return -1;
    }
    if (!*spec) {
        snprintf(err, errlen, "empty fault spec");
        return -1;
    }
    strcpy(buf, spec);
    enum { ALL = CBVH_FAULT_KINDS, DELAY_MS, SEED }; /* item numbers after the fault kinds */
    unsigned seen = 0; /* bit per item number: a repeated item would silently override the first */
    double all = 0;
    for (char *tok = buf, *next_tok; tok; tok = next_tok) {
        /* split by hand: strtok would skip empty items ("drop=0.1,,dup=0.1") */
        char *comma = strchr(tok, ',');
        next_tok = comma ? comma + 1 : NULL;
        if (comma) *comma = '\0';
        char *eq = strchr(tok, '=');
        if (!*tok) {
            snprintf(err, errlen, "fault spec has an empty item");
            return -1;
        }
        if (!eq) {
            snprintf(err, errlen, "fault spec item '%s' is not NAME=VALUE", tok);
            return -1;
        }
        *eq = '\0';
        const char *val = eq + 1;
        int k = -1;
        for (int i = 0; i < CBVH_FAULT_KINDS; i++)
            if (strcmp(tok, cbvh_fault_names[i]) == 0) k = i;
        int bit = k >= 0                            ? k
                  : strcmp(tok, "all") == 0         ? ALL
                  : strcmp(tok, "delay_ms") == 0    ? DELAY_MS
                  : strcmp(tok, "seed") == 0        ? SEED
                                                    : -1;
        if (bit < 0) {
            snprintf(err, errlen, "fault spec: unknown item '%s' (expected drop, corrupt, dup, trunc, delay, "
                     "disconnect, all, delay_ms or seed)", tok);
            return -1;
        }
        if (seen & (1u << bit)) {
            snprintf(err, errlen, "fault spec: item '%s' given twice", tok);
            return -1;
        }
        seen |= 1u << bit;
        if (bit <= ALL) {
            double v;
            if (parse_rate(val, &v)) {
                snprintf(err, errlen, "fault spec item '%s=%s': bad value, expected a probability in [0,1]", tok, val);
                return -1;
            }
            if (k >= 0) f->rate[k] = v;
            else all = v;
        } else if (bit == DELAY_MS) {
            unsigned long long v;
            if (parse_uint(val, CBVH_FAULT_DELAY_MS_MAX, &v)) {
                snprintf(err, errlen, "fault spec item 'delay_ms=%s': bad value, expected an integer in 0..%d", val,
                         CBVH_FAULT_DELAY_MS_MAX);
                return -1;
            }
            f->delay_ms = (int)v;
        } else {
            unsigned long long v;
            if (parse_uint(val, UINT64_MAX, &v)) {
                snprintf(err, errlen, "fault spec item 'seed=%s': bad value, expected a decimal integer in 0..2^64-1",
                         val);
                return -1;
            }
            f->rng = v ? (uint64_t)v : 1; /* xorshift state must not be 0 */
        }
    }
    /* "all" sets the kinds not named, wherever it stands in the list. */
    for (int i = 0; i < CBVH_FAULT_KINDS; i++)
        if (!(seen & (1u << i))) f->rate[i] = all;
    /* At most one fault per frame, drawn from one uniform number: rates adding
     * up to more than 1 would starve the kinds listed last. */
    double sum = 0;
    for (int i = 0; i < CBVH_FAULT_KINDS; i++) sum += f->rate[i];
    if (sum > 1 + 1e-9) {
        snprintf(err, errlen, "fault spec: the rates add up to %g, more than 1 (at most one fault per frame%s)", sum,
                 seen & (1u << ALL) ? "; all=R gives R to each kind not named" : "");
        return -1;
    }
    return 0;
}

int cbvh_send_all(int fd, const uint8_t *p, size_t n) {
    while (n > 0) {
        ssize_t w = send(fd, p, n, MSG_NOSIGNAL);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

int cbvh_link_fault_send(cbvh_link_fault *f, int fd, const uint8_t *frame, size_t len) {
    if (!f) return cbvh_send_all(fd, frame, len);
    f->frames++;
    /* At most one fault per frame, picked in this order. */
    double u = uniform(f), acc = 0;
    int kind = -1;
    for (int i = 0; i < CBVH_FAULT_KINDS; i++) {
        acc += f->rate[i];
        if (u < acc) {
            kind = i;
            break;
        }
    }
    if (kind < 0) return cbvh_send_all(fd, frame, len);
    f->injected[kind]++;
    switch (kind) {
    case CBVH_FAULT_DROP: return 0;
    case CBVH_FAULT_CORRUPT: {
        uint8_t tmp[8192];
        size_t n = len < sizeof tmp ? len : sizeof tmp;
        memcpy(tmp, frame, n);
        size_t at = (size_t)(next(f) % n);
        tmp[at] ^= (uint8_t)(1u << (next(f) % 8));
        return cbvh_send_all(fd, tmp, n);
    }
    case CBVH_FAULT_DUP:
        if (cbvh_send_all(fd, frame, len)) return -1;
        return cbvh_send_all(fd, frame, len);
    case CBVH_FAULT_TRUNC: return cbvh_send_all(fd, frame, (size_t)(next(f) % len));
    case CBVH_FAULT_DELAY: {
        struct timespec ts = {f->delay_ms / 1000, (long)(f->delay_ms % 1000) * 1000000L};
        while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {}
        return cbvh_send_all(fd, frame, len);
    }
    default: /* DISCONNECT: part of the frame, then the connection goes */
        cbvh_send_all(fd, frame, (size_t)(next(f) % len));
        return -1;
    }
}
