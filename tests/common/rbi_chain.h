/* Chains of boxes for the incremental ray-box unit (unit 10, docs/traversal.md
 * §17): a ray, a root grid box, and a walk down a CBVH-like hierarchy in which
 * every node has two children on its child grid (Eq. 2 child scales,
 * minimum-scale clamp, relative codes r, s and s' = S - s from the node's
 * upper plane).  Each child is tested by the incremental unit (with the
 * node's plane distances, which the walk carries as a traversal would) and by
 * the exact unit at M = 24 on the same exact planes; the walk then descends
 * into a child the incremental unit hits, as a traversal does.
 *
 * Shared by tests/traversal/test_ray_box_incr.c (conservativeness on 10^8
 * children, every structured kind) and bench/bench_box_incr.c (false
 * positives and looseness per N and M).  Header-only; binary64 is used only
 * to aim children at the ray, never to decide a result. */
#ifndef CBVH_RBI_CHAIN_H
#define CBVH_RBI_CHAIN_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "cbvh/ray_box_incr.h"
#include "test_util.h"

/* Structured kinds of chains (docs/traversal.md §17.6). */
enum {
    RBI_SCENE = 0,     /* scene-like: root near the origin, rays from outside and inside */
    RBI_AXIS,          /* one or two direction components +-0 */
    RBI_SUBNORMAL,     /* subnormal and tiny direction components */
    RBI_HUGE_DIR,      /* direction components up to 2^127 (reciprocal 0 above 2^126) */
    RBI_ON_PLANE,      /* origin exactly on a grid plane of the root */
    RBI_FAR,           /* tiny boxes far from the origin (2^20 .. 2^40) */
    RBI_MIN_SCALE,     /* minimum scale just below the root's: saturated child scales */
    RBI_EDGE_128,      /* the 2^+-128 edges: -2^128 lower planes, distances overflowing and underflowing */
    RBI_LONG,          /* chains of up to 200 levels, one bit of scale per level */
    RBI_KINDS
};
static const char *const rbi_kind_names[RBI_KINDS] = {"scene", "axis-parallel", "subnormal-dir", "huge-dir",
                                                      "origin-on-plane", "far-tiny", "min-scale", "edge-2^128",
                                                      "long-chain"};

#define RBI_MAX_DEPTH 200

typedef struct {
    cbvh_grid_axis g[3];  /* the child for the exact unit: node lower plane u, scale e, r, s */
    cbvh_rbi_axis ax[3];  /* the same child for the incremental unit: e, r, s' = S - s */
    cbvh_rbi_result inc;  /* incremental unit */
    uint32_t inc_st;
    cbvh_box_result ex;   /* exact unit, M = 24 */
    uint32_t ex_st;
} rbi_child;

typedef struct {
    cbvh_rbi_params p;
    int kind, min_scale, depth;
    cbvh_ray ray;
    cbvh_rbi_ray rr;
    /* the current node: lower plane u (a binary32; -Inf is -2^128), child
     * grid e, upper plane u + S 2^e, and its plane distances */
    cbvh_f32 u[3];
    int e[3];
    uint32_t S[3];
    cbvh_rbi_planes T;
    double t_aim; /* a ray parameter inside the node, for aiming children */
    uint64_t *rng;
} rbi_chain;

