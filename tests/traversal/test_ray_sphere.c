/* Ray-sphere unit (unit 9, docs/traversal.md §10):
 *   - status: NaN/Inf in every ray port, zero direction, NaN/Inf centre or
 *     radius, negative radius (-0 allowed), hit = 0 on every reject; an empty
 *     segment (tmin > tmax) is a miss;
 *   - named exact cases: tangent rays, segment ends on the surface, r = 0
 *     through the centre, origin inside, sphere behind, tmax = +Inf, and the
 *     one-ulp neighbours of each (decided the other way);
 *   - an independent exact oracle (GMP rationals, the textbook formulation
 *     with the division t* = B / A and explicit clamping) on >= 1M structured
 *     and random inputs;
 *   - the unit (binary64 fast path + exact path) equals the exact path alone
 *     on >= 2M inputs incl. the hard constructions at huge and tiny
 *     exponents, and the fast path alone never decides against it.
 * Prints the fast path's decided fraction. */
#include <gmp.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/traversal_units.h"
#include "units/ray_sphere_internal.h"
#include "test_util.h"

#ifdef CBVH_SANITIZE
#define N_ORACLE 120000
#define N_FAST 250000
#else
#define N_ORACLE 1100000
#define N_FAST 2000000
#endif

#define F_ONE 0x3F800000u
#define F_NAN 0x7FC00000u
#define F_INF CBVH_F32_POS_INF

static long failures;
#define CHECK(c, ...) TU_CHECK(failures, stderr, c, __VA_ARGS__)

static uint64_t rs = 0x5DEECE66D2545F49u;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static uint64_t below(uint64_t n) { return rnd() % n; }
static int64_t range(int64_t lo, int64_t hi) { return lo + (int64_t)below((uint64_t)(hi - lo + 1)); }

/* n * 2^e exactly (|n| < 2^24, the caller keeps it in range). */
static cbvh_f32 dy(int64_t n, int e) { return cbvh_f32_add_dyadic(n, e, 0, 0, CBVH_RND_DOWN); }

/* Structured random float: mostly moderate exponents, sometimes extreme. */
static cbvh_f32 rfloat(void) {
    int k = (int)below(10);
    int sign = (int)below(2);
    if (k == 0) return sign ? CBVH_F32_SIGN : 0;
    if (k == 1) return (sign ? CBVH_F32_SIGN : 0) | (uint32_t)(1 + below(0x7FFFFF)); /* subnormal */
    int e = k <= 6 ? (int)below(21) - 10 : (int)below(254) - 126;
    uint32_t frac = (uint32_t)rnd();
    if (below(3) == 0) frac &= 0xFFF000u;
    return cbvh_f32_make(sign, e, frac);
}
static cbvh_f32 nudge(cbvh_f32 x) { /* one ulp either way (finite) */
    if (below(2)) return x == CBVH_F32_MAX ? x : cbvh_f32_next_up(x);
    return x == (CBVH_F32_MAX | CBVH_F32_SIGN) ? x : cbvh_f32_next_down(x);
}

typedef struct {
    cbvh_ray ray;
    cbvh_f32 c[3], r;
} scase;

/* ---- the GMP oracle ----------------------------------------------------------- */

static void q_f32(mpq_t q, cbvh_f32 f) {
    int s, e;
    uint32_t sig;
    cbvh_f32_break(f, &s, &sig, &e);
    mpq_set_ui(q, sig, 1);
    if (s) mpq_neg(q, q);
    if (e > 0) mpq_mul_2exp(q, q, (unsigned long)e);
    else if (e < 0) mpq_div_2exp(q, q, (unsigned long)-e);
}

