/* Golden vector generator: TestFloat-style structured corner cases (level 1)
 * plus random cases (level 2).  Integer-only: inputs are built as binary32
 * bit patterns, so the files are identical on every host. */
#include "vectors/vecgen.h"

#include "cbvh/qbvh.h"
#include "cbvh/traversal_units.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- PRNG: splitmix64 seeds xoshiro256** --------------------------------- */

typedef struct {
    uint64_t s[4];
} rng_t;

static uint64_t splitmix64(uint64_t *x) {
    uint64_t z = (*x += UINT64_C(0x9E3779B97F4A7C15));
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static uint64_t rng_next(rng_t *r) {
    uint64_t *s = r->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

static void rng_seed(rng_t *r, uint64_t seed) {
    for (int i = 0; i < 4; i++) r->s[i] = splitmix64(&seed);
}

/* Uniform in [0, n) (n > 0); the tiny modulo bias does not matter here. */
static uint64_t rnd_below(rng_t *r, uint64_t n) { return rng_next(r) % n; }
static int64_t rnd_range(rng_t *r, int64_t lo, int64_t hi) { return lo + (int64_t)rnd_below(r, (uint64_t)(hi - lo) + 1); }

/* ---- binary32 patterns --------------------------------------------------- */

static cbvh_f32 mkf(int sign, int e, uint32_t frac) {
    return (sign ? CBVH_F32_SIGN : 0u) | (uint32_t)(e + 127) << 23 | (frac & CBVH_F32_FRAC);
}
static cbvh_f32 neg(cbvh_f32 x) { return x ^ CBVH_F32_SIGN; }

/* Order-preserving integer key of a finite float (+0 and -0 both 0). */
static int64_t fkey(cbvh_f32 x) { return (x & CBVH_F32_SIGN) ? -(int64_t)(x & ~CBVH_F32_SIGN) : (int64_t)x; }
static cbvh_f32 funkey(int64_t k) { return k < 0 ? CBVH_F32_SIGN | (uint32_t)-k : (uint32_t)k; }
static const int64_t KEY_MAX = CBVH_F32_MAX;

static cbvh_f32 up(cbvh_f32 x) { return x == CBVH_F32_MAX ? x : cbvh_f32_next_up(x); }
static cbvh_f32 down(cbvh_f32 x) { return x == (CBVH_F32_MAX | CBVH_F32_SIGN) ? x : cbvh_f32_next_down(x); }

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
    return mkf(0, pat_exp[i / N_FRAC], pat_frac[i % N_FRAC]);
}

#define F_NEG_0_4 0xBECCCCCDu /* -0.4f: the cloth plane */
#define F_ONE 0x3F800000u
#define F_QNAN 0x7FC00000u
#define F_TWO40 0x53800000u /* 2^40 */
#define F_TWO24 0x4B800000u /* 2^24 */
/* A handful of values whose pairs make boxes (incl. straddling zero). */
static const cbvh_f32 box_vals[] = {
    0x00000000, 0x80000000, 0x00000001, 0x80000001, 0x00800000, 0x30800000 /* 2^-30 */, 0x33C00000 /* 1.5*2^-24 */,
    0x3DCCCCCD /* 0.1 */, F_NEG_0_4, F_ONE, 0x3F800001, 0xBF800000, 0x40400000 /* 3 */, 0xC0B00000 /* -5.5 */,
    F_TWO24, 0x4B800001 /* 2^24+2 */, 0x49742400 /* 1e6 */, F_TWO40, 0xD3800000 /* -2^40 */, CBVH_F32_MAX,
    CBVH_F32_MAX | CBVH_F32_SIGN, 0x7F000000 /* 2^127 */};
#define N_BOX_VALS (int)(sizeof box_vals / sizeof box_vals[0])

static const cbvh_f32 nan_inf[] = {0x7FC00000, 0x7F800001, 0xFFC00000, 0x7FFFFFFF, CBVH_F32_POS_INF, CBVH_F32_NEG_INF};
#define N_NAN_INF (int)(sizeof nan_inf / sizeof nan_inf[0])

/* Random float with TestFloat-like structure: random sign, an exponent that
 * is often near the interesting ones, and a significand with runs of ones. */
static cbvh_f32 rnd_float(rng_t *r) {
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
    return mkf(sign, e, frac);
}

/* Random finite float in [a, b] (a <= b): near either end or anywhere. */
static cbvh_f32 rnd_between(rng_t *r, cbvh_f32 a, cbvh_f32 b) {
    int64_t ka = fkey(a), kb = fkey(b);
    switch (rnd_below(r, 4)) {
    case 0: return funkey(ka + (int64_t)rnd_below(r, (uint64_t)(kb - ka < 16 ? kb - ka + 1 : 16)));
    case 1: return funkey(kb - (int64_t)rnd_below(r, (uint64_t)(kb - ka < 16 ? kb - ka + 1 : 16)));
    default: return funkey(rnd_range(r, ka, kb));
    }
}

typedef struct {
    cbvh_f32 lo, hi;
} box_t;

/* A random box: a random float plus a random extent in ulps (often tiny). */
static box_t rnd_box(rng_t *r) {
    box_t b;
    uint64_t kind = rnd_below(r, 4);
    if (kind == 0) {
        b.lo = rnd_float(r);
        b.hi = rnd_float(r);
        if (cbvh_f32_cmp(b.lo, b.hi) > 0) {
            cbvh_f32 t = b.lo;
            b.lo = b.hi;
            b.hi = t;
        }
        return b;
    }
    b.lo = rnd_float(r);
    int64_t k = fkey(b.lo), ext = (int64_t)rnd_below(r, (uint64_t)1 << rnd_below(r, 32));
    if (ext > KEY_MAX - k) ext = KEY_MAX - k;
    b.hi = funkey(k + ext);
    return b;
}

/* A random sub-box of [lo, hi] (finite, lo <= hi). */
static box_t rnd_sub_box(rng_t *r, box_t in) {
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

/* ---- the vector list ------------------------------------------------------ */

typedef struct {
    const cbvh_vecgen_spec *spec;
    cbvh_layout lay;
    rng_t rng;
    uint32_t *in;
    size_t n, cap;
    int oom;
    int random_only; /* level 2's extra part: random cases only */
    int N;         /* quant_bits */
    int ms;        /* min_scale */
    uint32_t mask; /* 2^N - 1 */
} gen_t;

static void emit(gen_t *g, const uint32_t *in) {
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

static int valid_scale_word(int e) { return e >= -128 && e <= 127; }

/* ---- scale_estimate -------------------------------------------------------- */

static void emit_box2(gen_t *g, cbvh_f32 lo, cbvh_f32 hi) {
    uint32_t in[2] = {lo, hi};
    emit(g, in);
}

/* Structured boxes shared by the estimator and the compressor.  step thins
 * the pattern loops (1 = all). */
static size_t structured_boxes(box_t *out, size_t max, int step) {
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
    PUT(mkf(0, 100, 0x123456), up(mkf(0, 100, 0x123456)));
    PUT(F_NEG_0_4, F_NEG_0_4);
    PUT(down(F_NEG_0_4), up(F_NEG_0_4));
    PUT(0xBED1EB85 /* -0.41 */, 0xBEC7AE14 /* -0.39 */);
    PUT(0x80000000, 0x00000000);
    PUT(0x00000000, 0x80000000);
#undef PUT
    return n;
}

static void rejects(gen_t *g, void (*put)(gen_t *, cbvh_f32, cbvh_f32, int), int scale) {
    for (int i = 0; i < N_NAN_INF; i++) {
        put(g, nan_inf[i], F_ONE, scale);
        put(g, 0xBF800000, nan_inf[i], scale);
        put(g, nan_inf[i], nan_inf[i], scale);
    }
    put(g, CBVH_F32_NEG_INF, CBVH_F32_POS_INF, scale);
    put(g, F_ONE, 0, scale);                         /* inverted */
    put(g, up(F_ONE), F_ONE, scale);                 /* inverted by one ulp */
    put(g, 0x00000000, 0x80000001, scale);           /* inverted across zero */
    put(g, CBVH_F32_MAX, CBVH_F32_MAX | CBVH_F32_SIGN, scale);
}

static void put_estimate(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int scale) {
    (void)scale;
    emit_box2(g, lo, hi);
}

static void gen_estimate(gen_t *g, size_t target) {
    if (!g->random_only) { /* level-1 structured cases */
        box_t boxes[2048];
        size_t nb = structured_boxes(boxes, 2048, 1);
        for (size_t i = 0; i < nb && i < 2048; i++) emit_box2(g, boxes[i].lo, boxes[i].hi);
        rejects(g, put_estimate, 0);
    }
    while (g->n < target && !g->oom) {
        box_t b = rnd_box(&g->rng);
        emit_box2(g, b.lo, b.hi);
    }
}

/* Generator 6: a bound's last bit shifted out when the two are aligned.  A
 * bound far below the other's last bit is cut off, and only its sticky bit
 * can tell w = ub - lb from the width without it: ub just below 2^k and lb
 * = -2^j one to four binades below ub's last bit (and mirrored), so w is
 * just below or just above 2^k.  An RTL whose sticky bit ignored the last
 * bit shifted out failed one level-2 vector only (gateware/scripts/mutate-rtl). */
static void appended_estimate(gen_t *g) {
    static const int ks[] = {-20, 0, 13, 40, 100};
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++)
        for (int d = 1; d <= 4; d++)
            for (int m = 0; m < 2; m++) {
                cbvh_f32 big = cbvh_f32_next_down(mkf(0, ks[i], 0)); /* pred(2^k) */
                cbvh_f32 small = mkf(1, ks[i] - 24 - d, 0);        /* -2^(k-24-d) */
                if (m)
                    emit_box2(g, neg(big), neg(small)); /* [-pred(2^k), 2^(k-24-d)] */
                else
                    emit_box2(g, small, big);
            }
}

/* ---- axis_compress --------------------------------------------------------- */

static void emit_compress(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int e) {
    if (!valid_scale_word(e)) return;
    uint32_t in[3] = {lo, hi, cbvh_scale_to_word(e)};
    emit(g, in);
}

static void put_compress(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int scale) { emit_compress(g, lo, hi, scale); }

/* Scales around the estimate: estimate-1 (forces NO_FIT), the estimate,
 * +1..+3, the minimum and the maximum scale. */
static void compress_scales(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int all) {
    cbvh_params p = g->spec->cfg.params;
    int est;
    if (cbvh_scale_estimate(&p, lo, hi, &est) != 0) est = 0;
    emit_compress(g, lo, hi, est);
    if (est - 1 >= g->ms) emit_compress(g, lo, hi, est - 1);
    emit_compress(g, lo, hi, est + 1);
    if (all) {
        emit_compress(g, lo, hi, est + 2);
        emit_compress(g, lo, hi, est + 3);
    }
    if (est != g->ms) emit_compress(g, lo, hi, g->ms);
    if (all && est != CBVH_SCALE_CEIL) emit_compress(g, lo, hi, CBVH_SCALE_CEIL);
}

static void gen_compress(gen_t *g, size_t target) {
    if (!g->random_only) { /* level-1 structured cases */
        box_t boxes[2048];
        size_t nb = structured_boxes(boxes, 2048, 2);
        for (size_t i = 0; i < nb && i < 2048; i++) compress_scales(g, boxes[i].lo, boxes[i].hi, i % 3 == 0);
        rejects(g, put_compress, 0);
        /* Bad scales: below min_scale, above 126, the 8-bit extremes. */
        static const cbvh_f32 some[][2] = {{F_ONE, 0x40400000}, {0, 0}, {F_NEG_0_4, F_NEG_0_4}, {CBVH_F32_MAX, CBVH_F32_MAX}};
        for (int i = 0; i < 4; i++) {
            emit_compress(g, some[i][0], some[i][1], g->ms - 1);
            emit_compress(g, some[i][0], some[i][1], 127);
            emit_compress(g, some[i][0], some[i][1], -128);
        }
    }
    while (g->n < target && !g->oom) {
        box_t b = rnd_box(&g->rng);
        int est;
        cbvh_params p = g->spec->cfg.params;
        if (cbvh_scale_estimate(&p, b.lo, b.hi, &est) != 0) est = 0;
        int e;
        switch (rnd_below(&g->rng, 4)) {
        case 0: e = (int)rnd_range(&g->rng, g->ms, CBVH_SCALE_CEIL); break;
        case 1: e = est; break;
        default: e = est + (int)rnd_range(&g->rng, -2, 4); break;
        }
        if (e < g->ms - 1) e = g->ms - 1;
        emit_compress(g, b.lo, b.hi, e);
    }
}

/* ---- axis_decode ----------------------------------------------------------- */

static void emit_decode(gen_t *g, const cbvh_axis_ctx *c, uint32_t lb_code, uint32_t ub_code) {
    if (!valid_scale_word(c->parent_scale) || !valid_scale_word(c->scale)) return;
    uint32_t in[6] = {cbvh_scale_to_word(c->parent_scale), cbvh_scale_to_word(c->scale), c->lb_mod, c->clb, lb_code,
                      ub_code};
    emit(g, in);
}

/* Root boxes for the decoder and node-pair chains. */
static const box_t root_boxes[] = {
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
#define N_ROOT (int)(sizeof root_boxes / sizeof root_boxes[0])

static box_t pick_root(gen_t *g, int i) {
    if (i < N_ROOT) return root_boxes[i];
    return rnd_box(&g->rng);
}

/* One chain: a root box, a child inside it and a grandchild inside the
 * child; emits the decode vectors of both levels (the stored codes of a real
 * compression) plus random codes under the same contexts. */
static void decode_chain(gen_t *g, box_t root, int extras) {
    const cbvh_params *p = &g->spec->cfg.params;
    cbvh_encoding enc = g->spec->cfg.enc;
    cbvh_axis_ctx ctx;
    if (cbvh_axis_root_ctx(p, root.lo, root.hi, &ctx) != 0) return;
    box_t node = root;
    for (int depth = 0; depth < 2; depth++) {
        box_t child = rnd_sub_box(&g->rng, node);
        cbvh_axis_code code;
        if (cbvh_axis_compress(p, child.lo, child.hi, ctx.scale, &code) & CBVH_ST_REJECT) return;
        uint32_t lc, uc;
        cbvh_axis_store_codes(p, enc, &ctx, &code, &lc, &uc);
        emit_decode(g, &ctx, lc, uc);
        if (extras) {
            uint32_t a = (uint32_t)rnd_below(&g->rng, g->mask + 1u), b = (uint32_t)rnd_below(&g->rng, g->mask + 1u);
            emit_decode(g, &ctx, a, b);
        }
        ctx = cbvh_axis_child_ctx(&ctx, &code);
        node = child;
    }
}

/* Generator 2, after the random part (no draws: level 1's random part and
 * level 2's are unchanged): contexts whose lower bound clb has its lowest
 * significand bit d = 33..40 binades above or below the scale, around the
 * widest alignment u + r 2^e that fits a 64-bit datapath (the model's fast
 * path takes |d| <= 36), with codes for the first, last and whole-node cells. */
static void decode_alignment_limits(gen_t *g) {
    static const uint32_t fracs[4] = {0, CBVH_F32_FRAC, 0x400001u, 0x123457u};
    for (int d = -40; d <= 40; d++) {
        if (d > -33 && d < 33) continue;
        for (int v = 0; v < 4; v++) {
            cbvh_axis_ctx c;
            c.scale = g->ms + 7 * v;
            int eu = c.scale + d + 150; /* biased exponent of clb */
            if (c.scale > CBVH_SCALE_CEIL || eu < 1 || eu > 254) continue;
            c.parent_scale = c.scale + v % 3 > CBVH_SCALE_CEIL ? c.scale : c.scale + v % 3;
            c.lb_mod = (uint32_t)v & g->mask;
            c.clb = ((v & 2) ? CBVH_F32_SIGN : 0u) | (uint32_t)eu << 23 | fracs[v];
            int shift = c.parent_scale - c.scale;
            uint32_t pmod = shift >= g->N ? 0 : (c.lb_mod << shift) & g->mask;
            uint32_t r = (uint32_t)v % 3u, sc = g->mask + 1u - (uint32_t)(v % 2); /* r < s <= 2^N */
            int modulo = g->spec->cfg.enc == CBVH_ENC_MODULO;
            uint32_t lc = modulo ? (r + pmod) & g->mask : r, uc = modulo ? (sc + pmod) & g->mask : sc & g->mask;
            emit_decode(g, &c, lc, uc);
        }
    }
}

static void gen_decode(gen_t *g, size_t target) {
    const cbvh_params *p = &g->spec->cfg.params;
    uint32_t full = g->mask + 1u;
    if (!g->random_only) { /* level-1 structured cases */
        /* Real chains from structured roots, several children each. */
        for (int i = 0; i < N_ROOT; i++)
            for (int k = 0; k < 12; k++) decode_chain(g, root_boxes[i], 1);
        /* Corner codes under real contexts. */
        for (int i = 0; i < N_ROOT; i++) {
            cbvh_axis_ctx ctx;
            if (cbvh_axis_root_ctx(p, root_boxes[i].lo, root_boxes[i].hi, &ctx) != 0) continue;
            int shift = ctx.parent_scale - ctx.scale;
            uint32_t pmod = shift >= g->N ? 0 : (ctx.lb_mod << shift) & g->mask;
            emit_decode(g, &ctx, pmod, pmod);                       /* r = 0, s = 0 -> 2^N: the whole node */
            emit_decode(g, &ctx, pmod, (pmod + 1) & g->mask);       /* first cell */
            emit_decode(g, &ctx, (pmod + g->mask) & g->mask, pmod); /* last cell */
            emit_decode(g, &ctx, 0, 0);
            emit_decode(g, &ctx, g->mask, g->mask);                  /* r == s: inverted (unless s == 0) */
            emit_decode(g, &ctx, 1, 0);
            emit_decode(g, &ctx, full, 0);                           /* codes >= 2^N */
            emit_decode(g, &ctx, 0, full);
            emit_decode(g, &ctx, 0xFFF, 0xFFF);
            /* Bad contexts. */
            cbvh_axis_ctx b = ctx;
            b.lb_mod = full;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.clb = 0x7FC00000;
            emit_decode(g, &b, 0, 1);
            b.clb = CBVH_F32_POS_INF;
            emit_decode(g, &b, 0, 1);
            b.clb = CBVH_F32_NEG_INF; /* valid: -2^128 */
            emit_decode(g, &b, 0, 1);
            emit_decode(g, &b, 0, 0);
            b = ctx;
            b.scale = g->ms - 1;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.parent_scale = ctx.scale - 1;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.parent_scale = 127;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.parent_scale = CBVH_SCALE_CEIL;
            emit_decode(g, &b, 1, 3); /* shift >= N: p^ = 0 */
            b = ctx;
            b.scale = b.parent_scale = g->ms;
            emit_decode(g, &b, 2, 5); /* minimum-scale saturation */
        }
        /* Random contexts with every field in range. */
        for (int i = 0; i < 40; i++) {
            cbvh_axis_ctx c;
            c.scale = (int)rnd_range(&g->rng, g->ms, CBVH_SCALE_CEIL);
            c.parent_scale = (int)rnd_range(&g->rng, c.scale, CBVH_SCALE_CEIL);
            c.lb_mod = (uint32_t)rnd_below(&g->rng, full);
            c.clb = rnd_float(&g->rng);
            uint32_t lc = (uint32_t)rnd_below(&g->rng, full);
            uint32_t uc = (uint32_t)rnd_below(&g->rng, full);
            emit_decode(g, &c, lc, uc);
        }
    }
    /* Then chains from random roots, every fourth from a structured one. */
    for (int i = 0; g->n < target && !g->oom; i++) decode_chain(g, pick_root(g, i % 4 == 0 ? (i / 4) % N_ROOT : N_ROOT), 1);
    if (!g->random_only) decode_alignment_limits(g);
}

/* ---- node pairs -------------------------------------------------------------- */

typedef struct {
    box_t axis[3];
    cbvh_node_ctx ctx;
} node_t;

static int make_node(gen_t *g, node_t *nd, int i) {
    for (int a = 0; a < 3; a++) {
        /* Mix structured roots per axis so a node sees different cases on x, y, z. */
        nd->axis[a] = i < N_ROOT ? root_boxes[(i + 5 * a) % N_ROOT] : rnd_box(&g->rng);
        if (cbvh_axis_root_ctx(&g->spec->cfg.params, nd->axis[a].lo, nd->axis[a].hi, &nd->ctx.axis[a]) != 0) return -1;
    }
    return 0;
}

static uint32_t ptr_ones(int n) {
    int pb = cbvh_node_ptr_bits(n);
    return pb >= 32 ? 0xFFFFFFFFu : (1u << pb) - 1u;
}

static void ctx_words(const cbvh_node_ctx *c, uint32_t *w) {
    for (int a = 0; a < 3; a++) {
        w[4 * a] = cbvh_scale_to_word(c->axis[a].parent_scale);
        w[4 * a + 1] = cbvh_scale_to_word(c->axis[a].scale);
        w[4 * a + 2] = c->axis[a].lb_mod;
        w[4 * a + 3] = c->axis[a].clb;
    }
}

typedef struct {
    box_t b[3];
    uint32_t flags, ptr;
} child_t;

static child_t rnd_child(gen_t *g, const node_t *nd) {
    child_t c;
    for (int a = 0; a < 3; a++) c.b[a] = rnd_sub_box(&g->rng, nd->axis[a]);
    uint32_t ones = ptr_ones(g->N);
    c.flags = (uint32_t)rnd_below(&g->rng, 2); /* leaf or inner */
    switch (rnd_below(&g->rng, 4)) {
    case 0: c.ptr = (uint32_t)rnd_below(&g->rng, 16); break;
    case 1: c.ptr = ones - 1; break;
    default: c.ptr = (uint32_t)rnd_below(&g->rng, (uint64_t)ones); break;
    }
    return c;
}

/* Sequenced on purpose: the order of initializers is unspecified in C. */
static void two_children(gen_t *g, const node_t *nd, child_t ch[2]) {
    ch[0] = rnd_child(g, nd);
    ch[1] = rnd_child(g, nd);
}

static void encode_inputs(const node_t *nd, const child_t ch[2], uint32_t *in) {
    ctx_words(&nd->ctx, in);
    for (int c = 0; c < 2; c++) {
        uint32_t *w = in + 12 + 8 * c;
        for (int a = 0; a < 3; a++) {
            w[2 * a] = ch[c].b[a].lo;
            w[2 * a + 1] = ch[c].b[a].hi;
        }
        w[6] = ch[c].flags;
        w[7] = ch[c].ptr;
    }
}

/* The structured variations of one node's two children (encoder inputs). */
static int pair_cases(gen_t *g, const node_t *nd, child_t out[][2], int max) {
    int n = 0;
    uint32_t ones = ptr_ones(g->N);
    child_t a = rnd_child(g, nd), b = rnd_child(g, nd);
#define CASE(x, y)                                                                                                    \
    do {                                                                                                               \
        if (n < max) {                                                                                                 \
            out[n][0] = (x);                                                                                           \
            out[n][1] = (y);                                                                                           \
            n++;                                                                                                       \
        }                                                                                                              \
    } while (0)
    CASE(a, b);
    child_t t = a, u = b;
    t.flags = 1; /* two leaves */
    u.flags = 1;
    CASE(t, u);
    u.flags = 2; /* second empty, its box ignored */
    CASE(t, u);
    t.flags = 3; /* both empty (leaf bit with empty too) */
    u.flags = 2;
    CASE(t, u);
    t = a;
    t.flags = 0;
    t.ptr = ones; /* inner child at the all-ones pointer */
    u = b;
    u.flags = 1;
    u.ptr = ones - 1; /* largest leaf pointer */
    CASE(t, u);
    u.ptr = ones; /* leaf at the reserved pointer: bad format */
    CASE(t, u);
    if (ones != 0xFFFFFFFFu) {
        t.ptr = ones + 1; /* pointer too wide */
        CASE(t, b);
    }
    t = a;
    t.flags = 0xC; /* unused flag bits */
    CASE(t, b);
    /* A child box wider than the node: NO_FIT on that axis. */
    t = a;
    t.b[rnd_below(&g->rng, 3)] = (box_t){CBVH_F32_MAX | CBVH_F32_SIGN, CBVH_F32_MAX};
    CASE(t, b);
    /* NaN / inverted child. */
    t = a;
    t.b[rnd_below(&g->rng, 3)].lo = 0x7FC00000;
    CASE(b, t);
    t = a;
    t.b[1] = (box_t){t.b[1].hi, t.b[1].lo};
    if (cbvh_f32_cmp(t.b[1].lo, t.b[1].hi) > 0) CASE(t, b);
#undef CASE
    return n;
}

static void emit_encode(gen_t *g, const node_t *nd, const child_t ch[2]) {
    uint32_t in[28];
    encode_inputs(nd, ch, in);
    emit(g, in);
}

static void gen_encode_pair(gen_t *g, size_t target) {
    if (!g->random_only) { /* level-1 structured cases */
        for (int i = 0; i < N_ROOT * 2 && !g->oom; i++) {
            node_t nd;
            if (make_node(g, &nd, i % N_ROOT) != 0) continue;
            child_t cases[16][2];
            int nc = pair_cases(g, &nd, cases, 16);
            for (int k = 0; k < nc; k++) emit_encode(g, &nd, cases[k]);
        }
        /* Bad contexts: a bad scale, an out-of-range lb_mod, a NaN clb on one axis. */
        for (int i = 0; i < 6; i++) {
            node_t nd;
            if (make_node(g, &nd, i) != 0) continue;
            child_t ch[2];
            two_children(g, &nd, ch);
            cbvh_axis_ctx *ax = &nd.ctx.axis[i % 3];
            if (i < 3) ax->scale = g->ms - 1;
            else if (i < 5) ax->lb_mod = g->mask + 1u;
            else ax->clb = 0x7FC00000;
            emit_encode(g, &nd, ch);
        }
    }
    while (g->n < target && !g->oom) {
        node_t nd;
        if (make_node(g, &nd, N_ROOT) != 0) continue;
        child_t ch[2];
        two_children(g, &nd, ch);
        if (rnd_below(&g->rng, 8) == 0) ch[rnd_below(&g->rng, 2)].flags = 2;
        emit_encode(g, &nd, ch);
    }
}

static void emit_decode_pair(gen_t *g, const cbvh_node_ctx *ctx, const uint32_t *words, int nw) {
    uint32_t in[18];
    ctx_words(ctx, in);
    for (int i = 0; i < nw; i++) in[12 + i] = words[i];
    emit(g, in);
}

/* Decoder inputs from real node pairs (encoded by the model's encoder unit),
 * then corruptions of them: reserved bits, flipped code bits, garbage. */
static void decode_pair_node(gen_t *g, const cbvh_unit *enc_unit, const node_t *nd, child_t cases[][2], int nc,
                             int corrupt) {
    int nw = (int)cbvh_nodepair_bytes(g->N) / 4;
    int w = cbvh_node_bits(g->N), pb = cbvh_node_ptr_bits(g->N);
    int reserved = w - 6 * g->N - 1 - pb; /* per node */
    for (int k = 0; k < nc; k++) {
        uint32_t in[28], out[8];
        encode_inputs(nd, cases[k], in);
        enc_unit->eval(&g->spec->cfg, in, out);
        if (out[nw] & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) continue; /* zeroed words: nothing to decode */
        emit_decode_pair(g, &nd->ctx, out, nw);
        if (!corrupt || k > 1) continue;
        uint32_t bad[6];
        if (reserved > 0) {
            memcpy(bad, out, sizeof bad);
            int node = (int)rnd_below(&g->rng, 2);
            int bit = node * w + 6 * g->N + 1 + pb + (int)rnd_below(&g->rng, (uint64_t)reserved);
            bad[bit / 32] ^= 1u << (bit % 32);
            emit_decode_pair(g, &nd->ctx, bad, nw);
        }
        memcpy(bad, out, sizeof bad);
        int cb = (int)rnd_below(&g->rng, (uint64_t)g->N * 6); /* one code bit of node 0 flipped */
        bad[cb / 32] ^= 1u << (cb % 32);
        emit_decode_pair(g, &nd->ctx, bad, nw);
        for (int j = 0; j < nw; j++) bad[j] = (uint32_t)rng_next(&g->rng); /* garbage words */
        emit_decode_pair(g, &nd->ctx, bad, nw);
    }
}

static void gen_decode_pair(gen_t *g, size_t target) {
    const cbvh_unit *enc_unit = cbvh_unit_find("nodepair_encode");
    int nw = (int)cbvh_nodepair_bytes(g->N) / 4;
    if (!g->random_only) { /* level-1 structured cases */
        for (int i = 0; i < N_ROOT * 2 && !g->oom; i++) {
            node_t nd;
            if (make_node(g, &nd, i % N_ROOT) != 0) continue;
            child_t cases[16][2];
            int nc = pair_cases(g, &nd, cases, 16);
            decode_pair_node(g, enc_unit, &nd, cases, nc, 1);
            if (i >= N_ROOT) continue;
            /* Malformed empty marker: leaf + all-ones pointer but a nonzero code. */
            child_t ch[2];
            two_children(g, &nd, ch);
            ch[0].flags = 2;
            uint32_t in[28], out[8];
            encode_inputs(&nd, ch, in);
            enc_unit->eval(&g->spec->cfg, in, out);
            out[0] |= 1u;
            emit_decode_pair(g, &nd.ctx, out, nw);
            static const uint32_t zero[6], ones[6] = {~0u, ~0u, ~0u, ~0u, ~0u, ~0u};
            emit_decode_pair(g, &nd.ctx, zero, nw);
            emit_decode_pair(g, &nd.ctx, ones, nw);
            cbvh_node_ctx bc = nd.ctx;
            bc.axis[i % 3].parent_scale = bc.axis[i % 3].scale - 1; /* bad context */
            emit_decode_pair(g, &bc, out, nw);
        }
    }
    while (g->n < target && !g->oom) {
        node_t nd;
        if (make_node(g, &nd, N_ROOT) != 0) continue;
        if (rnd_below(&g->rng, 16) == 0) { /* garbage words under a real context */
            uint32_t junk[6];
            for (int j = 0; j < nw; j++) junk[j] = (uint32_t)rng_next(&g->rng);
            emit_decode_pair(g, &nd.ctx, junk, nw);
            continue;
        }
        child_t ch[1][2];
        two_children(g, &nd, ch[0]);
        decode_pair_node(g, enc_unit, &nd, ch, 1, 0);
    }
}

/* ---- ray_box (docs/traversal.md §3) ------------------------------------------ */

/* Input words: o[3] d[3] tmin tmax mant, then per axis u scale r s. */
static void emit_ray_box(gen_t *g, const cbvh_f32 o[3], const cbvh_f32 d[3], cbvh_f32 tmin, cbvh_f32 tmax, int mant,
                         const cbvh_f32 u[3], const int e[3], const uint32_t r[3], const uint32_t s[3]) {
    uint32_t in[21];
    for (int a = 0; a < 3; a++) {
        in[a] = o[a];
        in[3 + a] = d[a];
        in[9 + 4 * a] = u[a];
        in[10 + 4 * a] = cbvh_scale_to_word(e[a]);
        in[11 + 4 * a] = r[a];
        in[12 + 4 * a] = s[a];
    }
    in[6] = tmin;
    in[7] = tmax;
    in[8] = (uint32_t)mant;
    emit(g, in);
}

#define F_HALF 0x3F000000u
#define F_THIRD 0x3EAAAAABu
static const cbvh_f32 rb_orig[] = {0xBF800000u /* -1 */, 0, CBVH_F32_SIGN, F_HALF, F_ONE /* on the face x=1 */,
                                   0x3F800001u /* just outside */, 0x40000000u /* 2 */, 0x33800000u /* 2^-24 */};
static const cbvh_f32 rb_dir[] = {F_ONE, 0xBF800000u, 0, CBVH_F32_SIGN, F_THIRD, 0x00000001u /* tiny */,
                                  0x7F000000u /* 2^127 */, 0xC0400000u /* -3 */};
static const int rb_mant[] = {3, 8, 12, 24};
#define N_RB_ORIG (int)(sizeof rb_orig / sizeof rb_orig[0])
#define N_RB_DIR (int)(sizeof rb_dir / sizeof rb_dir[0])

static void gen_ray_box(gen_t *g, size_t target) {
    if (!g->random_only) {
        /* the box [0,1]^3 as u = 0, e = -3, r = 0, s = 8; axis x structured, y/z through the middle */
        const cbvh_f32 u[3] = {0, 0, 0};
        const int e[3] = {-3, -3, -3};
        const uint32_t r[3] = {0, 0, 0}, sc[3] = {8, 8, 8};
        for (int m = 0; m < 4; m++)
            for (int i = 0; i < N_RB_ORIG; i++)
                for (int j = 0; j < N_RB_DIR; j++) {
                    cbvh_f32 o[3] = {rb_orig[i], F_HALF, F_HALF}, d[3] = {rb_dir[j], rb_dir[(j + 1) % N_RB_DIR],
                                                                          rb_dir[(j + 3) % N_RB_DIR]};
                    if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[2] = F_ONE;
                    emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, rb_mant[m], u, e, r, sc);
                    o[1] = F_ONE; /* on the face y = 1 (grazing when d_y = +-0) */
                    emit_ray_box(g, o, d, 0, F_TWO24, rb_mant[m], u, e, r, sc);
                }
        /* extreme grids: -2^128 lower bound, scale 126, s = 2^10; tiny scale -126 */
        const cbvh_f32 ue[3] = {CBVH_F32_NEG_INF, CBVH_F32_NEG_INF, 0x00000001u};
        const int ee[3] = {126, 105, -126};
        const uint32_t re[3] = {0, 1000, 3}, se[3] = {1024, 1024, 4};
        for (int j = 0; j < N_RB_DIR; j++) {
            cbvh_f32 o[3] = {CBVH_F32_MAX | CBVH_F32_SIGN, 0, 0x00000004u};
            cbvh_f32 d[3] = {rb_dir[j], rb_dir[(j + 2) % N_RB_DIR], 0};
            if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1])) d[0] = F_ONE;
            for (int m = 0; m < 4; m++) emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, rb_mant[m], ue, ee, re, se);
        }
        /* rejects: NaN/Inf in every ray port, zero direction, bad M, scale, codes, inverted, u = +Inf */
        for (int k = 0; k < N_NAN_INF; k++)
            for (int port = 0; port < 8; port++) {
                cbvh_f32 o[3] = {rb_orig[0], F_HALF, F_HALF}, d[3] = {F_ONE, 0, 0}, tmin = 0,
                         tmax = CBVH_F32_POS_INF;
                cbvh_f32 *w = port < 3 ? &o[port] : port < 6 ? &d[port - 3] : port == 6 ? &tmin : &tmax;
                *w = nan_inf[k];
                emit_ray_box(g, o, d, tmin, tmax, 24, u, e, r, sc);
            }
        {
            const cbvh_f32 o[3] = {rb_orig[0], F_HALF, F_HALF}, dz[3] = {0, CBVH_F32_SIGN, 0}, d[3] = {F_ONE, 0, 0};
            emit_ray_box(g, o, dz, 0, CBVH_F32_POS_INF, 24, u, e, r, sc);
            static const int bad_m[] = {0, 2, 25, 255};
            for (int k = 0; k < 4; k++) emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, bad_m[k], u, e, r, sc);
            const int be[3] = {-127, 127, -128};
            emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, 24, u, be, r, sc);
            const uint32_t br[3] = {1025, 5, 0}, bs[3] = {1025, 5, 0};
            emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, 24, u, e, br, bs);
            const cbvh_f32 bu[3] = {CBVH_F32_POS_INF, 0x7FC00000u, 0};
            emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, 24, bu, e, r, sc);
        }
    }
    while (g->n < target && !g->oom) {
        cbvh_f32 o[3], d[3], u[3];
        int e[3];
        uint32_t r[3], s[3];
        for (int a = 0; a < 3; a++) {
            u[a] = rnd_float(&g->rng);
            uint64_t wide = rnd_below(&g->rng, 8);
            e[a] = wide == 0 ? (int)rnd_range(&g->rng, -126, 126) : (int)rnd_range(&g->rng, -30, 10);
            int bits = (int)rnd_range(&g->rng, 3, 10);
            r[a] = (uint32_t)rnd_below(&g->rng, (uint64_t)1 << bits);
            s[a] = r[a] + 1 + (uint32_t)rnd_below(&g->rng, ((uint64_t)1 << bits) - r[a]);
            o[a] = rnd_float(&g->rng);
            uint64_t kind = rnd_below(&g->rng, 6);
            if (kind == 0) d[a] = rnd_below(&g->rng, 2) ? 0 : CBVH_F32_SIGN;
            else if (kind == 1) { /* aim at the box's lower plane (when representable) */
                d[a] = cbvh_f32_add_dyadic((int64_t)r[a], e[a], 0, 0, CBVH_RND_DOWN);
            } else d[a] = rnd_float(&g->rng);
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[0] = F_ONE;
        uint64_t tk = rnd_below(&g->rng, 3);
        cbvh_f32 tmin = tk == 0 ? rnd_float(&g->rng) : 0;
        cbvh_f32 tmax = tk == 2 ? rnd_float(&g->rng) : CBVH_F32_POS_INF;
        int mant = (int)rnd_range(&g->rng, CBVH_MANT_MIN, CBVH_MANT_MAX);
        emit_ray_box(g, o, d, tmin, tmax, mant, u, e, r, s);
    }
}

