/* Property tests of the datapath units over >= 1M structured + random inputs
 * per unit, with independent FPU oracles (see prop_util.h).  Built twice from
 * the model sources (-O0 and -O2); each build prints a digest of every unit
 * output, and a ctest compares the two (determinism).
 *
 * usage: test_properties [--scale F] [--seed S] [--digest-out FILE] */
#include <getopt.h>

#include "prop_util.h"

static digest dg;
static long n_cases;

/* parameters: every N, min_scale mostly -30 / -126, sometimes anywhere */
static cbvh_params random_params(prng *r) {
    cbvh_params p;
    p.quant_bits = prng_range(r, CBVH_N_MIN, CBVH_N_MAX);
    switch (prng_below(r, 4)) {
    case 0: p.min_scale = CBVH_SCALE_FLOOR; break;
    case 1: p.min_scale = prng_range(r, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL); break;
    default: p.min_scale = CBVH_MIN_SCALE_DEFAULT; break;
    }
    return p;
}

/* A finite box: structured pairs, zero-width, straddling zero, far from the
 * origin with tiny extent, or random. */
static void random_box(prng *r, long i, cbvh_f32 *lb, cbvh_f32 *ub) {
    cbvh_f32 a, b;
    switch (prng_below(r, 6)) {
    case 0: /* structured x structured, walked in order */
        a = prop_structured((int)(i % PROP_N_STRUCT));
        b = prop_structured((int)((i / PROP_N_STRUCT) % PROP_N_STRUCT));
        break;
    case 1: /* zero-width (incl. -0 / +0 pairs) */
        a = b = prop_random_float(r);
        if (prng_below(r, 8) == 0) { a = CBVH_F32_SIGN; b = 0; }
        break;
    case 2: /* straddling zero */
        a = prop_random_float(r) | CBVH_F32_SIGN;
        b = prop_random_float(r) & ~CBVH_F32_SIGN;
        break;
    case 3: { /* far from the origin, a few ulps wide */
        a = prop_random_float(r);
        if (prng_below(r, 2)) a = (a & CBVH_F32_SIGN) | ((cbvh_f32)prng_range(r, 157, 254) << CBVH_F32_FRAC_BITS) | (a & CBVH_F32_FRAC);
        int64_t k = cbvh_f32_key(a) + prng_range(r, 0, 40);
        if (k > (int64_t)CBVH_F32_MAX) k = (int64_t)CBVH_F32_MAX;
        b = unkey(k);
        break;
    }
    default:
        a = prop_random_float(r);
        b = prop_random_float(r);
        break;
    }
    if (cbvh_f32_key(a) > cbvh_f32_key(b)) { cbvh_f32 t = a; a = b; b = t; }
    *lb = a;
    *ub = b;
}

static int oracle_fits(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e) {
    return oracle_cells(lb, ub, e) <= ldexp(1.0, p->quant_bits);
}

/* ---- unit 1: scale estimator ---- */
static void prop_scale_estimate(prng *r, long iters) {
    for (long i = 0; i < iters; i++) {
        cbvh_params p = random_params(r);
        cbvh_f32 lb, ub;
        random_box(r, i, &lb, &ub);
        int e;
        uint32_t st = cbvh_scale_estimate(&p, lb, ub, &e);
        digest_u32(&dg, st);
        digest_u32(&dg, (uint32_t)e);
        n_cases++;
        if (st) {
            prop_fail("scale_estimate status %#x for [%08x,%08x] N=%d", st, lb, ub, p.quant_bits);
            continue;
        }
        if (e < p.min_scale || e > CBVH_SCALE_CEIL) prop_fail("scale_estimate %d out of range", e);
        if (!oracle_fits(&p, lb, ub, e))
            prop_fail("scale_estimate: [%08x,%08x] does not fit at e=%d N=%d", lb, ub, e, p.quant_bits);
        if (e > p.min_scale && oracle_fits(&p, lb, ub, e - 1))
            prop_fail("scale_estimate: [%08x,%08x] also fits at e-1=%d N=%d ms=%d", lb, ub, e - 1, p.quant_bits,
                      p.min_scale);
        if ((i & 63) == 0) { /* full loop oracle on a sample */
            int k = p.min_scale;
            while (!oracle_fits(&p, lb, ub, k)) k++;
            if (k != e) prop_fail("scale_estimate: loop oracle %d, model %d", k, e);
        }
    }
}

