/* The incremental ray-box unit (unit 10, docs/traversal.md §17).
 *
 *   test_ray_box_incr cases            named values, formats, every reject
 *   test_ray_box_incr oracle [COUNT]   the unit, the reciprocal and the anchor
 *                                      bit for bit against a GMP oracle
 *                                      (exact rationals, an independent RND_F)
 *   test_ray_box_incr chains [COUNT]   conservativeness: COUNT children
 *                                      (default 10^8) of chains of every
 *                                      structured kind (rbi_chain.h), each
 *                                      against the exact unit at M = 24: it
 *                                      hits whenever the exact unit hits, and
 *                                      its [t_near, t_far] contains the exact
 *                                      unit's; every 64th child also plane by
 *                                      plane against the exact quotients
 *
 * Exit status 1 on any failure. */
#include <gmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbvh/ray_box_incr.h"
#include "rbi_chain.h"
#include "test_util.h"
#include "fast/rbi_fast.h"
#include "units/exact_wide.h"

static long fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

static uint64_t rs = 0x5EED0000CB7C0010u;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static uint64_t below(uint64_t n) { return rnd() % n; }

static const int MS[5] = {6, 8, 12, 16, 24};

/* ---- exact rationals ---------------------------------------------------- */
static void q_pow2(mpq_t q, int k) {
    mpq_set_ui(q, 1, 1);
    if (k > 0) mpq_mul_2exp(q, q, (unsigned)k);
    else if (k < 0) mpq_div_2exp(q, q, (unsigned)-k);
}
static void q_f32(mpq_t q, cbvh_f32 f) {
    int s, e;
    uint32_t sig;
    cbvh_f32_break(f, &s, &sig, &e);
    mpq_t p;
    mpq_init(p);
    q_pow2(p, e);
    mpq_set_ui(q, sig, 1);
    mpq_mul(q, q, p);
    if (s) mpq_neg(q, q);
    mpq_clear(p);
}
/* floor(log2 |x|), x != 0 */
static int q_log2(const mpq_t x) {
    mpq_t a, p;
    mpq_inits(a, p, NULL);
    mpq_abs(a, x);
    int e = (int)mpz_sizeinbase(mpq_numref(a), 2) - (int)mpz_sizeinbase(mpq_denref(a), 2);
    q_pow2(p, e);
    while (mpq_cmp(a, p) < 0) e--, q_pow2(p, e);
    q_pow2(p, e + 1);
    while (mpq_cmp(a, p) >= 0) e++, q_pow2(p, e + 1);
    mpq_clears(a, p, NULL);
    return e;
}
static cbvh_f32 pack(int neg, int E, uint64_t q, int M) { return rbi_pack(neg, E, q, M); }
/* RND_F written from the spec (§17.1), independently of cbvh_rbi_round. */
static cbvh_f32 oracle_round(const mpq_t x, int up, int M, int X) {
    if (mpq_sgn(x) == 0) return 0;
    int neg = mpq_sgn(x) < 0, away = neg ? !up : up;
    int emax = (1 << (X - 1)) - 1, emin = 2 - (1 << (X - 1));
    int E = q_log2(x);
    if (E < emin) return away ? pack(neg, emin, UINT64_C(1) << (M - 1), M) : 0u;
    if (E > emax) return away ? (neg ? CBVH_F32_NEG_INF : CBVH_F32_POS_INF) : pack(neg, emax, (UINT64_C(1) << M) - 1, M);
    mpq_t a, p;
    mpq_inits(a, p, NULL);
    mpq_abs(a, x);
    q_pow2(p, M - 1 - E);
    mpq_mul(a, a, p);
    mpz_t qz;
    mpz_init(qz);
    mpz_fdiv_q(qz, mpq_numref(a), mpq_denref(a));
    int exact = mpz_divisible_p(mpq_numref(a), mpq_denref(a));
    uint64_t q = mpz_get_ui(qz);
    mpz_clear(qz);
    mpq_clears(a, p, NULL);
    if (!exact && away) q++;
    if (q == (UINT64_C(1) << M)) {
        q >>= 1;
        if (++E > emax) return neg ? CBVH_F32_NEG_INF : CBVH_F32_POS_INF;
    }
    return pack(neg, E, q, M);
}

/* ---- the unit, from the spec, on rationals ------------------------------ */
static int64_t key(cbvh_f32 x) { return cbvh_f32_key(x); }

/* rcp +-0: a parallel axis, stepped with rho = 1 */
static cbvh_f32 oracle_step(cbvh_f32 t, int sub, uint32_t c, int e, cbvh_f32 rcp, int up, int M, int X) {
    if (cbvh_f32_is_nan_or_inf(t)) return t;
    mpq_t x, y;
    mpq_inits(x, y, NULL);
    q_f32(x, t);
    {
        if (cbvh_f32_is_zero(rcp)) mpq_set_ui(y, 1, 1);
        else q_f32(y, rcp);
        mpq_t p;
        mpq_init(p);
        q_pow2(p, e);
        mpq_mul(y, y, p);
        mpq_set_ui(p, c, 1);
        mpq_mul(y, y, p);
        mpq_clear(p);
        if (sub) mpq_sub(x, x, y);
        else mpq_add(x, x, y);
    }
    cbvh_f32 r = oracle_round(x, up, M, X);
    mpq_clears(x, y, NULL);
    return r;
}