/* Closest point of the segment by division and clamping, then |p - c|^2 <= r^2. */
static int oracle(const scase *s) {
    mpq_t A, B, t, lo, hi, x, y, sum, R;
    mpq_inits(A, B, t, lo, hi, x, y, sum, R, NULL);
    q_f32(lo, s->ray.tmin);
    int inf = s->ray.tmax == F_INF;
    if (!inf) q_f32(hi, s->ray.tmax);
    int hit = 0;
    if (inf || mpq_cmp(lo, hi) <= 0) {
        for (int k = 0; k < 3; k++) {
            q_f32(x, s->ray.d[k]);
            mpq_mul(y, x, x);
            mpq_add(A, A, y);
            q_f32(y, s->c[k]);
            q_f32(t, s->ray.o[k]);
            mpq_sub(y, y, t);
            mpq_mul(y, y, x);
            mpq_add(B, B, y);
        }
        mpq_div(t, B, A);
        if (mpq_cmp(t, lo) < 0) mpq_set(t, lo);
        if (!inf && mpq_cmp(t, hi) > 0) mpq_set(t, hi);
        for (int k = 0; k < 3; k++) {
            q_f32(x, s->ray.d[k]);
            mpq_mul(x, x, t);
            q_f32(y, s->ray.o[k]);
            mpq_add(x, x, y);
            q_f32(y, s->c[k]);
            mpq_sub(x, x, y);
            mpq_mul(x, x, x);
            mpq_add(sum, sum, x);
        }
        q_f32(R, s->r);
        mpq_mul(R, R, R);
        hit = mpq_cmp(sum, R) <= 0;
    }
    mpq_clears(A, B, t, lo, hi, x, y, sum, R, NULL);
    return hit;
}

/* ---- input generators ------------------------------------------------------------ */

/* Perpendicular integer pairs with integer norms: d . w = 0, |w| = n. */
static const int perp[][7] = {
    {3, 4, 0, 4, -3, 0, 5},  {3, 4, 12, 4, -3, 0, 5}, {1, 2, 2, 2, 1, -2, 3},  {2, 3, 6, 3, -6, 2, 7},
    {1, 4, 8, 4, 7, -4, 9},  {2, 6, 9, 6, 7, -6, 11}, {1, 0, 0, 0, 3, 4, 5},   {0, 0, 1, 0, 0, 0, 0},
};
#define N_PERP (int)(sizeof perp / sizeof perp[0])

