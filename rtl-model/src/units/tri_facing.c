/* Exact facing of a triangle for a ray direction (docs/traversal.md §4.5):
 * the sign of d . ((v1 - v0) x (v2 - v0)), computed exactly in wide dyadic
 * integers (no rounding anywhere), so one-sided traversal and the lists'
 * back-face culling agree on every triangle, on every host. */
#include "cbvh/traversal_units.h"
#include "units/exact_wide.h"

int cbvh_tri_facing(const cbvh_f32 d[3], const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3]) {
    cbvh_xw a, b, e1[3], e2[3], dd[3], p, q, n, s, t;
    for (int k = 0; k < 3; k++) {
        cbvh_xw_from_f32(&a, v1[k]);
        cbvh_xw_from_f32(&b, v0[k]);
        cbvh_xw_sub(&e1[k], &a, &b);
        cbvh_xw_from_f32(&a, v2[k]);
        cbvh_xw_sub(&e2[k], &a, &b);
        cbvh_xw_from_f32(&dd[k], d[k]);
    }
    cbvh_xw_zero(&s);
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3; /* n_k = e1_i e2_j - e1_j e2_i */
        cbvh_xw_mul(&p, &e1[i], &e2[j]);
        cbvh_xw_mul(&q, &e1[j], &e2[i]);
        cbvh_xw_sub(&n, &p, &q);
        cbvh_xw_mul(&p, &dd[k], &n);
        cbvh_xw_add(&t, &s, &p);
        s = t;
    }
    return -cbvh_xw_sign(&s);
}
