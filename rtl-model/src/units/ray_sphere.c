/* Unit 9: ray-sphere test for the stackless traversal lists (seed 004),
 * integer-defined (docs/traversal.md §10).
 *
 * hit = 1 iff the closed ball |p - c| <= r meets the segment o + t d,
 * t in [tmin, tmax] (tmax may be +Inf), decided exactly on the binary32
 * inputs.  With w = c - o, A = d.d > 0, B = w.d and R = r^2, the squared
 * distance f(t) = |o + t d - c|^2 = A t^2 - 2 B t + w.w is convex with its
 * minimum at t* = B / A, so over [tmin, tmax]:
 *   t* < tmin  (B < tmin A)            -> hit iff f(tmin) <= R
 *   t* > tmax  (B > tmax A, tmax < Inf) -> hit iff f(tmax) <= R
 *   otherwise                           -> hit iff f(t*) <= R, i.e.
 *                                          |w x d|^2 <= R A
 * (Lagrange: A f(t*) = A w.w - B^2 = |w x d|^2).  No division, no root: every
 * comparison is between exact dyadic polynomials of the inputs (exact_wide.h).
 * An empty segment (tmin > tmax) is a miss.
 *
 * A binary64 fast path with a rigorous error bound decides clear hits and
 * clear misses first (see fast_decide); it only ever returns what the exact
 * comparisons return, so the unit's output is the exact definition. */
#include <string.h>

#include "cbvh/traversal_units.h"
#include "units/exact_wide.h"
#include "fast/fast_paths.h"
#include "units/ray_sphere_internal.h"

static uint32_t check(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r) {
    uint32_t st = 0;
    int bad_ray = 0, bad_par = 0;
    for (int a = 0; a < 3; a++) {
        bad_ray |= cbvh_f32_is_nan_or_inf(ray->o[a]) | cbvh_f32_is_nan_or_inf(ray->d[a]);
        bad_par |= cbvh_f32_is_nan_or_inf(c[a]);
    }
    bad_ray |= cbvh_f32_is_nan_or_inf(ray->tmin) | cbvh_f32_is_nan(ray->tmax) | (ray->tmax == CBVH_F32_NEG_INF);
    bad_par |= cbvh_f32_is_nan_or_inf(r) | ((r & CBVH_F32_SIGN) && !cbvh_f32_is_zero(r));
    if (bad_par) st |= CBVH_ST_BAD_PARAM;
    if (bad_ray) st |= CBVH_ST_NAN_INF;
    else if (cbvh_f32_is_zero(ray->d[0]) && cbvh_f32_is_zero(ray->d[1]) && cbvh_f32_is_zero(ray->d[2]))
        st |= CBVH_ST_ZERO_DIR;
    return st;
}

/* ---------------------------------------------------------------------------
 * Exact path (the definition). */

/* f(t) - R <= 0 for a finite binary32 t: |t d - w|^2 <= r^2. */
static int inside_at(cbvh_f32 t, const cbvh_xw d[3], const cbvh_xw w[3], const cbvh_xw *R) {
    cbvh_xw tt, p, q, s;
    cbvh_xw_from_f32(&tt, t);
    cbvh_xw_zero(&s);
    for (int k = 0; k < 3; k++) {
        cbvh_xw_mul(&p, &tt, &d[k]);
        cbvh_xw_sub(&p, &p, &w[k]);
        cbvh_xw_mul(&q, &p, &p);
        cbvh_xw_add(&s, &s, &q);
    }
    return cbvh_xw_cmp(&s, R) <= 0;
}

static int exact_decide(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r) {
    cbvh_xw d[3], w[3], A, B, R, p, q;
    cbvh_xw_zero(&A);
    cbvh_xw_zero(&B);
    for (int k = 0; k < 3; k++) {
        cbvh_xw_from_f32(&d[k], ray->d[k]);
        cbvh_xw_from_f32(&p, c[k]);
        cbvh_xw_from_f32(&q, ray->o[k]);
        cbvh_xw_sub(&w[k], &p, &q);
        cbvh_xw_mul(&p, &d[k], &d[k]);
        cbvh_xw_add(&A, &A, &p);
        cbvh_xw_mul(&p, &w[k], &d[k]);
        cbvh_xw_add(&B, &B, &p);
    }
    cbvh_xw_from_f32(&p, r);
    cbvh_xw_mul(&R, &p, &p);
    /* t* < tmin: B < tmin A */
    cbvh_xw_from_f32(&p, ray->tmin);
    cbvh_xw_mul(&q, &p, &A);
    if (cbvh_xw_cmp(&B, &q) < 0) return inside_at(ray->tmin, d, w, &R);
    /* t* > tmax: B > tmax A */
    if (ray->tmax != CBVH_F32_POS_INF) {
        cbvh_xw_from_f32(&p, ray->tmax);
        cbvh_xw_mul(&q, &p, &A);
        if (cbvh_xw_cmp(&B, &q) > 0) return inside_at(ray->tmax, d, w, &R);
    }
    /* t* in [tmin, tmax]: |w x d|^2 <= R A */
    cbvh_xw s, x;
    cbvh_xw_zero(&s);
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        cbvh_xw_mul(&p, &w[i], &d[j]);
        cbvh_xw_mul(&q, &w[j], &d[i]);
        cbvh_xw_sub(&x, &p, &q);
        cbvh_xw_mul(&p, &x, &x);
        cbvh_xw_add(&s, &s, &p);
    }
    cbvh_xw_mul(&p, &R, &A);
    return cbvh_xw_cmp(&s, &p) <= 0;
}