/* ---- unit 2: single-axis compressor ---- */
static cbvh_f32 random_node_clb(prng *r, const cbvh_params *p, cbvh_f32 lb, int e);
static void check_compress(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_f32 node) {
    cbvh_axis_code c, o;
    uint32_t st = cbvh_axis_compress(p, lb, ub, e, node, &c);
    digest_code(&dg, st, &c);
    n_cases++;
    uint32_t ost = oracle_compress(p->quant_bits, p->min_scale, lb, ub, e, node, &o);
    if (st != ost || !code_equal(&c, &o)) {
        prop_fail("compress [%08x,%08x] e=%d node %08x N=%d ms=%d: model st=%#x " CODE_FMT ", oracle st=%#x " CODE_FMT,
                  lb, ub, e, node, p->quant_bits, p->min_scale, st, CODE_ARGS(c), ost, CODE_ARGS(o));
        return;
    }
    if (!encloses(&c, lb, ub)) prop_fail("compress: no enclosure [%08x,%08x] e=%d -> [%08x,%08x]", lb, ub, e, c.clb, c.cub);
    if (c.child_scale > e || c.child_scale < p->min_scale)
        prop_fail("compress: child_scale %d vs scale %d min %d", c.child_scale, e, p->min_scale);
}

static void prop_compress(prng *r, long iters) {
    for (long i = 0; i < iters; i++) {
        cbvh_params p = random_params(r);
        cbvh_f32 lb, ub;
        random_box(r, i, &lb, &ub);
        int est;
        if (cbvh_scale_estimate(&p, lb, ub, &est)) continue;
        int e;
        switch (prng_below(r, 5)) {
        case 0: e = est; break;
        case 1: e = est > p.min_scale ? est - 1 : est; break; /* NO_FIT unless clamped */
        case 2: e = p.min_scale; break;
        case 3:
            e = est + prng_range(r, 0, 8);
            if (e > CBVH_SCALE_CEIL) e = CBVH_SCALE_CEIL;
            break;
        default: e = prng_range(r, p.min_scale, CBVH_SCALE_CEIL); break;
        }
        check_compress(&p, lb, ub, e, random_node_clb(r, &p, lb, e));
    }
}

/* A node lower bound for a box [lb, ...] at scale e: the box's own (its
 * window starts at its lowest cell), one j cells lower or higher (the
 * window's ends around the box), off the grid, -Inf (-2^128), or any. */
static cbvh_f32 random_node_clb(prng *r, const cbvh_params *p, cbvh_f32 lb, int e) {
    double k = oracle_floor(lb, e);
    switch (prng_below(r, 6)) {
    case 0: return lb;
    case 1: return prng_below(r, 4) ? prop_random_float(r) : CBVH_F32_NEG_INF;
    case 2: /* a grid line j cells below: lb's window starts there */
    case 3: {
        double j = (double)prng_range(r, -2, (1 << p->quant_bits) + 2);
        return oracle_round_d(ldexp(k - j, e), prng_below(r, 2) ? FE_DOWNWARD : FE_UPWARD);
    }
    default: { /* off the grid: within a cell near lb's */
        double j = (double)prng_range(r, -2, 2), f = (double)(prng_next(r) >> 11) * 0x1p-53;
        return oracle_round_d(ldexp(k - j + f, e), FE_DOWNWARD);
    }
    }
}

/* ---- unit 3: decoder, (a) chains of nested boxes, (b) arbitrary contexts ---- */
static void check_child(const cbvh_params *p, const cbvh_axis_ctx *ctx, cbvh_f32 lb, cbvh_f32 ub, cbvh_axis_code *c) {
    uint32_t st = cbvh_axis_compress(p, lb, ub, ctx->scale, ctx->clb, c);
    digest_code(&dg, st, c);
    n_cases++;
    if (st) {
        prop_fail("chain: child [%08x,%08x] at scale %d status %#x", lb, ub, ctx->scale, st);
        return;
    }
    if (!encloses(c, lb, ub)) prop_fail("chain: no enclosure [%08x,%08x]", lb, ub);
    if (c->child_scale > ctx->scale || ctx->scale > ctx->parent_scale || c->child_scale < p->min_scale)
        prop_fail("chain: scales parent %d scale %d child %d", ctx->parent_scale, ctx->scale, c->child_scale);
    int cs = oracle_child_scale(p->quant_bits, p->min_scale, ctx->scale, oracle_cells(lb, ub, ctx->scale));
    if (cs != c->child_scale) prop_fail("chain: Eq.2 oracle %d, model %d", cs, c->child_scale);

    /* relative codes from the oracle's grid coordinates: node lower bound at
     * the child grid is clb / 2^scale (clb is exact: a truncated float). */
    uint32_t lc[2], uc[2];
    cbvh_axis_store_codes(p, CBVH_ENC_RELATIVE, ctx, c, &lc[1], &uc[1]);
    cbvh_axis_store_codes(p, CBVH_ENC_MODULO, ctx, c, &lc[0], &uc[0]);
    double node_k = ctx->clb == CBVH_F32_NEG_INF ? -ldexp(1.0, 128 - ctx->scale) : oracle_floor(ctx->clb, ctx->scale);
    double kr = oracle_floor(lb, ctx->scale) - node_k, sr = oracle_floor(ub, ctx->scale) + 1.0 - node_k;
    if (fabs(node_k) < 0x1p52 && fabs(oracle_floor(ub, ctx->scale)) < 0x1p52) {
        double full = ldexp(1.0, p->quant_bits);
        if (!(kr >= 0 && kr < sr && sr <= full) || lc[1] != (uint32_t)kr || uc[1] != (uint32_t)fmod(sr, full))
            prop_fail("chain: relative codes %u,%u vs oracle %.0f,%.0f", lc[1], uc[1], kr, sr);
    }
    if (lc[0] != c->lb_mod || uc[0] != c->ub_mod) prop_fail("chain: modulo codes differ from compressor output");
    for (int enc = 0; enc < 2; enc++) {
        cbvh_axis_code d;
        uint32_t dst = cbvh_axis_decode(p, (cbvh_encoding)enc, ctx, lc[enc], uc[enc], &d);
        digest_code(&dg, dst, &d);
        if (dst || !code_equal(&d, c))
            prop_fail("chain: %s decode st=%#x " CODE_FMT " != compress " CODE_FMT " (N=%d ms=%d ctx %d/%d/%u/%08x)",
                      enc ? "relative" : "modulo", dst, CODE_ARGS(d), CODE_ARGS(*c), p->quant_bits, p->min_scale,
                      ctx->parent_scale, ctx->scale, ctx->lb_mod, ctx->clb);
    }
}