static void oracle_unit(const cbvh_rbi_params *p, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *par,
                        const cbvh_rbi_axis ch[3], cbvh_rbi_result *o) {
    memset(o, 0, sizeof *o);
    cbvh_rbi_planes pl;
    cbvh_f32 tn = ray->tmin, tf = ray->tmax;
    int outside = 0;
    for (int a = 0; a < 3; a++) {
        int parallel = cbvh_f32_is_zero(ray->rcp[a]);
        int neg = !parallel && (ray->rcp[a] >> 31) != 0;
        pl.t_lb[a] = oracle_step(par->t_lb[a], 0, ch[a].r, ch[a].e, ray->rcp[a], neg, p->mant, p->texp);
        pl.t_ub[a] = oracle_step(par->t_ub[a], 1, ch[a].sp, ch[a].e, ray->rcp[a], !neg, p->mant, p->texp);
        if (parallel) { /* offsets: inside iff t_lb <= 0 <= t_ub */
            if (key(pl.t_lb[a]) > 0 || key(pl.t_ub[a]) < 0) outside = 1;
            continue;
        }
        cbvh_f32 n = neg ? pl.t_ub[a] : pl.t_lb[a], f = neg ? pl.t_lb[a] : pl.t_ub[a];
        if (key(n) > key(tn)) tn = n;
        if (key(f) < key(tf)) tf = f;
    }
    if (outside || key(tn) > key(tf)) return;
    o->hit = 1;
    o->t_near = cbvh_f32_is_zero(tn) ? 0 : tn;
    o->t_far = cbvh_f32_is_zero(tf) ? 0 : tf;
    o->planes = pl;
}

static cbvh_f32 oracle_rcp(cbvh_f32 d, int M) {
    if (cbvh_f32_is_zero(d)) return 0;
    mpq_t x;
    mpq_init(x);
    q_f32(x, d);
    mpq_abs(x, x);
    mpq_inv(x, x);
    int neg = (d >> 31) != 0;
    int E = q_log2(x);
    cbvh_f32 r;
    if (E < -126) r = neg ? CBVH_F32_SIGN : 0u;
    else if (E > 127) r = pack(neg, 127, (UINT64_C(1) << M) - 1, M);
    else r = oracle_round(x, 0, M, 8) | (neg ? CBVH_F32_SIGN : 0u); /* |1/d| truncated: RD of a positive value */
    mpq_clear(x);
    return r;
}

static cbvh_f32 oracle_anchor_plane(cbvh_f32 u, int e, uint32_t k, cbvh_f32 o, cbvh_f32 d, int up, int M, int X) {
    mpq_t P, t;
    mpq_inits(P, t, NULL);
    if (u == CBVH_F32_NEG_INF) {
        q_pow2(P, 128);
        mpq_neg(P, P);
    } else
        q_f32(P, u);
    q_pow2(t, e);
    mpq_t kk;
    mpq_init(kk);
    mpq_set_ui(kk, k, 1);
    mpq_mul(t, t, kk);
    mpq_add(P, P, t);
    q_f32(t, o);
    mpq_sub(P, P, t);
    q_f32(t, d);
    mpq_div(P, P, t);
    cbvh_f32 r = oracle_round(P, up, M, X);
    mpq_clears(P, t, kk, NULL);
    return r;
}

/* The fast path as this file compiles it (SSE2 lanes, or one plane at a time
 * with -DCBVH_NO_SSE2: test traversal_ray_box_incr.plain) against the unit's
 * outputs: 1 if equal. */
static int fast_matches(const cbvh_rbi_params *p, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *par,
                        const cbvh_rbi_axis ax[3], const cbvh_rbi_result *want) {
    if (!CBVH_RBI_FAST) return 1;
    cbvh_rbi_fray f;
    cbvh_rbi_fnode n, ch;
    int e[3];
    uint32_t r[3], sp[3];
    for (int a = 0; a < 3; a++) e[a] = ax[a].e, r[a] = ax[a].r, sp[a] = ax[a].sp;
    cbvh_rbi_fprep(p, ray, &f);
    cbvh_rbi_fnode_of(&f, par, e, &n);
    double tn, tf;
    cbvh_rbi_result got;
    memset(&got, 0, sizeof got);
    if (cbvh_rbi_ftest(&f, cbvh_rbi_d(ray->tmax), &n, r, sp, &ch, &tn, &tf)) {
        got.hit = 1;
        got.t_near = cbvh_rbi_f(tn);
        got.t_far = cbvh_rbi_f(tf);
        for (int a = 0; a < 3; a++) got.planes.t_lb[a] = cbvh_rbi_f(ch.t[a][0]), got.planes.t_ub[a] = cbvh_rbi_f(ch.t[a][1]);
    }
    return memcmp(&got, want, sizeof got) == 0;
}

/* ---- random inputs ------------------------------------------------------ */
static int rand_M(void) { return below(4) ? MS[below(5)] : 3 + (int)below(22); }
static int rand_X(void) { return below(3) ? 8 : 3 + (int)below(6); }

static cbvh_f32 rand_f32(void) { return rbi_rand_f32(&rs); }

static void print_result(const char *who, const cbvh_rbi_result *r) {
    printf("  %s: hit %d near %08x far %08x lb %08x %08x %08x ub %08x %08x %08x\n", who, r->hit, r->t_near, r->t_far,
           r->planes.t_lb[0], r->planes.t_lb[1], r->planes.t_lb[2], r->planes.t_ub[0], r->planes.t_ub[1],
           r->planes.t_ub[2]);
}

