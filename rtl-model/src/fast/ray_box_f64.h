/* Binary64 filter for the ray-box unit (docs/traversal.md §9, "Ray-box in
 * the traversals: binary64 filter").  Internal to rtl-model; used by the traversals.
 *
 * The unit's plane distance is t = (P - o) / d, exact, rounded to M bits
 * toward -Inf (near) or +Inf (far).  Here, with the plane P and the origin o
 * exact in binary64 and inv = fl(1 / d) prepared once per ray,
 *     t^ = fl(fl(P - o) * inv) = t (1 + e1)(1 + e2)(1 + e3),  |ei| <= 2^-53
 * (no underflow or overflow: P - o is a nonzero multiple of 2^-149 below
 * 2^137, 1/d lies in (2^-128, 2^149]).  So |t^ - t| <= ((1 + u)^3 - 1) |t|
 * with u = 2^-53, and since |t| <= |t^| / (1 - 3.01u) and |t^| < 2^(E+1)
 * (E = t^'s binary exponent), |t^ - t| < 3.01 * 2^(E-52): less than 3.01
 * units in the last place of t^.  The M-bit grid in t^'s binade is the
 * multiples of 2^K ulps, K = 53 - M.  The box test rounds only the largest
 * near and the smallest far estimate (see cbvh_rbf_box: the true extreme
 * lies within 6.02 ulps of it); if the low K bits L of that t^ satisfy
 * 8 <= L <= 2^K - 8, the true value lies strictly inside t^'s M-bit cell, so
 * RD_M and RU_M are the cell's ends (mirrored for t < 0) and it is not on the
 * grid.  With E in [-126, 126] these are normal binary32 values, which is
 * what the unit packs.  Every other case (t^ = 0, t^ near a grid point, E out
 * of range, non-finite inputs, an inverted box) is left undecided and the
 * caller runs the unit itself.  The slab logic then only compares the
 * rounded values (binary64 order equals the unit's key order, -0 == +0).
 *
 * Needs binary64 arithmetic without excess precision (FLT_EVAL_METHOD 0) in
 * round-to-nearest; elsewhere the filter is switched off.  The files using
 * it are compiled with -ffp-contract=off; the only product that is added
 * (r 2^e in a grid plane u + r 2^e) is exact, so a fused multiply-add would
 * give the same value anyway. */
#ifndef CBVH_RAY_BOX_F64_H
#define CBVH_RAY_BOX_F64_H

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "cbvh/traversal_units.h"
#include "fast/fast_paths.h"

#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0 && CBVH_FAST_PATHS
#define CBVH_RBF_ENABLED 1
#else
#define CBVH_RBF_ENABLED 0
#endif

#if defined(__SSE2__) && !defined(CBVH_NO_SSE2)
#define CBVH_RBF_SSE2 1
#include <emmintrin.h>
#else
#define CBVH_RBF_SSE2 0
#endif

typedef struct {
    double o[3], inv[3];
    double tmin;
    uint64_t mask; /* 2^K - 1, K = 53 - M */
    int near_hi[3]; /* d_a < 0: the near plane is the upper one */
    int near_at[3], far_at[3]; /* index of axis a's near / far plane of box 0 in a [2][3][2] plane array */
    int ok;         /* the filter applies to this ray (finite, no zero d_a, valid M) */
    _Alignas(16) double o2[3][2], inv2[3][2]; /* o, inv twice: an SSE2 register's two lanes */
} cbvh_rbf_ray;

static inline double cbvh_rbf_f32(cbvh_f32 b) { return (double)cbvh_float_of(b); }

/* exact for the values passed (binary32 or M-bit normal) */
static inline cbvh_f32 cbvh_rbf_to_f32(double x) { return cbvh_f32_of((float)x); }

