/* Unit 7: watertight ray-triangle test (Woop, Benthin, Wald 2013), integer-
 * defined (docs/traversal.md §4).
 *
 * The paper translates the vertices to the ray origin, permutes the axes so
 * that z is the largest direction component, shears the ray onto +z and
 * evaluates the three 2D edge functions; when an edge function is exactly 0
 * in single precision it recomputes it in double precision.  This model
 * evaluates every quantity exactly (scaled by powers of d_z so no division is
 * needed), which is what the fallback approximates: the edge functions' signs
 * are exact, so a ray through a shared edge or vertex of a closed mesh always
 * hits at least one of the adjacent triangles.  Integer-defined: a binary64
 * filter runs first and returns only results it proves equal to the integer
 * path's (docs/traversal.md §9); everything else takes the integer path. */
#include <math.h>
#include <string.h>

#include "cbvh/traversal_units.h"
#include "units/exact_wide.h"
#include "fast/fast_paths.h"
#include "fast/ray_prep.h"
#include "fast/tri_filter_tail.h"

/* kx, ky for kz and the sign of d_kz: cyclic after kz, swapped when d_kz < 0 */
static const uint8_t perm_xy[3][2][2] = {{{1, 2}, {2, 1}}, {{2, 0}, {0, 2}}, {{0, 1}, {1, 0}}};

/* Axis permutation: kz = largest |d| (first on ties), kx, ky follow
 * cyclically and swap when d_kz < 0 (keeps the winding, as in the paper).
 * Chosen with compares and bit arithmetic, not branches: the choice is a
 * coin toss per ray (a select became a branch, hence the arithmetic). */
static void tri_axes(const cbvh_ray *ray, int *kx, int *ky, int *kz) {
    uint32_t m0 = ray->d[0] & ~CBVH_F32_SIGN, m1 = ray->d[1] & ~CBVH_F32_SIGN, m2 = ray->d[2] & ~CBVH_F32_SIGN;
    int c1 = m1 > m0;
    uint32_t m01 = c1 ? m1 : m0;
    int c2 = m2 > m01;
    int z = (c1 | c2 << 1) - (c1 & c2); /* c2 ? 2 : c1 */
    int neg = (int)(ray->d[z] >> 31);
    *kx = perm_xy[z][neg][0];
    *ky = perm_xy[z][neg][1];
    *kz = z;
}