static int run_oracle(long count) {
    long hits = 0, cancel = 0;
    for (long i = 0; i < count; i++) {
        cbvh_rbi_params p = {3 + (int)below(8), rand_M(), rand_X()};
        int M = p.mant, X = p.texp;
        cbvh_rbi_ray ray;
        cbvh_rbi_planes par;
        cbvh_rbi_axis ch[3];
        rbi_random_inputs(&rs, &p, &ray, &par, ch);
        cbvh_rbi_result got, want;
        uint32_t st = cbvh_ray_box_incr(&p, &ray, &par, ch, &got);
        int bad_tmin = cbvh_f32_is_nan_or_inf(ray.tmin); /* rand_f32 never gives NaN/Inf: status must be 0 */
        CHECK(st == 0 && !bad_tmin, "oracle input %ld: status %02x", i, st);
        oracle_unit(&p, &ray, &par, ch, &want);
        cbvh_rbi_result gi;
        uint32_t sti = cbvh_ray_box_incr_int(&p, &ray, &par, ch, &gi);
        CHECK(sti == st && memcmp(&gi, &got, sizeof gi) == 0, "oracle input %ld: integer path != the unit", i);
        if (st == 0) CHECK(fast_matches(&p, &ray, &par, ch, &got), "oracle input %ld: fast path (this build) != the unit", i);
        if (memcmp(&got, &want, sizeof got) != 0) {
            CHECK(0, "oracle input %ld (N %d M %d X %d): unit != oracle", i, p.quant_bits, M, X);
            if (fails <= 5) {
                for (int a = 0; a < 3; a++)
                    printf("  axis %d rcp %08x lb %08x ub %08x e %d r %u sp %u\n", a, ray.rcp[a], par.t_lb[a],
                           par.t_ub[a], ch[a].e, ch[a].r, ch[a].sp);
                printf("  tmin %08x tmax %08x\n", ray.tmin, ray.tmax);
                print_result("unit  ", &got);
                print_result("oracle", &want);
            }
        }
        hits += got.hit;
        for (int a = 0; a < 3; a++) /* a new distance two binades below the old one: cancellation */
            for (int w = 0; w < 2; w++) {
                cbvh_f32 o = w ? par.t_ub[a] : par.t_lb[a], n = w ? got.planes.t_ub[a] : got.planes.t_lb[a];
                if (got.hit && !cbvh_f32_is_zero(n) && !cbvh_f32_is_zero(o) && ((n >> 23) & 0xFF) + 2 < ((o >> 23) & 0xFF))
                    cancel++;
            }

        /* the reciprocal */
        cbvh_f32 d = rand_f32(), r;
        if (below(8) == 0) d = rbi_pow2((int)below(2), (int)below(277) - 149);
        CHECK(cbvh_rbi_reciprocal(d, M, &r) == 0, "reciprocal status");
        CHECK(r == oracle_rcp(d, M), "reciprocal of %08x at M %d: %08x, oracle %08x", d, M, r, oracle_rcp(d, M));

        /* the anchor */
        if (i % 4 == 0) {
            cbvh_ray rr;
            cbvh_grid_axis g[3];
            for (int a = 0; a < 3; a++) {
                rr.o[a] = below(4) ? rbi_f32(tu_unit_d(&rs) * 200 - 100) : rand_f32();
                rr.d[a] = below(4) ? rbi_f32(tu_unit_d(&rs) * 2 - 1) : rand_f32();
                g[a].u = below(16) == 0 ? CBVH_F32_NEG_INF : below(4) ? rbi_f32(tu_unit_d(&rs) * 200 - 100) : rand_f32();
                g[a].e = below(4) ? (int)below(10) - 5 : (int)below(253) - 126;
                g[a].r = (uint32_t)below(1024);
                g[a].s = g[a].r + 1 + (uint32_t)below(1024 - g[a].r);
            }
            if (below(8) == 0) rr.o[0] = g[0].u == CBVH_F32_NEG_INF ? rr.o[0] : g[0].u; /* on the lower plane (r = 0) */
            rr.tmin = 0;
            rr.tmax = CBVH_F32_POS_INF;
            if (cbvh_f32_is_zero(rr.d[0]) && cbvh_f32_is_zero(rr.d[1]) && cbvh_f32_is_zero(rr.d[2])) rr.d[1] = rbi_f32(1);
            cbvh_rbi_planes an;
            CHECK(cbvh_rbi_anchor(&rr, &p, g, &an) == 0, "anchor status");
            for (int a = 0; a < 3; a++) {
                int neg = (rr.d[a] >> 31) != 0;
                cbvh_f32 dd = rr.d[a];
                if (cbvh_f32_is_zero(dd)) dd = 0x3F800000u, neg = 0; /* d = 0: the offsets (plane - o) / 1 */
                cbvh_f32 rc;
                cbvh_rbi_reciprocal(dd, M, &rc);
                if (cbvh_f32_is_zero(rc)) { /* |d| > 2^126: unconstrained */
                    CHECK(an.t_lb[a] == CBVH_F32_NEG_INF && an.t_ub[a] == CBVH_F32_POS_INF, "anchor of a huge d");
                    continue;
                }
                cbvh_f32 wl = oracle_anchor_plane(g[a].u, g[a].e, g[a].r, rr.o[a], dd, neg, M, X);
                cbvh_f32 wu = oracle_anchor_plane(g[a].u, g[a].e, g[a].s, rr.o[a], dd, !neg, M, X);
                CHECK(an.t_lb[a] == wl && an.t_ub[a] == wu, "anchor axis %d (M %d X %d): %08x %08x, oracle %08x %08x", a,
                      M, X, an.t_lb[a], an.t_ub[a], wl, wu);
            }
        }
    }
    /* the edges of F: parent distances at +-max, +-2^emin and one unit inside
     * them, increments of +-1/2, 1, 3/2 units, 2^emin and 2^(emax+1) - max on
     * either plane and either sign of rho, for every M and X */
    long edges = 0;
    for (int X = 3; X <= 8; X++)
        for (int M = 3; M <= 24; M++) {
            cbvh_rbi_params p = {10, M, X};
            int emax = cbvh_rbi_emax(X), emin = cbvh_rbi_emin(X);
            uint64_t qmax = (UINT64_C(1) << M) - 1, qmin = UINT64_C(1) << (M - 1);
            const cbvh_f32 ts[6] = {pack(0, emax, qmax, M), pack(1, emax, qmax, M), pack(0, emin, qmin, M),
                                    pack(1, emin, qmin, M), pack(0, emin, qmin + 1, M), pack(0, emax, qmax - 1, M)};
            for (int k = 0; k < 6; k++)
                for (int step = 0; step < 6; step++)
                    for (int sg = 0; sg < 4; sg++) {
                        /* rho = +-2^x with x chosen so that r 2^e rho is the wanted step */
                        int E = k < 2 || k == 5 ? emax : emin, ulp = E - (M - 1);
                        static const int st_exp[6] = {-1, 0, -1, 0, 0, 1}; /* 2^(ulp + st_exp) x st_c */
                        static const uint32_t st_c[6] = {1, 1, 3, 1, 1, 1};
                        int target = step == 4 ? emin : ulp + st_exp[step];
                        if (step == 5) target = emax + 1 - M; /* 2^(emax+1) - max */
                        cbvh_rbi_ray ray = {{0, 0, 0}, 0, CBVH_F32_POS_INF};
                        int rx = target - 0, e = 0; /* rho = 2^rx at e = 0, clamped into the ranges */
                        if (rx > 127) e = rx - 127, rx = 127;
                        if (rx < -126) e = rx + 126, rx = -126;
                        if (e < -126 || e > 126) continue;
                        ray.rcp[0] = rbi_pow2(sg & 1, rx);
                        ray.tmin = 0xFF7FFFFFu; /* -FLT_MAX: keeps every hit */
                        /* every other plane finite (+-max, rho = 0 on y and z), so that the SSE2 lanes
                         * decide; the tested plane is axis 0's lower (sg & 2 = 0) or upper one */
                        cbvh_f32 big = pack(0, emax, qmax, M);
                        cbvh_rbi_planes par = {{big | CBVH_F32_SIGN, big | CBVH_F32_SIGN, big | CBVH_F32_SIGN},
                                               {big, big, big}};
                        cbvh_rbi_axis ch[3] = {{e, 0, 0}, {0, 0, 0}, {0, 0, 0}};
                        int near_is_lb = !(ray.rcp[0] >> 31), tested_lb = !(sg & 2);
                        cbvh_f32 other = tested_lb == near_is_lb ? big : big | CBVH_F32_SIGN; /* far +max, near -max */
                        if (tested_lb) par.t_lb[0] = ts[k], par.t_ub[0] = other, ch[0].r = st_c[step];
                        else par.t_ub[0] = ts[k], par.t_lb[0] = other, ch[0].sp = st_c[step];
                        cbvh_rbi_result got, want, gi;
                        uint32_t st = cbvh_ray_box_incr(&p, &ray, &par, ch, &got);
                        oracle_unit(&p, &ray, &par, ch, &want);
                        cbvh_ray_box_incr_int(&p, &ray, &par, ch, &gi);
                        CHECK(st == 0 && !memcmp(&got, &want, sizeof got) && !memcmp(&gi, &got, sizeof gi) &&
                                  fast_matches(&p, &ray, &par, ch, &got),
                              "edge case M %d X %d t %08x step %d sign %d: status %02x, unit/oracle/integer differ", M, X,
                              ts[k], step, sg, st);
                        edges++;
                    }
        }
    printf("oracle: %ld unit inputs (%ld hits, %ld planes with cancellation), %ld reciprocals, %ld anchors, %ld edge cases\n",
           count, hits, cancel, count, (count + 3) / 4, edges);
    CHECK(hits > count / 10 && cancel > count / 100, "too few hits (%ld) or cancellations (%ld)", hits, cancel);
    return 0;
}