static inline uint64_t cbvh_rbf_bits(double x) {
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

static inline double cbvh_rbf_from_bits(uint64_t b) {
    double x;
    memcpy(&x, &b, sizeof x);
    return x;
}

/* 2^e as a binary64, e in [-1022, 1023]. */
static inline double cbvh_rbf_pow2(int e) { return cbvh_rbf_from_bits((uint64_t)(e + 1023) << 52); }

static inline void cbvh_rbf_prepare(const cbvh_ray *ray, int M, cbvh_rbf_ray *p) {
    p->mask = 0; /* every other field is set below */
    p->ok = CBVH_RBF_ENABLED && M >= CBVH_MANT_MIN && M <= CBVH_MANT_MAX && !cbvh_f32_is_nan_or_inf(ray->tmin);
    for (int a = 0; a < 3; a++) {
        if (cbvh_f32_is_nan_or_inf(ray->o[a]) || cbvh_f32_is_nan_or_inf(ray->d[a]) || cbvh_f32_is_zero(ray->d[a]))
            p->ok = 0;
        p->o[a] = cbvh_rbf_f32(ray->o[a]);
        double d = cbvh_rbf_f32(ray->d[a]);
        p->inv[a] = 1.0 / d;
        p->near_hi[a] = d < 0;
        p->near_at[a] = 6 * (d < 0) + 2 * a; /* an index, not a branch per axis and box pair */
        p->far_at[a] = 6 * !(d < 0) + 2 * a;
        p->o2[a][0] = p->o2[a][1] = p->o[a];
        p->inv2[a][0] = p->inv2[a][1] = p->inv[a];
    }
    p->tmin = cbvh_rbf_f32(ray->tmin);
    if (M >= CBVH_MANT_MIN && M <= CBVH_MANT_MAX) p->mask = (UINT64_C(1) << (53 - M)) - 1u;
    if (!p->ok) p->mask = 0;
}

/* Decidability of t^ (see the top of the file), with a margin of 8 ulps
 * (see cbvh_rbf_box): 1 if RD_M / RU_M of every real within 6.02 ulps of t^
 * are those of t^'s M-bit cell (and t^ is not on the grid). */
static inline int cbvh_rbf_decided(uint64_t b, uint64_t mask) {
    uint64_t ex = (b >> 52) & 0x7FFu;
    uint64_t low = b & mask;
    return ((ex - (1023u - 126u)) <= 252u) & ((low - 8u) <= mask - 15u); /* & : no branches */
}

/* RD_M and RU_M of the reals near a decided t^ (its M-bit cell's ends). */
static inline double cbvh_rbf_rd(uint64_t b, uint64_t mask) {
    return cbvh_rbf_from_bits((b >> 63) ? (b | mask) + 1u : b & ~mask);
}
static inline double cbvh_rbf_ru(uint64_t b, uint64_t mask) {
    return cbvh_rbf_from_bits((b >> 63) ? b & ~mask : (b | mask) + 1u);
}

/* The unit's slab test on exact binary64 planes lo[a] <= hi[a], finite (else
 * undecided).  Returns 1 and sets *hit and *t_near (the unit's t_near as
 * binary64, valid for a hit) when decided, else 0.  tmax is the unit's tmax
 * input as binary64.
 *
 * The unit's t_near is max(tmin, RD(n_x), RD(n_y), RD(n_z)) and, RD being
 * monotone (saturation and flushing included), max RD(n_a) = RD(N) with
 * N = max n_a; likewise min RU(f_a) = RU(F).  Only the largest estimate
 * n^_a* is rounded: N >= n_a* > n^_a* - 3.01 ulp(n^_a*), and if N = n_b > n_a*
 * then n^_b <= n^_a* while the two are within 3.01 (ulp(n^_a*) + ulp(n^_b))
 * of each other, so ulp(n^_b) <= 2 ulp(n^_a*) and N < n^_b + 3.01 ulp(n^_b)
 * <= n^_a* + 6.02 ulp(n^_a*).  A margin of 8 ulps on each side of the grid
 * point therefore gives RD(N) = RD of n^_a*'s cell (mirrored for F and RU). */
static inline int cbvh_rbf_box(const cbvh_rbf_ray *p, double tmax, const double lo[3], const double hi[3], int *hit,
                               double *t_near) {
    int ok = p->ok;
    double nh = -HUGE_VAL, fh = HUGE_VAL;
    for (int a = 0; a < 3; a++) {
        double w = hi[a] - lo[a]; /* >= 0 and finite iff lo <= hi, both finite */
        ok &= w >= 0 && w <= DBL_MAX;
        double pn = p->near_hi[a] ? hi[a] : lo[a];
        double pf = p->near_hi[a] ? lo[a] : hi[a];
        double n = (pn - p->o[a]) * p->inv[a], f = (pf - p->o[a]) * p->inv[a];
        nh = n > nh ? n : nh;
        fh = f < fh ? f : fh;
    }
    uint64_t bn = cbvh_rbf_bits(nh), bf = cbvh_rbf_bits(fh), mask = p->mask;
    ok &= cbvh_rbf_decided(bn, mask) & cbvh_rbf_decided(bf, mask);
    double n = cbvh_rbf_rd(bn, mask), f = cbvh_rbf_ru(bf, mask);
    double tn = n > p->tmin ? n : p->tmin, tf = f < tmax ? f : tmax;
    *hit = tn <= tf;
    *t_near = tn;
    return ok;
}

#if CBVH_RBF_SSE2
/* cbvh_rbf_decided for both lanes of b, when mask < 2^30: the exponent and
 * the low K bits sit in each lane's low 32 bits, where signed 32-bit compares
 * are exact; the verdict is spread over the lane's 64 bits.  lowmax is
 * mask - 6 in each 32-bit lane (low <= mask - 7). */
static inline __m128i cbvh_rbf_decided2(__m128i b, __m128i mask, __m128i lowmax) {
    __m128i ex = _mm_and_si128(_mm_srli_epi64(b, 52), _mm_set1_epi64x(0x7FF));
    __m128i low = _mm_and_si128(b, mask);
    __m128i ok = _mm_and_si128(_mm_cmpgt_epi32(ex, _mm_set1_epi32(1023 - 127)),
                               _mm_cmpgt_epi32(_mm_set1_epi32(1023 + 127), ex)); /* E in [-126, 126] */
    ok = _mm_and_si128(ok, _mm_and_si128(_mm_cmpgt_epi32(low, _mm_set1_epi32(7)), _mm_cmpgt_epi32(lowmax, low)));
    return _mm_shuffle_epi32(ok, _MM_SHUFFLE(2, 2, 0, 0));
}

/* Per lane: neg where b is negative, else pos (its sign spread over the lane). */
static inline __m128i cbvh_rbf_by_sign2(__m128i b, __m128i neg, __m128i pos) {
    __m128i s = _mm_shuffle_epi32(_mm_srai_epi32(b, 31), _MM_SHUFFLE(3, 3, 1, 1));
    return _mm_or_si128(_mm_and_si128(s, neg), _mm_andnot_si128(s, pos));
}

/* The end of cbvh_rbf_box2_core (valid planes) with both lanes in SSE2
 * registers: the same decidability tests, cbvh_rbf_rd / cbvh_rbf_ru, clamps
 * (maxpd(n, tmin) is n > tmin ? n : tmin, minpd(f, tmax) is f < tmax ? f :
 * tmax) and comparison, lane by lane. */
static inline int cbvh_rbf_finish2_sse2(const cbvh_rbf_ray *p, double tmax, __m128d vnh, __m128d vfh, int hit[2],
                                        double t_near[2]) {
    __m128i mask = _mm_set1_epi64x((long long)p->mask), lowmax = _mm_set1_epi32((int)p->mask - 6);
    __m128i bn = _mm_castpd_si128(vnh), bf = _mm_castpd_si128(vfh);
    __m128i dec = _mm_and_si128(cbvh_rbf_decided2(bn, mask, lowmax), cbvh_rbf_decided2(bf, mask, lowmax));
    __m128i one = _mm_set1_epi64x(1);
    __m128i n_up = _mm_add_epi64(_mm_or_si128(bn, mask), one), n_down = _mm_andnot_si128(mask, bn);
    __m128i f_up = _mm_add_epi64(_mm_or_si128(bf, mask), one), f_down = _mm_andnot_si128(mask, bf);
    __m128d n = _mm_castsi128_pd(cbvh_rbf_by_sign2(bn, n_up, n_down)); /* RD */
    __m128d f = _mm_castsi128_pd(cbvh_rbf_by_sign2(bf, f_down, f_up)); /* RU */
    __m128d tn = _mm_max_pd(n, _mm_set1_pd(p->tmin)), tf = _mm_min_pd(f, _mm_set1_pd(tmax));
    int hm = _mm_movemask_pd(_mm_cmple_pd(tn, tf));
    hit[0] = hm & 1;
    hit[1] = hm >> 1;
    _mm_storeu_pd(t_near, tn);
    return p->ok ? _mm_movemask_pd(_mm_castsi128_pd(dec)) : 0;
}
#endif

/* Element i of a plane array of binary32 (f32) or binary64 values. */
static inline double cbvh_rbf_plane(const void *planes, int f32, int i) {
    return f32 ? (double)((const float *)planes)[i] : ((const double *)planes)[i];
}

/* cbvh_rbf_box for two boxes at once (the children of a node): box c has
 * planes pl[0][a][c] (lower) and pl[1][a][c] (upper), a [2][3][2] array of
 * binary64, or of binary32 when f32 (their values exactly, converted on
 * loading).  Bit c of the result is set when box c is decided; hit[c] and
 * t_near[c] as for cbvh_rbf_box.  The same binary64 operations lane by lane,
 * written as plain C over two-element arrays (no compiler vector
 * extensions), or in SSE2 registers (see CBVH_RBF_SSE2). */
static inline int cbvh_rbf_box2_core(const cbvh_rbf_ray *p, double tmax, const void *pl, int f32, int check_planes,
                                     int hit[2], double t_near[2]) {
    double nh[2] = {-HUGE_VAL, -HUGE_VAL}, fh[2] = {HUGE_VAL, HUGE_VAL};
    int okv[2] = {1, 1};
#if CBVH_RBF_SSE2
    if (!check_planes) {
        __m128d vnh = _mm_set1_pd(-HUGE_VAL), vfh = _mm_set1_pd(HUGE_VAL);
        for (int a = 0; a < 3; a++) {
            __m128d vn, vf;
            if (f32) {
                const float *f = pl;
                vn = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(f + p->near_at[a]))));
                vf = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(f + p->far_at[a]))));
            } else {
                const double *d = pl;
                vn = _mm_loadu_pd(d + p->near_at[a]);
                vf = _mm_loadu_pd(d + p->far_at[a]);
            }
            __m128d o = _mm_load_pd(p->o2[a]), inv = _mm_load_pd(p->inv2[a]);
            vnh = _mm_max_pd(_mm_mul_pd(_mm_sub_pd(vn, o), inv), vnh);
            vfh = _mm_min_pd(_mm_mul_pd(_mm_sub_pd(vf, o), inv), vfh);
        }
        if (p->mask <= 0x3FFFFFFFu) /* M >= 23: the low K bits fit a 32-bit lane */
            return cbvh_rbf_finish2_sse2(p, tmax, vnh, vfh, hit, t_near);
        _mm_storeu_pd(nh, vnh);
        _mm_storeu_pd(fh, vfh);
    } else
