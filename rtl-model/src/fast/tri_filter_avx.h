/* The triangle unit's binary64 filter (docs/traversal.md §9) with the three
 * vertices, or the three edges, in the lanes of one four-lane register: the
 * wide float traversals' AVX build (§15, "The triangle filter in lanes").
 * Internal.
 *
 * Lane i < 3 is vertex i for P^ = v - o (on the ray's axes kx, ky, kz), X, Y,
 * Z = P^z and their bounds eX, eY, eZ, and edge function i for E_i = X_k Y_j
 * - Y_k X_j (j = i + 1, k = i + 2 mod 3: lane rotations) and its bound eE_i;
 * lane 3 repeats vertex 0 and is ignored.  Every lane performs the scalar
 * filter's binary64 operations in its order (ray_triangle.c; maxima are
 * exact in any order; no fused multiply-add: the AVX build has -mno-fma),
 * and the rest - the sign of T and the hit path - is the same source
 * (tri_filter_tail.h), so the result is the scalar filter's: 1 miss, 2 hit
 * with *out the exact path's outputs, 0 undecided.  Non-finite vertices give
 * 0, as the unit does not filter them, without a check: a bad vertex i makes
 * X_i or Y_i infinite or NaN, hence E_j and eE_j for both j != i, so those
 * lanes compare false and only lane i can decide a sign - too few for a miss
 * (two opposite signs) or a hit (three equal ones); and an infinite
 * coordinate makes B infinite for the quick miss.
 * tests/traversal/test_fast_path.c (traversal_fast_path.avx) compares it
 * with the scalar filter, result and values. */
#ifndef CBVH_TRI_FILTER_AVX_H
#define CBVH_TRI_FILTER_AVX_H

#include "fast/fast_paths.h"
#include "fast/ray_box_ref.h"
#include "fast/ray_prep.h"
#include "fast/tri_filter_tail.h"

#if CBVH_REF_AVX
/* Coordinate k of the three vertices widened to binary64, lane 3 = lane 0. */
static inline __m256d tri_lanes_axis(const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3], int k) {
    return _mm256_cvtps_pd(_mm_setr_ps(cbvh_float_of(v0[k]), cbvh_float_of(v1[k]), cbvh_float_of(v2[k]),
                                       cbvh_float_of(v0[k])));
}

/* x with lane 3 = lane 0, rotated: *j = (x1, x2, x0, .), *k = (x2, x0, x1, .) */
static inline void tri_lanes_rot(__m256d x, __m256d *j, __m256d *k) {
    __m256d t = _mm256_permute2f128_pd(x, x, 1); /* (x2, x0, x0, x1) */
    *j = _mm256_shuffle_pd(x, t, 5);
    *k = _mm256_shuffle_pd(t, x, 4);
}

static inline __m256d tri_lanes_abs(__m256d x) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), x); }