static void prop_decode_chains(prng *r, long iters) {
    long done = 0;
    for (long i = 0; done < iters; i++) {
        cbvh_params p = random_params(r);
        cbvh_f32 lb, ub;
        random_box(r, i, &lb, &ub);
        cbvh_axis_ctx ctx;
        uint32_t st = cbvh_axis_root_ctx(&p, lb, ub, &ctx);
        if (st) {
            prop_fail("root_ctx [%08x,%08x] status %#x", lb, ub, st);
            continue;
        }
        if (ctx.scale > ctx.parent_scale || ctx.scale < p.min_scale)
            prop_fail("root_ctx scales %d/%d min %d", ctx.parent_scale, ctx.scale, p.min_scale);
        int depth = prng_range(r, 1, 12);
        for (int d = 0; d < depth; d++, done++) {
            cbvh_f32 a = prop_point_in(r, lb, ub), b = prop_point_in(r, lb, ub);
            if (cbvh_f32_key(a) > cbvh_f32_key(b)) { cbvh_f32 t = a; a = b; b = t; }
            if (prng_below(r, 16) == 0) b = a; /* zero-width child */
            cbvh_axis_code c;
            check_child(&p, &ctx, a, b, &c);
            ctx = cbvh_axis_child_ctx(&ctx, &c);
            lb = a;
            ub = b;
        }
    }
}

/* ---- unit 2's window check, OUTSIDE (datapath.md §6) ----
 * Node/child pairs: a node box and its context (the root context, or up to
 * three levels down a chain of nested boxes); a child inside the node's box,
 * at the ends of the node's window (first and last binary32 inside, first
 * outside), across them, or anywhere.  Properties: the bit is set iff the
 * child leaves the window (FPU oracle); a child inside its node's box never
 * sets it (the builders' precondition); with the bit (and any reject) clear,
 * both encodings decode to the compressor's outputs, which enclose the
 * child. */
static cbvh_f32 dn(cbvh_f32 x) { return x == (CBVH_F32_SIGN | CBVH_F32_MAX) ? x : cbvh_f32_next_down(x); }
static cbvh_f32 upf(cbvh_f32 x) { return x == CBVH_F32_MAX ? x : cbvh_f32_next_up(x); }

/* prop_point_in for x and y in either order */
static cbvh_f32 point_between(prng *r, cbvh_f32 x, cbvh_f32 y) {
    return cbvh_f32_key(x) <= cbvh_f32_key(y) ? prop_point_in(r, x, y) : prop_point_in(r, y, x);
}

static long window_counts[3]; /* children inside the node's box, flagged OUTSIDE, decoded */

static void check_window_child(const cbvh_params *p, const cbvh_axis_ctx *ctx, cbvh_f32 a, cbvh_f32 b, int in_box) {
    cbvh_axis_code c;
    uint32_t st = cbvh_axis_compress(p, a, b, ctx->scale, ctx->clb, &c);
    digest_code(&dg, st, &c);
    n_cases++;
    int want = oracle_outside(p->quant_bits, a, b, ctx->scale, ctx->clb);
    if (st & CBVH_ST_REJECT) {
        prop_fail("window: child [%08x,%08x] rejected: %#x", a, b, st);
        return;
    }
    if (!(st & CBVH_ST_OUTSIDE) != !want)
        prop_fail("window: child [%08x,%08x] scale %d node_clb %08x N=%d: OUTSIDE %d, oracle %d", a, b, ctx->scale,
                  ctx->clb, p->quant_bits, !!(st & CBVH_ST_OUTSIDE), want);
    window_counts[0] += in_box;
    window_counts[1] += !!(st & CBVH_ST_OUTSIDE);
    if (in_box && st) prop_fail("window: child [%08x,%08x] inside its node's box: status %#x", a, b, st);
    if (st) return;
    window_counts[2]++;
    for (int enc = 0; enc < 2; enc++) {
        uint32_t lc, uc;
        cbvh_axis_code d;
        cbvh_axis_store_codes(p, (cbvh_encoding)enc, ctx, &c, &lc, &uc);
        uint32_t dst = cbvh_axis_decode(p, (cbvh_encoding)enc, ctx, lc, uc, &d);
        digest_code(&dg, dst, &d);
        if (dst || !code_equal(&d, &c) || !encloses(&d, a, b))
            prop_fail("window: %s decode of [%08x,%08x] (ctx %d/%d/%u/%08x N=%d) st=%#x " CODE_FMT " vs " CODE_FMT,
                      enc ? "relative" : "modulo", a, b, ctx->parent_scale, ctx->scale, ctx->lb_mod, ctx->clb,
                      p->quant_bits, dst, CODE_ARGS(d), CODE_ARGS(c));
    }
}