#endif
    for (int a = 0; a < 3; a++) {
        for (int c = 0; c < 2; c++) {
            if (check_planes) {
                double w = cbvh_rbf_plane(pl, f32, 6 + 2 * a + c) - cbvh_rbf_plane(pl, f32, 2 * a + c);
                okv[c] &= (w >= 0) & (w <= DBL_MAX);
            }
            double n = (cbvh_rbf_plane(pl, f32, p->near_at[a] + c) - p->o[a]) * p->inv[a],
                   f = (cbvh_rbf_plane(pl, f32, p->far_at[a] + c) - p->o[a]) * p->inv[a];
            nh[c] = n > nh[c] ? n : nh[c];
            fh[c] = f < fh[c] ? f : fh[c];
        }
    }
    int res = 0;
    uint64_t mask = p->mask;
    for (int c = 0; c < 2; c++) {
        uint64_t bn = cbvh_rbf_bits(nh[c]), bf = cbvh_rbf_bits(fh[c]);
        int ok = p->ok & okv[c] & cbvh_rbf_decided(bn, mask) & cbvh_rbf_decided(bf, mask);
        double n = cbvh_rbf_rd(bn, mask), f = cbvh_rbf_ru(bf, mask);
        double tn = n > p->tmin ? n : p->tmin, tf = f < tmax ? f : tmax;
        hit[c] = tn <= tf;
        t_near[c] = tn;
        res |= ok << c;
    }
    return res;
}