/* lanes != NULL (tests): E, eE, Z, eZ stored there when they are formed. */
static inline int cbvh_tri_filter_avx(const cbvh_tri_ray *p, const cbvh_f32 v0[3], const cbvh_f32 v1[3],
                                      const cbvh_f32 v2[3], cbvh_tri_result *out, double lanes[4][4]) {
    if (!CBVH_FAST_PATHS) return 0;
    const double u = 0x1p-53;
    __m256d px = _mm256_sub_pd(tri_lanes_axis(v0, v1, v2, p->kx), _mm256_set1_pd(p->ox));
    __m256d py = _mm256_sub_pd(tri_lanes_axis(v0, v1, v2, p->ky), _mm256_set1_pd(p->oy));
    __m256d pz = _mm256_sub_pd(tri_lanes_axis(v0, v1, v2, p->kz), _mm256_set1_pd(p->oz));
    __m256d dx = _mm256_set1_pd(p->dx), dy = _mm256_set1_pd(p->dy), dz = _mm256_set1_pd(p->dz);
    __m256d X = _mm256_sub_pd(_mm256_mul_pd(px, dz), _mm256_mul_pd(pz, dx));
    __m256d Y = _mm256_sub_pd(_mm256_mul_pd(py, dz), _mm256_mul_pd(pz, dy));
    __m256d apx = tri_lanes_abs(px), apy = tri_lanes_abs(py), apz = tri_lanes_abs(pz);
    __m256d m = _mm256_max_pd(_mm256_max_pd(apx, apy), apz); /* Pm: the largest of the nine |P^| */
    m = _mm256_max_pd(m, _mm256_permute2f128_pd(m, m, 1));
    m = _mm256_max_pd(m, _mm256_permute_pd(m, 5));
    __m256d Xj, Xk, Yj, Yk;
    tri_lanes_rot(X, &Xj, &Xk);
    tri_lanes_rot(Y, &Yj, &Yk);
    __m256d a = _mm256_mul_pd(Xk, Yj), c = _mm256_mul_pd(Yk, Xj), E = _mm256_sub_pd(a, c);
    /* quick miss: one bound B for all three edge functions */
    double s = _mm256_cvtsd_f64(m) * fabs(p->dz), B = 0x1p-46 * s * s;
    int pos = _mm256_movemask_pd(_mm256_cmp_pd(E, _mm256_set1_pd(B), _CMP_GT_OQ)) & 7;
    int neg = _mm256_movemask_pd(_mm256_cmp_pd(E, _mm256_set1_pd(-B), _CMP_LT_OQ)) & 7;
    if (pos && neg) return 1;
    /* per-vertex bounds, then the edge functions' */
    __m256d adz = tri_lanes_abs(dz);
    __m256d eX = _mm256_mul_pd(_mm256_set1_pd(4.0 * u),
                               _mm256_add_pd(_mm256_mul_pd(apx, adz), _mm256_mul_pd(apz, tri_lanes_abs(dx))));
    __m256d eY = _mm256_mul_pd(_mm256_set1_pd(4.0 * u),
                               _mm256_add_pd(_mm256_mul_pd(apy, adz), _mm256_mul_pd(apz, tri_lanes_abs(dy))));
    __m256d eZ = _mm256_mul_pd(_mm256_set1_pd(1.0001 * u), apz);
    __m256d eXj, eXk, eYj, eYk;
    tri_lanes_rot(eX, &eXj, &eXk);
    tri_lanes_rot(eY, &eYj, &eYk);
    __m256d sum = _mm256_mul_pd(tri_lanes_abs(Xk), eYj);
    sum = _mm256_add_pd(sum, _mm256_mul_pd(tri_lanes_abs(Yj), eXk));
    sum = _mm256_add_pd(sum, _mm256_mul_pd(eXk, eYj));
    sum = _mm256_add_pd(sum, _mm256_mul_pd(tri_lanes_abs(Yk), eXj));
    sum = _mm256_add_pd(sum, _mm256_mul_pd(tri_lanes_abs(Xj), eYk));
    sum = _mm256_add_pd(sum, _mm256_mul_pd(eXj, eYk));
    sum = _mm256_add_pd(sum, _mm256_mul_pd(_mm256_set1_pd(2.0001 * u),
                                           _mm256_add_pd(tri_lanes_abs(a), tri_lanes_abs(c))));
    __m256d eE = _mm256_mul_pd(_mm256_set1_pd(1.001), sum);
    if (lanes) {
        _mm256_storeu_pd(lanes[0], E);
        _mm256_storeu_pd(lanes[1], eE);
        _mm256_storeu_pd(lanes[2], pz);
        _mm256_storeu_pd(lanes[3], eZ);
    }
    int sp = _mm256_movemask_pd(_mm256_cmp_pd(E, eE, _CMP_GT_OQ)) & 7; /* sign +1 certain */
    int sn = _mm256_movemask_pd(_mm256_cmp_pd(E, _mm256_sub_pd(_mm256_setzero_pd(), eE), _CMP_LT_OQ)) & 7;
    if (sp && sn) return 1;
    if (sp != 7 && sn != 7) return 0;
    double e[4], ee[4], z[4], ez[4];
    _mm256_storeu_pd(e, E);
    _mm256_storeu_pd(ee, eE);
    _mm256_storeu_pd(z, pz);
    _mm256_storeu_pd(ez, eZ);
    return tri_filter_tail(e, ee, z, ez, p->dz, sp == 7 ? 1 : -1, 1, out);
}
#endif

#endif