static void prop_compress_window(prng *r, long iters) {
    for (long i = 0; i < iters; i++) {
        cbvh_params p = random_params(r);
        cbvh_f32 lo, hi;
        random_box(r, i, &lo, &hi);
        cbvh_axis_ctx ctx;
        if (cbvh_axis_root_ctx(&p, lo, hi, &ctx)) {
            prop_fail("window: root_ctx [%08x,%08x]", lo, hi);
            continue;
        }
        for (int d = (int)prng_range(r, 0, 3); d > 0; d--) { /* down a chain of nested boxes */
            cbvh_f32 x = prop_point_in(r, lo, hi), y = prop_point_in(r, lo, hi);
            if (cbvh_f32_key(x) > cbvh_f32_key(y)) { cbvh_f32 t = x; x = y; y = t; }
            cbvh_axis_code c;
            cbvh_axis_compress(&p, x, y, ctx.scale, ctx.clb, &c);
            ctx = cbvh_axis_child_ctx(&ctx, &c);
            lo = x;
            hi = y;
        }
        /* the window [g, top): its first binary32, its last, the first past it */
        double g = ctx.clb == CBVH_F32_NEG_INF ? -0x1p128 : f32_as_double(ctx.clb);
        fesetround(FE_UPWARD);
        volatile double top = g + ldexp(1.0, p.quant_bits + ctx.scale);
        fesetround(FE_TONEAREST);
        cbvh_f32 first = ctx.clb == CBVH_F32_NEG_INF ? (CBVH_F32_SIGN | CBVH_F32_MAX) : ctx.clb;
        cbvh_f32 past = oracle_round_d(top, FE_UPWARD), last = past == CBVH_F32_POS_INF ? CBVH_F32_MAX : dn(past);
        if (past == CBVH_F32_POS_INF) past = CBVH_F32_MAX;
        cbvh_f32 a, b;
        int in_box = 0;
        switch (prng_below(r, 6)) {
        case 0:
        case 1: /* inside the node's box */
            a = prop_point_in(r, lo, hi), b = prop_point_in(r, lo, hi);
            in_box = 1;
            break;
        case 2: { /* at the lower end: one below, on, one above the first */
            cbvh_f32 e3[3] = {dn(first), first, upf(first)};
            a = e3[prng_below(r, 3)];
            b = point_between(r, a, prng_below(r, 2) ? last : past);
            break;
        }
        case 3: { /* at the upper end: the last inside, the first past, one further */
            cbvh_f32 e3[3] = {last, past, upf(past)};
            b = e3[prng_below(r, 3)];
            a = point_between(r, prng_below(r, 2) ? first : dn(first), b);
            break;
        }
        case 4: /* anywhere near the window */
            a = point_between(r, dn(dn(first)), upf(past)), b = point_between(r, dn(dn(first)), upf(past));
            break;
        default: random_box(r, i, &a, &b); break;
        }
        if (cbvh_f32_key(a) > cbvh_f32_key(b)) { cbvh_f32 t = a; a = b; b = t; }
        check_window_child(&p, &ctx, a, b, in_box);
    }
    printf("  (window: %ld children inside their node's box, %ld flagged OUTSIDE, %ld decoded)\n", window_counts[0],
           window_counts[1], window_counts[2]);
    if (iters >= 1000 && (window_counts[1] < iters / 10 || window_counts[2] < iters / 3))
        prop_fail("window: too few children outside (%ld) or decoded (%ld)", window_counts[1], window_counts[2]);
}