static inline uint64_t rbi_below(rbi_chain *c, uint64_t n) { return tu_xorshift64(c->rng) % n; }
static inline int rbi_ceil_log2(uint32_t x) {
    int k = 0;
    while ((UINT32_C(1) << k) < x) k++;
    return k;
}
static inline cbvh_f32 rbi_f32(double x) { return cbvh_f32_of((float)x); }
static inline cbvh_f32 rbi_pow2(int sign, int k) { /* +-2^k, k in [-149, 127] */
    uint32_t s = sign ? CBVH_F32_SIGN : 0u;
    return k >= -126 ? s | (uint32_t)(k + 127) << 23 : s | (UINT32_C(1) << (k + 149));
}
/* A random direction component: scene-like, or of the chain's kind. */
static inline cbvh_f32 rbi_dir(rbi_chain *c) {
    double v = tu_unit_d(c->rng) * 2.0 - 1.0;
    if (fabs(v) < 1e-3) v = v < 0 ? -0.25 : 0.25;
    cbvh_f32 d = rbi_f32(v);
    uint32_t sign = (tu_xorshift64(c->rng) & 1) ? CBVH_F32_SIGN : 0u;
    switch (c->kind) {
    case RBI_SUBNORMAL:
        if (rbi_below(c, 3) == 0) return sign | (uint32_t)(1 + rbi_below(c, 0x7FFFFF)); /* subnormal */
        if (rbi_below(c, 3) == 0) return rbi_pow2((int)(sign >> 31), -149 + (int)rbi_below(c, 40));
        break;
    case RBI_HUGE_DIR:
        if (rbi_below(c, 2) == 0)
            return sign | (uint32_t)(100 + 127 + rbi_below(c, 28)) << 23 | (uint32_t)(tu_xorshift64(c->rng) & CBVH_F32_FRAC);
        break;
    case RBI_EDGE_128:
        if (rbi_below(c, 3) == 0) return rbi_pow2((int)(sign >> 31), -149 + (int)rbi_below(c, 30));
        if (rbi_below(c, 3) == 0) return rbi_pow2((int)(sign >> 31), 100 + (int)rbi_below(c, 28));
        break;
    default:
        break;
    }
    return d;
}

/* The exact value u + k 2^e as a binary32, if it is one (1), else 0. */
static inline int rbi_plane_f32(cbvh_f32 u, int e, uint32_t k, cbvh_f32 *out) {
    if (u == CBVH_F32_NEG_INF) {
        if (k == 0) {
            *out = u;
            return 1;
        }
        return 0;
    }
    int s, ex;
    uint32_t sig;
    cbvh_f32_break(u, &s, &sig, &ex);
    int64_t a = s ? -(int64_t)sig : (int64_t)sig;
    cbvh_f32 dn = cbvh_f32_add_dyadic(a, ex, (int64_t)k, e, CBVH_RND_DOWN);
    cbvh_f32 up = cbvh_f32_add_dyadic(a, ex, (int64_t)k, e, CBVH_RND_UP);
    if (dn != up || cbvh_f32_is_nan_or_inf(dn)) return 0;
    *out = dn;
    return 1;
}

/* The value (-1)^neg q 2^(E-M+1) of F(M, X) as a binary32 (2^(M-1) <= q < 2^M). */
static inline cbvh_f32 rbi_pack(int neg, int E, uint64_t q, int M) {
    return (neg ? CBVH_F32_SIGN : 0u) | (uint32_t)(E + 127) << 23 | ((uint32_t)q << (24 - M) & CBVH_F32_FRAC);
}

/* A random binary32: 0, subnormal, moderate or any normal exponent (no NaN or Inf). */
static inline cbvh_f32 rbi_rand_f32(uint64_t *rng) {
    uint64_t k = tu_xorshift64(rng) % 10;
    uint32_t sign = (tu_xorshift64(rng) & 1) ? CBVH_F32_SIGN : 0u;
    if (k == 0) return sign;
    if (k == 1) return sign | (uint32_t)(1 + tu_xorshift64(rng) % 0x7FFFFF);
    int E = k <= 6 ? (int)(tu_xorshift64(rng) % 21) - 10 : (int)(tu_xorshift64(rng) % 254) - 126;
    return sign | (uint32_t)(E + 127) << 23 | (uint32_t)(tu_xorshift64(rng) & CBVH_F32_FRAC);
}

