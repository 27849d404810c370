/* The plain floating-point traversal's box test (docs/traversal.md §11): a
 * conservative binary64 slab test of two boxes at once, not the M-bit unit.
 * Internal to rtl-model; tests/traversal/test_ray_box.c checks it against an
 * exact rational slab test.
 *
 * Error bound: for binary32 planes p, origin o and direction d != 0, the
 * binary64 value (p - o) * (1 / d) has three roundings, each <= 2^-53
 * relative, and no overflow or underflow (|p - o| is 0 or in [2^-149, 2^129),
 * |1 / d| in (2^-128, 2^149]), so it is within 3.0000001 * 2^-53 of the exact
 * plane distance, with its sign exact.  The computed near N and far F are
 * maxima / minima of such values and of the exact tmin / culling bound, so
 * N_exact <= F_exact implies N <= F + (|N| + |F|) * CBVH_REF_EPS, and
 * N - |N| * CBVH_REF_EPS <= N_exact. */
#ifndef CBVH_RAY_BOX_REF_H
#define CBVH_RAY_BOX_REF_H

#include <math.h>
#include <stdint.h>

#include "cbvh/fp32.h"
#include "cbvh/traversal_units.h"

#if defined(__SSE2__) && !defined(CBVH_NO_SSE2)
#define CBVH_REF_SSE2 1
#include <emmintrin.h>
#else
#define CBVH_REF_SSE2 0
#endif
#if CBVH_REF_SSE2 && defined(__AVX__)
#define CBVH_REF_AVX 1
#include <immintrin.h>
#else
#define CBVH_REF_AVX 0
#endif

#define CBVH_REF_EPS 0x1p-50 /* > 2 * 3.0000001 * 2^-53 */
/* The binary32 lanes (docs/traversal.md §16): magnitudes of origins, planes
 * and directions (and their inverses) within 2^62, and the margins. */
#define CBVH_REF32_LIMIT 0x1p62f
#define CBVH_REF32_LIMIT_BITS 0x5E800000u  /* 2^62 as binary32 */
#define CBVH_REF32_RLIMIT_BITS 0x20800000u /* 2^-62 */
#define CBVH_REF32_C0 (1.0f - 0x1p-20f)
#define CBVH_REF32_C1 (1.0f + 0x1p-20f)
#define CBVH_REF32_H 0x1p-140f

/* A plane the binary32 lanes take (|p| <= 2^62; not NaN). */
static inline int cbvh_ref32_plane_ok(float p) { return fabsf(p) <= CBVH_REF32_LIMIT; }

/* A pair of boxes as 12 binary32: plane (lo = 0, hi = 1) of axis a of child c
 * at [CBVH_REF_AT(plane, a, c)]; four boxes as 24 at [CBVH_REF4_AT(...)]. */
#define CBVH_REF_AT(plane, a, c) (((plane) * 3 + (a)) * 2 + (c))
#define CBVH_REF4_AT(plane, a, c) (((plane) * 3 + (a)) * 4 + (c))

typedef struct {
    double o[3], inv[3]; /* inv = 1 / d, 0 where d = +-0 */
    double tmin;
    int pn[3], pf[3]; /* CBVH_REF_AT(near / far plane, a, 0): the near plane is hi where d_a < 0 */
    int pn4[3], pf4[3]; /* the same for CBVH_REF4_AT */
    int general;      /* some d_a = +-0, or tmin < 0: cbvh_ref_box2_any, not cbvh_ref_box2 */
    int small;        /* !general, |o_a| <= 2^62, 2^-62 <= |d_a| <= 2^62: the binary32 lanes may run
                         (cbvh_ref_prepare32, docs/traversal.md §16; 0 until it runs) */
    float o32[3], inv32[3], tmin32; /* o, RN32(1 / d), tmin in binary32 (where small) */
    _Alignas(16) double o2[3][2], inv2[3][2]; /* o, inv twice: an SSE2 register's two lanes */
} cbvh_ref_ray;

/* Axis a's near and far plane offsets, for both layouts (both preparations):
 * the near plane is hi where d_a < 0. */
