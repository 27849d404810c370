/* Fault injector for the socket link (see link_fault.h). */
#define _GNU_SOURCE
#include "link_fault.h"

#include <errno.h>
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

int cbvh_link_fault_parse(cbvh_link_fault *f, const char *spec, char *err, size_t errlen) {
    cbvh_link_fault_init(f, 1);
    char buf[256];
    if (strlen(spec) >= sizeof buf) {
        snprintf(err, errlen, "fault spec too long");
        return -1;
    }
    strcpy(buf, spec);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        if (!eq) {
            snprintf(err, errlen, "fault spec item '%s' lacks '='", tok);
            return -1;
        }
        *eq = '\0';
        char *end;
        double v = strtod(eq + 1, &end);
        if (*end || end == eq + 1) {
            snprintf(err, errlen, "fault spec: bad number for '%s'", tok);
            return -1;
        }
        int k = -1;
        for (int i = 0; i < CBVH_FAULT_KINDS; i++)
            if (strcmp(tok, cbvh_fault_names[i]) == 0) k = i;
        if (k >= 0 || strcmp(tok, "all") == 0) {
            if (v < 0 || v > 1) {
                snprintf(err, errlen, "fault rate for '%s' must be in [0,1]", tok);
                return -1;
            }
            for (int i = 0; i < CBVH_FAULT_KINDS; i++)
                if (i == k || k < 0) f->rate[i] = v;
        } else if (strcmp(tok, "delay_ms") == 0 && v >= 0 && v <= 10000) {
            f->delay_ms = (int)v;
        } else if (strcmp(tok, "seed") == 0) {
            f->rng = (uint64_t)v ? (uint64_t)v : 1;
        } else {
            snprintf(err, errlen, "fault spec: unknown item '%s'", tok);
            return -1;
        }
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