uint32_t cbvh_ray_triangle_exact_only(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3],
                                      const cbvh_f32 v2[3], cbvh_tri_result *out) {
    memset(out, 0, sizeof *out);
    int bad = 0;
    for (int a = 0; a < 3; a++)
        bad |= cbvh_f32_is_nan_or_inf(ray->o[a]) | cbvh_f32_is_nan_or_inf(ray->d[a]) |
               cbvh_f32_is_nan_or_inf(v0[a]) | cbvh_f32_is_nan_or_inf(v1[a]) | cbvh_f32_is_nan_or_inf(v2[a]);
    if (bad) return CBVH_ST_NAN_INF;
    if (cbvh_f32_is_zero(ray->d[0]) && cbvh_f32_is_zero(ray->d[1]) && cbvh_f32_is_zero(ray->d[2]))
        return CBVH_ST_ZERO_DIR;

    int kx, ky, kz;
    tri_axes(ray, &kx, &ky, &kz);
    cbvh_xw dx, dy, dz;
    cbvh_xw_from_f32(&dx, ray->d[kx]);
    cbvh_xw_from_f32(&dy, ray->d[ky]);
    cbvh_xw_from_f32(&dz, ray->d[kz]);

    /* Translated vertices P = v - o; sheared, scaled by d_z:
     *   X = P_x d_z - P_z d_x = d_z * (paper's A_x),  Y likewise,
     *   Z = P_z                = d_z * (paper's A_z). */
    const cbvh_f32 *v[3] = {v0, v1, v2};
    cbvh_xw X[3], Y[3], Z[3];
    for (int i = 0; i < 3; i++) {
        cbvh_xw o, p, px, py, t1, t2;
        cbvh_xw_from_f32(&o, ray->o[kx]);
        cbvh_xw_from_f32(&p, v[i][kx]);
        cbvh_xw_sub(&px, &p, &o);
        cbvh_xw_from_f32(&o, ray->o[ky]);
        cbvh_xw_from_f32(&p, v[i][ky]);
        cbvh_xw_sub(&py, &p, &o);
        cbvh_xw_from_f32(&o, ray->o[kz]);
        cbvh_xw_from_f32(&p, v[i][kz]);
        cbvh_xw_sub(&Z[i], &p, &o);
        cbvh_xw_mul(&t1, &px, &dz);
        cbvh_xw_mul(&t2, &Z[i], &dx);
        cbvh_xw_sub(&X[i], &t1, &t2);
        cbvh_xw_mul(&t1, &py, &dz);
        cbvh_xw_mul(&t2, &Z[i], &dy);
        cbvh_xw_sub(&Y[i], &t1, &t2);
    }
    /* Edge functions (d_z^2 times the paper's U, V, W; same signs):
     *   U = X2 Y1 - Y2 X1,  V = X0 Y2 - Y0 X2,  W = X1 Y0 - Y1 X0. */
    cbvh_xw E[3];
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3; /* E[0] = U: opposite v0 */
        cbvh_xw t1, t2;
        cbvh_xw_mul(&t1, &X[k], &Y[j]);
        cbvh_xw_mul(&t2, &Y[k], &X[j]);
        cbvh_xw_sub(&E[i], &t1, &t2);
    }
    int s0 = cbvh_xw_sign(&E[0]), s1 = cbvh_xw_sign(&E[1]), s2 = cbvh_xw_sign(&E[2]);
    if ((s0 < 0 || s1 < 0 || s2 < 0) && (s0 > 0 || s1 > 0 || s2 > 0)) return 0; /* outside an edge */
    cbvh_xw det, T, t1;
    cbvh_xw_add(&det, &E[0], &E[1]);
    cbvh_xw_add(&det, &det, &E[2]);
    if (det.n == 0) return 0; /* ray in the triangle's plane, or degenerate triangle */
    /* T = U Z0 + V Z1 + W Z2 = d_z^3 * (paper's T);  t = T / (d_z det). */
    cbvh_xw_mul(&T, &E[0], &Z[0]);
    cbvh_xw_mul(&t1, &E[1], &Z[1]);
    cbvh_xw_add(&T, &T, &t1);
    cbvh_xw_mul(&t1, &E[2], &Z[2]);
    cbvh_xw_add(&T, &T, &t1);
    cbvh_xw den;
    cbvh_xw_mul(&den, &det, &dz);
    if (cbvh_xw_sign(&T) * cbvh_xw_sign(&den) <= 0) return 0; /* behind the origin or at t = 0 */
    out->hit = 1;
    out->t = cbvh_xw_div_round(&T, &den, 24, CBVH_RND_DOWN);
    out->b1 = cbvh_xw_div_round(&E[1], &det, 24, CBVH_RND_DOWN);
    out->b2 = cbvh_xw_div_round(&E[2], &det, 24, CBVH_RND_DOWN);
    return 0;
}

/* ---------------------------------------------------------------------------
 * Filter (docs/traversal.md §9, "Performance filter").  Most triangles a
 * traversal tests are misses; the filter proves a miss in binary64 with a
 * rigorous error bound and returns the exact path's miss result (hit 0, all
 * outputs +0, status 0).  For a certain hit it brackets t, b1, b2 and returns
 * their binary32 truncations when both ends of each bracket agree.  Anything
 * it cannot prove (near-zero edge functions, quotients next to a binary32)
 * goes to the exact path, so the unit's results stay integer-defined: the
 * filter chooses between computations proven to give the same outputs.
 *
 * Error bounds (running, u = 2^-53): binary32 inputs are exact in binary64
 * and keep every nonzero intermediate within [2^-960, 2^650] (no underflow or
 * overflow), so each operation is exact up to a factor (1 + d), |d| <= u.
 * Each computed y^ carries a bound e_y >= |y^ - y| formed from computed
 * values:
 *   P = v - o                       |P^ - P| <= u |P|
 *   X = P_x d_z - P_z d_x           e_X = 4u (|P_x^| |d_z| + |P_z^| |d_x|)   (3.0002u suffices)
 *   Z = P_z                         e_Z = 1.0001u |Z^|
 *   U = X_k Y_j - Y_k X_j           e_U = |X_k^| e_Yj + |Y_j^| e_Xk + e_Xk e_Yj (+ the same for Y_k X_j)
 *                                         + 2.0001u (|X_k^ Y_j^| + |Y_k^ X_j^|)   (product and sum roundings)
 *   T = U Z_0 + V Z_1 + W Z_2       e_T = sum (|E_i^| e_Zi + |Z_i^| e_Ei + e_Ei e_Zi) + 3.001u sum |E_i^ Z_i^|
 *   det = U + V + W                 e_det = sum e_Ei + 2.0001u |det^|   (terms of one sign)
 *   det d_z                         |d_z| e_det + 1.0001u |den^|
 * (propagation: x^ y^ - x y = x^ (y^ - y) + y^ (x^ - x) - (x^ - x)(y^ - y)).
 * Sums of positive terms are computed with at most a dozen roundings, so
 * they are multiplied by 1.001 to stay upper bounds.  |y^| > e_y proves
 * sign(y^) = sign(y).  The bounds grow with the triangle's distance from the
 * ray origin over its size (not its square, as bounds on absolute-value
 * expressions would), which keeps small, distant triangles decidable.  A
 * fused multiply-add only removes roundings and the margins cover the
 * bounds' own rounding, so the bounds also hold if the compiler contracts
 * (the file is compiled with -ffp-contract=off anyway, so the filter's
 * decisions are reproducible). */