/* Decoder with arbitrary valid contexts and codes against the FPU. */
static void prop_decode_random(prng *r, long iters) {
    for (long i = 0; i < iters; i++) {
        cbvh_params p = random_params(r);
        int n = p.quant_bits;
        uint32_t mask = (1u << n) - 1u;
        cbvh_axis_ctx ctx;
        ctx.scale = prng_below(r, 2) ? p.min_scale + prng_range(r, 0, 20) : prng_range(r, p.min_scale, CBVH_SCALE_CEIL);
        if (ctx.scale > CBVH_SCALE_CEIL) ctx.scale = CBVH_SCALE_CEIL;
        int up = prng_below(r, 3) ? prng_range(r, 0, n) : prng_range(r, 0, 40);
        ctx.parent_scale = ctx.scale + up > CBVH_SCALE_CEIL ? CBVH_SCALE_CEIL : ctx.scale + up;
        ctx.lb_mod = (uint32_t)prng_next(r) & mask;
        ctx.clb = prng_below(r, 64) == 0 ? CBVH_F32_NEG_INF : prop_random_float(r);
        uint32_t lc = (uint32_t)prng_next(r) & mask, uc = (uint32_t)prng_next(r) & mask;
        cbvh_encoding enc = (cbvh_encoding)prng_below(r, 2);
        cbvh_axis_code d;
        uint32_t st = cbvh_axis_decode(&p, enc, &ctx, lc, uc, &d);
        digest_code(&dg, st, &d);
        n_cases++;

        int shift = ctx.parent_scale - ctx.scale;
        uint32_t pmod = shift >= 32 ? 0 : (uint32_t)(((uint64_t)ctx.lb_mod << shift) & mask);
        uint32_t rr = enc == CBVH_ENC_MODULO ? ((lc - pmod) & mask) : lc;
        uint32_t ss = enc == CBVH_ENC_MODULO ? ((uc - pmod) & mask) : uc;
        if (ss == 0) ss = mask + 1u;
        if (rr >= ss) {
            cbvh_axis_code z = {0, 0, 0, 0, 0};
            if (st != CBVH_ST_INVERTED || !code_equal(&d, &z)) prop_fail("decode: r>=s gives st=%#x", st);
            continue;
        }
        if (st) {
            prop_fail("decode: status %#x", st);
            continue;
        }
        long double u = ctx.clb == CBVH_F32_NEG_INF ? -ldexpl(1.0L, 128) : (long double)bf(ctx.clb);
        cbvh_axis_code o;
        o.lb_mod = (rr + pmod) & mask;
        o.ub_mod = (ss + pmod) & mask;
        o.child_scale = oracle_child_scale(n, p.min_scale, ctx.scale, (double)(ss - rr));
        /* exact sum rounded in long double, then to float, same direction */
        fesetround(FE_DOWNWARD);
        volatile long double lo = u + ldexpl((long double)rr, ctx.scale);
        volatile float flo = (float)lo;
        fesetround(FE_UPWARD);
        volatile long double hi = u + ldexpl((long double)ss, ctx.scale);
        volatile float fhi = (float)hi;
        fesetround(FE_TONEAREST);
        o.clb = fb(flo);
        o.cub = fb(fhi);
        if ((o.clb & ~CBVH_F32_SIGN) == 0) o.clb = 0;
        if ((o.cub & ~CBVH_F32_SIGN) == 0) o.cub = 0;
        if (!code_equal(&d, &o))
            prop_fail("decode ctx %d/%d/%u/%08x codes %u,%u %s N=%d: model " CODE_FMT ", oracle " CODE_FMT,
                      ctx.parent_scale, ctx.scale, ctx.lb_mod, ctx.clb, lc, uc, enc ? "rel" : "mod", n, CODE_ARGS(d),
                      CODE_ARGS(o));
    }
}

/* ---- unit 4: node-pair codec ---- */
/* Independent field reader: bit i of the node = bit (i%8) of byte i/8. */
static uint32_t read_field(const uint8_t *node, int pos, int width) {
    uint32_t v = 0;
    for (int i = 0; i < width; i++) v |= (uint32_t)((node[(pos + i) / 8] >> ((pos + i) % 8)) & 1u) << i;
    return v;
}

static void random_node_ctx(prng *r, const cbvh_params *p, cbvh_node_ctx *ctx, cbvh_f32 lo[3], cbvh_f32 hi[3]) {
    for (int a = 0; a < 3; a++) {
        random_box(r, (long)prng_below(r, 1u << 30), &lo[a], &hi[a]);
        cbvh_axis_root_ctx(p, lo[a], hi[a], &ctx->axis[a]);
        int depth = prng_range(r, 0, 3); /* sometimes a deeper context */
        for (int d = 0; d < depth; d++) {
            cbvh_f32 x = prop_point_in(r, lo[a], hi[a]), y = prop_point_in(r, lo[a], hi[a]);
            if (cbvh_f32_key(x) > cbvh_f32_key(y)) { cbvh_f32 t = x; x = y; y = t; }
            cbvh_axis_code c;
            cbvh_axis_compress(p, x, y, ctx->axis[a].scale, ctx->axis[a].clb, &c);
            ctx->axis[a] = cbvh_axis_child_ctx(&ctx->axis[a], &c);
            lo[a] = x;
            hi[a] = y;
        }
    }
}