/* A random value of F(M, X) near 2^near_exp: mostly normal, sometimes 0, +-Inf, the extremes. */
static inline cbvh_f32 rbi_rand_fmt(uint64_t *rng, int M, int X, int near_exp) {
    int emax = cbvh_rbi_emax(X), emin = cbvh_rbi_emin(X);
    uint64_t k = tu_xorshift64(rng) % 32;
    int neg = (int)(tu_xorshift64(rng) & 1);
    if (k == 0) return neg ? CBVH_F32_SIGN : 0u;
    if (k == 1) return neg ? CBVH_F32_NEG_INF : CBVH_F32_POS_INF;
    int E = k == 2 ? emax : k == 3 ? emin : near_exp + (int)(tu_xorshift64(rng) % 9) - 4;
    if (tu_xorshift64(rng) % 4 == 0) E = emin + (int)(tu_xorshift64(rng) % (uint64_t)(emax - emin + 1));
    E = E > emax ? emax : E < emin ? emin : E;
    uint64_t q = (UINT64_C(1) << (M - 1)) | (tu_xorshift64(rng) & ((UINT64_C(1) << (M - 1)) - 1));
    if (tu_xorshift64(rng) % 8 == 0) q = UINT64_C(1) << (M - 1);
    if (tu_xorshift64(rng) % 8 == 0) q = (UINT64_C(1) << M) - 1;
    return rbi_pack(neg, E, q, M);
}

/* Random valid inputs of the unit at design point p: half of them shaped to
 * hit (near distances of either sign below positive far ones, increments a
 * few bits below the distances: cancellations and carries), half wild
 * (distances anywhere in F, +-0, +-Inf, any scale); reciprocals of random
 * directions, sometimes +-0. */
static inline void rbi_random_inputs(uint64_t *rng, const cbvh_rbi_params *p, cbvh_rbi_ray *ray, cbvh_rbi_planes *par,
                                     cbvh_rbi_axis ch[3]) {
    int M = p->mant, X = p->texp, rexp[3];
    for (int a = 0; a < 3; a++) {
        cbvh_f32 d = tu_xorshift64(rng) % 8 == 0 ? rbi_rand_f32(rng) : rbi_f32(tu_unit_d(rng) * 2 - 1);
        cbvh_rbi_reciprocal(d, M, &ray->rcp[a]);
        if (tu_xorshift64(rng) % 16 == 0) ray->rcp[a] = (tu_xorshift64(rng) & 1) ? CBVH_F32_SIGN : 0u;
        rexp[a] = cbvh_f32_is_zero(ray->rcp[a]) ? 0 : (int)((ray->rcp[a] >> 23) & 0xFF) - 127;
    }
    int te = (int)(tu_xorshift64(rng) % 40) - 20, shaped = (tu_xorshift64(rng) & 1) != 0;
    ray->tmin = tu_xorshift64(rng) % 4 ? 0u : rbi_rand_f32(rng);
    ray->tmax = tu_xorshift64(rng) % 2 ? CBVH_F32_POS_INF : rbi_rand_f32(rng) & ~CBVH_F32_SIGN;
    if (shaped && tu_xorshift64(rng) % 4) ray->tmin = 0, ray->tmax = CBVH_F32_POS_INF;
    for (int a = 0; a < 3; a++) {
        cbvh_f32 n = rbi_rand_fmt(rng, M, X, te), f = rbi_rand_fmt(rng, M, X, te + (int)(tu_xorshift64(rng) % 3));
        if (shaped) {
            int emax = cbvh_rbi_emax(X), emin = cbvh_rbi_emin(X), ts = te;
            ts = ts > emax - 4 ? emax - 4 : ts;
            ts = ts < emin + 4 ? emin + 4 : ts;
            uint64_t qm = (UINT64_C(1) << (M - 1)) - 1;
            int En = ts - 1 - (int)(tu_xorshift64(rng) % 3), Ef = ts + 1 + (int)(tu_xorshift64(rng) % 3);
            En = En < emin ? emin : En > emax ? emax : En;
            Ef = Ef < emin ? emin : Ef > emax ? emax : Ef;
            n = rbi_pack(tu_xorshift64(rng) % 4 == 0, En, (qm + 1) | (tu_xorshift64(rng) & qm), M);
            f = rbi_pack(0, Ef, (qm + 1) | (tu_xorshift64(rng) & qm), M);
        }
        int neg = (ray->rcp[a] >> 31) != 0;
        par->t_lb[a] = neg ? f : n;
        par->t_ub[a] = neg ? n : f;
        uint32_t lim = UINT32_C(1) << p->quant_bits;
        ch[a].r = (uint32_t)(tu_xorshift64(rng) % lim);
        ch[a].sp = (uint32_t)(tu_xorshift64(rng) % (lim - ch[a].r));
        int e = te - rexp[a] - (int)(tu_xorshift64(rng) % (uint64_t)(p->quant_bits + 4)) + (int)(tu_xorshift64(rng) % 6);
        if (shaped) e = te - rexp[a] - p->quant_bits - 3 + (int)(tu_xorshift64(rng) % 4);
        if (tu_xorshift64(rng) % 8 == 0) e = (int)(tu_xorshift64(rng) % 253) - 126;
        ch[a].e = e < -126 ? -126 : e > 126 ? 126 : e;
    }
}