static inline void cbvh_ref_plane_order(cbvh_ref_ray *r, int a, int neg) {
    r->pn[a] = CBVH_REF_AT(neg, a, 0);
    r->pf[a] = CBVH_REF_AT(!neg, a, 0);
    r->pn4[a] = CBVH_REF4_AT(neg, a, 0);
    r->pf4[a] = CBVH_REF4_AT(!neg, a, 0);
}

/* For a ray the units accept (finite, d != 0). */
static inline void cbvh_ref_prepare(const cbvh_ray *ray, cbvh_ref_ray *r) {
    int axis_par = 0;
    for (int a = 0; a < 3; a++) {
        double d = cbvh_float_of(ray->d[a]);
        r->o[a] = cbvh_float_of(ray->o[a]);
        r->inv[a] = d != 0 ? 1.0 / d : 0;
        cbvh_ref_plane_order(r, a, d < 0);
        r->o2[a][0] = r->o2[a][1] = r->o[a];
        r->inv2[a][0] = r->inv2[a][1] = r->inv[a];
        axis_par |= d == 0;
    }
    r->tmin = cbvh_float_of(ray->tmin);
    r->general = axis_par || r->tmin < 0;
    r->small = 0;
}

/* The binary32 lanes' preparation (docs/traversal.md §16), alone or after
 * cbvh_ref_prepare: r->small, and where small r->general = 0, the planes'
 * order (pn, pf, pn4, pf4) and o, 1 / d (RN32) and tmin in binary32 - all
 * that the lanes read, so a small ray needs no binary64 preparation. */
static inline void cbvh_ref_prepare32(const cbvh_ray *ray, cbvh_ref_ray *r) {
    /* the limits as tests of the magnitude's bit pattern (branch-free; NaN's
     * is above 2^62's): |o| <= 2^62 and 2^-62 <= |d| <= 2^62 */
    uint32_t small = !(cbvh_float_of(ray->tmin) < 0);
    for (int a = 0; a < 3; a++) {
        uint32_t mo = ray->o[a] & ~CBVH_F32_SIGN, md = ray->d[a] & ~CBVH_F32_SIGN;
        small &= (mo <= CBVH_REF32_LIMIT_BITS) & (md - CBVH_REF32_RLIMIT_BITS <= CBVH_REF32_LIMIT_BITS - CBVH_REF32_RLIMIT_BITS);
        float d = cbvh_float_of(ray->d[a]);
        r->o32[a] = cbvh_float_of(ray->o[a]);
        cbvh_ref_plane_order(r, a, d < 0);
    }
    for (int a = 0; a < 3; a++) r->inv32[a] = small ? 1.0f / cbvh_float_of(ray->d[a]) : 0.0f;
    r->tmin32 = cbvh_float_of(ray->tmin);
    r->small = (int)small;
    if (small) r->general = 0; /* d != 0 and tmin >= 0 */
}

/* Two boxes (lo <= hi, finite) against [tmin, cull] for a ray without zero
 * direction components and tmin >= 0 (!r->general): hit[c] = 1 if the ray
 * may meet box c, and then t_lo[c] <= its exact entry t.  Here N >= 0 and F
 * has its exact sign, so N_exact <= F_exact implies N <= F * (1 + 2^-50) and
 * N * (1 - 2^-50) <= N_exact (the margins also cover these two products'
 * own roundings).  Both children go through the same operations: plain C
 * here, lane by lane in SSE2 registers in cbvh_ref_box2 (same results bit
 * for bit; tests/traversal/test_box_f64.c compares them). */
static inline void cbvh_ref_box2_c(const cbvh_ref_ray *r, const float box[12], double cull, int hit[2],
                                   double t_lo[2]) {
    double n0 = r->tmin, n1 = r->tmin, f0 = cull, f1 = cull;
    for (int a = 0; a < 3; a++) {
        const float *pn = box + r->pn[a], *pf = box + r->pf[a];
        double o = r->o[a], inv = r->inv[a];
        double tn0 = ((double)pn[0] - o) * inv, tn1 = ((double)pn[1] - o) * inv;
        double tf0 = ((double)pf[0] - o) * inv, tf1 = ((double)pf[1] - o) * inv;
        n0 = tn0 > n0 ? tn0 : n0;
        n1 = tn1 > n1 ? tn1 : n1;
        f0 = tf0 < f0 ? tf0 : f0;
        f1 = tf1 < f1 ? tf1 : f1;
    }
    t_lo[0] = n0 * (1 - CBVH_REF_EPS);
    t_lo[1] = n1 * (1 - CBVH_REF_EPS);
    hit[0] = n0 <= f0 * (1 + CBVH_REF_EPS);
    hit[1] = n1 <= f1 * (1 + CBVH_REF_EPS);
}