static void prop_nodepair_roundtrip(prng *r, long iters) {
    for (long i = 0; i < iters; i++) {
        cbvh_params p = random_params(r);
        int n = p.quant_bits, w = cbvh_node_bits(n), pb = cbvh_node_ptr_bits(n);
        uint32_t ones = pb >= 32 ? 0xFFFFFFFFu : (1u << pb) - 1u;
        cbvh_node_ctx ctx;
        cbvh_f32 lo[3], hi[3];
        random_node_ctx(r, &p, &ctx, lo, hi);
        cbvh_encoding enc = (cbvh_encoding)prng_below(r, 2);
        cbvh_child_in in[2];
        memset(in, 0, sizeof in);
        for (int c = 0; c < 2; c++) {
            in[c].empty = prng_below(r, 8) == 0;
            in[c].leaf = (int)prng_below(r, 2);
            uint32_t ptrmax = in[c].leaf ? ones - 1u : ones; /* leaf: all-ones is the empty marker */
            in[c].ptr = prng_below(r, 4) == 0 ? ptrmax : (uint32_t)prng_next(r) & ptrmax;
            for (int a = 0; a < 3; a++) {
                cbvh_f32 x = prop_point_in(r, lo[a], hi[a]), y = prop_point_in(r, lo[a], hi[a]);
                if (cbvh_f32_key(x) > cbvh_f32_key(y)) { cbvh_f32 t = x; x = y; y = t; }
                in[c].lo[a] = x;
                in[c].hi[a] = y;
            }
        }
        uint8_t bytes[24];
        cbvh_child_out eo[2], dout[2];
        uint32_t st = cbvh_nodepair_encode(&p, enc, &ctx, in, bytes, eo);
        size_t nb = cbvh_nodepair_bytes(n);
        for (size_t b = 0; b < nb; b++) digest_u32(&dg, bytes[b]);
        digest_u32(&dg, st);
        n_cases++;
        if (st) {
            prop_fail("nodepair encode status %#x", st);
            continue;
        }
        uint32_t dst = cbvh_nodepair_decode(&p, enc, &ctx, bytes, dout);
        digest_u32(&dg, dst);
        if (dst) prop_fail("nodepair decode status %#x", dst);
        for (int c = 0; c < 2; c++) {
            const uint8_t *node = bytes + c * w / 8;
            if (dout[c].empty != in[c].empty || dout[c].leaf != (in[c].empty ? 1 : in[c].leaf) ||
                dout[c].ptr != (in[c].empty ? ones : in[c].ptr))
                prop_fail("nodepair: child %d flags/pointer not preserved", c);
            if (read_field(node, 6 * n, 1) != (uint32_t)dout[c].leaf || read_field(node, 6 * n + 1, pb) != dout[c].ptr)
                prop_fail("nodepair: leaf/pointer not at bits 6N / 6N+1");
            for (int pos = 6 * n + 1 + pb; pos < w; pos++)
                if (read_field(node, pos, 1)) prop_fail("nodepair: reserved bit %d set by encoder", pos);
            if (in[c].empty) {
                if (read_field(node, 0, 6 * n > 32 ? 32 : 6 * n) || (6 * n > 32 && read_field(node, 32, 6 * n - 32)))
                    prop_fail("nodepair: empty child has non-zero codes");
                continue;
            }
            for (int a = 0; a < 3; a++) {
                uint32_t lc, uc;
                cbvh_axis_store_codes(&p, enc, &ctx.axis[a], &eo[c].axis[a], &lc, &uc);
                if (read_field(node, 2 * a * n, n) != lc || read_field(node, 2 * a * n + n, n) != uc)
                    prop_fail("nodepair: codes of axis %d not at their bits", a);
                if (!code_equal(&dout[c].axis[a], &eo[c].axis[a]))
                    prop_fail("nodepair: decoded axis %d " CODE_FMT " != encoded " CODE_FMT, a,
                              CODE_ARGS(dout[c].axis[a]), CODE_ARGS(eo[c].axis[a]));
                if (!encloses(&dout[c].axis[a], in[c].lo[a], in[c].hi[a])) prop_fail("nodepair: no enclosure");
            }
        }
    }
}

/* Random bytes: never crash; reserved bits and malformed empties flagged;
 * every output zero on a reject. */
