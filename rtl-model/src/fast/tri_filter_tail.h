/* The end of the triangle unit's binary64 filter (docs/traversal.md §9):
 * from the three edge functions E (of one certain strict sign sg0), their
 * error bounds eE, Z = P^z and its bounds eZ, and d_z - the sign of T and the
 * hit path.  Shared by ray_triangle.c's filter and the wide AVX loop's
 * four-lane one (tri_filter_avx.h), so both run these operations from the
 * same source.  Internal. */
#ifndef CBVH_TRI_FILTER_TAIL_H
#define CBVH_TRI_FILTER_TAIL_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "cbvh/traversal_units.h"

/* Truncation of a positive binary64 to binary32 (round toward zero = the
 * exact path's CBVH_RND_DOWN for a positive quotient), integer-only; 0 when
 * x is outside the binary32 normal range (the exact path then decides). */
static inline cbvh_f32 trunc_f32(double x) {
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    int e = (int)(b >> 52 & 0x7FF) - 1023;
    if (e < CBVH_F32_EMIN || e > CBVH_F32_EMAX || (b >> 63)) return 0;
    return cbvh_f32_make(0, e, (uint32_t)((b & 0xFFFFFFFFFFFFFull) >> 29)); /* the top 23 of 52 fraction bits */
}

/* The binary32 truncation of the exact quotient a/b, given binary64
 * approximations â (|â - a| <= ea) and b̂ (|b̂ - b| <= eb < 2^-20 |b̂|, b
 * of b̂'s sign) through rb = RN(1 / b̂): with q = RN(â rb),
 *     |a/b - q| <= (ea + |q| eb) |rb| (1 + 2^-19) + 2.0001 * 2^-53 |q|
 * (|b| >= |b̂| (1 - 2^-20); q and |rb| are within two and one roundings of
 * â/b̂ and 1/|b̂|).  W below exceeds that by more than the roundings of
 * forming W and q -+ W (the factor 1.001 and 2^-48 |q| against three
 * roundings of 2^-53 |q|), so a/b lies in [RN(q - W), RN(q + W)]; when both
 * ends truncate to the same binary32 (trunc_f32: 0 unless positive and
 * normal) that is the exact result (truncation is monotone).  0: undecided.
 * One division (rb) serves every quotient with the same divisor. */
static inline cbvh_f32 quot_trunc(double a, double ea, double rb, double eb) {
    double q = a * rb, aq = fabs(q);
    double W = 1.001 * ((ea + aq * eb) * fabs(rb)) + 0x1p-48 * aq;
    cbvh_f32 lo = trunc_f32(q - W), hi = trunc_f32(q + W);
    return lo == hi ? lo : 0;
}

/* 1: certainly a miss (t <= 0); 2: certainly a hit and *out = the exact
 * path's outputs (fill_hit only); 0: undecided. */
static inline int tri_filter_tail(const double E[3], const double eE[3], const double Z[3], const double eZ[3],
                                  double dz, int sg0, int fill_hit, cbvh_tri_result *out) {
    const double u = 0x1p-53, adz = fabs(dz);
    /* U, V, W certainly of one strict sign: det has that sign, det != 0.
     * T = U Z0 + V Z1 + W Z2: propagated error plus 3 products and 2 sums. */
    double P0 = E[0] * Z[0], P1 = E[1] * Z[1], P2 = E[2] * Z[2];
    double T = P0 + P1 + P2;
    double eT = 0;
    for (int i = 0; i < 3; i++) eT += fabs(E[i]) * eZ[i] + fabs(Z[i]) * eE[i] + eE[i] * eZ[i];
    eT = 1.001 * (eT + 3.001 * u * (fabs(P0) + fabs(P1) + fabs(P2)));
    int sT = T > eT ? 1 : T < -eT ? -1 : 0;
    int sden = sg0 * (dz > 0 ? 1 : -1); /* d_z != 0: the largest |d| of a nonzero d */
    if (sT == 0) return 0;
    if (sT != sden) return 1;
    if (!fill_hit) return 0;
    /* A certain hit: t = T / (det d_z), b1 = V / det, b2 = W / det, each the
     * truncation of a positive quotient.  det = U + V + W adds two roundings
     * (its terms share a sign: <= 2.0001u sum |E|); det d_z one more.  Two
     * divisions: 1 / det for b1 and b2, 1 / (det d_z) for t. */
    double det = E[0] + E[1] + E[2], adet = fabs(det);
    double e_det = 1.001 * (eE[0] + eE[1] + eE[2] + 2.0001 * u * adet);
    double den = det * dz, aden = fabs(den);
    double e_den = adz * e_det + 1.0001 * u * aden;
    if (!(e_det < 0x1p-20 * adet && e_den < 0x1p-20 * aden)) return 0;
    double r_det = 1.0 / det, r_den = 1.0 / den;
    cbvh_f32 t = quot_trunc(T, eT, r_den, e_den);
    cbvh_f32 b1 = quot_trunc(E[1], eE[1], r_det, e_det);
    cbvh_f32 b2 = quot_trunc(E[2], eE[2], r_det, e_det);
    if (!t || !b1 || !b2) return 0;
    memset(out, 0, sizeof *out);
    out->hit = 1;
    out->t = t;
    out->b1 = b1;
    out->b2 = b2;
    return 2;
}

#endif