/* cbvh_ref_box2_c with child c in lane c: a child's two planes of an axis
 * are adjacent binary32 values, loaded and widened together; maxpd(t, n) is
 * t > n ? t : n and minpd(t, f) is t < f ? t : f, as in the C. */
static inline void cbvh_ref_box2(const cbvh_ref_ray *r, const float box[12], double cull, int hit[2],
                                 double t_lo[2]) {
#if CBVH_REF_SSE2
    __m128d n = _mm_set1_pd(r->tmin), f = _mm_set1_pd(cull);
    for (int a = 0; a < 3; a++) {
        __m128d pn = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(box + r->pn[a]))));
        __m128d pf = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(box + r->pf[a]))));
        __m128d o = _mm_set1_pd(r->o[a]), inv = _mm_set1_pd(r->inv[a]);
        n = _mm_max_pd(_mm_mul_pd(_mm_sub_pd(pn, o), inv), n);
        f = _mm_min_pd(_mm_mul_pd(_mm_sub_pd(pf, o), inv), f);
    }
    _mm_storeu_pd(t_lo, _mm_mul_pd(n, _mm_set1_pd(1 - CBVH_REF_EPS)));
    int hm = _mm_movemask_pd(_mm_cmple_pd(n, _mm_mul_pd(f, _mm_set1_pd(1 + CBVH_REF_EPS))));
    hit[0] = hm & 1;
    hit[1] = hm >> 1;
#else
    cbvh_ref_box2_c(r, box, cull, hit, t_lo);
#endif
}

/* Any valid ray (zero direction components, tmin < 0): an axis with d_a = 0
 * constrains nothing where o_a lies in the closed slab, else the box is
 * missed; the slack is the sign-free N <= F + (|N| + |F|) * 2^-50.  w boxes
 * (2, 4 or 8), plane of axis a of box c at ((plane * 3) + a) * w + c. */
static inline void cbvh_ref_boxw_any(const cbvh_ref_ray *r, const float *box, int w, double cull, int *hit,
                                     double *t_lo) {
    for (int c = 0; c < w; c++) {
        double nn = r->tmin, ff = cull;
        int in = 1;
        for (int a = 0; a < 3; a++) {
            double lo = box[(0 * 3 + a) * w + c], hi = box[(1 * 3 + a) * w + c];
            if (r->inv[a] == 0) {
                in &= r->o[a] >= lo && r->o[a] <= hi;
                continue;
            }
            int neg = r->inv[a] < 0;
            double tn = ((neg ? hi : lo) - r->o[a]) * r->inv[a];
            double tf = ((neg ? lo : hi) - r->o[a]) * r->inv[a];
            nn = tn > nn ? tn : nn;
            ff = tf < ff ? tf : ff;
        }
        t_lo[c] = nn - fabs(nn) * CBVH_REF_EPS;
        hit[c] = in && nn <= ff + (fabs(nn) + fabs(ff)) * CBVH_REF_EPS;
    }
}

static inline void cbvh_ref_box2_any(const cbvh_ref_ray *r, const float box[12], double cull, int hit[2],
                                     double t_lo[2]) {
    cbvh_ref_boxw_any(r, box, 2, cull, hit, t_lo);
}

/* cbvh_ref_box2_c on w boxes (4 or 8; plane of axis a of box c at
 * ((plane * 3) + a) * w + c): the plain C of cbvh_ref_box4 / box8.  Returns
 * the hit mask (bit c for box c). */
static inline int cbvh_ref_boxw_c(const cbvh_ref_ray *r, const float *box, int w, double cull, double *t_lo) {
    int m = 0;
    for (int c = 0; c < w; c++) {
        double n = r->tmin, f = cull;
        for (int a = 0; a < 3; a++) {
            double tn = ((double)box[r->pn4[a] / 4 * w + c] - r->o[a]) * r->inv[a];
            double tf = ((double)box[r->pf4[a] / 4 * w + c] - r->o[a]) * r->inv[a];
            n = tn > n ? tn : n;
            f = tf < f ? tf : f;
        }
        t_lo[c] = n * (1 - CBVH_REF_EPS);
        m |= (n <= f * (1 + CBVH_REF_EPS)) << c;
    }
    return m;
}