static void prop_nodepair_random_bytes(prng *r, long iters) {
    for (long i = 0; i < iters; i++) {
        cbvh_params p = random_params(r);
        int n = p.quant_bits, w = cbvh_node_bits(n), pb = cbvh_node_ptr_bits(n);
        uint32_t ones = pb >= 32 ? 0xFFFFFFFFu : (1u << pb) - 1u;
        cbvh_node_ctx ctx;
        cbvh_f32 lo[3], hi[3];
        random_node_ctx(r, &p, &ctx, lo, hi);
        uint8_t bytes[24];
        for (int b = 0; b < 24; b++) bytes[b] = (uint8_t)prng_next(r);
        int mode = (int)prng_below(r, 4);
        int expect_bad = 0;
        for (int c = 0; c < 2; c++) {
            uint8_t *node = bytes + c * w / 8;
            if (mode >= 1) /* mostly clear the reserved bits */
                for (int pos = 6 * n + 1 + pb; pos < w; pos++) node[pos / 8] &= (uint8_t)~(1u << (pos % 8));
            if (mode == 2 && prng_below(r, 2)) { /* an empty marker, maybe with stray codes */
                for (int pos = 6 * n; pos < 6 * n + 1 + pb; pos++) node[pos / 8] |= (uint8_t)(1u << (pos % 8));
                if (prng_below(r, 2))
                    for (int pos = 0; pos < 6 * n; pos++) node[pos / 8] &= (uint8_t)~(1u << (pos % 8));
            }
            for (int pos = 6 * n + 1 + pb; pos < w; pos++)
                if (read_field(node, pos, 1)) expect_bad = 1;
            if (read_field(node, 6 * n, 1) && read_field(node, 6 * n + 1, pb) == ones)
                for (int f = 0; f < 6; f++)
                    if (read_field(node, f * n, n)) expect_bad = 1;
        }
        cbvh_encoding enc = (cbvh_encoding)prng_below(r, 2);
        cbvh_child_out out[2];
        uint32_t st = cbvh_nodepair_decode(&p, enc, &ctx, bytes, out);
        digest_u32(&dg, st);
        for (int c = 0; c < 2; c++)
            for (int a = 0; a < 3; a++) digest_code(&dg, 0, &out[c].axis[a]);
        n_cases++;
        if (!!(st & CBVH_ST_BAD_FORMAT) != expect_bad)
            prop_fail("nodepair random bytes: BAD_FORMAT=%d expected %d (N=%d)", !!(st & CBVH_ST_BAD_FORMAT), expect_bad,
                      n);
        if (st & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) {
            static const cbvh_child_out zero[2];
            if (memcmp(out, zero, sizeof zero) != 0) prop_fail("nodepair random bytes: outputs not zero on reject");
        }
    }
}

/* ---- fp32 helpers against the FPU ---- */
static const int fe_modes[2] = {FE_DOWNWARD, FE_UPWARD};

static cbvh_f32 ld_to_f32(long double v, int mode) {
    fesetround(mode);
    volatile long double vv = v;
    volatile float f = (float)vv;
    fesetround(FE_TONEAREST);
    cbvh_f32 b = fb(f);
    return (b & ~CBVH_F32_SIGN) == 0 ? 0u : b;
}

static uint64_t random_mag(prng *r) {
    int bits = prng_range(r, 0, 64);
    uint64_t m = prng_next(r);
    if (prng_below(r, 4) == 0) m = ~UINT64_C(0); /* all ones: carries */
    if (prng_below(r, 4) == 0) m = UINT64_C(1) << 63;
    return bits == 64 ? m : bits == 0 ? 0 : (m & ((UINT64_C(1) << bits) - 1)) | (UINT64_C(1) << (bits - 1));
}