static double f32d(cbvh_f32 b) { return (double)cbvh_float_of(b); }

void cbvh_tri_ray_prepare(const cbvh_ray *ray, cbvh_tri_ray *p) {
    int bad = 0;
    for (int a = 0; a < 3; a++) bad |= cbvh_f32_is_nan_or_inf(ray->o[a]) | cbvh_f32_is_nan_or_inf(ray->d[a]);
    cbvh_tri_ray_prepare_valid(ray, p);
    p->ok = !bad && !(cbvh_f32_is_zero(ray->d[0]) && cbvh_f32_is_zero(ray->d[1]) && cbvh_f32_is_zero(ray->d[2]));
}

void cbvh_tri_ray_prepare_valid(const cbvh_ray *ray, cbvh_tri_ray *p) {
    p->ok = 1;
    int kx, ky, kz; /* the exact path's axes */
    tri_axes(ray, &kx, &ky, &kz);
    p->kx = kx;
    p->ky = ky;
    p->kz = kz;
    p->dx = f32d(ray->d[kx]);
    p->dy = f32d(ray->d[ky]);
    p->dz = f32d(ray->d[kz]);
    p->ox = f32d(ray->o[kx]);
    p->oy = f32d(ray->o[ky]);
    p->oz = f32d(ray->o[kz]);
}

/* 1: certainly a miss (*out = the exact path's miss); 2: certainly a hit and
 * *out = the exact path's outputs (fill_hit only); 0: undecided (the exact
 * path decides).  p->ok and finite vertices required. */