static void permute_signs(int v[2][3]) {
    int p = (int)below(6), idx[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int sg[3] = {below(2) ? -1 : 1, below(2) ? -1 : 1, below(2) ? -1 : 1};
    for (int j = 0; j < 2; j++) {
        int t[3];
        for (int k = 0; k < 3; k++) t[k] = v[j][idx[p][k]] * sg[k];
        memcpy(v[j], t, sizeof t);
    }
}

static void random_t(scase *s) {
    uint64_t k = below(4);
    s->ray.tmin = k == 0 ? rfloat() : below(2) ? 0 : CBVH_F32_SIGN;
    k = below(4);
    s->ray.tmax = k == 0 ? rfloat() : k == 1 ? s->ray.tmin : F_INF;
}

/* Hard constructions on an integer grid scaled by 2^es (positions) and 2^ed
 * (direction), so every coordinate is exact; t* = m 2^(es - ed).
 *   kind 0: tangent line (|w x d| = r |d|), t* inside, at an end, or outside;
 *   kind 1: the segment's end point on the surface, ray leaving or arriving;
 *   kind 2: r = 0, the line through the centre. */
static void gen_hard(scase *s, int extreme) {
    int es, ed;
    if (extreme) { /* huge and tiny exponents, every coordinate still exact */
        es = (int)range(-149, 90);
        ed = (int)range(-149, 100);
    } else {
        es = (int)range(-12, 6);
        ed = (int)range(-8, 8);
    }
    int te = es - ed; /* t = m 2^te must be representable */
    if (te > 100) te = 100, es = ed + 100;
    if (te < -140) te = -140, es = ed - 140;
    if (es < -149) es = -149, ed = es - te;
    int v[2][3];
    const int *pp = perp[below(N_PERP)];
    for (int k = 0; k < 3; k++) v[0][k] = pp[k], v[1][k] = pp[3 + k];
    permute_signs(v);
    int n = pp[6], dm = (int)range(1, 3);
    int kind = (int)below(3);
    int64_t C[3], O[3];
    int64_t m = range(-20, 20);
    for (int k = 0; k < 3; k++) C[k] = range(-1000, 1000);
    int64_t R = 0;
    if (kind == 0) { /* c - o = w + m d: distance |w| = n from the line, closest at t = m */
        for (int k = 0; k < 3; k++) O[k] = C[k] - v[1][k] - m * dm * v[0][k];
        R = n;
    } else if (kind == 1) { /* p = o + m d = c + w on the surface; d . w = 0 here, so tilt d into w */
        int sgn = below(2) ? 1 : -1; /* leaving (+) or arriving (-) at p */
        for (int k = 0; k < 3; k++) v[0][k] = v[0][k] + sgn * v[1][k];
        for (int k = 0; k < 3; k++) O[k] = C[k] + v[1][k] - m * dm * v[0][k];
        R = n;
    } else { /* r = 0: c = o + m d */
        for (int k = 0; k < 3; k++) O[k] = C[k] - m * dm * v[0][k];
        R = 0;
    }
    if (kind == 2 && v[0][0] == 0 && v[0][1] == 0 && v[0][2] == 0) v[0][2] = 1;
    for (int k = 0; k < 3; k++) {
        s->c[k] = dy(C[k], es);
        s->ray.o[k] = dy(O[k], es);
        s->ray.d[k] = dy((int64_t)dm * v[0][k], ed);
    }
    if (cbvh_f32_is_zero(s->ray.d[0]) && cbvh_f32_is_zero(s->ray.d[1]) && cbvh_f32_is_zero(s->ray.d[2]))
        s->ray.d[0] = dy(1, ed);
    s->r = dy(R, es);
    cbvh_f32 tm = dy(m, te); /* the critical parameter */
    switch (below(8)) {
    case 0: s->ray.tmin = tm, s->ray.tmax = F_INF; break;
    case 1: s->ray.tmin = dy(m - 5, te), s->ray.tmax = tm; break;
    case 2: s->ray.tmin = tm, s->ray.tmax = tm; break;
    case 3: s->ray.tmin = nudge(tm), s->ray.tmax = F_INF; break;
    case 4: s->ray.tmin = dy(m - 7, te), s->ray.tmax = nudge(tm); break;
    case 5: s->ray.tmin = 0, s->ray.tmax = F_INF; break;
    case 6: s->ray.tmin = dy(m - (int64_t)range(-3, 3), te), s->ray.tmax = dy(m + (int64_t)range(-3, 3), te); break;
    default: s->ray.tmin = CBVH_F32_MAX | CBVH_F32_SIGN, s->ray.tmax = F_INF; break;
    }
    /* one-ulp perturbations of one port (half the time) */
    if (below(2)) {
        int port = (int)below(11);
        cbvh_f32 *p = port < 3 ? &s->c[port] : port < 6 ? &s->ray.o[port - 3] : port < 9 ? &s->ray.d[port - 6]
                    : port == 9 ? &s->r : &s->ray.tmin;
        *p = nudge(*p);
        if (port == 9) s->r &= ~CBVH_F32_SIGN;
    }
    if (cbvh_f32_is_zero(s->ray.d[0]) && cbvh_f32_is_zero(s->ray.d[1]) && cbvh_f32_is_zero(s->ray.d[2]))
        s->ray.d[0] = F_ONE;
}

/* Random cases: independent floats, or a ray aimed near a sphere of a
 * comparable size (inside, behind, grazing by chance). */
static void gen_random(scase *s) {
    uint64_t kind = below(4);
    for (int k = 0; k < 3; k++) {
        s->ray.o[k] = rfloat();
        s->ray.d[k] = rfloat();
        s->c[k] = rfloat();
    }
    s->r = rfloat() & ~CBVH_F32_SIGN;
    if (kind >= 1) { /* moderate scene: c = o + offset, d roughly toward c, r ~ |offset| */
        int e = (int)range(-20, 20);
        for (int k = 0; k < 3; k++) {
            int64_t o = range(-(1 << 20), 1 << 20), off = range(-(1 << 20), 1 << 20);
            s->ray.o[k] = dy(o, e);
            s->c[k] = dy(o + off, e);
            int64_t dd = kind == 1 ? off + range(-(1 << 16), 1 << 16) : kind == 2 ? -off : range(-(1 << 20), 1 << 20);
            s->ray.d[k] = dy(dd, (int)range(-30, 0));
        }
        s->r = dy(range(0, 1 << 21), e);
    }
    random_t(s);
    if (cbvh_f32_is_zero(s->ray.d[0]) && cbvh_f32_is_zero(s->ray.d[1]) && cbvh_f32_is_zero(s->ray.d[2]))
        s->ray.d[1] = F_ONE;
}

/* ---- deep cases: the decision within ~2^-48 .. 2^-75 of the binary64 bound's scale ----
 * The fast path's polynomials are evaluated with rounding errors up to about
 * 7 * 2^-53 of their absolute-value bound; these inputs put the exact value
 * of one polynomial far below that (cancellation in w x d, in B - t A, in
 * t d - w) with full-width significands so the binary64 evaluation rounds.
 * (Cancellation inside the polynomials is harmless for the bound, which is
 * relative to the absolute-value tree; test_bound checks the bound itself.) */

static float qd_to_f(const mpq_t q) { return (float)mpq_get_d(q); }
/* A full-width significand at exponent e (normal range). */
static cbvh_f32 wide(int sign, int e) { return cbvh_f32_make(sign, e, (uint32_t)rnd() | 1u); }
/* binary32 nearest to sqrt(q) (q >= 0, within range), then a few ulps either way. */
static cbvh_f32 sqrt_near(const mpq_t q) {
    double v = mpq_get_d(q);
    float f = (float)sqrt(v);
    cbvh_f32 b = fb(f) & ~CBVH_F32_SIGN;
    for (int k = (int)below(3); k > 0 && !cbvh_f32_is_nan_or_inf(b); k--) b = nudge(b) & ~CBVH_F32_SIGN;
    return cbvh_f32_is_nan_or_inf(b) ? CBVH_F32_MAX : b;
}

/* |o + t d - c|^2 at a rational t, and t* = B / A. */
static void q_f_at(mpq_t out, const scase *s, const mpq_t t) {
    mpq_t x, y;
    mpq_inits(x, y, NULL);
    mpq_set_ui(out, 0, 1);
    for (int k = 0; k < 3; k++) {
        q_f32(x, s->ray.d[k]);
        mpq_mul(x, x, t);
        q_f32(y, s->ray.o[k]);
        mpq_add(x, x, y);
        q_f32(y, s->c[k]);
        mpq_sub(x, x, y);
        mpq_mul(x, x, x);
        mpq_add(out, out, x);
    }
    mpq_clears(x, y, NULL);
}
static void q_tstar(mpq_t t, const scase *s) {
    mpq_t A, B, x, y;
    mpq_inits(A, B, x, y, NULL);
    for (int k = 0; k < 3; k++) {
        q_f32(x, s->ray.d[k]);
        mpq_mul(y, x, x);
        mpq_add(A, A, y);
        q_f32(t, s->ray.o[k]);
        q_f32(y, s->c[k]);
        mpq_sub(y, y, t);
        mpq_mul(y, y, x);
        mpq_add(B, B, y);
    }
    mpq_div(t, B, A);
    mpq_clears(A, B, x, y, NULL);
}

static void gen_deep(scase *s) {
    int eo = (int)range(-40, 40), ec = eo + (int)range(-30, 30), ed = (int)range(-40, 40);
    for (int k = 0; k < 3; k++) {
        s->ray.o[k] = wide((int)below(2), eo + (int)range(-3, 3));
        s->c[k] = wide((int)below(2), ec + (int)range(-3, 3));
    }
    mpq_t q, t;
    mpq_inits(q, t, NULL);
    uint64_t kind = below(3);
    if (kind == 0) { /* aimed almost at the centre, r about the miss distance */
        for (int k = 0; k < 3; k++) {
            q_f32(q, s->c[k]);
            q_f32(t, s->ray.o[k]);
            mpq_sub(q, q, t);
            float f = qd_to_f(q);
            s->ray.d[k] = fb(f);
            if (below(4) == 0) s->ray.d[k] = nudge(s->ray.d[k]);
        }
        q_tstar(t, s);
        q_f_at(q, s, t);
        s->r = sqrt_near(q);
        random_t(s);
        if (below(2)) s->ray.tmin = fb(qd_to_f(t)), s->ray.tmax = F_INF;
    } else { /* t* (nearly) at tmin or tmax, r about the distance there */
        for (int k = 0; k < 3; k++) s->ray.d[k] = wide((int)below(2), ed + (int)range(-3, 3));
        if (below(2)) { /* d nearly perpendicular to w = c - o: B = w . d cancels, t* near 0 */
            double w[3], u[3];
            for (int k = 0; k < 3; k++) {
                q_f32(q, s->c[k]);
                q_f32(t, s->ray.o[k]);
                mpq_sub(q, q, t);
                w[k] = mpq_get_d(q);
                q_f32(q, s->ray.d[k]);
                u[k] = mpq_get_d(q);
            }
            double v[3], m = 0;
            for (int k = 0; k < 3; k++) {
                int i = (k + 1) % 3, j = (k + 2) % 3;
                v[k] = w[i] * u[j] - w[j] * u[i];
                m = v[k] > m ? v[k] : -v[k] > m ? -v[k] : m;
            }
            for (int k = 0; k < 3; k++) s->ray.d[k] = m > 0 ? fb((float)(v[k] / m * 0x1p20)) : F_ONE;
            if (cbvh_f32_is_zero(s->ray.d[0]) && cbvh_f32_is_zero(s->ray.d[1]) && cbvh_f32_is_zero(s->ray.d[2]))
                s->ray.d[0] = F_ONE;
        }
        q_tstar(t, s);
        cbvh_f32 tb = fb(qd_to_f(t));
        if (below(2)) tb = nudge(tb);
        if (cbvh_f32_is_nan_or_inf(tb)) tb = 0;
        if (kind == 1) s->ray.tmin = tb, s->ray.tmax = below(2) ? F_INF : nudge(nudge(tb));
        else s->ray.tmax = tb, s->ray.tmin = below(2) ? CBVH_F32_MAX | CBVH_F32_SIGN : nudge(nudge(tb));
        if (cbvh_f32_key(s->ray.tmin) > cbvh_f32_key(s->ray.tmax)) {
            cbvh_f32 x = s->ray.tmin;
            s->ray.tmin = s->ray.tmax, s->ray.tmax = x;
        }
        q_f32(t, kind == 1 ? s->ray.tmin : s->ray.tmax);
        q_f_at(q, s, t);
        s->r = sqrt_near(q);
    }
    mpq_clears(q, t, NULL);
}

static void gen_any(scase *s) {
    uint64_t k = below(10);
    if (k < 3) gen_hard(s, 0);
    else if (k < 5) gen_hard(s, 1);
    else if (k < 7) gen_deep(s);
    else gen_random(s);
}

static void show(const char *what, const scase *s, int got, int want) {
    CHECK(got == want,
          "%s: got %d want %d: o=%08X %08X %08X d=%08X %08X %08X t=[%08X,%08X] c=%08X %08X %08X r=%08X", what,
          got, want, s->ray.o[0], s->ray.o[1], s->ray.o[2], s->ray.d[0], s->ray.d[1], s->ray.d[2], s->ray.tmin,
          s->ray.tmax, s->c[0], s->c[1], s->c[2], s->r);
}

/* ---- tests -------------------------------------------------------------------------- */

static int unit(const scase *s, uint32_t *st) {
    int hit = -1;
    *st = cbvh_ray_sphere(&s->ray, s->c, s->r, &hit);
    return hit;
}

static scase base(void) {
    /* ray from (-5,0,0) along +x through the unit sphere at the origin */
    scase s = {{{0xC0A00000u, 0, 0}, {F_ONE, 0, 0}, 0, F_INF}, {0, 0, 0}, F_ONE};
    return s;
}

static void test_status(void) {
    static const cbvh_f32 bad[] = {F_NAN, 0x7F800001u, 0xFFC00000u, F_INF, CBVH_F32_NEG_INF};
    uint32_t st;
    for (int b = 0; b < 5; b++) {
        for (int port = 0; port < 8; port++) {
            scase s = base();
            cbvh_f32 *p = port < 3 ? &s.ray.o[port] : port < 6 ? &s.ray.d[port - 3] : port == 6 ? &s.ray.tmin
                                                                                               : &s.ray.tmax;
            *p = bad[b];
            int hit = unit(&s, &st);
            uint32_t want = (port == 7 && bad[b] == F_INF) ? 0 : CBVH_ST_NAN_INF;
            CHECK(st == want && hit == (want ? 0 : 1), "ray port %d = %08X: status %X hit %d", port, bad[b], st, hit);
        }
        for (int port = 0; port < 4; port++) {
            scase s = base();
            cbvh_f32 *p = port < 3 ? &s.c[port] : &s.r;
            *p = bad[b];
            int hit = unit(&s, &st);
            CHECK(st == CBVH_ST_BAD_PARAM && hit == 0, "sphere port %d = %08X: status %X hit %d", port, bad[b], st,
                  hit);
        }
    }
    scase s = base();
    s.ray.d[0] = CBVH_F32_SIGN;
    int hit = unit(&s, &st);
    CHECK(st == CBVH_ST_ZERO_DIR && hit == 0, "zero direction: status %X hit %d", st, hit);
    s.r = 0xBF800000u; /* -1: both bits */
    hit = unit(&s, &st);
    CHECK(st == (CBVH_ST_ZERO_DIR | CBVH_ST_BAD_PARAM) && hit == 0, "zero dir + r < 0: status %X", st);
    s = base();
    s.r = 0x80000001u; /* -tiny */
    hit = unit(&s, &st);
    CHECK(st == CBVH_ST_BAD_PARAM && hit == 0, "r = -2^-149: status %X", st);
    s = base();
    s.r = CBVH_F32_SIGN; /* -0: a point sphere at the origin, on the ray */
    hit = unit(&s, &st);
    CHECK(st == 0 && hit == 1, "r = -0: status %X hit %d", st, hit);
    s = base();
    s.ray.tmin = 0x40000000u, s.ray.tmax = F_ONE; /* empty segment */
    hit = unit(&s, &st);
    CHECK(st == 0 && hit == 0, "tmin > tmax: status %X hit %d", st, hit);
    /* the exact path alone gives the same statuses */
    s = base();
    s.c[1] = F_NAN;
    st = cbvh_ray_sphere_exact_only(&s.ray, s.c, s.r, &hit);
    CHECK(st == CBVH_ST_BAD_PARAM && hit == 0, "exact_only status %X", st);
}

/* Named exact cases and their one-ulp neighbours. */
static void named(const char *what, scase s, int want) {
    uint32_t st;
    int hit = unit(&s, &st);
    CHECK(st == 0, "%s: status %X", what, st);
    show(what, &s, hit, want);
    show(what, &s, oracle(&s), want);
    int ex;
    cbvh_ray_sphere_exact_only(&s.ray, s.c, s.r, &ex);
    show(what, &s, ex, want);
}

static void test_named(void) {
    scase s;
    /* tangent: the line y = 1 touches the unit sphere at (0,1,0) */
    s = base();
    s.ray.o[1] = F_ONE;
    named("tangent", s, 1);
    s.ray.o[1] = 0x3F800001u;
    named("tangent + 1 ulp", s, 0);
    s.ray.o[1] = F_ONE, s.r = 0x3F7FFFFFu;
    named("tangent, r - 1 ulp", s, 0);
    /* tangent point exactly at tmax = 5, and one ulp before */
    s = base();
    s.ray.o[1] = F_ONE, s.ray.tmax = 0x40A00000u;
    named("tangent at tmax", s, 1);
    s.ray.tmax = 0x409FFFFFu;
    named("tangent just after tmax", s, 0);
    /* tangent point exactly at tmin = 5 */
    s.ray.tmin = 0x40A00000u, s.ray.tmax = F_INF;
    named("tangent at tmin", s, 1);
    s.ray.tmin = 0x40A00001u;
    named("tangent just before tmin", s, 0);
    /* 3-4-5: o = (-3, 4, 0) + ..., d = (3, 4, 0)/: c - o = (3, -4, 0) ⊥ d?  (3*3 - 4*4 != 0); use d = (4, 3, 0) */
    s = base();
    s.ray.o[0] = 0xC0400000u, s.ray.o[1] = 0x40800000u; /* (-3, 4, 0): |w| = 5, w . d = 0 for d = (4, 3, 0) */
    s.ray.d[0] = 0x40800000u, s.ray.d[1] = 0x40400000u;
    s.r = 0x40A00000u; /* r = 5: o on the surface, tangent there */
    named("origin on the surface, tangent", s, 1);
    s.ray.tmin = 0x00000001u; /* just past the touching point */
    named("tangent, tmin = 2^-149 past the touch", s, 0);
    /* origin on the surface, leaving: d = -w = (3, -4, 0) points... d = (-3, 4, 0) points away from c */
    s = base();
    s.ray.o[0] = 0xC0400000u, s.ray.o[1] = 0x40800000u;
    s.ray.d[0] = 0xC0400000u, s.ray.d[1] = 0x40800000u;
    s.r = 0x40A00000u;
    named("origin on the surface, leaving", s, 1);
    s.r = 0x409FFFFFu;
    named("origin just outside, leaving", s, 0);
    s.ray.tmin = 0xBF800000u; /* tmin = -1: the segment reaches back inside */
    named("origin just outside, leaving, tmin = -1", s, 1);
    /* r = 0 through the centre */
    s = base();
    s.r = 0;
    named("r = 0, through the centre", s, 1);
    s.c[2] = 0x00000001u;
    named("r = 0, centre 2^-149 off the line", s, 0);
    s.r = 0x00000001u;
    named("r = 2^-149, centre 2^-149 off the line", s, 1);
    /* origin inside, every direction and bounded segment */
    s = base();
    s.ray.o[0] = 0x3F000000u;
    s.ray.tmax = 0x00000001u;
    named("origin inside, tiny segment", s, 1);
    /* sphere behind the origin */
    s = base();
    s.ray.d[0] = 0xBF800000u;
    named("sphere behind", s, 0);
    s.ray.tmin = CBVH_F32_MAX | CBVH_F32_SIGN;
    named("sphere behind, tmin = -FLT_MAX", s, 1);
    /* a point segment (tmin = tmax) on the surface */
    s = base();
    s.ray.tmin = s.ray.tmax = 0x40800000u; /* t = 4: p = (-1, 0, 0) */
    named("point segment on the surface", s, 1);
    s.ray.tmin = s.ray.tmax = 0x407FFFFFu;
    named("point segment just outside", s, 0);
    /* huge: sphere of radius 2^127 at FLT_MAX, ray from -FLT_MAX */
    s = base();
    s.ray.o[0] = CBVH_F32_MAX | CBVH_F32_SIGN;
    s.c[0] = CBVH_F32_MAX, s.c[1] = 0x7F000000u, s.r = 0x7F000000u;
    s.ray.d[0] = 0x00000001u;
    named("huge tangent, tiny direction", s, 1);
    s.r = 0x7EFFFFFFu;
    named("huge near-tangent, tiny direction", s, 0);
}

static void test_oracle(void) {
    long hits = 0;
    for (long i = 0; i < N_ORACLE; i++) {
        scase s;
        gen_any(&s);
        uint32_t st;
        int hit = unit(&s, &st);
        CHECK(st == 0, "status %X on a valid input", st);
        int want = oracle(&s);
        show("oracle", &s, hit, want);
        hits += want;
    }
    printf("oracle: %d inputs, %ld hits\n", N_ORACLE, hits);
    CHECK(hits > N_ORACLE / 5 && hits < N_ORACLE - N_ORACLE / 5, "unbalanced hit/miss mix: %ld hits", hits);
}

/* The fast path's error bound itself: |y^ - y| <= 2^-49 A^ for each of its
 * polynomials, y exact (GMP).  Also reports the largest |y^ - y| / A^ seen
 * (a sanity check that the evaluation does round: it must exceed 2^-60). */
static void q_poly(mpq_t out, const scase *s, int which) {
    mpq_t d[3], w[3], A, B, t, x, y;
    for (int k = 0; k < 3; k++) mpq_inits(d[k], w[k], NULL);
    mpq_inits(A, B, t, x, y, NULL);
    for (int k = 0; k < 3; k++) {
        q_f32(d[k], s->ray.d[k]);
        q_f32(w[k], s->c[k]);
        q_f32(x, s->ray.o[k]);
        mpq_sub(w[k], w[k], x);
        mpq_mul(x, d[k], d[k]);
        mpq_add(A, A, x);
        mpq_mul(x, w[k], d[k]);
        mpq_add(B, B, x);
    }
    q_f32(y, s->r);
    mpq_mul(y, y, y); /* R */
    mpq_set_ui(out, 0, 1);
    if (which == 0) {
        for (int k = 0; k < 3; k++) {
            int i = (k + 1) % 3, j = (k + 2) % 3;
            mpq_mul(x, w[i], d[j]);
            mpq_mul(t, w[j], d[i]);
            mpq_sub(x, x, t);
            mpq_mul(x, x, x);
            mpq_add(out, out, x);
        }
        mpq_mul(x, y, A);
        mpq_sub(out, out, x);
    } else if (which == 1 || which == 3) {
        q_f32(t, which == 1 ? s->ray.tmin : s->ray.tmax);
        mpq_mul(x, t, A);
        mpq_sub(out, B, x);
        if (which == 3) mpq_neg(out, out);
    } else {
        q_f32(t, which == 2 ? s->ray.tmin : s->ray.tmax);
        for (int k = 0; k < 3; k++) {
            mpq_mul(x, t, d[k]);
            mpq_sub(x, x, w[k]);
            mpq_mul(x, x, x);
            mpq_add(out, out, x);
        }
        mpq_sub(out, out, y);
    }
    for (int k = 0; k < 3; k++) mpq_clears(d[k], w[k], NULL);
    mpq_clears(A, B, t, x, y, NULL);
}

static void test_bound(void) {
    double worst = 0;
    mpq_t exact, got, err, lim;
    mpq_inits(exact, got, err, lim, NULL);
    for (long i = 0; i < N_ORACLE / 8; i++) {
        scase s;
        gen_any(&s);
        double y[5], ay[5];
        int n = cbvh_ray_sphere_fast_terms(&s.ray, s.c, s.r, y, ay);
        for (int j = 0; j < n; j++) {
            q_poly(exact, &s, j);
            mpq_set_d(got, y[j]);
            mpq_sub(err, got, exact);
            mpq_abs(err, err);
            mpq_set_d(lim, ay[j]);
            if (mpq_sgn(lim) == 0) {
                CHECK(mpq_sgn(err) == 0, "term %d: A^ = 0 but y^ != y", j);
                continue;
            }
            mpq_div(err, err, lim);
            double ratio = mpq_get_d(err);
            if (ratio > worst) worst = ratio;
            mpq_set_d(lim, CBVH_RAY_SPHERE_REL_BOUND);
            if (mpq_cmp(err, lim) >= 0) show("error bound", &s, j, -1);
        }
    }
    mpq_clears(exact, got, err, lim, NULL);
    printf("error bound: largest |y^ - y| / A^ = 2^%.2f (bound 2^-49)\n", worst > 0 ? log2(worst) : -INFINITY);
    CHECK(worst > 0x1p-60, "the binary64 evaluation never rounded: %g", worst);
}

static void test_fast(void) {
    long decided = 0, decided_hard = 0, hard = 0, hits = 0;
    for (long i = 0; i < N_FAST; i++) {
        scase s;
        gen_any(&s);
        uint32_t st;
        int hit = unit(&s, &st);
        int ex = -1;
        uint32_t st2 = cbvh_ray_sphere_exact_only(&s.ray, s.c, s.r, &ex);
        CHECK(st == st2, "status %X vs exact %X", st, st2);
        show("unit vs exact", &s, hit, ex);
        hits += ex;
        if (cbvh_f32_key(s.ray.tmin) > cbvh_f32_key(s.ray.tmax)) continue;
        int f = cbvh_ray_sphere_fast_only(&s.ray, s.c, s.r);
        if (f >= 0) {
            decided++;
            show("fast path vs exact", &s, f, ex);
        }
    }
    /* the hard constructions alone: how often the fast path still decides */
    for (long i = 0; i < N_FAST / 4; i++) {
        scase s;
        gen_hard(&s, (int)(i & 1));
        if (cbvh_f32_key(s.ray.tmin) > cbvh_f32_key(s.ray.tmax)) continue;
        int ex;
        cbvh_ray_sphere_exact_only(&s.ray, s.c, s.r, &ex);
        int f = cbvh_ray_sphere_fast_only(&s.ray, s.c, s.r);
        hard++;
        if (f >= 0) {
            decided_hard++;
            show("fast path vs exact (hard)", &s, f, ex);
        }
    }
    printf("fast path: %d inputs (%ld hits), decided %.2f%%; hard constructions: decided %.2f%% of %ld\n", N_FAST,
           hits, 100.0 * (double)decided / N_FAST, 100.0 * (double)decided_hard / (double)hard, hard);
    CHECK(decided > N_FAST / 2, "fast path decides too little: %ld", decided);
}

int main(void) {
    test_status();
    test_named();
    test_oracle();
    test_bound();
    test_fast();
    if (failures) {
        fprintf(stderr, "%ld failure(s)\n", failures);
        return 1;
    }
    printf("ray_sphere: all checks passed\n");
    return 0;
}