/* ---- ray_triangle (docs/traversal.md §4) ----------------------------------------- */

static void emit_ray_tri(gen_t *g, const cbvh_f32 o[3], const cbvh_f32 d[3], const cbvh_f32 v[9]) {
    uint32_t in[15];
    for (int a = 0; a < 3; a++) {
        in[a] = o[a];
        in[3 + a] = d[a];
    }
    for (int i = 0; i < 9; i++) in[6 + i] = v[i];
    emit(g, in);
}

static void gen_ray_triangle(gen_t *g, size_t target) {
    if (!g->random_only) {
        /* unit right triangle in z = 0; rays down -z through vertices, edges, inside, just outside */
        const cbvh_f32 tri[9] = {0, 0, 0, F_ONE, 0, 0, 0, F_ONE, 0};
        static const cbvh_f32 xy[] = {0, CBVH_F32_SIGN, F_HALF, F_ONE, 0x3F000001u, 0x3E800000u /* .25 */,
                                      0x3F7FFFFFu, 0xBF800000u};
        const int nxy = (int)(sizeof xy / sizeof xy[0]);
        static const cbvh_f32 dz[] = {0xBF800000u, F_ONE, CBVH_F32_SIGN | 0x00000001u, 0xC0400000u};
        for (int i = 0; i < nxy; i++)
            for (int j = 0; j < nxy; j++)
                for (int k = 0; k < 4; k++) {
                    const cbvh_f32 o[3] = {xy[i], xy[j], 0x40000000u}, d[3] = {0, CBVH_F32_SIGN, dz[k]};
                    emit_ray_tri(g, o, d, tri);
                    const cbvh_f32 d2[3] = {F_THIRD, 0xBE800000u, dz[k]};
                    emit_ray_tri(g, o, d2, tri);
                }
        /* grazing: rays in the plane z = 0 and one subnormal above it */
        for (int i = 0; i < nxy; i++) {
            const cbvh_f32 o[3] = {0xBF800000u, xy[i], 0}, d[3] = {F_ONE, 0, 0};
            emit_ray_tri(g, o, d, tri);
            const cbvh_f32 o2[3] = {0xBF800000u, xy[i], 1}, d2[3] = {F_ONE, F_THIRD, CBVH_F32_SIGN};
            emit_ray_tri(g, o2, d2, tri);
        }
        /* far from the origin */
        const cbvh_f32 far[9] = {0x497423F0u, 0xC9F42408u, 0, 0x49742420u, 0xC9F42408u, 0, 0x49742400u, 0xC9F423F0u, 0};
        const cbvh_f32 fo[3] = {0x49742400u, 0xC9F42400u, 0x49800000u}, fd[3] = {0, 0, 0xBF800000u};
        emit_ray_tri(g, fo, fd, far);
        /* rejects: NaN/Inf in each port, zero direction */
        for (int k = 0; k < N_NAN_INF; k++)
            for (int port = 0; port < 15; port++) {
                cbvh_f32 o[3] = {0x3E800000u, 0x3E800000u, 0x40000000u}, d[3] = {0, 0, 0xBF800000u}, v[9];
                memcpy(v, tri, sizeof v);
                cbvh_f32 *w = port < 3 ? &o[port] : port < 6 ? &d[port - 3] : &v[port - 6];
                *w = nan_inf[k];
                emit_ray_tri(g, o, d, v);
            }
        const cbvh_f32 o[3] = {0x3E800000u, 0x3E800000u, 0x40000000u}, d0[3] = {CBVH_F32_SIGN, 0, CBVH_F32_SIGN};
        emit_ray_tri(g, o, d0, tri);
    }
    while (g->n < target && !g->oom) {
        cbvh_f32 o[3], d[3], v[9];
        for (int i = 0; i < 9; i++) v[i] = rnd_float(&g->rng);
        uint64_t kind = rnd_below(&g->rng, 3);
        for (int a = 0; a < 3; a++) {
            o[a] = rnd_float(&g->rng);
            if (kind == 0) { /* aim at a vertex: d = v - o rounded down */
                int s1, e1, s2, e2;
                uint32_t m1, m2;
                cbvh_f32_break(v[a], &s1, &m1, &e1);
                cbvh_f32_break(o[a], &s2, &m2, &e2);
                d[a] = cbvh_f32_add_dyadic(s1 ? -(int64_t)m1 : (int64_t)m1, e1, s2 ? (int64_t)m2 : -(int64_t)m2, e2,
                                           CBVH_RND_DOWN);
                if (cbvh_f32_is_nan_or_inf(d[a])) d[a] = F_ONE;
            } else if (kind == 1 && rnd_below(&g->rng, 3) == 0) {
                d[a] = rnd_below(&g->rng, 2) ? 0 : CBVH_F32_SIGN;
            } else {
                d[a] = rnd_float(&g->rng);
            }
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[2] = F_ONE;
        emit_ray_tri(g, o, d, v);
    }
}

/* ---- ray_sphere (docs/traversal.md §10) ------------------------------------------ */

/* Input words: o[3] d[3] tmin tmax, then cx cy cz r. */
static void emit_ray_sphere(gen_t *g, const cbvh_f32 o[3], const cbvh_f32 d[3], cbvh_f32 tmin, cbvh_f32 tmax,
                            const cbvh_f32 c[3], cbvh_f32 r) {
    uint32_t in[12];
    for (int a = 0; a < 3; a++) {
        in[a] = o[a];
        in[3 + a] = d[a];
        in[8 + a] = c[a];
    }
    in[6] = tmin;
    in[7] = tmax;
    in[11] = r;
    emit(g, in);
}

/* n * 2^e exactly (|n| < 2^24 and the value in range: the callers ensure it). */
static cbvh_f32 dyadic(int64_t n, int e) { return cbvh_f32_add_dyadic(n, e, 0, 0, CBVH_RND_DOWN); }

static void gen_ray_sphere(gen_t *g, size_t target) {
    if (!g->random_only) {
        /* the unit sphere at the origin; rays along +-x at heights y through the
         * centre, inside, tangent (y = 1) and one ulp either side of it */
        static const cbvh_f32 ys[] = {0, CBVH_F32_SIGN, F_HALF, F_ONE, 0x3F800001u, 0x3F7FFFFFu, 0xBF800000u,
                                      0x00000001u};
        static const cbvh_f32 xs[] = {0xC0A00000u /* -5 */, 0xBF800000u /* on the surface */, 0, 0x40A00000u};
        /* segments: unbounded, ending at the tangent point x = 0 and just before, a point, empty */
        static const cbvh_f32 ts[][2] = {{0, CBVH_F32_POS_INF},
                                         {0, 0x40A00000u /* 5 */},
                                         {0, 0x409FFFFFu},
                                         {0x40A00000u, CBVH_F32_POS_INF},
                                         {0x40A00001u, CBVH_F32_POS_INF},
                                         {0x40800000u /* 4 */, 0x40800000u},
                                         {CBVH_F32_MAX | CBVH_F32_SIGN, CBVH_F32_POS_INF},
                                         {0x40000000u, F_ONE /* empty */}};
        const cbvh_f32 c0[3] = {0, 0, 0};
        for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++)
            for (size_t j = 0; j < sizeof ys / sizeof ys[0]; j++)
                for (size_t k = 0; k < sizeof ts / sizeof ts[0]; k++)
                    for (int sgn = 0; sgn < 2; sgn++) {
                        const cbvh_f32 o[3] = {xs[i], ys[j], 0}, d[3] = {sgn ? 0xBF800000u : F_ONE, 0, 0};
                        emit_ray_sphere(g, o, d, ts[k][0], ts[k][1], c0, F_ONE);
                    }
        /* radii: 0, -0 (a point), subnormal, 2^127, FLT_MAX; direction patterns as the box unit's */
        static const cbvh_f32 rs[] = {0, CBVH_F32_SIGN, 0x00000001u, 0x7F000000u, CBVH_F32_MAX};
        for (size_t i = 0; i < sizeof rs / sizeof rs[0]; i++)
            for (int j = 0; j < N_RB_DIR; j++) {
                cbvh_f32 o[3] = {rb_orig[j], 0x40000000u, F_HALF}, d[3] = {rb_dir[j], rb_dir[(j + 1) % N_RB_DIR],
                                                                         rb_dir[(j + 3) % N_RB_DIR]};
                if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[2] = F_ONE;
                const cbvh_f32 c[3] = {F_HALF, F_HALF, F_HALF};
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, rs[i]);
                emit_ray_sphere(g, o, d, 0, F_TWO24, c, rs[i]);
            }
        /* exact tangents in 3D (d . w = 0, |w| = r integer), scaled to huge and tiny
         * exponents, with the tangent point at tmin, at tmax, and one ulp off */
        static const int perp[][7] = {{3, 4, 12, 4, -3, 0, 5}, {1, 2, 2, 2, 1, -2, 3}, {2, 3, 6, 3, -6, 2, 7},
                                      {1, 4, 8, 4, 7, -4, 9}};
        static const int scales[][2] = {{0, 0}, {-20, 3}, {90, -10}, {-149, -149}, {-100, 0}, {60, 60}, {-140, -40}};
        for (size_t p = 0; p < sizeof perp / sizeof perp[0]; p++)
            for (size_t sc = 0; sc < sizeof scales / sizeof scales[0]; sc++) {
                int es = scales[sc][0], ed = scales[sc][1], m = 3;
                cbvh_f32 o[3], d[3], c[3];
                for (int a = 0; a < 3; a++) {
                    int64_t C = 100 * (a + 1);
                    c[a] = dyadic(C, es);
                    o[a] = dyadic(C - perp[p][3 + a] - m * perp[p][a], es);
                    d[a] = dyadic(perp[p][a], ed);
                }
                cbvh_f32 r = dyadic(perp[p][6], es), tm = dyadic(m, es - ed);
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, r);
                emit_ray_sphere(g, o, d, 0, tm, c, r);
                emit_ray_sphere(g, o, d, 0, down(tm), c, r);
                emit_ray_sphere(g, o, d, tm, CBVH_F32_POS_INF, c, r);
                emit_ray_sphere(g, o, d, up(tm), CBVH_F32_POS_INF, c, r);
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, down(r));
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, up(r));
            }
        /* rejects: NaN/Inf in every port, zero direction, negative radius */
        const cbvh_f32 o[3] = {0xC0A00000u, 0, 0}, d[3] = {F_ONE, 0, 0};
        for (int k = 0; k < N_NAN_INF; k++)
            for (int port = 0; port < 12; port++) {
                cbvh_f32 oo[3] = {o[0], o[1], o[2]}, dd[3] = {d[0], d[1], d[2]}, c[3] = {0, 0, 0}, r = F_ONE,
                         tmin = 0, tmax = CBVH_F32_POS_INF;
                cbvh_f32 *w = port < 3    ? &oo[port]
                              : port < 6  ? &dd[port - 3]
                              : port == 6 ? &tmin
                              : port == 7 ? &tmax
                              : port < 11 ? &c[port - 8]
                                          : &r;
                *w = nan_inf[k];
                emit_ray_sphere(g, oo, dd, tmin, tmax, c, r);
            }
        const cbvh_f32 dz[3] = {CBVH_F32_SIGN, 0, CBVH_F32_SIGN};
        emit_ray_sphere(g, o, dz, 0, CBVH_F32_POS_INF, c0, F_ONE);
        emit_ray_sphere(g, o, dz, 0, CBVH_F32_POS_INF, c0, 0xBF800000u);
        emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c0, 0x80000001u);
        emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c0, CBVH_F32_MAX | CBVH_F32_SIGN);
    }
    while (g->n < target && !g->oom) {
        cbvh_f32 o[3], d[3], c[3], r;
        uint64_t kind = rnd_below(&g->rng, 4);
        if (kind == 0) { /* independent floats */
            for (int a = 0; a < 3; a++) {
                o[a] = rnd_float(&g->rng);
                d[a] = rnd_float(&g->rng);
                c[a] = rnd_float(&g->rng);
            }
            r = rnd_float(&g->rng) & ~CBVH_F32_SIGN;
        } else { /* a scene-like sphere near the ray: aimed at it, past it, or anywhere */
            int e = (int)rnd_range(&g->rng, -20, 20);
            for (int a = 0; a < 3; a++) {
                int64_t oi = rnd_range(&g->rng, -(1 << 20), 1 << 20);
                int64_t off = rnd_range(&g->rng, -(1 << 20), 1 << 20);
                int64_t dd = kind == 1   ? off + rnd_range(&g->rng, -(1 << 16), 1 << 16)
                             : kind == 2 ? -off
                                         : rnd_range(&g->rng, -(1 << 20), 1 << 20);
                o[a] = dyadic(oi, e);
                c[a] = dyadic(oi + off, e);
                d[a] = dyadic(dd, (int)rnd_range(&g->rng, -30, 0));
            }
            r = dyadic(rnd_range(&g->rng, 0, 1 << 21), e);
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[0] = F_ONE;
        uint64_t tk = rnd_below(&g->rng, 3);
        cbvh_f32 tmin = tk == 0 ? rnd_float(&g->rng) : 0;
        cbvh_f32 tmax = tk == 2 ? rnd_float(&g->rng) : CBVH_F32_POS_INF;
        emit_ray_sphere(g, o, d, tmin, tmax, c, r);
    }
}

