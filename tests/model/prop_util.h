/* Shared helpers of the model property and hard-case tests: a seeded PRNG,
 * float-pattern generators, an output digest, a failure counter, and FPU
 * oracles that are independent of the model (double/long double arithmetic
 * under fesetround; compile users with -frounding-math). */
#ifndef CBVH_PROP_UTIL_H
#define CBVH_PROP_UTIL_H

#include <fenv.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/datapath.h"
#include "test_util.h" /* fb, bf (tests/common) */

/* ---- PRNG: splitmix64, seeded, identical at every optimisation level ---- */
typedef struct {
    uint64_t s;
} prng;

static inline uint64_t prng_next(prng *r) {
    uint64_t z = (r->s += UINT64_C(0x9E3779B97F4A7C15));
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}
/* uniform in [0, n) (n > 0; tiny bias is irrelevant here) */
static inline uint32_t prng_below(prng *r, uint32_t n) { return (uint32_t)((prng_next(r) >> 32) % n); }
static inline int prng_range(prng *r, int lo, int hi) { return lo + (int)prng_below(r, (uint32_t)(hi - lo + 1)); }

/* ---- bit patterns (fb, bf: tests/common/test_util.h) ---- */
/* back from cbvh_f32_key, the monotone integer key (0 -> +0) */
static inline cbvh_f32 unkey(int64_t k) { return k < 0 ? (CBVH_F32_SIGN | (cbvh_f32)(-k)) : (cbvh_f32)k; }

/* A float pattern from the structured table or random, finite. */
static const uint32_t prop_exp_patterns[] = {0,   1,   2,   3,   22,  23,  24,  25,  60,  63,  64,  96,  97,  100,
                                             103, 110, 120, 125, 126, 127, 128, 129, 130, 140, 150, 157, 160, 180,
                                             190, 200, 220, 226, 227, 230, 240, 250, 252, 253, 254};
static const uint32_t prop_sig_patterns[] = {0x000000, 0x000001, 0x000002, 0x7FFFFF, 0x7FFFFE, 0x400000, 0x400001,
                                             0x3FFFFF, 0x555555, 0x2AAAAA, 0x000100, 0x7FFF00, 0x0FFFF0, 0x100000};
#define PROP_N_EXP ((int)(sizeof prop_exp_patterns / sizeof prop_exp_patterns[0]))
#define PROP_N_SIG ((int)(sizeof prop_sig_patterns / sizeof prop_sig_patterns[0]))
#define PROP_N_STRUCT (PROP_N_EXP * PROP_N_SIG * 2)

static inline cbvh_f32 prop_structured(int i) {
    int s = i % 2, j = i / 2;
    return ((cbvh_f32)s << 31) | (prop_exp_patterns[j % PROP_N_EXP] << CBVH_F32_FRAC_BITS) | prop_sig_patterns[j / PROP_N_EXP];
}

/* Random finite float with a wide spread of magnitudes. */
static inline cbvh_f32 prop_random_float(prng *r) {
    cbvh_f32 b;
    switch (prng_below(r, 4)) {
    case 0: /* any finite pattern */
        do b = (cbvh_f32)prng_next(r);
        while ((b & CBVH_F32_EXP) == CBVH_F32_EXP);
        return b;
    case 1: /* scene-like magnitudes 2^-20..2^20 */
        return ((cbvh_f32)prng_below(r, 2) << 31) | ((cbvh_f32)prng_range(r, 107, 147) << CBVH_F32_FRAC_BITS) |
               ((cbvh_f32)prng_next(r) & CBVH_F32_FRAC);
    case 2: /* structured */
        return prop_structured((int)prng_below(r, PROP_N_STRUCT));
    default: /* a structured exponent with a random significand */
        return ((cbvh_f32)prng_below(r, 2) << 31) | (prop_exp_patterns[prng_below(r, PROP_N_EXP)] << CBVH_F32_FRAC_BITS) |
               ((cbvh_f32)prng_next(r) & CBVH_F32_FRAC);
    }
}

/* A point in [lo, hi] (finite, lo <= hi): the ends, their neighbours, uniform
 * in the key space (log-like) or linear (double arithmetic, deterministic). */
static inline cbvh_f32 prop_point_in(prng *r, cbvh_f32 lo, cbvh_f32 hi) {
    int64_t a = cbvh_f32_key(lo), b = cbvh_f32_key(hi);
    switch (prng_below(r, 8)) {
    case 0: return lo;
    case 1: return hi;
    case 2: return unkey(a + (b > a ? 1 : 0));
    case 3: return unkey(b - (b > a ? 1 : 0));
    case 4:
    case 5: return unkey(a + (int64_t)(prng_next(r) % (uint64_t)(b - a + 1)));
    default: {
        double t = (double)(prng_next(r) >> 11) * 0x1p-53;
        double v = (double)bf(lo) + t * ((double)bf(hi) - (double)bf(lo));
        float f = (float)v; /* round to nearest, then clamp into [lo, hi] */
        cbvh_f32 x = fb(f);
        if ((x & CBVH_F32_EXP) == CBVH_F32_EXP || cbvh_f32_key(x) < a) x = lo;
        if (cbvh_f32_key(x) > b) x = hi;
        return x;
    }
    }
}

/* ---- digest (test_util.h) of an axis unit's outputs ---- */
static inline void digest_code(digest *d, uint32_t st, const cbvh_axis_code *c) {
    digest_u32(d, st);
    digest_u32(d, c->lb_mod);
    digest_u32(d, c->ub_mod);
    digest_u32(d, (uint32_t)c->child_scale);
    digest_u32(d, c->clb);
    digest_u32(d, c->cub);
}

