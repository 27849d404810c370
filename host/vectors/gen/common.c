/* What the units' generators share (gen/gen.h): random floats and boxes,
 * the vector list, structured boxes, root boxes and ray patterns. */
#include "vectors/gen/gen.h"

#include <stdlib.h>

/* The inverse of cbvh_f32_key (0 -> +0). */
static cbvh_f32 funkey(int64_t k) { return k < 0 ? CBVH_F32_SIGN | (uint32_t)-k : (uint32_t)k; }
static const int64_t KEY_MAX = CBVH_F32_MAX;

/* Exponents x significands, TestFloat style; subnormals separately. */
static const int pat_exp[] = {-126, -125, -64, -32, -31, -30, -29, -25, -24, -23, -2, -1,
                              0,    1,    2,   23,  24,  25,  40,  64,  100, 125, 126, 127};
static const uint32_t pat_frac[] = {0, 1, 0x400000, 0x7FFFFE, 0x7FFFFF};
static const uint32_t pat_sub[] = {1, 2, 0x400000, 0x7FFFFF};
#define N_EXP (int)(sizeof pat_exp / sizeof pat_exp[0])
#define N_FRAC (int)(sizeof pat_frac / sizeof pat_frac[0])
#define N_SUB (int)(sizeof pat_sub / sizeof pat_sub[0])
#define N_MAG (1 + N_SUB + N_EXP * N_FRAC)

/* Magnitude pattern i in [0, N_MAG): zero, subnormals, then exponent x fraction. */
static cbvh_f32 pat_mag(int i) {
    if (i == 0) return 0;
    if (i <= N_SUB) return pat_sub[i - 1];
    i -= 1 + N_SUB;
    return cbvh_f32_make(0, pat_exp[i / N_FRAC], pat_frac[i % N_FRAC]);
}

/* A handful of values whose pairs make boxes (incl. straddling zero). */
static const cbvh_f32 box_vals[] = {
    0x00000000, 0x80000000, 0x00000001, 0x80000001, 0x00800000, 0x30800000 /* 2^-30 */, 0x33C00000 /* 1.5*2^-24 */,
    0x3DCCCCCD /* 0.1 */, F_NEG_0_4, F_ONE, 0x3F800001, 0xBF800000, 0x40400000 /* 3 */, 0xC0B00000 /* -5.5 */,
    F_TWO24, 0x4B800001 /* 2^24+2 */, 0x49742400 /* 1e6 */, F_TWO40, 0xD3800000 /* -2^40 */, CBVH_F32_MAX,
    CBVH_F32_MAX | CBVH_F32_SIGN, 0x7F000000 /* 2^127 */};
#define N_BOX_VALS (int)(sizeof box_vals / sizeof box_vals[0])

const cbvh_f32 vg_nan_inf[N_NAN_INF] = {0x7FC00000, 0x7F800001, 0xFFC00000, 0x7FFFFFFF, CBVH_F32_POS_INF, CBVH_F32_NEG_INF};

cbvh_f32 vg_rnd_float(rng_t *r) {
    uint64_t k = rnd_below(r, 8);
    int sign = (int)rnd_below(r, 2);
    if (k == 0) { /* any finite bit pattern */
        cbvh_f32 x;
        do x = (cbvh_f32)rng_next(r);
        while (cbvh_f32_is_nan_or_inf(x));
        return x;
    }
    if (k == 1) return pat_mag((int)rnd_below(r, N_MAG)) | (sign ? CBVH_F32_SIGN : 0u);
    int e = k <= 4 ? (int)rnd_range(r, -40, 40) : (int)rnd_range(r, -126, 127);
    uint32_t frac;
    switch (rnd_below(r, 4)) {
    case 0: frac = (uint32_t)rng_next(r); break;
    case 1: frac = (uint32_t)(((uint64_t)1 << rnd_below(r, 24)) - 1); break;                  /* low ones */
    case 2: frac = ~(uint32_t)(((uint64_t)1 << rnd_below(r, 24)) - 1); break;                 /* high ones */
    default: {
        uint32_t bits = (uint32_t)rng_next(r); /* one call per statement: C leaves argument order open */
        frac = bits & ~(uint32_t)(((uint64_t)1 << rnd_below(r, 24)) - 1);
        break;
    }
    }
    return cbvh_f32_make(sign, e, frac);
}