/* ---- qbvh_stack (docs/qbvh.md §2) ------------------------------------------------ */

static void emit_qstack(gen_t *g, uint32_t op, uint32_t first, uint32_t mask, const cbvh_f32 t[4], uint32_t entry) {
    uint32_t in[8] = {op, first, mask, t[0], t[1], t[2], t[3], entry};
    emit(g, in);
}

static void gen_qbvh_stack(gen_t *g, size_t target) {
    static const cbvh_f32 zero_t[4] = {0, 0, 0, 0};
    if (!g->random_only) {
        /* every hit mask x hit-time patterns: distinct, all equal, pairs equal, +-0, Inf, FLT_MAX, reversed */
        static const cbvh_f32 tp[][4] = {
            {F_ONE, 0x40000000u, 0x40400000u, 0x40800000u}, {0x40800000u, 0x40400000u, 0x40000000u, F_ONE},
            {F_ONE, F_ONE, F_ONE, F_ONE},                   {0, CBVH_F32_SIGN, 0, CBVH_F32_SIGN},
            {0x40000000u, F_ONE, 0x40000000u, F_ONE},       {CBVH_F32_MAX, CBVH_F32_POS_INF, F_HALF, CBVH_F32_MAX},
            {0xBF800000u, F_ONE, CBVH_F32_NEG_INF, 0},      {0x3F800001u, F_ONE, 0x3F7FFFFFu, F_ONE}};
        static const uint32_t firsts[] = {0, 1, 5, 0x3FFFFFCu, 0x3FFFFFFu, 0x4000000u, 0xFFFFFFFFu};
        for (size_t k = 0; k < sizeof tp / sizeof tp[0]; k++)
            for (uint32_t m = 0; m < 16; m++) emit_qstack(g, 0, 5, m, tp[k], 0);
        for (size_t f = 0; f < sizeof firsts / sizeof firsts[0]; f++) {
            emit_qstack(g, 0, firsts[f], 15, tp[1], 0);
            emit_qstack(g, 0, firsts[f], 1, tp[1], 0); /* one hit: nothing pushed, ID still checked */
        }
        /* rejects: NaN hit time (hit and not hit), mask > 15, bad op */
        const cbvh_f32 tn[4] = {F_ONE, 0x7FC00000u, 0x40000000u, 0x7F800001u};
        emit_qstack(g, 0, 5, 15, tn, 0);
        emit_qstack(g, 0, 5, 5, tn, 0);
        emit_qstack(g, 0, 5, 16, tp[0], 0);
        emit_qstack(g, 2, 5, 15, tp[0], 0);
        emit_qstack(g, 0xF, 5, 15, tp[0], 0);
        /* pop: every offset block with IDs at the ends of the 26-bit range */
        static const uint32_t ids[] = {0, 7, 0x3FFFFFCu, 0x3FFFFFFu};
        for (size_t i = 0; i < sizeof ids / sizeof ids[0]; i++)
            for (uint32_t b = 0; b < 64; b++) emit_qstack(g, 1, 0, 0, zero_t, ids[i] | b << 26);
    }
    while (g->n < target && !g->oom) {
        uint32_t op = (uint32_t)rnd_below(&g->rng, 2);
        if (op == 1) {
            uint32_t entry = (uint32_t)rng_next(&g->rng);
            emit_qstack(g, 1, 0, 0, zero_t, entry);
            continue;
        }
        uint32_t first = (uint32_t)rnd_below(&g->rng, CBVH_QSTACK_ID_LIMIT + 4u);
        uint32_t mask = (uint32_t)rnd_below(&g->rng, 16);
        cbvh_f32 t[4];
        uint64_t tie = rnd_below(&g->rng, 4); /* 1 in 4: hit times from a set of two values */
        cbvh_f32 a = rnd_float(&g->rng);
        cbvh_f32 b = rnd_float(&g->rng);
        for (int c = 0; c < 4; c++) {
            if (tie == 0) {
                uint64_t pick = rnd_below(&g->rng, 2);
                t[c] = pick ? a : b;
            } else {
                t[c] = rnd_float(&g->rng);
            }
        }
        emit_qstack(g, 0, first, mask, t, 0);
    }
    if (g->random_only) return;
    /* Generator 2, after the random part (no draws): NaN and Inf in the lanes
     * that did not hit (ignored, not rejected) for every mask, and the first
     * child ID at 2^26 - 1, 2^26 and 2^26 + 1 for masks with 0..4 hits. */
    static const cbvh_f32 odd[4] = {0x7FC00000u, 0x7F800001u, CBVH_F32_POS_INF, 0xFFC00000u};
    for (uint32_t m = 0; m < 15; m++) {
        cbvh_f32 t[4];
        for (int c = 0; c < 4; c++) t[c] = ((m >> c) & 1u) ? F_ONE + (uint32_t)c : odd[c];
        emit_qstack(g, 0, 5, m, t, 0);
    }
    static const cbvh_f32 tdist[4] = {0x40400000u, F_ONE, 0x40800000u, 0x40000000u};
    static const uint32_t masks[] = {0, 1, 3, 7, 15};
    for (size_t k = 0; k < sizeof masks / sizeof masks[0]; k++)
        for (uint32_t d = 0; d < 3; d++) emit_qstack(g, 0, CBVH_QSTACK_ID_LIMIT - 1u + d, masks[k], tdist, 0);
}