/* ---- conservativeness on chains ---------------------------------------- */
typedef struct {
    long children, ex_hits, inc_hits, fp, planes_checked, int_checked;
    int max_depth;
} kind_stats;

static void check_planes(const rbi_chain *c, const rbi_child *x) {
    /* every plane distance against the exact quotient rounded outward at 24 bits */
    for (int a = 0; a < 3; a++) {
        int parallel = cbvh_f32_is_zero(c->rr.rcp[a]);
        if (parallel && !cbvh_f32_is_zero(c->ray.d[a])) { /* |d| > 2^126: unconstrained */
            CHECK(x->inc.planes.t_lb[a] == CBVH_F32_NEG_INF && x->inc.planes.t_ub[a] == CBVH_F32_POS_INF,
                  "%s: a huge direction's axis is not unconstrained", rbi_kind_names[c->kind]);
            continue;
        }
        int neg = !parallel && (c->ray.d[a] >> 31) != 0; /* d = 0: offsets, plane - o over 1 */
        cbvh_xw u, st, pl, o, d, num;
        if (x->g[a].u == CBVH_F32_NEG_INF) cbvh_xw_from_int(&u, -1, 128);
        else cbvh_xw_from_f32(&u, x->g[a].u);
        cbvh_xw_from_f32(&o, c->ray.o[a]);
        if (parallel) cbvh_xw_from_int(&d, 1, 0);
        else cbvh_xw_from_f32(&d, c->ray.d[a]);
        for (int w = 0; w < 2; w++) {
            cbvh_xw_from_int(&st, (int64_t)(w ? x->g[a].s : x->g[a].r), x->g[a].e);
            cbvh_xw_add(&pl, &u, &st);
            cbvh_xw_sub(&num, &pl, &o);
            int up = w ? !neg : neg; /* lower plane: near (RD) for d > 0 */
            cbvh_f32 ex = cbvh_xw_div_round(&num, &d, 24, up ? CBVH_RND_UP : CBVH_RND_DOWN);
            cbvh_f32 got = w ? x->inc.planes.t_ub[a] : x->inc.planes.t_lb[a];
            int ok = up ? key(got) >= key(ex) : key(got) <= key(ex);
            CHECK(ok, "%s: plane %s axis %d distance %08x not outside the exact %08x (depth %d)",
                  rbi_kind_names[c->kind], w ? "ub" : "lb", a, got, ex, c->depth);
        }
    }
}