static int filter(const cbvh_tri_ray *p, const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3],
                  int fill_hit, cbvh_tri_result *out) {
    const double u = 0x1p-53;
    int kx = p->kx, ky = p->ky, kz = p->kz;
    double dx = p->dx, dy = p->dy, dz = p->dz;
    double adx = fabs(dx), ady = fabs(dy), adz = fabs(dz);
    double ox = p->ox, oy = p->oy, oz = p->oz;
    const cbvh_f32 *v[3] = {v0, v1, v2};
    /* X, Y and the largest |P^| component, Pm */
    double px[3], py[3], pz[3], X[3], Y[3], Pm = 0;
    for (int i = 0; i < 3; i++) {
        px[i] = f32d(v[i][kx]) - ox;
        py[i] = f32d(v[i][ky]) - oy;
        pz[i] = f32d(v[i][kz]) - oz;
        X[i] = px[i] * dz - pz[i] * dx;
        Y[i] = py[i] * dz - pz[i] * dy;
        double ax = fabs(px[i]), ay = fabs(py[i]), az = fabs(pz[i]);
        Pm = ax > Pm ? ax : Pm;
        Pm = ay > Pm ? ay : Pm;
        Pm = az > Pm ? az : Pm;
    }
    double E[3], a[3], c[3];
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        a[i] = X[k] * Y[j];
        c[i] = Y[k] * X[j];
        E[i] = a[i] - c[i];
    }
    /* Quick miss (most misses end here): one bound for all three E_i.  With
     * s = Pm |d_z| (|d_z| is the largest |d|): e_X, e_Y <= 3.0002u 2s and
     * |X^|, |Y^| <= 2s (1 + u)^2, so every e_E <= 4 |X^| e_Y + 2 e_X e_Y +
     * 2.0001u (|a| + |c|) < 64.01u s^2; B = 2^-46 s^2 = 128u s^2 stays above
     * that after its own two roundings (u s^2 >= 2^-649: no underflow).  E_i
     * of both signs beyond B: a miss, without the per-vertex bounds below,
     * which decide the rest (tighter where a triangle is small next to its
     * distance from the origin). */
    double s = Pm * adz, B = 0x1p-46 * s * s;
    int pos = (E[0] > B) | (E[1] > B) | (E[2] > B), neg = (E[0] < -B) | (E[1] < -B) | (E[2] < -B);
    if (pos & neg) return 1;
    /* Bounds eX, eY, eZ on the errors of X, Y, Z = P_z (see the top of the
     * section): |X^ - X| <= 3.0002u (|px^ dz| + |pz^ dx|) < 4u (...)^ */
    const double *Z = pz;
    double eX[3], eY[3], eZ[3];
    for (int i = 0; i < 3; i++) {
        double apz = fabs(pz[i]);
        eX[i] = 4.0 * u * (fabs(px[i]) * adz + apz * adx);
        eY[i] = 4.0 * u * (fabs(py[i]) * adz + apz * ady);
        eZ[i] = 1.0001 * u * apz;
    }
    /* E_i = X_k Y_j - Y_k X_j: propagated error of the inputs plus the three
     * roundings; every term positive, so the computed sum times 1.001 is an
     * upper bound. */
    double eE[3];
    int sg[3];
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        eE[i] = 1.001 * (fabs(X[k]) * eY[j] + fabs(Y[j]) * eX[k] + eX[k] * eY[j] + fabs(Y[k]) * eX[j] +
                         fabs(X[j]) * eY[k] + eX[j] * eY[k] + 2.0001 * u * (fabs(a[i]) + fabs(c[i])));
        sg[i] = E[i] > eE[i] ? 1 : E[i] < -eE[i] ? -1 : 0; /* 0: sign unknown */
    }
    if ((sg[0] < 0 || sg[1] < 0 || sg[2] < 0) && (sg[0] > 0 || sg[1] > 0 || sg[2] > 0)) return 1;
    if (sg[0] == 0 || sg[0] != sg[1] || sg[1] != sg[2]) return 0;
    return tri_filter_tail(E, eE, Z, eZ, dz, sg[0], fill_hit, out);
}

static int verts_bad(const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3]) {
    int bad = 0;
    for (int a = 0; a < 3; a++)
        bad |= cbvh_f32_is_nan_or_inf(v0[a]) | cbvh_f32_is_nan_or_inf(v1[a]) | cbvh_f32_is_nan_or_inf(v2[a]);
    return bad;
}

uint32_t cbvh_ray_triangle_prepared(const cbvh_tri_ray *p, const cbvh_ray *ray, const cbvh_f32 v0[3],
                                    const cbvh_f32 v1[3], const cbvh_f32 v2[3], cbvh_tri_result *out) {
    if (CBVH_FAST_PATHS && p->ok && !verts_bad(v0, v1, v2)) {
        int f = filter(p, v0, v1, v2, 1, out);
        if (f == 1) memset(out, 0, sizeof *out); /* the exact path's miss */
        if (f) return 0;
    }
    return cbvh_ray_triangle_exact_only(ray, v0, v1, v2, out);
}

uint32_t cbvh_ray_triangle(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3],
                           cbvh_tri_result *out) {
    cbvh_tri_ray p;
    cbvh_tri_ray_prepare(ray, &p);
    return cbvh_ray_triangle_prepared(&p, ray, v0, v1, v2, out);
}

int cbvh_ray_triangle_filter_miss(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3],
                                  const cbvh_f32 v2[3]) {
    cbvh_tri_ray p;
    cbvh_tri_result r;
    cbvh_tri_ray_prepare(ray, &p);
    return filter(&p, v0, v1, v2, 0, &r) == 1;
}

int cbvh_ray_triangle_filter_hit(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3],
                                 cbvh_tri_result *out) {
    cbvh_tri_ray p;
    cbvh_tri_ray_prepare(ray, &p);
    return filter(&p, v0, v1, v2, 1, out) == 2;
}

cbvh_unit_path cbvh_ray_triangle_path(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3],
                                      const cbvh_f32 v2[3]) {
    cbvh_tri_ray p;
    cbvh_tri_result r;
    cbvh_tri_ray_prepare(ray, &p);
    if (!p.ok || verts_bad(v0, v1, v2)) return CBVH_PATH_REJECT;
    return filter(&p, v0, v1, v2, 1, &r) ? CBVH_PATH_FAST : CBVH_PATH_EXACT;
}