/* cbvh_ref_box2 on four boxes (a 4-wide node, planes at CBVH_REF4_AT):
 * lane by lane the same operations, so the same results as cbvh_ref_box2_c
 * on any two of them.  Returns the hit mask (bit c for box c). */
static inline int cbvh_ref_box4(const cbvh_ref_ray *r, const float box[24], double cull, double t_lo[4]) {
#if CBVH_REF_AVX
    __m256d n = _mm256_set1_pd(r->tmin), f = _mm256_set1_pd(cull);
    for (int a = 0; a < 3; a++) {
        __m256d o = _mm256_set1_pd(r->o[a]), inv = _mm256_set1_pd(r->inv[a]);
        __m256d pn = _mm256_cvtps_pd(_mm_loadu_ps(box + r->pn4[a]));
        __m256d pf = _mm256_cvtps_pd(_mm_loadu_ps(box + r->pf4[a]));
        n = _mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(pn, o), inv), n);
        f = _mm256_min_pd(_mm256_mul_pd(_mm256_sub_pd(pf, o), inv), f);
    }
    _mm256_storeu_pd(t_lo, _mm256_mul_pd(n, _mm256_set1_pd(1 - CBVH_REF_EPS)));
    return _mm256_movemask_pd(_mm256_cmp_pd(n, _mm256_mul_pd(f, _mm256_set1_pd(1 + CBVH_REF_EPS)), _CMP_LE_OS));
#elif CBVH_REF_SSE2
    __m128d n01 = _mm_set1_pd(r->tmin), n23 = n01, f01 = _mm_set1_pd(cull), f23 = f01;
    for (int a = 0; a < 3; a++) { /* lanes c, c + 1 of a plane row: two binary32 widened */
        const float *pn = box + r->pn4[a], *pf = box + r->pf4[a];
        __m128d o = _mm_load_pd(r->o2[a]), inv = _mm_load_pd(r->inv2[a]);
        __m128d pn01 = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)pn)));
        __m128d pn23 = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(pn + 2))));
        __m128d pf01 = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)pf)));
        __m128d pf23 = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(pf + 2))));
        n01 = _mm_max_pd(_mm_mul_pd(_mm_sub_pd(pn01, o), inv), n01);
        n23 = _mm_max_pd(_mm_mul_pd(_mm_sub_pd(pn23, o), inv), n23);
        f01 = _mm_min_pd(_mm_mul_pd(_mm_sub_pd(pf01, o), inv), f01);
        f23 = _mm_min_pd(_mm_mul_pd(_mm_sub_pd(pf23, o), inv), f23);
    }
    __m128d lo = _mm_set1_pd(1 - CBVH_REF_EPS), hi = _mm_set1_pd(1 + CBVH_REF_EPS);
    _mm_storeu_pd(t_lo, _mm_mul_pd(n01, lo));
    _mm_storeu_pd(t_lo + 2, _mm_mul_pd(n23, lo));
    return _mm_movemask_pd(_mm_cmple_pd(n01, _mm_mul_pd(f01, hi))) |
           _mm_movemask_pd(_mm_cmple_pd(n23, _mm_mul_pd(f23, hi))) << 2;
#else
    return cbvh_ref_boxw_c(r, box, 4, cull, t_lo);
#endif
}

/* cbvh_ref_box4 on eight boxes (an 8-wide node, plane of axis a of box c at
 * ((plane * 3) + a) * 8 + c: twice the 4-wide offsets): lanes 2k, 2k + 1 in
 * register pair k, the same operations per box as cbvh_ref_box2_c.  Returns
 * the hit mask (bit c for box c). */