/* ---------------------------------------------------------------------------
 * Fast path (docs/traversal.md §10.3).  Every decision the unit makes is the
 * sign of one of four polynomials of the binary32 inputs:
 *   D  = |w x d|^2 - R A         (line distance vs r; k = 7 roundings deep)
 *   S0 = B - tmin A              (t* vs tmin; k = 5)
 *   S1 = tmax A - B              (t* vs tmax; k = 5)
 *   E  = |t d - w|^2 - R, t = tmin or tmax  (end point inside; k = 6)
 * each evaluated in binary64 as a tree of +, -, x over exact leaves (a
 * binary32 converts to binary64 exactly), with w_k = c_k - o_k a tree node.
 *
 * Bound: let y~ be the same tree on the leaves' absolute values with - read
 * as + (the sum of the absolute values of y's monomials, each taken with its
 * multiplicity), and k the most roundings on a root-to-leaf path.  If no
 * operation underflows or overflows, every monomial of the computed y^ carries
 * a factor (1 + theta), |theta| <= gamma_k = k u / (1 - k u), so
 * |y^ - y| <= gamma_k y~ (Higham, ASNA 2nd ed., 3.1-3.3), for u = 2^-53 in
 * round-to-nearest and u = 2^-52 in any directed mode (the determinism tests
 * run the model under fesetround).  The filter computes y~ as A^ with + and x
 * on non-negative values, so A^ >= y~ (1 - u)^k, and
 *   |y^ - y| <= gamma_7 (1 - u)^-7 A^ < 8 * 2^-52 A^ = 2^-49 A^   (k <= 7).
 * Hence y^ > 2^-49 A^ proves y > 0 and y^ < -2^-49 A^ proves y < 0
 * (2^-49 A^ is exact: a power-of-two scaling of a normal number).
 *
 * Range: the leaves are multiples of 2^-149 with magnitude < 2^128.  A
 * rounded sum or product of multiples of 2^-g1 and 2^-g2 is a multiple of
 * 2^-max(g1,g2) resp. 2^-(g1+g2), in every rounding mode, and the
 * polynomials have degree <= 4, so every nonzero intermediate is at least
 * 2^-596 (far above the binary64 normal minimum 2^-1022: no underflow) and
 * at most about 2^520 (no overflow).
 *
 * A fused multiply-add only removes roundings, so the bound also holds if the
 * compiler contracts; the file is compiled with -ffp-contract=off anyway. */
static double f32d(cbvh_f32 b) { return (double)cbvh_float_of(b); }
/* |x| by clearing the sign bit: no data-dependent branch (random signs
 * would mispredict), and exact. */
static double dabs(double x) {
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    b &= ~(UINT64_C(1) << 63);
    memcpy(&x, &b, sizeof x);
    return x;
}

#define REL_BOUND CBVH_RAY_SPHERE_REL_BOUND

/* Sign of y proven from y^ and A^: 1, -1, or 0 (not proven). */
static int proven_sign(double y, double ay) {
    double b = ay * REL_BOUND;
    return y > b ? 1 : y < -b ? -1 : 0;
}

/* The binary64 leaves: d, w = c - o, their absolute-value trees, A, R. */
typedef struct {
    double d[3], ad[3], w[3], aw[3], A, R;
} fp_ray;

static void fp_setup(fp_ray *f, const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r) {
    for (int k = 0; k < 3; k++) {
        double o = f32d(ray->o[k]), cc = f32d(c[k]);
        f->d[k] = f32d(ray->d[k]);
        f->ad[k] = dabs(f->d[k]);
        f->w[k] = cc - o;
        f->aw[k] = dabs(cc) + dabs(o);
    }
    double rr = f32d(r);
    f->R = rr * rr;
    f->A = f->d[0] * f->d[0] + f->d[1] * f->d[1] + f->d[2] * f->d[2]; /* its own absolute tree */
}

/* D = |w x d|^2 - R A. */
static void fp_line(const fp_ray *f, double *y, double *ay) {
    double x[3], ax[3];
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        x[k] = f->w[i] * f->d[j] - f->w[j] * f->d[i];
        ax[k] = f->aw[i] * f->ad[j] + f->aw[j] * f->ad[i];
    }
    double x2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2], ax2 = ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2];
    double RA = f->R * f->A;
    *y = x2 - RA;
    *ay = ax2 + RA;
}