static int run_chains(long count) {
    kind_stats ks[RBI_KINDS];
    memset(ks, 0, sizeof ks);
    uint64_t crng = 0xC4A1750000000001u;
    long done = 0, chains = 0;
    clock_t t0 = clock();
    while (done < count) {
        int kind = (int)(chains % RBI_KINDS);
        cbvh_rbi_params p = {3 + (int)(tu_xorshift64(&crng) % 8), 0, 0};
        uint64_t mk = tu_xorshift64(&crng);
        p.mant = (mk & 3) ? MS[(mk >> 2) % 5] : 3 + (int)((mk >> 8) % 22);
        p.texp = (mk >> 16) % 4 ? 8 : 3 + (int)((mk >> 20) % 6);
        rbi_chain c;
        chains++;
        if (rbi_chain_start(&c, &p, &crng, kind)) {
            CHECK(0, "chain %ld (%s): the ray was rejected", chains, rbi_kind_names[kind]);
            continue;
        }
        kind_stats *k = &ks[kind];
        rbi_child ch[2];
        int more = 1;
        while (more && done < count) {
            cbvh_rbi_planes Tpar = c.T; /* the step descends: keep the parent's distances */
            more = rbi_chain_step(&c, ch);
            for (int j = 0; j < 2; j++) {
                rbi_child *x = &ch[j];
                done++;
                k->children++;
                CHECK(x->inc_st == 0 && x->ex_st == 0, "%s: status incremental %02x exact %02x",
                      rbi_kind_names[kind], x->inc_st, x->ex_st);
                if ((done & 3) == 0) { /* the integer path gives the unit's bits */
                    cbvh_rbi_result gi;
                    uint32_t sti = cbvh_ray_box_incr_int(&p, &c.rr, &Tpar, x->ax, &gi);
                    CHECK(sti == x->inc_st && memcmp(&gi, &x->inc, sizeof gi) == 0,
                          "%s: integer path != the unit (depth %d)", rbi_kind_names[kind], c.depth);
                    if (x->inc_st == 0)
                        CHECK(fast_matches(&p, &c.rr, &Tpar, x->ax, &x->inc), "%s: fast path (this build) != the unit",
                              rbi_kind_names[kind]);
                    k->int_checked++;
                }
                k->ex_hits += x->ex.hit;
                k->inc_hits += x->inc.hit;
                k->fp += x->inc.hit && !x->ex.hit;
                if (x->ex.hit) {
                    CHECK(x->inc.hit, "%s: FALSE MISS at depth %d (N %d M %d X %d): exact [%08x, %08x]",
                          rbi_kind_names[kind], c.depth, p.quant_bits, p.mant, p.texp, x->ex.t_near, x->ex.t_far);
                    if (x->inc.hit)
                        CHECK(key(x->inc.t_near) <= key(x->ex.t_near) && key(x->inc.t_far) >= key(x->ex.t_far),
                              "%s: [%08x, %08x] does not contain the exact [%08x, %08x] (depth %d, M %d)",
                              rbi_kind_names[kind], x->inc.t_near, x->inc.t_far, x->ex.t_near, x->ex.t_far,
                              c.depth, p.mant);
                }
                if (x->inc.hit) {
                    for (int a = 0; a < 3; a++)
                        CHECK(cbvh_rbi_in_format(x->inc.planes.t_lb[a], p.mant, p.texp) &&
                                  cbvh_rbi_in_format(x->inc.planes.t_ub[a], p.mant, p.texp),
                              "output plane not in F(%d, %d)", p.mant, p.texp);
                    if ((done & 63) == 0) {
                        check_planes(&c, x);
                        k->planes_checked++;
                    }
                }
            }
            if (c.depth > k->max_depth) k->max_depth = c.depth;
        }
    }
    double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    printf("chains: %ld children in %ld chains, %.1f s (%.0f ns per child, both units)\n", done, chains, secs,
           secs * 1e9 / (double)done);
    printf("%-16s %12s %12s %12s %10s %8s %10s\n", "kind", "children", "exact hits", "incr hits", "false pos",
           "depth", "planes");
    for (int k = 0; k < RBI_KINDS; k++) {
        printf("%-16s %12ld %12ld %12ld %10ld %8d %10ld\n", rbi_kind_names[k], ks[k].children, ks[k].ex_hits,
               ks[k].inc_hits, ks[k].fp, ks[k].max_depth, ks[k].planes_checked);
        if (count >= 100000)
            CHECK(ks[k].ex_hits > ks[k].children / 50, "%s: too few exact hits to test anything", rbi_kind_names[k]);
    }
    if (count >= 100000) CHECK(ks[RBI_LONG].max_depth >= 100, "long chains reach only depth %d", ks[RBI_LONG].max_depth);
    return 0;
}

/* ---- named cases --------------------------------------------------------- */
static cbvh_f32 F(float x) { return fb(x); }