/* Starts a chain: a ray and a root box of the given kind, and the root's
 * plane distances (cbvh_rbi_anchor).  Returns 0, or -1 if the unit rejects
 * the ray (never for the kinds above). */
static inline int rbi_chain_start(rbi_chain *c, const cbvh_rbi_params *p, uint64_t *rng, int kind) {
    memset(c, 0, sizeof *c);
    c->p = *p;
    c->kind = kind;
    c->rng = rng;
    int N = p->quant_bits;
    c->min_scale = -30;
    if (kind == RBI_LONG || kind == RBI_EDGE_128 || rbi_below(c, 8) == 0) c->min_scale = -126;
    double centre[3], half = 1.0;
    int ms_set = 0;
    for (int a = 0; a < 3; a++) {
        int e;
        double lo;
        switch (kind) {
        case RBI_FAR:
            e = -12 + (int)rbi_below(c, 8);
            lo = ldexp(1.0, 20 + (int)rbi_below(c, 21)) * (rbi_below(c, 2) ? 1 : -1);
            break;
        case RBI_EDGE_128:
            e = 100 + (int)rbi_below(c, 27 - (N > 6 ? N - 6 : 0));
            lo = rbi_below(c, 2) ? -INFINITY : -ldexp(1.0, 127);
            break;
        case RBI_LONG:
            e = 10 + (int)rbi_below(c, 30);
            lo = -ldexp(1.0, e + N - 1) * tu_unit_d(c->rng);
            break;
        default:
            e = -3 + (int)rbi_below(c, 8);
            lo = tu_unit_d(c->rng) * 128.0 - 64.0;
            break;
        }
        if (kind == RBI_MIN_SCALE) { /* just below the finest root scale */
            int cand = e - 1 - (int)rbi_below(c, 3);
            if (!ms_set || cand < c->min_scale) c->min_scale = cand;
            ms_set = 1;
        }
        if (c->min_scale > e) c->min_scale = e;
        c->u[a] = isinf(lo) ? CBVH_F32_NEG_INF : rbi_f32(ldexp(floor(ldexp(lo, -e)), e));
        c->e[a] = e;
        c->S[a] = (UINT32_C(1) << (N - 1)) + 1u + (uint32_t)rbi_below(c, UINT32_C(1) << (N - 1));
        double ud = c->u[a] == CBVH_F32_NEG_INF ? -ldexp(1.0, 128) : (double)cbvh_float_of(c->u[a]);
        centre[a] = ud + ldexp((double)c->S[a], e) * (0.2 + 0.6 * tu_unit_d(c->rng));
        /* long chains aim near 0, where the planes of every level stay binary32 values */
        if (kind == RBI_LONG) centre[a] = ldexp(tu_unit_d(c->rng) - 0.5, -100);
        half = fmax(half, ldexp((double)c->S[a], e));
    }
    /* the ray: aimed at a point inside the root (3 in 4), else random */
    int aim = rbi_below(c, 4) != 0;
    double dmax = 1e-300;
    for (int a = 0; a < 3; a++) {
        c->ray.d[a] = rbi_dir(c);
        dmax = fmax(dmax, fabs((double)cbvh_float_of(c->ray.d[a])));
    }
    double t0 = (0.5 + 2.0 * tu_unit_d(c->rng)) * half / dmax; /* o = aim point - t0 d */
    for (int a = 0; a < 3; a++) {
        double o = centre[a] + (tu_unit_d(c->rng) * 4.0 - 2.0) * half;
        if (aim) o = centre[a] - (double)cbvh_float_of(c->ray.d[a]) * t0;
        if (!isfinite(o)) o = centre[a];
        o = fmax(fmin(o, 3.0e38), -3.0e38);
        c->ray.o[a] = rbi_f32(o);
    }
    if (kind == RBI_AXIS) {
        int a0 = (int)rbi_below(c, 3);
        c->ray.d[a0] = rbi_below(c, 2) ? CBVH_F32_SIGN : 0u;
        if (rbi_below(c, 2)) c->ray.d[(a0 + 1) % 3] = rbi_below(c, 2) ? CBVH_F32_SIGN : 0u;
        if (rbi_below(c, 4) == 0) c->ray.o[a0] = c->u[a0] == CBVH_F32_NEG_INF ? c->ray.o[a0] : c->u[a0];
    }
    if (kind == RBI_ON_PLANE) {
        int a0 = (int)rbi_below(c, 3);
        cbvh_f32 pl;
        if (rbi_plane_f32(c->u[a0], c->e[a0], (uint32_t)rbi_below(c, c->S[a0] + 1), &pl)) c->ray.o[a0] = pl;
    }
    if (cbvh_f32_is_zero(c->ray.d[0]) && cbvh_f32_is_zero(c->ray.d[1]) && cbvh_f32_is_zero(c->ray.d[2]))
        c->ray.d[2] = rbi_f32(0.5);
    c->ray.tmin = 0;
    c->ray.tmax = CBVH_F32_POS_INF;
    uint64_t tk = rbi_below(c, 16);
    half = fmin(half, 1e37);
    if (tk == 0) c->ray.tmin = rbi_f32(-tu_unit_d(c->rng) * half);
    if (tk == 1) c->ray.tmax = rbi_f32(tu_unit_d(c->rng) * 4.0 * half);
    if (tk == 2) c->ray.tmin = rbi_f32(tu_unit_d(c->rng) * half);
    if (tk == 3) c->ray.tmin = rbi_pow2(rbi_below(c, 2), -149); /* +-2^-149 */
    if (cbvh_rbi_ray_setup(&c->ray, p, &c->rr)) return -1;
    cbvh_grid_axis root[3];
    for (int a = 0; a < 3; a++) root[a] = (cbvh_grid_axis){c->u[a], c->e[a], 0, c->S[a]};
    if (cbvh_rbi_anchor(&c->ray, p, root, &c->T)) return -1;
    cbvh_box_result ex;
    cbvh_ray_box(&c->ray, 24, root, &ex);
    c->t_aim = ex.hit ? 0.5 * ((double)cbvh_float_of(ex.t_near) + fmin((double)cbvh_float_of(ex.t_far), 1e30))
                      : tu_unit_d(c->rng) * half;
    return 0;
}