/* ---- exact-path cases (docs/vectors.md, "Exact-path cases") ----------------------
 *
 * The ray units' fast paths and binary64 filters decide most inputs; an RTL
 * implementation has only the exact datapath, and its hard cases are the ones
 * the filters leave to the model's exact path: exact ties (a ray through an
 * edge or vertex, a tangent, a segment ending on a sphere), quotients that are
 * exactly representable or land on the M-bit grid, results next to the
 * binary32 subnormal border, and planes or origins beyond 62-bit fixed point.
 * These are built constructively from small integers scaled by powers of two,
 * so every case is exact by construction (not selected by running the
 * model: the files do not depend on the model's fast paths), from a stream
 * of their own so the random part before and level 2's part after are those
 * of generator 1.  tests/vectors/test_exact_paths.c checks how many of them
 * reach the exact path. */

#define EXACT_CASES_BOX 400
#define EXACT_CASES_TRI 400
#define EXACT_CASES_SPHERE 300

/* A random odd integer with exactly `bits` bits (bits >= 2). */
static int64_t rnd_odd_bits(rng_t *r, int bits) {
    return (int64_t)(((uint64_t)1 << (bits - 1)) | (rng_next(r) & (((uint64_t)1 << (bits - 1)) - 1)) | 1u);
}
/* A random normal float of either sign with exponent in [elo, ehi] (one draw
 * per statement: argument order is unspecified). */
static cbvh_f32 rnd_f32_in(rng_t *r, int elo, int ehi) {
    int sign = (int)rnd_below(r, 2);
    int e = (int)rnd_range(r, elo, ehi);
    uint32_t frac = (uint32_t)rng_next(r);
    return mkf(sign, e, frac);
}
/* x nudged by one ulp either way, or unchanged (2 in 3). */
static cbvh_f32 nudge(rng_t *r, cbvh_f32 x) {
    switch (rnd_below(r, 6)) {
    case 0: return up(x);
    case 1: return down(x);
    default: return x;
    }
}

static void exact_ray_box(gen_t *g, rng_t *rng, int count) {
    for (int i = 0; i < count && !g->oom; i++) {
        cbvh_f32 o[3], d[3], u[3], tmin = 0, tmax = CBVH_F32_POS_INF;
        int e[3];
        uint32_t r[3], s[3];
        int mant = (int)rnd_range(rng, CBVH_MANT_MIN, CBVH_MANT_MAX);
        switch (i % 3) {
        case 0: { /* plane distances that are exact multiples of a non-power-of-two d:
                   * t = j 2^p, on the M-bit grid whenever j has <= M bits */
            int p = (int)rnd_range(rng, -20, 20);
            int64_t jn[3] = {0, 0, 0};
            for (int a = 0; a < 3; a++) {
                e[a] = (int)rnd_range(rng, -30, 10);
                int64_t ui = rnd_below(rng, 2) ? rnd_range(rng, -(1 << 16), 1 << 16) : 0;
                u[a] = dyadic(ui, e[a]);
                if (rnd_below(rng, 4) == 0) { /* parallel, origin inside the slab or on a face */
                    r[a] = (uint32_t)rnd_range(rng, 0, 1000);
                    s[a] = r[a] + (uint32_t)rnd_range(rng, 1, 1024 - r[a]);
                    int64_t c = rnd_range(rng, r[a], s[a]);
                    o[a] = dyadic(ui + c, e[a]);
                    d[a] = rnd_below(rng, 2) ? 0 : CBVH_F32_SIGN;
                    continue;
                }
                int64_t m = rnd_odd_bits(rng, (int)rnd_range(rng, 2, 7));
                int64_t j1 = rnd_range(rng, 0, 4), j2 = j1 + rnd_range(rng, 1, 8);
                while (m * (j2 - j1) > 1024) m = 3;
                r[a] = (uint32_t)rnd_range(rng, 0, 1024 - m * (j2 - j1));
                s[a] = r[a] + (uint32_t)(m * (j2 - j1));
                int neg = (int)rnd_below(rng, 2);
                int64_t c = neg ? (int64_t)s[a] + m * j1 : (int64_t)r[a] - m * j1;
                o[a] = dyadic(ui + c, e[a]);
                d[a] = dyadic(neg ? -m : m, e[a] - p);
                jn[a] = j1;
            }
            uint64_t tk = rnd_below(rng, 4);
            if (tk == 1) tmin = dyadic(jn[rnd_below(rng, 3)], p); /* tmin on an entry distance */
            if (tk == 2) tmax = dyadic(jn[rnd_below(rng, 3)], p); /* tmax on one */
            break;
        }
        case 1: { /* an origin far from a box around 0: L - O needs more than 62 bits */
            uint32_t k = (uint32_t)rnd_range(rng, 0, 6); /* the far axes' d = -o 2^(k-3): all at t = 2^(3-k) */
            for (int a = 0; a < 3; a++) {
                e[a] = (int)rnd_range(rng, -30, 0);
                r[a] = (uint32_t)rnd_range(rng, 0, 500);
                s[a] = r[a] + 2 * (uint32_t)rnd_range(rng, 1, 250);
                u[a] = dyadic(-(int64_t)(r[a] + s[a]) / 2, e[a]); /* 0 is the box's centre */
                uint64_t kind = rnd_below(rng, 3);
                if (kind == 0 && a != 0) { /* inside, slow */
                    o[a] = dyadic(rnd_range(rng, -(int64_t)(s[a] - r[a]) / 2, (int64_t)(s[a] - r[a]) / 2), e[a]);
                    d[a] = rnd_f32_in(rng, -40, -10);
                } else { /* far, aimed back at 0 (t = 2^(3-k)), sometimes an ulp off */
                    o[a] = rnd_f32_in(rng, 40, 123);
                    d[a] = nudge(rng, (o[a] ^ CBVH_F32_SIGN) + ((k << 23) - (3u << 23)));
                }
            }
            break;
        }
        default: { /* planes at the ends of the range: grids from u = -Inf (-2^128) or
                    * -FLT_MAX at scale 2^126 around an origin up to 2^126 (distances
                    * that overflow binary32), or planes past +FLT_MAX */
            for (int a = 0; a < 3; a++) {
                uint64_t kind = rnd_below(rng, 5);
                o[a] = rnd_f32_in(rng, 100, 125);
                d[a] = rnd_f32_in(rng, -20, 20);
                if (kind < 4) { /* [u + r 2^126, u + s 2^126] contains o */
                    u[a] = kind < 2 ? CBVH_F32_NEG_INF : CBVH_F32_MAX | CBVH_F32_SIGN;
                    e[a] = 126;
                    r[a] = (uint32_t)rnd_range(rng, 0, 3);
                    s[a] = (uint32_t)rnd_range(rng, 5, 16);
                } else { /* past FLT_MAX, the ray heading there */
                    u[a] = CBVH_F32_MAX;
                    e[a] = (int)rnd_range(rng, 100, 126);
                    r[a] = (uint32_t)rnd_range(rng, 0, 16);
                    s[a] = r[a] + (uint32_t)rnd_range(rng, 1, 16);
                    d[a] &= ~CBVH_F32_SIGN;
                }
            }
            break;
        }
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[0] = F_ONE;
        emit_ray_box(g, o, d, tmin, tmax, mant, u, e, r, s);
    }
}

/* Triangle vertices as 4x integers V[3][3], a point P4 (4x) on it and a ray
 * o = P - k D, d = D 2^sd (t = k 2^-sd exactly, k = 0 included), all scaled
 * by 2^(s-2). */
static void exact_tri_lattice(gen_t *g, rng_t *rng, int kind) {
    int64_t V[3][3], P4[3], D[3];
    int s = (int)rnd_range(rng, -24, 24), sd = (int)rnd_range(rng, -8, 8);
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) V[i][a] = 4 * rnd_range(rng, -64, 64);
    int i0 = (int)rnd_below(rng, 3), i1 = (i0 + 1) % 3, i2 = (i0 + 2) % 3;
    for (int a = 0; a < 3; a++) {
        if (kind == 0) P4[a] = V[i0][a];                                     /* a vertex */
        else if (kind == 1) P4[a] = (V[i0][a] + V[i1][a]) / 2;               /* an edge's midpoint */
        else if (kind == 2) P4[a] = (V[i0][a] + V[i1][a] + 2 * V[i2][a]) / 4; /* inside, exact */
        else P4[a] = (3 * V[i0][a] + V[i1][a]) / 4;                          /* on an edge, off centre */
    }
    do
        for (int a = 0; a < 3; a++) D[a] = rnd_range(rng, -8, 8);
    while (!D[0] && !D[1] && !D[2]);
    int64_t k = rnd_range(rng, 0, 16); /* k = 0: the origin on the triangle, t = 0 (not a hit) */
    int64_t off = rnd_below(rng, 4) == 0 ? rnd_range(rng, 1 << 20, 1 << 21) : 0; /* far along axis ax */
    int ax = (int)rnd_below(rng, 3);
    cbvh_f32 o[3], d[3], v[9];
    for (int a = 0; a < 3; a++) {
        int64_t sh = a == ax ? off : 0;
        for (int i = 0; i < 3; i++) v[3 * i + a] = dyadic(V[i][a] + sh, s - 2);
        o[a] = dyadic(P4[a] - 4 * k * D[a] + sh, s - 2);
        d[a] = dyadic(4 * D[a], s - 2 + sd);
    }
    if (rnd_below(rng, 3) == 0) { /* an ulp off: tiny nonzero edge functions */
        int a = (int)rnd_below(rng, 3);
        if (!cbvh_f32_is_zero(d[a])) d[a] = nudge(rng, d[a]);
    }
    emit_ray_tri(g, o, d, v);
}

