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

#define CBVH_REF_EPS 0x1p-50 /* > 2 * 3.0000001 * 2^-53 */

/* A pair of boxes as 12 binary32: plane (lo = 0, hi = 1) of axis a of child c
 * at [CBVH_REF_AT(plane, a, c)]. */
#define CBVH_REF_AT(plane, a, c) (((plane) * 3 + (a)) * 2 + (c))

typedef struct {
    double o[3], inv[3]; /* inv = 1 / d, 0 where d = +-0 */
    double tmin;
    int pn[3], pf[3]; /* CBVH_REF_AT(near / far plane, a, 0): the near plane is hi where d_a < 0 */
    int general;      /* some d_a = +-0, or tmin < 0: cbvh_ref_box2_any, not cbvh_ref_box2 */
} cbvh_ref_ray;

/* For a ray the units accept (finite, d != 0). */
static inline void cbvh_ref_prepare(const cbvh_ray *ray, cbvh_ref_ray *r) {
    int axis_par = 0;
    for (int a = 0; a < 3; a++) {
        double d = cbvh_float_of(ray->d[a]);
        r->o[a] = cbvh_float_of(ray->o[a]);
        r->inv[a] = d != 0 ? 1.0 / d : 0;
        r->pn[a] = CBVH_REF_AT(d < 0, a, 0);
        r->pf[a] = CBVH_REF_AT(!(d < 0), a, 0);
        axis_par |= d == 0;
    }
    r->tmin = cbvh_float_of(ray->tmin);
    r->general = axis_par || r->tmin < 0;
}

/* Two boxes (lo <= hi, finite) against [tmin, cull] for a ray without zero
 * direction components and tmin >= 0 (!r->general): hit[c] = 1 if the ray
 * may meet box c, and then t_lo[c] <= its exact entry t.  Here N >= 0 and F
 * has its exact sign, so N_exact <= F_exact implies N <= F * (1 + 2^-50) and
 * N * (1 - 2^-50) <= N_exact (the margins also cover these two products'
 * own roundings).  Both children go through the same operations. */
static inline void cbvh_ref_box2(const cbvh_ref_ray *r, const float box[12], double cull, int hit[2],
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

/* Any valid ray (zero direction components, tmin < 0): an axis with d_a = 0
 * constrains nothing where o_a lies in the closed slab, else the box is
 * missed; the slack is the sign-free N <= F + (|N| + |F|) * 2^-50. */
static inline void cbvh_ref_box2_any(const cbvh_ref_ray *r, const float box[12], double cull, int hit[2],
                                     double t_lo[2]) {
    double nn[2] = {r->tmin, r->tmin}, ff[2] = {cull, cull};
    int in[2] = {1, 1};
    for (int a = 0; a < 3; a++) {
        for (int c = 0; c < 2; c++) {
            if (r->inv[a] == 0) {
                in[c] &= r->o[a] >= box[CBVH_REF_AT(0, a, c)] && r->o[a] <= box[CBVH_REF_AT(1, a, c)];
                continue;
            }
            double tn = ((double)box[r->pn[a] + c] - r->o[a]) * r->inv[a];
            double tf = ((double)box[r->pf[a] + c] - r->o[a]) * r->inv[a];
            nn[c] = tn > nn[c] ? tn : nn[c];
            ff[c] = tf < ff[c] ? tf : ff[c];
        }
    }
    for (int c = 0; c < 2; c++) {
        t_lo[c] = nn[c] - fabs(nn[c]) * CBVH_REF_EPS;
        hit[c] = in[c] && nn[c] <= ff[c] + (fabs(nn[c]) + fabs(ff[c])) * CBVH_REF_EPS;
    }
}

/* The variant the ray calls for. */
static inline void cbvh_ref_box2_for(const cbvh_ref_ray *r, const float box[12], double cull, int hit[2],
                                     double t_lo[2]) {
    if (r->general) cbvh_ref_box2_any(r, box, cull, hit, t_lo);
    else cbvh_ref_box2(r, box, cull, hit, t_lo);
}

#endif