static inline int cbvh_rbf_box2(const cbvh_rbf_ray *p, double tmax, const double pl[2][3][2], int hit[2],
                                double t_near[2]) {
    return cbvh_rbf_box2_core(p, tmax, pl, 0, 1, hit, t_near);
}

/* The same for planes known to satisfy lo < hi, both finite (the CBVH's
 * decoded grid planes u + r 2^e < u + s 2^e, exact in binary64): the
 * validity tests are skipped. */
static inline int cbvh_rbf_box2_valid(const cbvh_rbf_ray *p, double tmax, const double pl[2][3][2], int hit[2],
                                      double t_near[2]) {
    return cbvh_rbf_box2_core(p, tmax, pl, 0, 0, hit, t_near);
}

/* The same on binary32 planes (each exactly the binary64 plane). */
static inline int cbvh_rbf_box2_valid_f32(const cbvh_rbf_ray *p, double tmax, const float pl[2][3][2], int hit[2],
                                          double t_near[2]) {
    return cbvh_rbf_box2_core(p, tmax, pl, 1, 0, hit, t_near);
}

/* An axis of a node's context (u = clb, e = scale in [-126, 126]) in
 * binary64: u and 2^e, and whether
 * u + c 2^e is exact in binary64 for every c in [0, 2^10].  u = m 2^x with
 * m < 2^24 (x = -149 for a subnormal): with d = x - e, the sum is the integer
 * m 2^d + c (d >= 0, below 2^53 for d <= 29) or m + c 2^-d (d < 0, below 2^53
 * for d >= -42) times a power of two.  u = +-0: always exact.  u = -Inf
 * (-2^128): left to the units. */