/* Random finite float in [a, b] (a <= b): near either end or anywhere. */
static cbvh_f32 rnd_between(rng_t *r, cbvh_f32 a, cbvh_f32 b) {
    int64_t ka = cbvh_f32_key(a), kb = cbvh_f32_key(b);
    switch (rnd_below(r, 4)) {
    case 0: return funkey(ka + (int64_t)rnd_below(r, (uint64_t)(kb - ka < 16 ? kb - ka + 1 : 16)));
    case 1: return funkey(kb - (int64_t)rnd_below(r, (uint64_t)(kb - ka < 16 ? kb - ka + 1 : 16)));
    default: return funkey(rnd_range(r, ka, kb));
    }
}

box_t vg_rnd_box(rng_t *r) {
    box_t b;
    uint64_t kind = rnd_below(r, 4);
    if (kind == 0) {
        b.lo = vg_rnd_float(r);
        b.hi = vg_rnd_float(r);
        if (cbvh_f32_cmp(b.lo, b.hi) > 0) {
            cbvh_f32 t = b.lo;
            b.lo = b.hi;
            b.hi = t;
        }
        return b;
    }
    b.lo = vg_rnd_float(r);
    int64_t k = cbvh_f32_key(b.lo), ext = (int64_t)rnd_below(r, (uint64_t)1 << rnd_below(r, 32));
    if (ext > KEY_MAX - k) ext = KEY_MAX - k;
    b.hi = funkey(k + ext);
    return b;
}

box_t vg_rnd_sub_box(rng_t *r, box_t in) {
    box_t b;
    switch (rnd_below(r, 8)) {
    case 0: return in;
    case 1: b.lo = b.hi = in.lo; return b;
    case 2: b.lo = b.hi = in.hi; return b;
    default: break;
    }
    b.lo = rnd_between(r, in.lo, in.hi);
    b.hi = rnd_between(r, in.lo, in.hi);
    if (cbvh_f32_cmp(b.lo, b.hi) > 0) {
        cbvh_f32 t = b.lo;
        b.lo = b.hi;
        b.hi = t;
    }
    return b;
}

void vg_emit(gen_t *g, const uint32_t *in) {
    if (g->oom) return;
    if (g->n == g->cap) {
        size_t cap = g->cap ? g->cap * 2 : 1024;
        uint32_t *ni = realloc(g->in, cap * (size_t)g->lay.n_in * sizeof *ni);
        if (!ni) {
            g->oom = 1;
            return;
        }
        g->in = ni;
        g->cap = cap;
    }
    uint32_t *dst = g->in + g->n * (size_t)g->lay.n_in;
    /* Keep every input inside its field so the file can be written. */
    for (int i = 0; i < g->lay.n_in; i++) {
        int d = g->lay.in[i].hex_digits;
        dst[i] = d >= 8 ? in[i] : in[i] & ((1u << (4 * d)) - 1u);
    }
    g->n++;
}

/* ---- cases shared by several units ------------------------------------------- */

size_t vg_structured_boxes(box_t *out, size_t max, int step) {
    size_t n = 0;
#define PUT(a, b)                                                                                                     \
    do {                                                                                                               \
        if (n < max) out[n] = (box_t){(a), (b)};                                                                       \
        n++;                                                                                                           \
    } while (0)
    for (int i = 0; i < N_MAG; i += step) {
        cbvh_f32 m = pat_mag(i);
        PUT(m, m);                   /* zero-width */
        PUT(neg(m), neg(m));         /* zero-width, negative (incl. -0) */
        PUT(m, up(m));               /* one ulp */
        PUT(down(neg(m)), neg(m));   /* one ulp, negative */
        if (i % (2 * step) == 0) PUT(neg(m), m); /* straddling zero */
    }
    for (int i = 0; i < N_BOX_VALS; i++)
        for (int j = 0; j < N_BOX_VALS; j += step)
            if (cbvh_f32_cmp(box_vals[i], box_vals[j]) < 0) PUT(box_vals[i], box_vals[j]);
    /* Far from the origin with tiny extents, and the cloth plane. */
    PUT(F_TWO40, up(F_TWO40));
    PUT(neg(up(F_TWO40)), neg(F_TWO40));
    PUT(F_TWO24, up(up(F_TWO24)));
    PUT(cbvh_f32_make(0, 100, 0x123456), up(cbvh_f32_make(0, 100, 0x123456)));
    PUT(F_NEG_0_4, F_NEG_0_4);
    PUT(down(F_NEG_0_4), up(F_NEG_0_4));
    PUT(0xBED1EB85 /* -0.41 */, 0xBEC7AE14 /* -0.39 */);
    PUT(0x80000000, 0x00000000);
    PUT(0x00000000, 0x80000000);
#undef PUT
    return n;
}