static void exact_ray_triangle(gen_t *g, rng_t *rng, int count) {
    for (int i = 0; i < count && !g->oom; i++) {
        int fam = i % 6;
        if (fam < 4) {
            exact_tri_lattice(g, rng, fam);
            continue;
        }
        /* the binary32 subnormal border: t (family 4) or b1, b2 (family 5) just
         * below or above 2^-126, as truncations of inexact quotients */
        int ax = (int)rnd_below(rng, 3), bx = (ax + 1) % 3, cx = (ax + 2) % 3; /* the plane's normal is ax */
        int j = (int)rnd_range(rng, -2, 2);
        int64_t m = 3; /* legs of 3 2^j: inexact barycentrics */
        cbvh_f32 o[3], d[3], v[9] = {0};
        v[3 + bx] = dyadic(m, j); /* v0 = 0, v1 = m 2^j e_b, v2 = m 2^j e_c */
        v[6 + cx] = dyadic(m, j);
        int64_t dm = rnd_odd_bits(rng, (int)rnd_range(rng, 2, 3)); /* 3, 5, 7 */
        if (rnd_below(rng, 4) == 0) dm = 1;
        int dj = (int)rnd_range(rng, -2, 2);
        /* the small input: anywhere below 2^-121, or a full significand that puts
         * the quotient within a factor 4 of 2^-126 (divisor dm 2^dj or m 2^j) */
        int64_t tiny;
        int te;
        if (rnd_below(rng, 2)) {
            int bits = (int)rnd_range(rng, 1, 24);
            tiny = (int64_t)((uint64_t)1 << (bits - 1) | (rng_next(rng) & (((uint64_t)1 << (bits - 1)) - 1)));
            te = -149 + (int)rnd_range(rng, 0, 4);
        } else {
            tiny = rnd_odd_bits(rng, 24);
            te = -150 + (fam == 4 ? (dm > 4 ? 3 : dm > 1 ? 2 : 0) + dj : 2 + j) + (int)rnd_range(rng, -2, 1);
            if (te < -149) te = -149;
        }
        int sgn = rnd_below(rng, 5) == 0; /* sometimes the other side: a miss decided by an exact sign */
        if (fam == 4) {
            o[bx] = dyadic(1, j - 2);
            o[cx] = dyadic(1, j - 2);
            o[ax] = dyadic(sgn ? -tiny : tiny, te);
            d[bx] = d[cx] = 0;
            d[ax] = dyadic(-dm, dj);
        } else {
            int which = (int)rnd_below(rng, 2);
            o[which ? cx : bx] = dyadic(sgn ? -tiny : tiny, te);
            o[which ? bx : cx] = dyadic(1, j - 2);
            o[ax] = F_ONE;
            d[bx] = d[cx] = 0;
            d[ax] = dyadic(-dm, dj); /* t = 1 / (dm 2^dj): inexact but for dm = 1 */
        }
        emit_ray_tri(g, o, d, v);
    }
}

/* Pythagorean triples a^2 + b^2 = c^2: exact distances from small integers. */
static const int pyth[][3] = {{3, 4, 5}, {5, 12, 13}, {8, 15, 17}, {7, 24, 25}, {20, 21, 29}};

static void exact_ray_sphere(gen_t *g, rng_t *rng, int count) {
    for (int i = 0; i < count && !g->oom; i++) {
        const int *tr = pyth[rnd_below(rng, sizeof pyth / sizeof pyth[0])];
        int ax = (int)rnd_below(rng, 3), bx = (ax + 1) % 3, cx = (ax + 2) % 3;
        int s = (int)rnd_range(rng, -20, 20), sd = (int)rnd_range(rng, -6, 6);
        int64_t C[3], k = rnd_range(rng, 1, 8), Dv[3] = {0, 0, 0}, Ov[3];
        for (int a = 0; a < 3; a++) C[a] = rnd_range(rng, -100, 100);
        cbvh_f32 tmin = 0, tmax = CBVH_F32_POS_INF;
        if (i % 2 == 0) { /* a tangent line: d = (a, b, 0), offset k c along the third axis or (-b, a, 0) */
            Dv[ax] = tr[0];
            Dv[bx] = tr[1];
            int64_t jj = rnd_range(rng, -10, 10);
            for (int a = 0; a < 3; a++) Ov[a] = C[a] - jj * Dv[a];
            if (rnd_below(rng, 2)) Ov[cx] += k * tr[2];
            else {
                Ov[ax] -= k * tr[1];
                Ov[bx] += k * tr[0];
            }
            /* t* = jj 2^(s-(s+sd)); put a segment end on it, beside it, or none */
            cbvh_f32 ts = dyadic(jj, -sd);
            switch (rnd_below(rng, 4)) {
            case 1: tmax = jj >= 0 ? ts : CBVH_F32_POS_INF; break;
            case 2: tmin = ts; break;
            default: break;
            }
        } else { /* a segment that ends (or starts) exactly on the sphere: P = C + k (a, b, 0) */
            do
                for (int a = 0; a < 3; a++) Dv[a] = rnd_range(rng, -8, 8);
            while (!Dv[0] && !Dv[1] && !Dv[2]);
            /* at P the segment must only touch: heading in at its end (tmax), out at its start (tmin) */
            int at_end = (int)rnd_below(rng, 2);
            int64_t dot = Dv[ax] * tr[0] + Dv[bx] * tr[1];
            if ((at_end && dot > 0) || (!at_end && dot < 0))
                for (int a = 0; a < 3; a++) Dv[a] = -Dv[a];
            int64_t t0 = rnd_range(rng, 1, 8);
            for (int a = 0; a < 3; a++) Ov[a] = C[a] - t0 * Dv[a];
            Ov[ax] += k * tr[0];
            Ov[bx] += k * tr[1];
            cbvh_f32 te = dyadic(t0, -sd);
            if (at_end) tmax = te;
            else tmin = te;
        }
        cbvh_f32 o[3], d[3], c[3];
        for (int a = 0; a < 3; a++) {
            o[a] = dyadic(Ov[a], s);
            c[a] = dyadic(C[a], s);
            d[a] = dyadic(Dv[a], s + sd);
        }
        cbvh_f32 r = dyadic(k * tr[2], s);
        if (rnd_below(rng, 5) == 0) r = nudge(rng, r);
        emit_ray_sphere(g, o, d, tmin, tmax, c, r);
    }
}

/* ---- reject combinations (generator 3) --------------------------------------
 *
 * Which status bits an input with several faults at once gets (a NaN bound
 * and a bad scale, a bad code in an inverted child, ...) is each unit's own
 * rule: one bit from an order of checks for the axis units, the QBVH stack
 * and the triangle unit, an OR with stated exceptions for the node pairs, the
 * ray-box and the sphere unit (datapath.md §9-§10, traversal.md §3, §4,
 * §10.2, qbvh.md §2).  Generators 1 and 2 had (almost) single faults only,
 * so independent RTL that chose other rules passed them (docs/gateware.md).
 * These cases combine each unit's faults; they are appended after the
 * level-1 part, with no random draws. */

static void reject_combinations_compress(gen_t *g) {
    const cbvh_f32 F3 = 0x40400000u; /* 3.0 */
    const cbvh_f32 boxes[][2] = {{F_ONE, F3},         {F_QNAN, F3}, {F_ONE, CBVH_F32_POS_INF}, {F3, F_ONE},
                                 {CBVH_F32_POS_INF, F_ONE}, {F_ONE, CBVH_F32_NEG_INF}, {F_QNAN, F_QNAN}};
    const int valid = g->ms <= 0 ? 0 : g->ms;
    const int scales[] = {valid, g->ms - 1, 127, -128};
    for (size_t b = 0; b < sizeof boxes / sizeof boxes[0]; b++)
        for (size_t e = 0; e < sizeof scales / sizeof scales[0]; e++) emit_compress(g, boxes[b][0], boxes[b][1], scales[e]);
}

/* Generator 7: node_clb far below the child grid, where the decoder's shift
 * of u_node reaches its clamp (every bit of u_node sticky).  The alignment
 * limits above stop at clb ~ 2^(scale-17); an RTL clamping that shift one
 * short left u_node's top bit in the sum and passed every vector, though it
 * gives pred(2^e) for a cub of 2^e - |clb| (a third mutation run,
 * docs/gateware.md).  clb = +-(1.f) 2^(scale+d+23) for d = -47 .. -51 (the
 * clamp starts at d = -49), -64 and -100, codes (r, s) = (0, 1), (1, 2),
 * (0, 2), (2, 3) with p^ = 0: with clb < 0, s = 1 and r = 1 the sum is
 * 2^24 - 1 units of 2^(e-24), on the binary32 grid. */
static void decode_clb_far_below(gen_t *g) {
    static const int ds[] = {-47, -48, -49, -50, -51, -64, -100};
    static const uint32_t fracs[] = {0, CBVH_F32_FRAC, 0x400001u};
    static const uint32_t rs[][2] = {{0, 1}, {1, 2}, {0, 2}, {2, 3}};
    cbvh_axis_ctx c;
    c.scale = g->ms + 3 > CBVH_SCALE_CEIL ? CBVH_SCALE_CEIL : g->ms + 3;
    c.parent_scale = c.scale;
    c.lb_mod = 0;
    for (size_t i = 0; i < sizeof ds / sizeof ds[0]; i++) {
        int eu = c.scale + ds[i] + 150; /* biased exponent of clb */
        if (eu < 1 || eu > 254) continue;
        for (size_t f = 0; f < sizeof fracs / sizeof fracs[0]; f++)
            for (int neg = 0; neg < 2; neg++)
                for (size_t k = 0; k < sizeof rs / sizeof rs[0]; k++) {
                    c.clb = (neg ? CBVH_F32_SIGN : 0u) | (uint32_t)eu << 23 | fracs[f];
                    emit_decode(g, &c, rs[k][0], rs[k][1]);
                }
    }
}

static void reject_combinations_decode(gen_t *g) {
    const uint32_t full = g->mask + 1u;
    /* A valid context: ms <= scale <= parent_scale <= 126, p^ = 0. */
    cbvh_axis_ctx base;
    base.scale = g->ms + 2 > CBVH_SCALE_CEIL ? CBVH_SCALE_CEIL : g->ms + 2;
    base.parent_scale = base.scale + 2 > CBVH_SCALE_CEIL ? CBVH_SCALE_CEIL : base.scale + 2;
    base.lb_mod = 0;
    base.clb = F_ONE;
    for (int sc = 0; sc < 4; sc++)               /* none, scale < ms, parent_scale > 126, parent_scale < scale */
        for (int nc = 0; nc < 2; nc++)           /* none, node_lb_mod >= 2^N */
            for (int cl = 0; cl < 3; cl++)       /* none, clb NaN, clb +Inf */
                for (int cc = 0; cc < 3; cc++)   /* none, lb_code >= 2^N, ub_code >= 2^N */
                    for (int inv = 0; inv < 2; inv++) { /* r < s, r >= s */
                        cbvh_axis_ctx c = base;
                        if (sc == 1) c.scale = g->ms - 1;
                        if (sc == 2) c.parent_scale = 127;
                        if (sc == 3) c.parent_scale = c.scale - 1;
                        if (nc) c.lb_mod = full;
                        if (cl == 1) c.clb = F_QNAN;
                        if (cl == 2) c.clb = CBVH_F32_POS_INF;
                        uint32_t lc = inv ? 2 : 1, uc = inv ? 1 : 2;
                        if (cc == 1) lc = full;
                        if (cc == 2) uc = 0xFFF;
                        emit_decode(g, &c, lc, uc);
                    }
    decode_clb_far_below(g);
}

/* QBVH stack: a push with a NaN hit time and a first-child ID >= 2^26 (NAN_INF
 * wins), an invalid op with both, and pops whose push-only inputs (first,
 * hit_mask, t) hold those faults: a pop ignores them and never rejects. */
static void reject_combinations_qstack(gen_t *g) {
    const cbvh_f32 t_nan[4] = {F_ONE, F_QNAN, 0x40000000u, F_QNAN};
    const cbvh_f32 t_ok[4] = {F_ONE, 0x40400000u, 0x40000000u, 0x40800000u};
    static const uint32_t masks[] = {0, 1, 2, 3, 10, 15};
    static const uint32_t firsts[] = {5, CBVH_QSTACK_ID_LIMIT, 0xFFFFFFFFu};
    static const uint32_t entries[] = {0x00000005u, 0xE4000007u, 0x03FFFFFFu};
    for (size_t m = 0; m < sizeof masks / sizeof masks[0]; m++)
        for (size_t f = 0; f < sizeof firsts / sizeof firsts[0]; f++) {
            emit_qstack(g, 0, firsts[f], masks[m], t_nan, 0);
            emit_qstack(g, 0, firsts[f], masks[m], t_nan, entries[f]); /* entry is pop-only */
            emit_qstack(g, 2, firsts[f], masks[m], t_nan, 0);
            emit_qstack(g, 15, firsts[f], masks[m], t_ok, 0);
            emit_qstack(g, 1, firsts[f], masks[m], t_nan, entries[f]);
            emit_qstack(g, 1, firsts[f], masks[m], t_ok, entries[(f + 1) % 3]);
        }
}

/* Node pairs: the status is an OR over the axes and children (datapath.md §9),
 * so these combine a context rejected on one or several axes (one fault or
 * two on one axis) with children that are NaN, inverted, too wide for the
 * grid (NO_FIT), with a pointer wider than its field, empty with a NaN box and
 * a stray pointer, or with unused flag bits; the decoder gets the encoder's
 * words for such pairs (and an all-empty pair, a malformed empty marker with a
 * reserved bit) under the same contexts. */
static void np_context(gen_t *g, int variant, cbvh_node_ctx *c) {
    int e = g->ms > -4 ? g->ms : -4;
    for (int a = 0; a < 3; a++) c->axis[a] = (cbvh_axis_ctx){e, e, 0, 0};
    if (variant == 1) c->axis[0].scale = g->ms - 1;
    if (variant == 2) c->axis[0].scale = g->ms - 1, c->axis[0].clb = F_QNAN;
    if (variant == 3) c->axis[0].scale = g->ms - 1, c->axis[1].clb = F_QNAN, c->axis[2].lb_mod = g->mask + 1u;
}