typedef struct {
    double u, step;
    int exact;
} cbvh_rbf_axis;

static inline cbvh_rbf_axis cbvh_rbf_axis_prep(cbvh_f32 clb, int scale) {
    cbvh_rbf_axis r;
    r.step = cbvh_rbf_pow2(scale);
    r.u = 0;
    uint32_t mag = clb & ~CBVH_F32_SIGN;
    if (mag == 0) {
        r.exact = 1;
        return r;
    }
    uint32_t eu = cbvh_f32_exp_field(mag);
    int d = (eu ? (int)eu - CBVH_F32_ULP_BIAS : CBVH_F32_SUB_EXP) - scale;
    r.exact = eu != CBVH_F32_EXP_FIELD_MAX && d >= -42 && d <= 29;
    r.u = cbvh_rbf_f32(clb);
    return r;
}

/* RD of an exact binary64 x to binary32 (what cbvh_grid_pack does for the
 * decoder's exact sum), when the result is a normal number or zero; else 0. */
static inline int cbvh_rbf_rd32(double x, cbvh_f32 *out) {
    if (x == 0) {
        *out = 0; /* the decoder packs an exact zero sum as +0 */
        return 1;
    }
    uint64_t b = cbvh_rbf_bits(x), m = (UINT64_C(1) << 29) - 1u;
    if (((b >> 52) & 0x7FFu) - (1023u - 126u) > 252u) return 0;
    uint64_t r = (b >> 63) ? ((b & m) ? (b | m) + 1u : b) : b & ~m;
    *out = cbvh_rbf_to_f32(cbvh_rbf_from_bits(r));
    return 1;
}

#endif