/* B = w . d and its absolute-value tree. */
static void fp_dot(const fp_ray *f, double *B, double *aB) {
    *B = f->w[0] * f->d[0] + f->w[1] * f->d[1] + f->w[2] * f->d[2];
    *aB = f->aw[0] * f->ad[0] + f->aw[1] * f->ad[1] + f->aw[2] * f->ad[2];
}

/* S = sgn (B - t A), sgn = +1 for tmin (S0), -1 for tmax (S1). */
static void fp_side(const fp_ray *f, double B, double aB, double t, int sgn, double *y, double *ay) {
    *y = sgn > 0 ? B - t * f->A : t * f->A - B;
    *ay = aB + dabs(t) * f->A;
}

/* E = |t d - w|^2 - R. */
static void fp_end(const fp_ray *f, double t, double *y, double *ay) {
    double at = dabs(t), p[3], ap[3];
    for (int k = 0; k < 3; k++) {
        p[k] = t * f->d[k] - f->w[k];
        ap[k] = at * f->ad[k] + f->aw[k];
    }
    double e = p[0] * p[0] + p[1] * p[1] + p[2] * p[2], ae = ap[0] * ap[0] + ap[1] * ap[1] + ap[2] * ap[2];
    *y = e - f->R;
    *ay = ae + f->R;
}

static int end_sign(const fp_ray *f, double t) {
    double y, ay;
    fp_end(f, t, &y, &ay);
    return proven_sign(y, ay);
}

static int fast_decide(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r) {
    fp_ray f;
    fp_setup(&f, ray, c, r);
    double y, ay;
    /* the infinite line: |w x d|^2 - R A > 0 -> every t misses */
    fp_line(&f, &y, &ay);
    int sD = proven_sign(y, ay);
    if (sD > 0) return 0;
    /* where t* = B / A lies relative to the segment */
    double tmin = f32d(ray->tmin), B, aB;
    fp_dot(&f, &B, &aB);
    fp_side(&f, B, aB, tmin, 1, &y, &ay);
    int s0 = proven_sign(y, ay);
    if (s0 < 0) { /* t* < tmin: the nearest point is tmin */
        int e = end_sign(&f, tmin);
        return e < 0 ? 1 : e > 0 ? 0 : -1;
    }
    int finite = ray->tmax != CBVH_F32_POS_INF;
    double tmax = finite ? f32d(ray->tmax) : 0;
    int s1 = 1;
    if (finite) {
        fp_side(&f, B, aB, tmax, -1, &y, &ay);
        s1 = proven_sign(y, ay);
    }
    if (s1 < 0) { /* t* > tmax: the nearest point is tmax */
        int e = end_sign(&f, tmax);
        return e < 0 ? 1 : e > 0 ? 0 : -1;
    }
    if (s0 > 0 && s1 > 0) return sD < 0 ? 1 : -1; /* t* inside: the line decides */
    /* t* at or near an end: an end point proven inside the ball is a hit */
    if (end_sign(&f, tmin) < 0) return 1;
    if (finite && end_sign(&f, tmax) < 0) return 1;
    return -1;
}

/* ---------------------------------------------------------------------------
 * The unit. */

static int empty_segment(const cbvh_ray *ray) { return cbvh_f32_key(ray->tmin) > cbvh_f32_key(ray->tmax); }

uint32_t cbvh_ray_sphere(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r, int *hit) {
    *hit = 0;
    uint32_t st = check(ray, c, r);
    if (st || empty_segment(ray)) return st;
    int f = CBVH_FAST_PATHS ? fast_decide(ray, c, r) : -1;
    *hit = f >= 0 ? f : exact_decide(ray, c, r);
    return 0;
}

uint32_t cbvh_ray_sphere_exact_only(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r, int *hit) {
    *hit = 0;
    uint32_t st = check(ray, c, r);
    if (st || empty_segment(ray)) return st;
    *hit = exact_decide(ray, c, r);
    return 0;
}

int cbvh_ray_sphere_fast_only(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r) {
    return fast_decide(ray, c, r);
}

int cbvh_ray_sphere_fast_terms(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r, double y[5], double ay[5]) {
    fp_ray f;
    fp_setup(&f, ray, c, r);
    double tmin = f32d(ray->tmin), B, aB;
    fp_line(&f, &y[0], &ay[0]);
    fp_dot(&f, &B, &aB);
    fp_side(&f, B, aB, tmin, 1, &y[1], &ay[1]);
    fp_end(&f, tmin, &y[2], &ay[2]);
    if (ray->tmax == CBVH_F32_POS_INF) return 3;
    double tmax = f32d(ray->tmax);
    fp_side(&f, B, aB, tmax, -1, &y[3], &ay[3]);
    fp_end(&f, tmax, &y[4], &ay[4]);
    return 5;
}

cbvh_unit_path cbvh_ray_sphere_path(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r) {
    if (check(ray, c, r) || empty_segment(ray)) return CBVH_PATH_REJECT;
    return fast_decide(ray, c, r) >= 0 ? CBVH_PATH_FAST : CBVH_PATH_EXACT;
}