static inline int cbvh_ref_box8(const cbvh_ref_ray *r, const float box[48], double cull, double t_lo[8]) {
#if CBVH_REF_AVX
    __m256d n0 = _mm256_set1_pd(r->tmin), n1 = n0, f0 = _mm256_set1_pd(cull), f1 = f0;
    for (int a = 0; a < 3; a++) {
        const float *pn = box + 2 * r->pn4[a], *pf = box + 2 * r->pf4[a];
        __m256d o = _mm256_set1_pd(r->o[a]), inv = _mm256_set1_pd(r->inv[a]);
        n0 = _mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(pn)), o), inv), n0);
        n1 = _mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(pn + 4)), o), inv), n1);
        f0 = _mm256_min_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(pf)), o), inv), f0);
        f1 = _mm256_min_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(pf + 4)), o), inv), f1);
    }
    __m256d lo = _mm256_set1_pd(1 - CBVH_REF_EPS), hi = _mm256_set1_pd(1 + CBVH_REF_EPS);
    _mm256_storeu_pd(t_lo, _mm256_mul_pd(n0, lo));
    _mm256_storeu_pd(t_lo + 4, _mm256_mul_pd(n1, lo));
    return _mm256_movemask_pd(_mm256_cmp_pd(n0, _mm256_mul_pd(f0, hi), _CMP_LE_OS)) |
           _mm256_movemask_pd(_mm256_cmp_pd(n1, _mm256_mul_pd(f1, hi), _CMP_LE_OS)) << 4;
#elif CBVH_REF_SSE2
    __m128d n[4], f[4];
    for (int k = 0; k < 4; k++) {
        n[k] = _mm_set1_pd(r->tmin);
        f[k] = _mm_set1_pd(cull);
    }
    for (int a = 0; a < 3; a++) {
        const float *pn = box + 2 * r->pn4[a], *pf = box + 2 * r->pf4[a];
        __m128d o = _mm_load_pd(r->o2[a]), inv = _mm_load_pd(r->inv2[a]);
        for (int k = 0; k < 4; k++) {
            __m128d tn = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(pn + 2 * k))));
            __m128d tf = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(pf + 2 * k))));
            n[k] = _mm_max_pd(_mm_mul_pd(_mm_sub_pd(tn, o), inv), n[k]);
            f[k] = _mm_min_pd(_mm_mul_pd(_mm_sub_pd(tf, o), inv), f[k]);
        }
    }
    __m128d lo = _mm_set1_pd(1 - CBVH_REF_EPS), hi = _mm_set1_pd(1 + CBVH_REF_EPS);
    int m = 0;
    for (int k = 0; k < 4; k++) {
        _mm_storeu_pd(t_lo + 2 * k, _mm_mul_pd(n[k], lo));
        m |= _mm_movemask_pd(_mm_cmple_pd(n[k], _mm_mul_pd(f[k], hi))) << 2 * k;
    }
    return m;
#else
    return cbvh_ref_boxw_c(r, box, 8, cull, t_lo);
#endif
}

/* The binary32 lanes of docs/traversal.md §16, for a small ray (r->small)
 * and planes of magnitude <= 2^62: per box and axis T = RN32(RN32(p - o) *
 * inv32), N = max(tmin, T_near...), F = min(cull, T_far...), hit when
 * N <= RN32(RN32(F * C1) + H), t_lo = RN32(RN32(N * C0) - H) widened.  One
 * box, its near and far planes of axis a at box[pn[a]], box[pf[a]] (the
 * root's test: r->pn, r->pf); cull a binary32 value.  Returns 1 on a hit. */
static inline int cbvh_ref_box32_one(const cbvh_ref_ray *r, const float *box, const int pn[3], const int pf[3],
                                     float cull, double *t_lo) {
    float n = r->tmin32, f = cull;
    for (int a = 0; a < 3; a++) {
        float tn = (box[pn[a]] - r->o32[a]) * r->inv32[a];
        float tf = (box[pf[a]] - r->o32[a]) * r->inv32[a];
        n = tn > n ? tn : n;
        f = tf < f ? tf : f;
    }
    float lo = n * CBVH_REF32_C0, hi = f * CBVH_REF32_C1;
    *t_lo = (double)(lo - CBVH_REF32_H);
    return n <= hi + CBVH_REF32_H;
}

/* The same for all w boxes of a row (2, 4 or 8; plane of axis a of box c at
 * ((plane * 3) + a) * w + c): the hit mask, bit c for box c - what the SIMD
 * versions below compute lane by lane. */