/* ---- failures: count all, print the first few ---- */
static long prop_failures;
static inline void prop_fail(const char *fmt, ...) {
    if (prop_failures++ < 12) {
        va_list ap;
        va_start(ap, fmt);
        fputs("FAIL: ", stderr);
        vfprintf(stderr, fmt, ap);
        fputc('\n', stderr);
        va_end(ap);
    }
}

/* ---- FPU oracles (independent of the model) ---- */

/* binary32 of a double in a directed mode; zero results are +0 (model rule). */
static inline cbvh_f32 oracle_round_d(double v, int mode) {
    fesetround(mode);
    volatile double vv = v;
    volatile float f = (float)vv;
    fesetround(FE_TONEAREST);
    cbvh_f32 b = fb(f);
    return (b & ~CBVH_F32_SIGN) == 0 ? 0u : b;
}

static inline double f32_as_double(cbvh_f32 b) { return (double)bf(b); }

/* Eq. 2, by a loop: smallest k >= min_scale with cells * 2^e <= 2^N * 2^k. */
static inline int oracle_child_scale(int n, int min_scale, int e, double cells) {
    for (int k = min_scale;; k++)
        if (ldexp(cells, e) <= ldexp(1.0, n + k)) return k;
}

/* floor(x / 2^e) as an exact double (x finite). */
static inline double oracle_floor(cbvh_f32 x, int e) { return floor(ldexp(f32_as_double(x), -e)); }

/* Cells spanned by [lb, ub] at scale e (exact when small, > 2^N when large). */
static inline double oracle_cells(cbvh_f32 lb, cbvh_f32 ub, int e) { return oracle_floor(ub, e) - oracle_floor(lb, e) + 1.0; }

static inline uint32_t oracle_mod(double k, int n) {
    double m = fmod(k, ldexp(1.0, n)); /* exact */
    if (m < 0) m += ldexp(1.0, n);
    return (uint32_t)m;
}

/* The compressor's OUTSIDE (datapath.md §6) with the FPU: lb < g or
 * ub >= g + 2^(N+e), g = floor(u / 2^e) 2^e, u = node_clb (-Inf: -2^128).
 * g is exact in binary64; the sum is rounded up, and a binary32 ub is >= the
 * sum iff it is >= its binary64 RU. */
static inline int oracle_outside(int n, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_f32 node_clb) {
    double u = node_clb == CBVH_F32_NEG_INF ? -0x1p128 : f32_as_double(node_clb);
    double g = ldexp(floor(ldexp(u, -e)), e);
    fesetround(FE_UPWARD);
    volatile double top = g + ldexp(1.0, n + e);
    fesetround(FE_TONEAREST);
    return f32_as_double(lb) < g || f32_as_double(ub) >= top;
}

/* The compressor's outputs, computed with the FPU (inputs without faults). */
static inline uint32_t oracle_compress(int n, int min_scale, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_f32 node_clb,
                                       cbvh_axis_code *o) {
    double k = oracle_floor(lb, e), ku = oracle_floor(ub, e);
    double cells = ku - k + 1.0;
    int fit = cells <= ldexp(1.0, n);
    o->lb_mod = oracle_mod(k, n);
    o->ub_mod = (oracle_mod(ku, n) + 1u) & ((1u << n) - 1u);
    o->child_scale = fit ? oracle_child_scale(n, min_scale, e, cells) : e;
    o->clb = oracle_round_d(ldexp(k, e), FE_DOWNWARD); /* k * 2^e is exact in double */
    fesetround(FE_UPWARD);
    volatile double kd = ldexp(ku, e), one = ldexp(1.0, e);
    volatile double l = kd + one; /* rounded up in double, then up again: same as once */
    fesetround(FE_TONEAREST);
    o->cub = oracle_round_d(l, FE_UPWARD);
    return (fit ? 0 : CBVH_ST_NO_FIT) | (oracle_outside(n, lb, ub, e, node_clb) ? CBVH_ST_OUTSIDE : 0);
}

static inline int code_equal(const cbvh_axis_code *a, const cbvh_axis_code *b) {
    return a->lb_mod == b->lb_mod && a->ub_mod == b->ub_mod && a->child_scale == b->child_scale && a->clb == b->clb &&
           a->cub == b->cub;
}

/* Enclosure as real numbers: clb <= lb and cub >= ub (clb may be -Inf, cub +Inf). */
static inline int encloses(const cbvh_axis_code *c, cbvh_f32 lb, cbvh_f32 ub) {
    return f32_as_double(c->clb) <= f32_as_double(lb) && f32_as_double(c->cub) >= f32_as_double(ub);
}

#define CODE_FMT "lb_mod=%u ub_mod=%u cs=%d clb=%08x cub=%08x"
#define CODE_ARGS(c) (c).lb_mod, (c).ub_mod, (c).child_scale, (c).clb, (c).cub

/* Print the run's digest; optionally write it to a file (temp + rename). */
static inline int prop_finish(const char *name, const digest *d, long cases, const char *digest_out) {
    printf("%s: %ld cases, %ld failures\n", name, cases, prop_failures);
    printf("digest: %016llx\n", (unsigned long long)d->h);
    if (digest_out) {
        char tmp[4096];
        snprintf(tmp, sizeof tmp, "%s.tmp", digest_out);
        FILE *f = fopen(tmp, "w");
        if (!f || fprintf(f, "%016llx\n", (unsigned long long)d->h) < 0 || fclose(f) != 0 || rename(tmp, digest_out) != 0) {
            fprintf(stderr, "error: cannot write digest file %s\n", digest_out);
            return 2;
        }
    }
    return prop_failures ? 1 : 0;
}

#endif