static void np_children(gen_t *g, int variant, child_t ch[2]) {
    const box_t good = {0x3E800000u /* 0.25 */, 0x3F000000u /* 0.5 */};
    for (int c = 0; c < 2; c++) {
        for (int a = 0; a < 3; a++) ch[c].b[a] = good;
        ch[c].flags = (uint32_t)c; /* inner, leaf */
        ch[c].ptr = 7;
    }
    switch (variant) {
    case 1: ch[0].b[0].lo = F_QNAN, ch[1].b[2].hi = 0x42C80000u /* 100: NO_FIT */; break;
    case 2: ch[0].b[1] = (box_t){0x40400000u, F_ONE}; break; /* inverted */
    case 3: ch[0].ptr = ptr_ones(g->N) == 0xFFFFFFFFu ? 0xFFFFFFFFu : ptr_ones(g->N) + 1u, /* inner: too wide */
            ch[1].b[0].hi = 0x42C80000u;
            break;
    case 4: ch[0].flags = 2, ch[0].b[0].lo = F_QNAN, ch[0].ptr = 0xFFFFFFFFu; break; /* empty */
    case 5: ch[0].flags = 0xD, ch[1].ptr = ptr_ones(g->N); break; /* unused flag bits; leaf at the marker */
    case 6: ch[0].flags = ch[1].flags = 2; break; /* both empty */
    default: break;
    }
}

static void reject_combinations_nodepair(gen_t *g, int decode) {
    const cbvh_unit *enc_unit = cbvh_unit_find("nodepair_encode");
    int nw = (int)cbvh_nodepair_bytes(g->N) / 4;
    for (int cv = 0; cv < 4; cv++)
        for (int kv = 0; kv < 7; kv++) {
            node_t nd;
            np_context(g, cv, &nd.ctx);
            child_t ch[2];
            np_children(g, kv, ch);
            if (!decode) {
                emit_encode(g, &nd, ch);
                continue;
            }
            /* the words of the pair under the valid context (zero if rejected) */
            node_t ok;
            np_context(g, 0, &ok.ctx);
            uint32_t in[28], out[8];
            encode_inputs(&ok, ch, in);
            enc_unit->eval(&g->spec->cfg, in, out);
            emit_decode_pair(g, &nd.ctx, out, nw);
            if (kv == 6) { /* both empty; node 0's marker with a code bit set, the top bit of the pair set
                            * (reserved where the layout has spare bits) */
                out[0] |= 1u;
                out[nw - 1] |= 0x80000000u;
                emit_decode_pair(g, &nd.ctx, out, nw);
            }
        }
    /* Generator 6, after the clean-room RTLs (docs/gateware.md): p^ is 0 for
     * every shift parent_scale - scale >= N the ports allow.  A tree's own
     * contexts have shifts <= N, so no earlier node-pair vector had one of 16
     * or more, and a p^ built from the shift's low four bits passed.  Shifts
     * N, N + 1 and 15 ... 130 (those that keep parent_scale <= 126), with a
     * nonzero node lower-bound code on every axis, and the shift differing
     * per axis; children a few cells wide at the child scale.  The decoder
     * gets the encoder's words under the same context. */
    static const int wide[] = {0, 1, 15, 16, 17, 20, 31, 32, 33, 48, 63, 64, 65, 96, 127, 128, 129, 130};
    for (size_t i = 0; i < sizeof wide / sizeof wide[0]; i++) {
        int sh = wide[i] < 2 ? g->N + wide[i] : wide[i];
        int e = CBVH_SCALE_CEIL - sh - 2 < -4 ? CBVH_SCALE_CEIL - sh - 2 : -4;
        if (e < g->ms) continue;
        node_t nd;
        child_t ch[2];
        for (int a = 0; a < 3; a++) {
            static const uint32_t lbm[3] = {1u, 0xFFFFFFFFu, 0x5u};
            nd.ctx.axis[a] = (cbvh_axis_ctx){e + sh + a, e, lbm[a] & g->mask, a == 1 ? mkf(1, e + 3, 0) : 0};
            for (int c = 0; c < 2; c++)
                ch[c].b[a] = (box_t){mkf(0, e + 2, c ? 0x400000u : 0), mkf(0, e + 3, c ? 0 : 0x200000u)};
        }
        ch[0].flags = 0, ch[0].ptr = 5; /* inner */
        ch[1].flags = 1, ch[1].ptr = 9; /* leaf */
        if (!decode) {
            emit_encode(g, &nd, ch);
            continue;
        }
        uint32_t in[28], out[8];
        encode_inputs(&nd, ch, in);
        enc_unit->eval(&g->spec->cfg, in, out);
        emit_decode_pair(g, &nd.ctx, out, nw);
    }
}

/* Ray-box (traversal.md §3: every applicable reject bit is ORed): each
 * combination of a NaN origin, a zero direction, a bad M, a bad scale, a NaN
 * plane base and bad codes (r = s; codes >= 2^11, which an 11-bit port would
 * cut off); then rays whose t_near or t_far is decided by a tmin or tmax of
 * -0 against a +0 plane distance or one inside the box (the unit's max/min
 * keep the first of equal values, so -0 can come out). */
static void reject_combinations_ray_box(gen_t *g) {
    const cbvh_f32 half = 0x3F000000u, quarter = 0x3E800000u, pinf = CBVH_F32_POS_INF;
    static const uint32_t rs[][2] = {{0, 8}, {5, 5}, {0x800, 0x801}, {0xFFF, 0}};
    for (int k = 0; k < 128; k++) {
        cbvh_f32 o[3] = {(k & 1) ? F_QNAN : half, half, half};
        cbvh_f32 d[3] = {F_ONE, half, quarter};
        if (k & 2) d[0] = d[1] = d[2] = 0;
        int mant = (k & 4) ? 2 : 24;
        int e[3] = {-3, -3, (k & 8) ? 127 : -3};
        cbvh_f32 u[3] = {0, (k & 16) ? F_QNAN : 0, 0};
        uint32_t r[3] = {0, 0, rs[(k >> 5) & 3][0]}, sv[3] = {8, 8, rs[(k >> 5) & 3][1]};
        emit_ray_box(g, o, d, 0, pinf, mant, u, e, r, sv);
    }
    const int e[3] = {-3, -3, -3};
    const cbvh_f32 u[3] = {0, 0, 0};
    const uint32_t r[3] = {0, 0, 0}, sv[3] = {8, 8, 8}; /* the box [0, 1]^3 */
    const cbvh_f32 inside[3] = {half, half, half}, on_face[3] = {0, half, half}, far_face[3] = {F_ONE, half, half};
    const cbvh_f32 dpos[3] = {F_ONE, half, quarter}, dneg[3] = {0xBF800000u, half, quarter};
    for (int m = 3; m <= 24; m += 21) {
        emit_ray_box(g, inside, dpos, CBVH_F32_SIGN, pinf, m, u, e, r, sv);   /* t_near = tmin = -0 */
        emit_ray_box(g, on_face, dpos, CBVH_F32_SIGN, pinf, m, u, e, r, sv);  /* n_x = +0 against tmin -0 */
        emit_ray_box(g, on_face, dpos, 0, pinf, m, u, e, r, sv);              /* n_x = +0 against tmin +0 */
        emit_ray_box(g, far_face, dneg, CBVH_F32_SIGN, pinf, m, u, e, r, sv); /* the same from the far face */
        emit_ray_box(g, on_face, dneg, CBVH_F32_SIGN, CBVH_F32_SIGN, m, u, e, r, sv); /* f_x = +0, tmax -0 */
        emit_ray_box(g, on_face, dneg, CBVH_F32_SIGN, 0, m, u, e, r, sv);
        emit_ray_box(g, inside, dpos, CBVH_F32_SIGN, CBVH_F32_SIGN, m, u, e, r, sv); /* empty interval [-0, -0] */
    }
    /* Generator 6: the code range's upper end, 1024 (s = 2^N at N = 10) valid
     * and 1025 BAD_CODE (not INVERTED), on each axis.  The codes above were
     * 8, 0x800, 0x801 and 0xFFF only, so an RTL whose range check let
     * s = 1025 through passed (gateware/scripts/mutate-rtl, docs/gateware.md).
     * Grid 2^-10 from u = 0 on the axis under test, so [r, s] is inside
     * [0, 1.0009765625]; the ray crosses the box. */
    static const uint32_t lim[][2] = {{0, 1024}, {1023, 1024}, {0, 1025}, {1024, 1025}, {1025, 1024}, {1024, 1024}};
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < sizeof lim / sizeof lim[0]; i++) {
            int ea[3] = {-3, -3, -3};
            uint32_t ra[3] = {0, 0, 0}, sa[3] = {8, 8, 8};
            ea[a] = -10, ra[a] = lim[i][0], sa[a] = lim[i][1];
            const cbvh_f32 o[3] = {0xBF800000u, 0xBF800000u, 0xBF800000u} /* -1 */, d[3] = {F_ONE, F_ONE, F_ONE};
            emit_ray_box(g, o, d, 0, pinf, 24, u, ea, ra, sa);
        }
    /* Generator 6: subnormal plane bases u and origins o that decide t: the
     * box [U, U + 8 2^-126]^3 (r = 0), o = (O, O, O), d = (1, 1, 1), so
     * t_near = U - O, a multiple of 2^-149.  The subnormal u and o above only
     * ever added 2^-149-sized amounts to larger terms, and an RTL placing a
     * subnormal's significand one bit low passed (gateware/scripts/mutate-rtl). */
    static const cbvh_f32 uo[][2] = {{3u, 0}, {0x007FFFFFu, 0}, {0, CBVH_F32_SIGN | 5u}, {7u, 2u}, {0x00400000u, 1u}};
    for (size_t i = 0; i < sizeof uo / sizeof uo[0]; i++)
        for (int m = 3; m <= 24; m += 21) {
            const int es[3] = {-126, -126, -126};
            const uint32_t rz[3] = {0, 0, 0}, s8[3] = {8, 8, 8};
            const cbvh_f32 ub[3] = {uo[i][0], uo[i][0], uo[i][0]}, o[3] = {uo[i][1], uo[i][1], uo[i][1]};
            const cbvh_f32 d[3] = {F_ONE, F_ONE, F_ONE};
            emit_ray_box(g, o, d, 0, pinf, m, ub, es, rz, s8);
        }
    /* Generator 7: INVERTED at r = s on each axis.  The x and y axes had one
     * such vector each ((1024, 1024) above), so an RTL testing r > s there
     * failed one vector (a third mutation run); r = s at 0, 1, 8 and 1023 and
     * r = s + 1, in range, on each axis, the box otherwise [0, 1]^3.  And the
     * range ends again with M = 3 (a fourth run killed the limits r <= 1024 in
     * BAD_CODE and s <= 1024 in INVERTED by one vector each): r = 1025 with
     * s = 0 and 1025, s = 1026, and (1024, 1024). */
    static const uint32_t eq[][2] = {{0, 0}, {1, 1}, {8, 8}, {1023, 1023}, {9, 8},
                                     {1025, 0}, {1025, 1025}, {0, 1026}, {1024, 1024}};
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < sizeof eq / sizeof eq[0]; i++) {
            int ea[3] = {-3, -3, -3};
            uint32_t ra[3] = {0, 0, 0}, sa[3] = {8, 8, 8};
            ea[a] = -10, ra[a] = eq[i][0], sa[a] = eq[i][1];
            emit_ray_box(g, inside, dpos, 0, pinf, i < 5 ? 24 : 3, u, ea, ra, sa);
        }
    /* Generator 8: plane distances of 0 and +-2^-149 against tmin and tmax of
     * +-0 and +-2^-149.  The comparator orders binary32 by a key in which -0
     * and +0 are equal; an RTL keying 2^-149 like 0 (and -0 below +0) passed
     * every vector (a sixth mutation run, docs/gateware.md): no entry or exit
     * distance was ever 2^-149.  The box [0, 1]^3, the ray along axis a
     * (the other direction components +0, origin 1/2 there): from
     * o_a = -2^-149 forward (entry at 2^-149), from +2^-149 backward (exit at
     * 2^-149), from 0 either way (entry or exit at 0). */
    static const cbvh_f32 od[][2] = {{CBVH_F32_SIGN | 1u, F_ONE}, {1u, 0xBF800000u}, {0, F_ONE}, {0, 0xBF800000u}};
    static const cbvh_f32 tmins[] = {0, CBVH_F32_SIGN, 1u, CBVH_F32_SIGN | 1u}, tmaxs[] = {pinf, 0, 1u};
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < sizeof od / sizeof od[0]; i++)
            for (size_t j = 0; j < sizeof tmins / sizeof tmins[0]; j++)
                for (size_t k = 0; k < sizeof tmaxs / sizeof tmaxs[0]; k++) {
                    cbvh_f32 o[3] = {half, half, half}, d[3] = {0, 0, 0};
                    o[a] = od[i][0];
                    d[a] = od[i][1];
                    emit_ray_box(g, o, d, tmins[j], tmaxs[k], 3, u, e, r, sv);
                }
}

/* Emits the ray o0 + t d0 and the triangle (0, p1, p2), given in a frame
 * (x, y, z), with frame axis k moved to axis (k + rot) % 3 and, when mirror,
 * every nonzero coordinate negated (a point reflection; a zero stays +0). */
static void emit_tri_frame(gen_t *g, const cbvh_f32 o0[3], const cbvh_f32 d0[3], const cbvh_f32 p1[3],
                           const cbvh_f32 p2[3], int rot, int mirror) {
    const cbvh_f32 m = mirror ? CBVH_F32_SIGN : 0;
    cbvh_f32 o[3], d[3], v[9] = {0};
    for (int k = 0; k < 3; k++) {
        int a = (k + rot) % 3;
        o[a] = o0[k] ? o0[k] ^ m : 0;
        d[a] = d0[k] ? d0[k] ^ m : 0;
        v[3 + a] = p1[k] ? p1[k] ^ m : 0;
        v[6 + a] = p2[k] ? p2[k] ^ m : 0;
    }
    emit_ray_tri(g, o, d, v);
}

/* Generator 8: a barycentric weight just below 1/2 while det' spans more
 * than 765 bits, with bits in its lowest 32-bit words.  An RTL whose shift
 * pass starts at word 1 (word 0 never written, words 1 and 2 from the wrong
 * source words) passed every level-1 and level-2 vector (a sixth mutation
 * run, docs/gateware.md): the lost bits lower det' by less than one unit in
 * its top 25 bits, which shows only at a rounding boundary.  v0 = 0,
 * v1 = (h, -2^-149, 0), v2 = (0, h, -w), d = (-2^-149, 0, -H), o = (x, 0, 0):
 * with h = 2^112, H = 2^127, w = 2^-149, x = 2^111, det' = 2^351 + 2^-447 and
 * V' = 2^350, so b1 = RD(V'/det') = pred(1/2), where det' without its
 * lowest term gives exactly 1/2; the FLT_MAX-sized version (h = H = FLT_MAX,
 * w = 2^-117, x = FLT_MAX/2) has det' leading at bit 830 and a 2^-415 term.
 * The axes rotated, the winding swapped (the weight is then b2), the scene
 * mirrored through the origin. */
static void tri_low_word_ties(gen_t *g) {
    /* o_x, h, d_z, v2's last coordinate */
    static const cbvh_f32 cfg[][4] = {{0x77000000u, 0x77800000u, 0xFF000000u, 0x80000001u},
                                      {0x7EFFFFFFu, 0x7F7FFFFFu, 0xFF7FFFFFu, 0x85000000u}};
    for (size_t c = 0; c < 2; c++)
        for (int rot = 0; rot < 3; rot++)
            for (int swap = 0; swap < 2; swap++)
                for (int mirror = 0; mirror < 2; mirror++) {
                    const cbvh_f32 o0[3] = {cfg[c][0], 0, 0}, d0[3] = {0x80000001u, 0, cfg[c][2]};
                    const cbvh_f32 a0[3] = {cfg[c][1], 0x80000001u, 0}, b0[3] = {0, cfg[c][1], cfg[c][3]};
                    emit_tri_frame(g, o0, d0, swap ? b0 : a0, swap ? a0 : b0, rot, mirror);
                }
}