/* Codes of a child of the current node on axis a: aimed at the ray point
 * at t_aim (aim = 1) or random; cells log-spread, mostly large as in real
 * trees (a child is often half its parent). */
static inline void rbi_codes(rbi_chain *c, int a, int aim, uint32_t *r, uint32_t *s) {
    uint32_t S = c->S[a], cells;
    uint64_t k = rbi_below(c, 8);
    if (c->kind == RBI_LONG) cells = S / 2 + 1 + (uint32_t)rbi_below(c, S - S / 2);
    else if (k < 4) cells = (S + 1) / 2 + (uint32_t)rbi_below(c, S - (S + 1) / 2 + 1);
    else if (k < 6) cells = 1 + (uint32_t)rbi_below(c, S);
    else cells = 1 + (uint32_t)rbi_below(c, S < 4 ? S : 4);
    uint32_t lo = (uint32_t)rbi_below(c, S - cells + 1);
    if (aim && c->u[a] != CBVH_F32_NEG_INF) {
        double x = ((double)cbvh_float_of(c->ray.o[a]) + c->t_aim * (double)cbvh_float_of(c->ray.d[a]) -
                    (double)cbvh_float_of(c->u[a])) / ldexp(1.0, c->e[a]);
        if (x >= 0 && x < (double)S) {
            uint32_t idx = (uint32_t)x, rmin = idx + 1 >= cells ? idx + 1 - cells : 0;
            uint32_t rmax = idx < S - cells ? idx : S - cells;
            lo = rmin + (uint32_t)rbi_below(c, rmax - rmin + 1);
        }
    }
    if ((c->kind == RBI_FAR || c->kind == RBI_EDGE_128) && rbi_below(c, 2)) lo = 0; /* keeps u representable */
    *r = lo;
    *s = lo + cells;
}