void vg_box_rejects(gen_t *g, void (*put)(gen_t *, cbvh_f32, cbvh_f32, int), int scale) {
    for (int i = 0; i < N_NAN_INF; i++) {
        put(g, vg_nan_inf[i], F_ONE, scale);
        put(g, 0xBF800000, vg_nan_inf[i], scale);
        put(g, vg_nan_inf[i], vg_nan_inf[i], scale);
    }
    put(g, CBVH_F32_NEG_INF, CBVH_F32_POS_INF, scale);
    put(g, F_ONE, 0, scale);                         /* inverted */
    put(g, up(F_ONE), F_ONE, scale);                 /* inverted by one ulp */
    put(g, 0x00000000, 0x80000001, scale);           /* inverted across zero */
    put(g, CBVH_F32_MAX, CBVH_F32_MAX | CBVH_F32_SIGN, scale);
}

const box_t vg_root_boxes[N_ROOT] = {
    {0xBF800000, F_ONE},                     /* [-1, 1] */
    {0x00000000, F_ONE},                     /* [0, 1] */
    {F_NEG_0_4, F_NEG_0_4},                  /* cloth plane, zero width */
    {0xBF000000, F_NEG_0_4},                 /* [-0.5, -0.4] */
    {F_TWO40, 0x53800001},                   /* [2^40, nextup(2^40)] */
    {0xD3800001, 0xD3800000},                /* its mirror */
    {CBVH_F32_MAX | CBVH_F32_SIGN, CBVH_F32_MAX}, /* the whole float line: clb = -Inf */
    {0x7E000000, CBVH_F32_MAX},              /* near FLT_MAX: cub overflows */
    {0x00000001, 0x00000010},                /* subnormals */
    {0x80000000, 0x00000000},                /* -0 .. 0 */
    {0x30800000, 0x30800000},                /* 2^-30 point */
    {0xC0B00000, 0x4B800001},                /* [-5.5, 2^24+2] */
    {0x3DCCCCCD, 0x49742400},                /* [0.1, 1e6] */
    {0x4B7FFFFF, 0x4B800001},                /* around 2^24 */
};

const cbvh_f32 vg_ray_orig[N_RB_ORIG] = {0xBF800000u /* -1 */, 0, CBVH_F32_SIGN, F_HALF, F_ONE /* on the face x=1 */,
                                          0x3F800001u /* just outside */, 0x40000000u /* 2 */, 0x33800000u /* 2^-24 */};
const cbvh_f32 vg_ray_dir[N_RB_DIR] = {F_ONE, 0xBF800000u, 0, CBVH_F32_SIGN, F_THIRD, 0x00000001u /* tiny */,
                                        0x7F000000u /* 2^127 */, 0xC0400000u /* -3 */};

int64_t vg_rnd_odd_bits(rng_t *r, int bits) {
    return (int64_t)(((uint64_t)1 << (bits - 1)) | (rng_next(r) & (((uint64_t)1 << (bits - 1)) - 1)) | 1u);
}
/* One draw per statement: argument order is unspecified. */
cbvh_f32 vg_rnd_f32_in(rng_t *r, int elo, int ehi) {
    int sign = (int)rnd_below(r, 2);
    int e = (int)rnd_range(r, elo, ehi);
    uint32_t frac = (uint32_t)rng_next(r);
    return cbvh_f32_make(sign, e, frac);
}
cbvh_f32 vg_nudge(rng_t *r, cbvh_f32 x) {
    switch (rnd_below(r, 6)) {
    case 0: return up(x);
    case 1: return down(x);
    default: return x;
    }
}

cbvh_f32 vg_add_cells(cbvh_f32 x, int64_t j, int e, cbvh_rnd mode) {
    int sign, ex;
    uint32_t sig;
    if (x == CBVH_F32_NEG_INF) { /* -2^128 */
        sign = 1, sig = CBVH_F32_HIDDEN, ex = 128 - CBVH_F32_FRAC_BITS;
    } else {
        cbvh_f32_break(x, &sign, &sig, &ex);
    }
    return cbvh_f32_add_dyadic(sign ? -(int64_t)sig : (int64_t)sig, ex, j, e, mode);
}

vg_window vg_window_of(const cbvh_axis_ctx *c, int n) {
    vg_window w;
    cbvh_f32 top = vg_add_cells(c->clb, (int64_t)1 << n, c->scale, CBVH_RND_UP); /* RU(u + 2^(N+e)) */
    w.first = c->clb == CBVH_F32_NEG_INF ? (CBVH_F32_SIGN | CBVH_F32_MAX) : c->clb;
    w.has_past = top != CBVH_F32_POS_INF;
    w.past = w.has_past ? top : 0;
    w.last = w.has_past ? down(top) : CBVH_F32_MAX;
    return w;
}