/* Generator 7: quotients that tie exactly while det' and Nt span more than
 * 800 bits, above 2^380 and below 2^-415 at once.  Two RTL slips that touch
 * only the lowest words of the 27-word operands (the shift pass dropping the
 * first word, the divider reading word 1 for word 0) passed every level-1
 * and level-2 vector (a fourth mutation run, docs/gateware.md): no vector had
 * both ends in one sum.  With v0 = 0, v1 = (h, tau, 0), v2 = (0, h, tau) and
 * d = (k tau, 0, h), d . (v1 x v2) = k tau^3 + h^3, and o = -d (t = 1) or
 * o = -d/2 (k = 2, t = 1/2) puts the hit on v0 with Nt = t det' exactly;
 * tau = 2^-149 or 3 2^-149, h = 2^127 or 1.5 2^127, the axes rotated, the
 * winding swapped and the scene mirrored through the origin. */
static void tri_wide_ties(gen_t *g) {
    static const cbvh_f32 taus[] = {0x00000001u, 0x00000003u}, hs[] = {0x7F000000u, 0x7F400000u};
    for (size_t ti = 0; ti < 2; ti++)
        for (size_t hi = 0; hi < 2; hi++)
            for (int half = 0; half < 2; half++)
                for (int rot = 0; rot < 3; rot++)
                    for (int swap = 0; swap < 2; swap++)
                        for (int mirror = 0; mirror < 2; mirror++) {
                            const cbvh_f32 tau = taus[ti], h = hs[hi];
                            /* in the unrotated frame (x, y, z); h - 2^23 halves h */
                            const cbvh_f32 d0[3] = {half ? tau * 2 : tau, 0, h};
                            const cbvh_f32 o0[3] = {neg(tau), 0, neg(half ? h - (1u << 23) : h)};
                            const cbvh_f32 a0[3] = {h, tau, 0}, b0[3] = {0, h, tau};
                            emit_tri_frame(g, o0, d0, swap ? b0 : a0, swap ? a0 : b0, rot, mirror);
                        }
}

/* Generator 7: as for the sphere below, every input of a ray-triangle in
 * turn is +-2^-149 (e) and decides the hit: read as 0 (a zero factor's
 * monomials skipped) the answer flips.  In a frame (P, Q, N) of rotated axes,
 * the triangle A = 0, B = sp e_P, C = sq e_Q in the plane N = 0, the ray
 * along N through a point of the edge AC (P = 0) or AB (Q = 0) or inside:
 * o_P, d_P (or o_Q, d_Q) = e move the hit point off the edge, outward (a
 * miss); o_N = e starts the ray e before the plane (t = 2^-149 > 0, a hit;
 * t = 0 is not); d = e e_N alone gives t = 2^149 (a hit; d_N = 0 gives
 * det' = 0); A_P = e (A_Q) moves the edge past the hit point (a miss), and
 * A_N = e lifts the plane to t = 2^-150 (a hit), with A each of v0, v1, v2. */
static void tri_place(cbvh_f32 out[3], int rot, cbvh_f32 p, cbvh_f32 q, cbvh_f32 n) {
    out[rot] = p, out[(rot + 1) % 3] = q, out[(rot + 2) % 3] = n;
}

static void tri_emit_roles(gen_t *g, int rot, const cbvh_f32 o[3], const cbvh_f32 d[3], const cbvh_f32 a[3],
                           int sp, int sq, int cyc) {
    cbvh_f32 oo[3], dd[3], r[3][3], v[9];
    tri_place(oo, rot, o[0], o[1], o[2]);
    tri_place(dd, rot, d[0], d[1], d[2]);
    tri_place(r[0], rot, a[0], a[1], a[2]);
    tri_place(r[1], rot, sp < 0 ? neg(F_ONE) : F_ONE, 0, 0);
    tri_place(r[2], rot, 0, sq < 0 ? neg(F_ONE) : F_ONE, 0);
    for (int k = 0; k < 3; k++) /* v_k = role (k + cyc) mod 3: the winding is kept */
        for (int c = 0; c < 3; c++) v[3 * k + c] = r[(k + cyc) % 3][c];
    emit_ray_tri(g, oo, dd, v);
}

static void tri_smallest_deciders(gen_t *g) {
    const cbvh_f32 half = 0x3F000000u, quarter = 0x3E800000u, one = F_ONE, m1 = 0xBF800000u;
    const cbvh_f32 zero3[3] = {0, 0, 0};
    for (int rot = 0; rot < 3; rot++)
        for (int si = 0; si < 2; si++) {
            const int s = si ? -1 : 1;
            const cbvh_f32 e = si ? 0x80000001u : 0x00000001u, sone = si ? m1 : one, msone = si ? one : m1;
            const cbvh_f32 up[3] = {0, 0, one};
            /* the ray's inputs, v0 = A = 0 */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){e, half, m1}, up, zero3, -s, 1, 0);          /* o_P */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){half, e, m1}, up, zero3, 1, -s, 0);          /* o_Q */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){quarter, quarter, e}, (const cbvh_f32[3]){0, 0, msone},
                           zero3, 1, 1, 0);                                                         /* o_N */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){0, half, m1}, (const cbvh_f32[3]){e, 0, one}, zero3, -s, 1,
                           0);                                                                      /* d_P */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){half, 0, m1}, (const cbvh_f32[3]){0, e, one}, zero3, 1, -s,
                           0);                                                                      /* d_Q */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){quarter, quarter, msone}, (const cbvh_f32[3]){0, 0, e}, zero3,
                           1, 1, 0);                                                                /* d_N */
            /* the vertex A = v0, v1, v2 in turn */
            for (int cyc = 0; cyc < 3; cyc++) {
                tri_emit_roles(g, rot, (const cbvh_f32[3]){0, half, m1}, up, (const cbvh_f32[3]){e, 0, 0}, s, 1,
                               cyc);                                                                /* A_P */
                tri_emit_roles(g, rot, (const cbvh_f32[3]){half, 0, m1}, up, (const cbvh_f32[3]){0, e, 0}, 1, s,
                               cyc);                                                                /* A_Q */
                tri_emit_roles(g, rot, (const cbvh_f32[3]){quarter, quarter, 0}, (const cbvh_f32[3]){0, 0, sone},
                               (const cbvh_f32[3]){0, 0, e}, 1, 1, cyc);                            /* A_N */
            }
        }
}

/* Ray-triangle (traversal.md §4: one bit, NAN_INF before ZERO_DIR) and
 * ray-sphere (§10.2: BAD_PARAM ORed with NAN_INF or ZERO_DIR, ZERO_DIR only for
 * a ray without NaN/Inf): every combination of a NaN or Inf in the ray, a zero
 * direction (also -0 components) and a bad vertex, centre or radius. */
static void reject_combinations_ray_tri(gen_t *g) {
    const cbvh_f32 pinf = CBVH_F32_POS_INF;
    for (int k = 0; k < 16; k++) {
        cbvh_f32 o[3] = {(k & 1) ? F_QNAN : 0x3E800000u, 0x3E800000u, 0xBF800000u};
        cbvh_f32 d[3] = {0, 0, F_ONE};
        if (k & 2) d[2] = (k & 8) ? CBVH_F32_SIGN : 0; /* (0, 0, +-0) */
        cbvh_f32 v[9] = {0, 0, 0, F_ONE, 0, 0, 0, F_ONE, 0};
        if (k & 4) v[4] = (k & 8) ? pinf : F_QNAN;
        if ((k & 8) && !(k & 2)) d[0] = pinf; /* an Inf direction component */
        emit_ray_tri(g, o, d, v);
    }
    /* Generator 5, after a clean-room RTL (docs/gateware.md): no level-1
     * vector needed more than 807 bits for an exact sum, so an 832-bit
     * accumulator passed them all.  Vertices +-a along the rows of
     * [[1, 1, -1], [-1, 1, 1], [1, -1, 1]] (determinant 4) with a near 2^127:
     * the triple product [v0, v2, v1] is 4 a^3 (about 2^386, 834 bits in the
     * units' 2^-447 grid); rays from o = 0 along +-(1, 1, 1) s through the
     * centroid (hit, or t < 0) with s = 1 and s = a (det ~ a^3 too), with the
     * vertices negated, and with v1, v2 swapped (the other winding). */
    const cbvh_f32 big[] = {0x7F7FFFFFu /* FLT_MAX */, 0x7F000000u /* 2^127 */, 0x7EC00000u /* 1.5 2^126 */};
    static const int rows[3][3] = {{1, 1, -1}, {-1, 1, 1}, {1, -1, 1}};
    for (size_t bi = 0; bi < sizeof big / sizeof big[0]; bi++)
        for (int var = 0; var < 8; var++) {
            int neg = var & 1, swap = (var >> 1) & 1, dneg = (var >> 2) & 1;
            cbvh_f32 v[9], o[3] = {0, 0, 0}, d[3];
            for (int i = 0; i < 3; i++) {
                int src = swap && i ? 3 - i : i;
                for (int a = 0; a < 3; a++)
                    v[3 * i + a] = big[bi] | ((rows[src][a] < 0) != neg ? CBVH_F32_SIGN : 0);
            }
            for (int a = 0; a < 3; a++) d[a] = (bi == 0 ? F_ONE : big[bi]) | (dneg ? CBVH_F32_SIGN : 0);
            emit_ray_tri(g, o, d, v);
        }
    /* Generator 6: two readings were pinned by one and two vectors only
     * (docs/gateware.md).  (1) A hit is decided on the exact t, whose RD may
     * be +0: the unit triangle in the plane x_k = 0 of each axis k, the
     * origin a distance delta in front of it (or behind: a miss, or on it:
     * t = 0, a miss) and |d_k| = D, so t = delta / D; delta / D = 2^-149
     * exactly (t = 2^-149), just below it and far below (t = +0).
     * (2) NaN/Inf vertices suppress ZERO_DIR: a zero direction (+-0
     * components) with a NaN or +-Inf vertex coordinate in each vertex
     * (below). */
    static const struct {
        cbvh_f32 delta, dk;
    } tiny[] = {
        {0x00000001u /* 2^-149 */, F_ONE},         {0x00000001u, 0x40000000u /* 2 */},
        {0x00000001u, 0x7F7FFFFFu /* FLT_MAX */},    {0x00800000u /* 2^-126 */, 0x4B800000u /* 2^24 */},
        {0x00800000u, 0x4B7FFFFFu /* pred 2^24 */}, {0x00C00000u /* 1.5 2^-126 */, 0x4B800001u},
        {0x3F800000u /* 1 */, 0x7F7FFFFFu},          {0x00000003u /* 3 2^-149 */, 0x40400001u /* succ 3 */},
        {0, 0x40000000u /* on the plane: t = 0 */},
    };
    for (int k = 0; k < 3; k++)
        for (size_t i = 0; i < sizeof tiny / sizeof tiny[0]; i++)
            for (int side = 0; side < 2; side++) {
                if (side && !tiny[i].delta) continue;
                int ka = (k + 1) % 3, kb = (k + 2) % 3;
                cbvh_f32 v[9] = {0}, o[3], d[3] = {0, 0, 0};
                v[3 + ka] = F_ONE; /* v1 = e_ka, v2 = e_kb, v0 = 0 */
                v[6 + kb] = F_ONE;
                o[ka] = 0x3E800000u; /* 0.25 */
                o[kb] = 0x3E800000u;
                /* side 0: origin at -delta, direction +D (t > 0); side 1: behind it */
                o[k] = tiny[i].delta | (side ? 0 : CBVH_F32_SIGN);
                d[k] = tiny[i].dk;
                if (i % 2) o[k] ^= CBVH_F32_SIGN, d[k] |= CBVH_F32_SIGN; /* the mirrored ray */
                emit_ray_tri(g, o, d, v);
            }
    /* (3) Every monomial at the bottom of the units' 2^-447 grid: triangles
     * and rays of subnormals only (multiples of 2^-149), so every exact sum
     * lies in the accumulator's two lowest 32-bit words; an RTL whose shift
     * pass read those words as 0 passed every earlier vector
     * (gateware/scripts/mutate-rtl).  Origin 0, the triangle in the plane
     * z = 2^-149 k around the z axis, d = (0, 0, 2^-149 m): t = k / m. */
    static const int km[][2] = {{1, 1}, {1, 2}, {3, 1}, {2, 3}, {5, 4}, {7, 7}};
    for (size_t i = 0; i < sizeof km / sizeof km[0]; i++)
        for (int w = 0; w < 2; w++) {
            cbvh_f32 o[3] = {0, 0, 0}, d[3] = {0, 0, (cbvh_f32)km[i][1]};
            cbvh_f32 z = (cbvh_f32)km[i][0];
            cbvh_f32 v[9] = {CBVH_F32_SIGN | 3u, CBVH_F32_SIGN | 3u, z, 5u, CBVH_F32_SIGN | 3u, z,
                             CBVH_F32_SIGN | 3u, 5u, z};
            if (w) { /* the other winding, and the direction's x and y tiny too */
                cbvh_f32 t0 = v[3], t1 = v[4];
                v[3] = v[6], v[4] = v[7], v[6] = t0, v[7] = t1;
                d[0] = 1u, d[1] = CBVH_F32_SIGN | 1u;
            }
            emit_ray_tri(g, o, d, v);
        }
    /* (4) t with exponent 127, in [2^127, 2^128): the largest finite range,
     * next to §2's directed overflow (t >= 2^128 gives FLT_MAX); no earlier
     * vector had one, and an RTL that took exponent 127 for an overflow
     * failed level 2 only.  The unit triangle around the z axis in the plane
     * z = Z, d = (0, 0, D): t = Z / D. */
    static const cbvh_f32 zd[][2] = {
        {0x7E800000u /* 2^126 */, 0x3F000000u /* 0.5: t = 2^127 */},  {0x7E800000u, 0x3EC00000u /* 0.375 */},
        {0x7E800000u, 0x3EFFFFFFu /* pred 0.5 */},                      {0x7F7FFFFFu /* FLT_MAX */, F_ONE},
        {0x7F7FFFFFu, 0x3F800001u /* succ 1 */},                         {0x7F7FFFFFu, 0x3FC00000u /* 1.5 */},
    };
    for (size_t i = 0; i < sizeof zd / sizeof zd[0]; i++) {
        cbvh_f32 o[3] = {0, 0, 0}, d[3] = {0, 0, zd[i][1]}, z = zd[i][0];
        cbvh_f32 v[9] = {0xBF800000u, 0xBF800000u, z, 0x40000000u, 0xBF800000u, z, 0xBF800000u, 0x40000000u, z};
        emit_ray_tri(g, o, d, v);
    }
    static const cbvh_f32 bad[] = {F_QNAN, CBVH_F32_POS_INF, CBVH_F32_NEG_INF, 0x7F800001u /* sNaN */};
    for (int pos = 0; pos < 9; pos += 4)
        for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++)
            for (int z = 0; z < 2; z++) {
                cbvh_f32 o[3] = {0x3E800000u, 0x3E800000u, 0xBF800000u};
                cbvh_f32 d[3] = {z ? CBVH_F32_SIGN : 0, 0, z ? CBVH_F32_SIGN : 0};
                cbvh_f32 v[9] = {0, 0, 0, F_ONE, 0, 0, 0, F_ONE, 0};
                v[pos] = bad[b];
                emit_ray_tri(g, o, d, v);
            }
    tri_wide_ties(g);
    tri_smallest_deciders(g);
    tri_low_word_ties(g);
}

/* A binary32 with an exponent in 120..hi and a random significand, of random
 * sign when `signed_`: one draw per statement (the order of function
 * arguments is unspecified in C). */