static void run_cases(void) {
    cbvh_f32 r;
    /* reciprocals */
    CHECK(cbvh_rbi_reciprocal(F(1.0f), 8, &r) == 0 && r == F(1.0f), "1/1");
    CHECK(cbvh_rbi_reciprocal(F(-2.0f), 8, &r) == 0 && r == F(-0.5f), "1/-2: %08x", r);
    CHECK(cbvh_rbi_reciprocal(F(3.0f), 6, &r) == 0 && r == F(0.328125f), "1/3 at M 6: %08x", r); /* 21/64 */
    CHECK(cbvh_rbi_reciprocal(F(3.0f), 24, &r) == 0 && r == 0x3EAAAAAAu, "1/3 at M 24: %08x", r);
    CHECK(cbvh_rbi_reciprocal(0u, 8, &r) == 0 && r == 0u, "1/+0");
    CHECK(cbvh_rbi_reciprocal(CBVH_F32_SIGN, 8, &r) == 0 && r == 0u, "1/-0 is +0");
    CHECK(cbvh_rbi_reciprocal(1u, 8, &r) == 0 && r == 0x7F7F0000u, "1/2^-149 clamps to (2^8-1) 2^120: %08x", r);
    CHECK(cbvh_rbi_reciprocal(rbi_pow2(0, -127), 8, &r) == 0 && r == 0x7F000000u, "1/2^-127 = 2^127: %08x", r);
    CHECK(cbvh_rbi_reciprocal(rbi_pow2(0, -128), 12, &r) == 0 && r == 0x7F7FF000u, "1/2^-128 clamps: %08x", r);
    CHECK(cbvh_rbi_reciprocal(rbi_pow2(0, 126), 8, &r) == 0 && r == 0x00800000u, "1/2^126 = 2^-126: %08x", r);
    CHECK(cbvh_rbi_reciprocal(rbi_pow2(1, 126) + 1u, 8, &r) == 0 && r == CBVH_F32_SIGN, "1/-(2^126+) = -0: %08x", r);
    CHECK(cbvh_rbi_reciprocal(0x7F7FFFFFu, 8, &r) == 0 && r == 0u, "1/FLT_MAX = 0");
    CHECK(cbvh_rbi_reciprocal(CBVH_F32_POS_INF, 8, &r) == CBVH_ST_NAN_INF && r == 0, "1/Inf rejected");
    CHECK(cbvh_rbi_reciprocal(F(1.0f), 2, &r) == CBVH_ST_BAD_PARAM, "M 2 rejected");
    CHECK(cbvh_rbi_reciprocal(F(1.0f), 25, &r) == CBVH_ST_BAD_PARAM, "M 25 rejected");

    /* RND_F */
    CHECK(cbvh_rbi_round(0, 3, 0, 0, CBVH_RND_DOWN, 3, 8) == F(3.0f), "3 exact");
    CHECK(cbvh_rbi_round(0, 9, 0, 0, CBVH_RND_DOWN, 3, 8) == F(8.0f), "RD 9 to 3 bits");
    CHECK(cbvh_rbi_round(0, 9, 0, 0, CBVH_RND_UP, 3, 8) == F(10.0f), "RU 9 to 3 bits");
    CHECK(cbvh_rbi_round(1, 9, 0, 0, CBVH_RND_UP, 3, 8) == F(-8.0f), "RU -9");
    CHECK(cbvh_rbi_round(1, 9, 0, 0, CBVH_RND_DOWN, 3, 8) == F(-10.0f), "RD -9");
    CHECK(cbvh_rbi_round(0, 15, 0, 0, CBVH_RND_UP, 3, 8) == F(16.0f), "RU 15: carry");
    CHECK(cbvh_rbi_round(0, 8, 0, 1, CBVH_RND_UP, 3, 8) == F(10.0f), "RU 8+: sticky");
    CHECK(cbvh_rbi_round(0, 8, 0, 1, CBVH_RND_DOWN, 3, 8) == F(8.0f), "RD 8+");
    CHECK(cbvh_rbi_round(0, 1, 4, 0, CBVH_RND_UP, 3, 3) == CBVH_F32_POS_INF, "16 above X 3's range: +Inf up");
    CHECK(cbvh_rbi_round(0, 1, 4, 0, CBVH_RND_DOWN, 3, 3) == F(14.0f), "16 down: the largest value 7 2^1");
    CHECK(cbvh_rbi_round(0, 15, 0, 0, CBVH_RND_UP, 3, 3) == CBVH_F32_POS_INF, "RU 15 carries past emax 3: +Inf");
    CHECK(cbvh_rbi_round(0, 1, -3, 0, CBVH_RND_UP, 3, 3) == F(0.25f), "2^-3 up at X 3: 2^emin = 2^-2");
    CHECK(cbvh_rbi_round(0, 1, -3, 0, CBVH_RND_DOWN, 3, 3) == 0, "2^-3 down: +0");
    CHECK(cbvh_rbi_round(1, 1, -3, 0, CBVH_RND_UP, 3, 3) == 0, "-2^-3 up: +0 (not -0)");
    CHECK(cbvh_rbi_round(1, 1, -3, 0, CBVH_RND_DOWN, 3, 3) == F(-0.25f), "-2^-3 down");
    CHECK(cbvh_rbi_round(0, 1, -149, 0, CBVH_RND_UP, 24, 8) == 0x00800000u, "2^-149 up at X 8: 2^-126 (no subnormals)");
    CHECK(cbvh_rbi_in_format(F(1.5f), 2, 8) == 1 && cbvh_rbi_in_format(F(1.25f), 2, 8) == 0, "in_format M");
    CHECK(cbvh_rbi_in_format(1u, 24, 8) == 0 && cbvh_rbi_in_format(0x00800000u, 24, 8) == 1, "in_format subnormal");
    CHECK(cbvh_rbi_in_format(F(16.0f), 8, 3) == 0 && cbvh_rbi_in_format(F(8.0f), 8, 3) && cbvh_rbi_in_format(F(-4.0f), 8, 3) == 1, "in_format X 3");
    CHECK(cbvh_rbi_in_format(CBVH_F32_NEG_INF, 8, 3) && !cbvh_rbi_in_format(0x7FC00000u, 8, 3), "Inf, NaN");

    /* the unit, named values: ray o = 0, d = (1, -2, 0), M = 8, X = 8, N = 6 */
    cbvh_rbi_params p = {6, 8, 8};
    cbvh_ray ray = {{0, 0, 0}, {F(1.0f), F(-2.0f), 0}, 0, CBVH_F32_POS_INF};
    cbvh_rbi_ray rr;
    CHECK(cbvh_rbi_ray_setup(&ray, &p, &rr) == 0, "setup");
    CHECK(rr.rcp[0] == F(1.0f) && rr.rcp[1] == F(-0.5f) && rr.rcp[2] == 0, "setup rcp");
    /* root: x [1, 1 + 64 0.25], y [-20, -20 + 32 0.5], z [-1, 1]: o inside on z */
    cbvh_grid_axis root[3] = {{F(1.0f), -2, 0, 64}, {F(-20.0f), -1, 0, 32}, {F(-1.0f), -5, 0, 64}};
    cbvh_rbi_planes T;
    CHECK(cbvh_rbi_anchor(&ray, &p, root, &T) == 0, "anchor");
    CHECK(T.t_lb[0] == F(1.0f) && T.t_ub[0] == F(17.0f), "anchor x: %08x %08x", T.t_lb[0], T.t_ub[0]);
    CHECK(T.t_lb[1] == F(10.0f) && T.t_ub[1] == F(2.0f), "anchor y (d < 0): %08x %08x", T.t_lb[1], T.t_ub[1]);
    CHECK(T.t_lb[2] == F(-1.0f) && T.t_ub[2] == F(1.0f), "anchor z (d = 0: offsets -1 - 0, 1 - 0)");
    cbvh_rbi_axis ch[3] = {{-2, 4, 20}, {-1, 6, 2}, {-5, 7, 9}};
    cbvh_rbi_result res;
    CHECK(cbvh_ray_box_incr(&p, &rr, &T, ch, &res) == 0, "unit status");
    /* x: lb 1 + 4 0.25 = 2, ub 17 - 20 0.25 = 12; y: lb 10 - 6 0.5 0.5 = 8.5, ub 2 + 2 0.5 0.5 = 2.5 */
    CHECK(res.hit && res.planes.t_lb[0] == F(2.0f) && res.planes.t_ub[0] == F(12.0f), "x planes");
    CHECK(res.planes.t_lb[1] == F(8.5f) && res.planes.t_ub[1] == F(2.5f), "y planes %08x %08x", res.planes.t_lb[1],
          res.planes.t_ub[1]);
    CHECK(res.t_near == F(2.5f) && res.t_far == F(8.5f), "near/far %08x %08x", res.t_near, res.t_far);
    CHECK(res.planes.t_lb[2] == F(-0.78125f) && res.planes.t_ub[2] == F(0.71875f), "z offsets -1 + 7/32, 1 - 9/32");
    /* a parallel axis whose child lies beside the origin: a miss whatever the other axes give */
    cbvh_rbi_axis chz[3] = {{-2, 4, 20}, {-1, 6, 2}, {-5, 40, 9}};
    CHECK(cbvh_ray_box_incr(&p, &rr, &T, chz, &res) == 0 && !res.hit, "z: -1 + 40/32 > 0, the origin is below");
    /* rounding outward: rcp 1/3 at M 6 = 21/64; lb 1 + 1 21/64 = 85/64 -> 6 bits: 1.328125 exactly (85 = 1010101b,
       7 bits) -> RD to 6 bits: 84/64 = 1.3125; ub 17 - 21/64 = 16.671875 -> RU to 6 bits (ulp 1/2): 17 */
    cbvh_rbi_params p6 = {6, 6, 8};
    cbvh_rbi_ray r6 = {{0x3EA80000u, 0, 0}, 0, CBVH_F32_POS_INF}; /* 21/64 */
    cbvh_rbi_planes T6 = {{F(1.0f), CBVH_F32_NEG_INF, CBVH_F32_NEG_INF}, {F(17.0f), CBVH_F32_POS_INF, CBVH_F32_POS_INF}};
    cbvh_rbi_axis c6[3] = {{0, 1, 1}, {0, 0, 0}, {0, 0, 0}};
    CHECK(cbvh_ray_box_incr(&p6, &r6, &T6, c6, &res) == 0 && res.hit, "M 6 hit");
    CHECK(res.planes.t_lb[0] == F(1.3125f) && res.planes.t_ub[0] == F(17.0f), "M 6 planes %08x %08x",
          res.planes.t_lb[0], res.planes.t_ub[0]);
    /* d = 0 outside the root: (+Inf, -Inf) and every child misses */
    cbvh_ray rz = {{F(5.0f), 0, 0}, {0, F(1.0f), 0}, 0, CBVH_F32_POS_INF};
    cbvh_grid_axis rootz[3] = {{F(-1.0f), 0, 0, 2}, {F(-1.0f), 0, 0, 2}, {F(-1.0f), 0, 0, 2}};
    CHECK(cbvh_rbi_anchor(&rz, &p, rootz, &T) == 0 && T.t_lb[0] == F(-6.0f) && T.t_ub[0] == F(-4.0f),
          "d = 0 outside: offsets -6, -4");
    rz.o[0] = F(1.0f); /* on the upper face: inside */
    CHECK(cbvh_rbi_anchor(&rz, &p, rootz, &T) == 0 && T.t_lb[0] == F(-2.0f) && T.t_ub[0] == 0, "d = 0 on the face");
    cbvh_rbi_ray rzr;
    CHECK(cbvh_rbi_ray_setup(&rz, &p, &rzr) == 0 && rzr.rcp[0] == 0, "setup rz");
    cbvh_rbi_axis cz[3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    CHECK(cbvh_ray_box_incr(&p, &rzr, &T, cz, &res) == 0 && res.hit, "on the upper face: a hit");
    cz[0].sp = 1; /* the child's upper face one cell below the origin */
    CHECK(cbvh_ray_box_incr(&p, &rzr, &T, cz, &res) == 0 && !res.hit, "one cell below: a miss");
    rz.d[0] = 0x7F000001u; /* |d| > 2^126: unconstrained */
    CHECK(cbvh_rbi_anchor(&rz, &p, rootz, &T) == 0 && T.t_lb[0] == CBVH_F32_NEG_INF && T.t_ub[0] == CBVH_F32_POS_INF,
          "huge d: unconstrained");
    /* the tmin = -0 / +0 outputs */
    cbvh_rbi_ray rm = rr;
    rm.tmin = CBVH_F32_SIGN;
    cbvh_rbi_planes Tm = {{F(-1.0f), F(-1.0f), CBVH_F32_NEG_INF}, {F(4.0f), F(4.0f), CBVH_F32_POS_INF}};
    cbvh_rbi_axis c0[3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    rm.rcp[1] = F(0.5f);
    CHECK(cbvh_ray_box_incr(&p, &rm, &Tm, c0, &res) == 0 && res.hit && res.t_near == 0u, "t_near -0 -> +0");

    /* rejects: each alone, then all ORed; outputs zero */
    cbvh_rbi_ray rb;
    cbvh_rbi_planes Tb;
    cbvh_rbi_axis cb[3];
    cbvh_rbi_params pb;
#define RESET() (rb = rr, Tb = T6, pb = p, memcpy(cb, c0, sizeof cb))
    RESET();
    pb.quant_bits = 11;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_PARAM, "reject: N 11");
    RESET();
    pb.mant = 2;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_PARAM, "reject: M 2");
    RESET();
    pb.texp = 9;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_PARAM, "reject: X 9");
    RESET();
    rb.rcp[1] = CBVH_F32_POS_INF;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_NAN_INF, "reject: rcp Inf");
    RESET();
    Tb.t_ub[2] = 0x7FC00000u;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_NAN_INF, "reject: t NaN");
    RESET();
    rb.tmax = CBVH_F32_NEG_INF;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_NAN_INF, "reject: tmax -Inf");
    RESET();
    rb.tmin = CBVH_F32_POS_INF;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_NAN_INF, "reject: tmin Inf");
    RESET();
    rb.rcp[0] = 0x3F800001u; /* 24 significant bits at M 8 */
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_FORMAT, "reject: rcp off format");
    RESET();
    rb.rcp[0] = 1u; /* subnormal */
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_FORMAT, "reject: rcp subnormal");
    RESET();
    Tb.t_lb[0] = 0x3F808000u; /* 1 + 2^-8: 9 significant bits */
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_FORMAT, "reject: t off format");
    RESET();
    cb[1].e = 127;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_SCALE, "reject: e 127");
    RESET();
    cb[2].r = 64;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_BAD_CODE, "reject: r 64 at N 6");
    RESET();
    cb[2].r = 40, cb[2].sp = 24;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == CBVH_ST_INVERTED, "reject: r + s' = 64");
    RESET();
    cb[2].r = 40, cb[2].sp = 23;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) == 0, "reject: r + s' = 63 is valid");
    RESET();
    rb.rcp[0] = 0x7FC00000u, Tb.t_lb[1] = 1u, cb[0].e = -127, cb[1].sp = 0xFFF, cb[2].r = 63, cb[2].sp = 1;
    CHECK(cbvh_ray_box_incr(&pb, &rb, &Tb, cb, &res) ==
              (CBVH_ST_NAN_INF | CBVH_ST_BAD_FORMAT | CBVH_ST_BAD_SCALE | CBVH_ST_BAD_CODE | CBVH_ST_INVERTED),
          "reject: all ORed");
    int zero = 1;
    for (size_t i = 0; i < sizeof res; i++) zero &= ((const unsigned char *)&res)[i] == 0;
    CHECK(zero, "outputs zero on a reject");
    /* the anchor's rejects are the exact unit's */
    cbvh_grid_axis gb[3] = {{F(1.0f), 0, 3, 3}, {0x7FC00000u, 0, 0, 1}, {0, 127, 0, 1025}};
    CHECK(cbvh_rbi_anchor(&ray, &p, gb, &T) == (CBVH_ST_INVERTED | CBVH_ST_NAN_INF | CBVH_ST_BAD_SCALE | CBVH_ST_BAD_CODE),
          "anchor rejects");
    cbvh_ray r0 = ray;
    r0.d[0] = r0.d[1] = 0;
    CHECK(cbvh_rbi_ray_setup(&r0, &p, &rr) == CBVH_ST_ZERO_DIR, "zero direction");
    printf("cases: done\n");
}

int main(int argc, char **argv) {
    const char *what = argc > 1 ? argv[1] : "all";
    long n = argc > 2 ? atol(argv[2]) : 0;
    if (!strcmp(what, "cases") || !strcmp(what, "all")) run_cases();
    if (!strcmp(what, "oracle") || !strcmp(what, "all")) run_oracle(n > 0 ? n : 200000);
    if (!strcmp(what, "chains") || !strcmp(what, "all")) run_chains(n > 0 ? n : 100000000L);
    if (fails) printf("%ld failures\n", fails);
    else printf("ok\n");
    return fails != 0;
}