static void prop_fp32(prng *r, long iters) {
    for (long i = 0; i < iters; i++) {
        int mode = (int)prng_below(r, 2), neg = (int)prng_below(r, 2);
        /* pack */
        uint64_t mag = random_mag(r);
        int exp = prng_range(r, -230, 140);
        cbvh_f32 got = cbvh_f32_pack(neg, mag, exp, (cbvh_rnd)mode);
        long double v = ldexpl((long double)mag, exp); /* exact: 64-bit significand */
        cbvh_f32 want = ld_to_f32(neg ? -v : v, fe_modes[mode]);
        digest_u32(&dg, got);
        if (got != want) prop_fail("pack(%d,%#llx,%d,%d) = %08x, FPU %08x", neg, (unsigned long long)mag, exp, mode, got, want);

        /* add_dyadic: |a|,|b| < 2^25 */
        int64_t a = (int64_t)(random_mag(r) >> prng_range(r, 39, 63));
        int64_t b = (int64_t)(random_mag(r) >> prng_range(r, 39, 63));
        if (prng_below(r, 2)) a = -a;
        if (prng_below(r, 2)) b = -b;
        int ea = prng_range(r, -200, 130), eb;
        switch (prng_below(r, 3)) {
        case 0: eb = ea + prng_range(r, -30, 30); break;
        case 1: /* near cancellation */
            eb = ea;
            b = -a + prng_range(r, -3, 3);
            if (b >= (INT64_C(1) << 25) || b <= -(INT64_C(1) << 25)) b = -a;
            break;
        default: eb = prng_range(r, -200, 130); break;
        }
        got = cbvh_f32_add_dyadic(a, ea, b, eb, (cbvh_rnd)mode);
        fesetround(fe_modes[mode]);
        volatile long double s = ldexpl((long double)a, ea) + ldexpl((long double)b, eb);
        fesetround(FE_TONEAREST);
        want = ld_to_f32(s, fe_modes[mode]);
        digest_u32(&dg, got);
        n_cases++;
        if (got != want)
            prop_fail("add_dyadic(%lld,%d,%lld,%d,%d) = %08x, FPU %08x", (long long)a, ea, (long long)b, eb, mode, got, want);

        /* cmp / next_up / next_down */
        cbvh_f32 x = prop_random_float(r), y = prng_below(r, 4) ? prop_random_float(r) : x ^ (prng_below(r, 2) << 31);
        float fx = bf(x), fy = bf(y);
        int c = cbvh_f32_cmp(x, y);
        digest_u32(&dg, (uint32_t)c);
        if (c != ((fx > fy) - (fx < fy))) prop_fail("cmp(%08x,%08x) = %d", x, y, c);
        /* bit patterns, not float values (where -0 == +0): a zero result is +0
         * by the header's rule, where the FPU gives -0 from the negative side */
        cbvh_f32 nu = cbvh_f32_next_up(x), nd = cbvh_f32_next_down(x);
        cbvh_f32 wu = fb(nextafterf(fx, INFINITY)), wd = fb(nextafterf(fx, -INFINITY));
        if (wu == CBVH_F32_SIGN) wu = 0;
        if (wd == CBVH_F32_SIGN) wd = 0;
        if (nu != wu || nd != wd) prop_fail("next_up/down(%08x) = %08x/%08x, FPU (zero as +0) %08x/%08x", x, nu, nd, wu, wd);
    }
    /* the steps across zero and the ends of the range, which random floats rarely are */
    static const cbvh_f32 edge[] = {0x80000001u, 0x00000001u, 0x00000000u, 0x80000000u, 0x007FFFFFu,
                                    0x807FFFFFu, 0x00800000u, 0x80800000u, 0x7F7FFFFEu, 0xFF7FFFFEu};
    for (size_t i = 0; i < sizeof edge / sizeof edge[0]; i++) {
        float fx = bf(edge[i]);
        cbvh_f32 wu = fb(nextafterf(fx, INFINITY)), wd = fb(nextafterf(fx, -INFINITY));
        if (wu == CBVH_F32_SIGN) wu = 0;
        if (wd == CBVH_F32_SIGN) wd = 0;
        if (cbvh_f32_next_up(edge[i]) != wu || cbvh_f32_next_down(edge[i]) != wd)
            prop_fail("next_up/down(%08x) = %08x/%08x, FPU (zero as +0) %08x/%08x", edge[i], cbvh_f32_next_up(edge[i]),
                      cbvh_f32_next_down(edge[i]), wu, wd);
    }
}

int main(int argc, char **argv) {
    double scale = 1.0;
    uint64_t seed = 20261122;
    const char *digest_out = NULL;
    static const struct option opts[] = {{"scale", required_argument, 0, 's'},
                                         {"seed", required_argument, 0, 'S'},
                                         {"digest-out", required_argument, 0, 'o'},
                                         {0, 0, 0, 0}};
    int ch;
    while ((ch = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        char *end;
        switch (ch) {
        case 's':
            scale = strtod(optarg, &end);
            if (*end || !(scale > 0)) { fprintf(stderr, "error: --scale needs a positive number\n"); return 2; }
            break;
        case 'S':
            seed = strtoull(optarg, &end, 0);
            if (*end) { fprintf(stderr, "error: --seed needs an integer\n"); return 2; }
            break;
        case 'o': digest_out = optarg; break;
        default: fprintf(stderr, "usage: %s [--scale F] [--seed S] [--digest-out FILE]\n", argv[0]); return 2;
        }
    }
    if (digest_out) remove(digest_out); /* never leave a stale digest behind */
    long m = (long)(1000000 * scale);
    digest_init(&dg);
    struct {
        const char *name;
        void (*fn)(prng *, long);
        long iters;
    } units[] = {
        {"scale_estimate", prop_scale_estimate, m},
        {"axis_compress", prop_compress, m},
        {"axis_compress window (OUTSIDE) and decode", prop_compress_window, m},
        {"axis_decode chains (compress == modulo == relative)", prop_decode_chains, m},
        {"axis_decode vs FPU", prop_decode_random, m},
        {"nodepair round trip", prop_nodepair_roundtrip, m / 2},
        {"nodepair random bytes", prop_nodepair_random_bytes, m / 2},
        {"fp32 pack/add_dyadic/cmp vs FPU", prop_fp32, m},
    };
    for (size_t u = 0; u < sizeof units / sizeof units[0]; u++) {
        prng r = {seed + u};
        long before = n_cases, fails = prop_failures;
        units[u].fn(&r, units[u].iters);
        printf("  %-52s %8ld cases  %ld failures\n", units[u].name, n_cases - before, prop_failures - fails);
    }
    return prop_finish("properties", &dg, n_cases, digest_out);
}