static inline int cbvh_ref_boxw32_c(const cbvh_ref_ray *r, const float *box, int w, float cull, double *t_lo) {
    int m = 0;
    for (int c = 0; c < w; c++) {
        int pn[3], pf[3];
        for (int a = 0; a < 3; a++) pn[a] = r->pn4[a] / 4 * w + c, pf[a] = r->pf4[a] / 4 * w + c;
        m |= cbvh_ref_box32_one(r, box, pn, pf, cull, t_lo + c) << c;
    }
    return m;
}

#if CBVH_REF_SSE2
/* Four boxes of a row of w in one SSE register (lanes c .. c + 3). */
static inline int cbvh_ref_box32_sse(const cbvh_ref_ray *r, const float *box, int w, float cull, double *t_lo) {
    __m128 n = _mm_set1_ps(r->tmin32), f = _mm_set1_ps(cull);
    for (int a = 0; a < 3; a++) {
        __m128 o = _mm_set1_ps(r->o32[a]), inv = _mm_set1_ps(r->inv32[a]);
        n = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(box + r->pn4[a] / 4 * w), o), inv), n);
        f = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(box + r->pf4[a] / 4 * w), o), inv), f);
    }
    __m128 h = _mm_set1_ps(CBVH_REF32_H), lo = _mm_sub_ps(_mm_mul_ps(n, _mm_set1_ps(CBVH_REF32_C0)), h);
    _mm_storeu_pd(t_lo, _mm_cvtps_pd(lo));
    _mm_storeu_pd(t_lo + 2, _mm_cvtps_pd(_mm_movehl_ps(lo, lo)));
    return _mm_movemask_ps(_mm_cmple_ps(n, _mm_add_ps(_mm_mul_ps(f, _mm_set1_ps(CBVH_REF32_C1)), h)));
}
#endif

static inline int cbvh_ref_box4_32(const cbvh_ref_ray *r, const float box[24], float cull, double t_lo[4]) {
#if CBVH_REF_SSE2
    return cbvh_ref_box32_sse(r, box, 4, cull, t_lo);
#else
    return cbvh_ref_boxw32_c(r, box, 4, cull, t_lo);
#endif
}

static inline int cbvh_ref_box8_32(const cbvh_ref_ray *r, const float box[48], float cull, double t_lo[8]) {
#if CBVH_REF_AVX
    __m256 n = _mm256_set1_ps(r->tmin32), f = _mm256_set1_ps(cull);
    for (int a = 0; a < 3; a++) {
        __m256 o = _mm256_set1_ps(r->o32[a]), inv = _mm256_set1_ps(r->inv32[a]);
        n = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(box + 2 * r->pn4[a]), o), inv), n);
        f = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(box + 2 * r->pf4[a]), o), inv), f);
    }
    __m256 h = _mm256_set1_ps(CBVH_REF32_H), lo = _mm256_sub_ps(_mm256_mul_ps(n, _mm256_set1_ps(CBVH_REF32_C0)), h);
    _mm256_storeu_pd(t_lo, _mm256_cvtps_pd(_mm256_castps256_ps128(lo)));
    _mm256_storeu_pd(t_lo + 4, _mm256_cvtps_pd(_mm256_extractf128_ps(lo, 1)));
    return _mm256_movemask_ps(
        _mm256_cmp_ps(n, _mm256_add_ps(_mm256_mul_ps(f, _mm256_set1_ps(CBVH_REF32_C1)), h), _CMP_LE_OS));
#elif CBVH_REF_SSE2
    return cbvh_ref_box32_sse(r, box, 8, cull, t_lo) | cbvh_ref_box32_sse(r, box + 4, 8, cull, t_lo + 4) << 4;
#else
    return cbvh_ref_boxw32_c(r, box, 8, cull, t_lo);
#endif
}

/* The variant the ray calls for. */
static inline void cbvh_ref_box2_for(const cbvh_ref_ray *r, const float box[12], double cull, int hit[2],
                                     double t_lo[2]) {
    if (r->general) cbvh_ref_box2_any(r, box, cull, hit, t_lo);
    else cbvh_ref_box2(r, box, cull, hit, t_lo);
}

#endif