/* One level: two children of the current node, each tested by both units,
 * then the walk descends into one the incremental unit hits (an exact hit
 * when there is one, 3 times in 4).  Returns 1 while the chain goes on, 0
 * when it ends (no child hit, or depth RBI_MAX_DEPTH). */
static inline int rbi_chain_step(rbi_chain *c, rbi_child ch[2]) {
    int N = c->p.quant_bits;
    for (int k = 0; k < 2; k++) {
        rbi_child *x = &ch[k];
        for (int a = 0; a < 3; a++) {
            uint32_t r, s;
            rbi_codes(c, a, k == 0, &r, &s);
            x->g[a] = (cbvh_grid_axis){c->u[a], c->e[a], r, s};
            x->ax[a] = (cbvh_rbi_axis){c->e[a], r, c->S[a] - s};
        }
        x->inc_st = cbvh_ray_box_incr(&c->p, &c->rr, &c->T, x->ax, &x->inc);
        x->ex_st = cbvh_ray_box(&c->ray, 24, x->g, &x->ex);
    }
    c->depth++;
    if (c->depth >= RBI_MAX_DEPTH) return 0;
    if (c->S[0] <= 1 && c->S[1] <= 1 && c->S[2] <= 1) return 0; /* one cell on every axis: a leaf */
    int pick = -1;
    for (int k = 0; k < 2; k++)
        if (ch[k].inc.hit && (pick < 0 || (ch[k].ex.hit && !ch[pick].ex.hit && rbi_below(c, 4) != 0))) pick = k;
    if (pick < 0) return 0;
    rbi_child *x = &ch[pick];
    for (int a = 0; a < 3; a++) {
        cbvh_f32 lc;
        if (!rbi_plane_f32(c->u[a], c->e[a], x->g[a].r, &lc)) return 0; /* the child's lower plane is not a binary32 */
        uint32_t cells = x->g[a].s - x->g[a].r;
        int ec = c->e[a] - N + rbi_ceil_log2(cells);
        if (ec < c->min_scale) ec = c->min_scale;
        c->u[a] = lc;
        c->S[a] = cells << (c->e[a] - ec);
        c->e[a] = ec;
    }
    c->T = x->inc.planes;
    if (x->ex.hit)
        c->t_aim = 0.5 * ((double)cbvh_float_of(x->ex.t_near) + fmin((double)cbvh_float_of(x->ex.t_far), 1e30));
    return 1;
}

#endif