static cbvh_f32 huge_f(rng_t *r, int signed_, int hi) {
    uint32_t frac = (uint32_t)rng_next(r);
    int e = (int)rnd_range(r, 120, hi);
    int sign = signed_ ? (int)rnd_below(r, 2) : 0;
    return mkf(sign, e, frac);
}

/* Generator 7, after RTL mutation (docs/gateware.md): a unit that skips the
 * monomials of a zero factor passed every vector when it took 2^-149 for 0 in
 * r or o_x.  Here each of the 12 inputs in turn is +-2^-149 (e) and decides
 * the hit: with that input read as 0 the answer flips.  Along axis a, across
 * axis b, d = e_a unless said otherwise, segment [0, +Inf) unless said. */
static void sphere_reset(cbvh_f32 o[3], cbvh_f32 d[3], cbvh_f32 c[3], int a) {
    for (int i = 0; i < 3; i++) o[i] = d[i] = c[i] = 0;
    d[a] = F_ONE;
}

static void sphere_smallest_deciders(gen_t *g) {
    const cbvh_f32 pinf = CBVH_F32_POS_INF, five = 0x40A00000u;
    const cbvh_f32 p2m140 = 0x00000200u, p2m140_less_e = 0x000001FFu; /* 2^-140, 2^-140 - e */
    for (int a = 0; a < 3; a++)
        for (int s = 0; s < 2; s++) {
            const int b = (a + 1) % 3;
            const cbvh_f32 e = s ? 0x80000001u : 0x00000001u, e2 = e + 1; /* +-2^-149, +-2^-148 */
            cbvh_f32 o[3], d[3], c[3];
            /* r = e: tangent at distance e (hit; r = 0 misses), at 2e (miss) */
            sphere_reset(o, d, c, a);
            c[a] = five, c[b] = e;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0x00000001u);
            c[b] = e2;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0x00000001u);
            /* r = e, c behind the origin by e: the end point t = 0 decides */
            sphere_reset(o, d, c, a);
            c[a] = 0x80000001u;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0x00000001u);
            /* c_b = e, r = 0: the line misses c by e (miss; c_b = 0 hits) */
            sphere_reset(o, d, c, a);
            c[a] = five, c[b] = e;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            /* c_a = e on the point segment [0, 0] (miss; c_a = 0 hits) */
            sphere_reset(o, d, c, a);
            c[a] = e;
            emit_ray_sphere(g, o, d, 0, 0, c, 0);
            /* o_b = e across the ray (miss); o_a = e with c = 0 (+e: miss,
             * the origin is past c; -e: before it, a hit) */
            sphere_reset(o, d, c, a);
            o[b] = e, c[a] = five;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            sphere_reset(o, d, c, a);
            o[a] = e;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            /* d_b = e: the line leans off c = 5 e_a by 5e (miss; d_b = 0 hits) */
            sphere_reset(o, d, c, a);
            d[b] = e, c[a] = five;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            /* d = e e_a alone on [0, 1]: it reaches c = e e_a (hit) but not
             * c = 2e e_a (miss; d = 0 would give A = 0 and |w x d|^2 = 0 <= 0) */
            sphere_reset(o, d, c, a);
            d[a] = e, c[a] = e;
            emit_ray_sphere(g, o, d, 0, F_ONE, c, 0);
            c[a] = e2;
            emit_ray_sphere(g, o, d, 0, F_ONE, c, 0);
            /* tmin = e beyond t* = -1 (c = -e_a, r = 1): the end point is at
             * 1 + e (miss) for +e, 1 - e (hit) for -e; and c = -2^-140 e_a
             * with r = 2^-140 - e: tmin = -e reaches it exactly (hit) */
            sphere_reset(o, d, c, a);
            c[a] = 0xBF800000u;
            emit_ray_sphere(g, o, d, e, pinf, c, F_ONE);
            c[a] = p2m140 | CBVH_F32_SIGN;
            emit_ray_sphere(g, o, d, e, pinf, c, p2m140_less_e);
            /* tmax = e before t* = 2^-140 (c = 2^-140 e_a, r = 2^-140 - e):
             * tmax = +e reaches the sphere exactly (hit), t = 0 does not;
             * tmax = -e < tmin is an empty segment */
            sphere_reset(o, d, c, a);
            c[a] = p2m140;
            emit_ray_sphere(g, o, d, 0, e, c, p2m140_less_e);
        }
}

static void reject_combinations_ray_sphere(gen_t *g) {
    const cbvh_f32 pinf = CBVH_F32_POS_INF;
    for (int k = 0; k < 32; k++) {
        cbvh_f32 o[3] = {(k & 1) ? F_QNAN : 0, 0, 0xC0000000u /* -2 */};
        cbvh_f32 d[3] = {0, 0, (k & 2) ? CBVH_F32_SIGN : F_ONE};
        cbvh_f32 tmin = (k & 16) ? pinf : 0, tmax = pinf;
        cbvh_f32 c[3] = {0, (k & 4) ? F_QNAN : 0, 0};
        cbvh_f32 r = (k & 8) ? 0xBF800000u /* -1 */ : F_ONE;
        emit_ray_sphere(g, o, d, tmin, tmax, c, r);
    }
    /* Generator 4, after a clean-room RTL (docs/gateware.md): neither reading
     * below was pinned by a level-1 vector.  (1) A segment's ends compare as
     * values, -0 = +0: [+0, -0] and [-0, +0] are the point t = 0, not empty;
     * the origin is inside the ball, on its surface, or outside it.  (2) The
     * status does not depend on the segment: every fault with an empty segment
     * [2, 1], next to the valid ray with it (hit 0, status 0). */
    const cbvh_f32 zeros[][2] = {{0, CBVH_F32_SIGN}, {CBVH_F32_SIGN, 0}, {CBVH_F32_SIGN, CBVH_F32_SIGN}};
    const cbvh_f32 centre_z[] = {0xBF000000u /* -0.5: o inside */, F_ONE /* on the surface */,
                                 0x40000000u /* 2: outside */};
    for (size_t z = 0; z < sizeof zeros / sizeof zeros[0]; z++)
        for (size_t i = 0; i < sizeof centre_z / sizeof centre_z[0]; i++) {
            cbvh_f32 o[3] = {0, 0, 0}, d[3] = {0, 0, F_ONE}, c[3] = {0, 0, centre_z[i]};
            emit_ray_sphere(g, o, d, zeros[z][0], zeros[z][1], c, F_ONE);
        }
    for (int k = 0; k < 5; k++) {
        cbvh_f32 o[3] = {k == 1 ? F_QNAN : 0, 0, 0xC0000000u}, d[3] = {0, 0, k == 2 ? 0 : F_ONE};
        cbvh_f32 c[3] = {0, k == 3 ? pinf : 0, 0};
        cbvh_f32 r = k == 4 ? 0xBF800000u : F_ONE;
        emit_ray_sphere(g, o, d, 0x40000000u /* 2 */, F_ONE, c, r);
    }
    /* Generator 6: the accumulator's top words.  A 33-word (1,056-bit)
     * accumulator failed one level-1 vector and a 32-word one three
     * (docs/gateware.md): few vectors had an exact sum near the 1,115 bits of
     * §10.1.  Every input here has an exponent in 120..127 (tmin, tmax too),
     * so |w x d|^2, R A and |t d - w|^2 are near 2^510, 2^1106 in the unit of
     * 2^-596: the sign of each decision sits in the top words.  A stream of
     * its own (fixed seed); every fourth a segment [0, +Inf), otherwise a
     * segment around, before or after t*; every other one with o and c
     * within 2^122 of the origin and r >= 2^126 (mostly hits). */
    rng_t hr;
    rng_seed(&hr, UINT64_C(0x5A1E5C0FFEE00006));
    for (int k = 0; k < 48; k++) {
        cbvh_f32 o[3], d[3], c[3], r, t0, t1;
        int top = k % 2 ? 121 : 127; /* odd k: |w| < 2^123 <= r, mostly hits */
        for (int a = 0; a < 3; a++) {
            o[a] = huge_f(&hr, 1, top);
            d[a] = huge_f(&hr, 1, 127);
            c[a] = huge_f(&hr, 1, top);
        }
        if (k % 2) r = mkf(0, 126, (uint32_t)rng_next(&hr));
        else r = huge_f(&hr, 0, 127);
        t0 = huge_f(&hr, 1, 127);
        t1 = huge_f(&hr, 0, 127);
        if (k % 4 == 0) t0 = 0, t1 = CBVH_F32_POS_INF;
        else if (cbvh_f32_cmp(t0, t1) > 0) {
            cbvh_f32 x = t0;
            t0 = t1, t1 = x;
        }
        emit_ray_sphere(g, o, d, t0, t1, c, r);
    }
    sphere_smallest_deciders(g);
}

static void reject_combinations_encode_pair(gen_t *g) { reject_combinations_nodepair(g, 0); }
static void reject_combinations_decode_pair(gen_t *g) { reject_combinations_nodepair(g, 1); }

/* ---- files ------------------------------------------------------------------- */

/* Per unit: the size of a level-1 file before the appended cases (the
 * committed set stays small), its generator, the exact-path cases of the ray
 * units (generator 2) and the reject combinations (generator 3) or other
 * structured cases appended later (generators 6 and 7). */
typedef struct {
    const char *unit;
    size_t level1;
    void (*gen)(gen_t *, size_t);
    void (*exact)(gen_t *, rng_t *, int);
    int n_exact;
    void (*rejects)(gen_t *);
} unit_gen;

static const unit_gen unit_gens[] = {
    {"scale_estimate", 2000, gen_estimate, NULL, 0, appended_estimate},
    {"axis_compress", 2000, gen_compress, NULL, 0, reject_combinations_compress},
    {"axis_decode", 1500, gen_decode, NULL, 0, reject_combinations_decode},
    {"nodepair_encode", 500, gen_encode_pair, NULL, 0, reject_combinations_encode_pair},
    {"nodepair_decode", 500, gen_decode_pair, NULL, 0, reject_combinations_decode_pair},
    {"ray_box", 1500, gen_ray_box, exact_ray_box, EXACT_CASES_BOX, reject_combinations_ray_box},
    {"ray_triangle", 1500, gen_ray_triangle, exact_ray_triangle, EXACT_CASES_TRI, reject_combinations_ray_tri},
    {"qbvh_stack", 2000, gen_qbvh_stack, NULL, 0, reject_combinations_qstack},
    {"ray_sphere", 1500, gen_ray_sphere, exact_ray_sphere, EXACT_CASES_SPHERE, reject_combinations_ray_sphere},
};

static void stem(const cbvh_vecgen_spec *s, char *buf, size_t n) {
    if (s->unit->uses_encoding)
        snprintf(buf, n, "%s-N%d-ms%d-%s", s->unit->name, s->cfg.params.quant_bits, s->cfg.params.min_scale,
                 cbvh_encoding_name(s->cfg.enc));
    else
        snprintf(buf, n, "%s-N%d-ms%d", s->unit->name, s->cfg.params.quant_bits, s->cfg.params.min_scale);
}

void cbvh_vecgen_filename(const cbvh_vecgen_spec *s, char *buf, size_t n) {
    char st[128];
    stem(s, st, sizeof st);
    snprintf(buf, n, "%s%s.vec", st, s->level >= 2 ? "-L2" : "");
}

int cbvh_vecgen_generate(const cbvh_vecgen_spec *s, cbvh_vecfile *vf) {
    memset(vf, 0, sizeof *vf);
    gen_t g;
    memset(&g, 0, sizeof g);
    g.spec = s;
    s->unit->layout(&s->cfg, &g.lay);
    g.N = s->cfg.params.quant_bits;
    g.ms = s->cfg.params.min_scale;
    g.mask = (1u << g.N) - 1u;
    /* One stream per file: the seed mixed with the file's stem (FNV-1a), the
     * same for both levels so level 2 extends level 1. */
    char st[128];
    stem(s, st, sizeof st);
    uint64_t h = UINT64_C(0xCBF29CE484222325);
    for (const char *c = st; *c; c++) h = (h ^ (uint8_t)*c) * UINT64_C(0x100000001B3);
    rng_seed(&g.rng, s->seed ^ h);

    const unit_gen *ug = NULL;
    for (size_t i = 0; i < sizeof unit_gens / sizeof unit_gens[0]; i++)
        if (strcmp(s->unit->name, unit_gens[i].unit) == 0) ug = &unit_gens[i];
    if (!ug) return -1;
    ug->gen(&g, ug->level1);
    rng_t ex; /* generator 2: the exact-path cases, from a stream of their own */
    rng_seed(&ex, s->seed ^ h ^ UINT64_C(0xE7AC7CA5E5000002));
    if (ug->exact) ug->exact(&g, &ex, ug->n_exact);
    if (ug->rejects) ug->rejects(&g);
    if (s->level >= 2) {
        g.random_only = 1;
        ug->gen(&g, g.n + CBVH_VECGEN_LEVEL2_RANDOM);
        if (ug->exact) ug->exact(&g, &ex, CBVH_VECGEN_LEVEL2_EXACT);
    }
    if (g.oom) {
        free(g.in);
        return -1;
    }
    uint32_t *out = malloc((g.n ? g.n : 1) * (size_t)g.lay.n_out * sizeof *out);
    if (!out) {
        free(g.in);
        return -1;
    }
    for (size_t i = 0; i < g.n; i++)
        s->unit->eval(&s->cfg, g.in + i * (size_t)g.lay.n_in, out + i * (size_t)g.lay.n_out);
    vf->unit = s->unit;
    vf->cfg = s->cfg;
    if (!s->unit->uses_encoding) vf->cfg.enc = CBVH_ENC_MODULO;
    vf->level = s->level;
    vf->seed = s->seed;
    vf->generator = CBVH_VECGEN_VERSION;
    vf->layout = g.lay;
    vf->count = g.n;
    vf->first_line = 0;
    vf->in = g.in;
    vf->out = out;
    return 0;
}

/* The traversal units do not depend on N or min_scale: one file (N = 6) in the default set. */
static int is_ray_unit(const cbvh_unit *u) {
    return strncmp(u->name, "ray_", 4) == 0 || strcmp(u->name, "qbvh_stack") == 0; /* qbvh_stack: no N either */
}
static int is_axis_unit(const cbvh_unit *u) { return strncmp(u->name, "nodepair", 8) != 0 && !is_ray_unit(u); }

size_t cbvh_vecgen_specs(const cbvh_vecgen_select *sel, cbvh_vecgen_spec *out, size_t max) {
    size_t n = 0;
    for (int pass = 0; pass < 2; pass++) {
        /* pass 0: the N sweep; pass 1: the extra minimum scales (default set only) */
        if (pass == 1 && (sel->bits || sel->ms_given)) break;
        for (int u = 0; u < cbvh_unit_count; u++) {
            const cbvh_unit *unit = cbvh_units[u];
            if (sel->unit && sel->unit != unit) continue;
            if (pass == 1 && !is_axis_unit(unit)) continue;
            static const int extra_ms[] = {-126, -10};
            int nlo = sel->bits ? sel->bits : CBVH_N_MIN, nhi = sel->bits ? sel->bits : CBVH_N_MAX;
            if (pass == 1) nlo = nhi = 6;
            if (is_ray_unit(unit) && !sel->bits) nlo = nhi = 6;
            for (int bits = nlo; bits <= nhi; bits++)
                for (int m = 0; m < (pass == 1 ? 2 : 1); m++)
                    for (int e = 0; e < (unit->uses_encoding ? 2 : 1); e++) {
                        cbvh_encoding enc = e ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO;
                        if (unit->uses_encoding && sel->enc_given && enc != sel->enc) continue;
                        if (n < max) {
                            cbvh_vecgen_spec *s = &out[n];
                            s->unit = unit;
                            s->cfg.params.quant_bits = bits;
                            s->cfg.params.min_scale = pass == 1 ? extra_ms[m]
                                                      : sel->ms_given ? sel->min_scale
                                                                      : CBVH_MIN_SCALE_DEFAULT;
                            s->cfg.enc = enc;
                            s->level = sel->level;
                            s->seed = sel->seed;
                        }
                        n++;
                    }
        }
    }
    return n;
}
