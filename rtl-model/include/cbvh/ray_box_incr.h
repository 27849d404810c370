/* Unit 10: the incremental reduced-precision ray-box test (seed 003's Eq. 5,
 * after Vaidyanathan et al. 2016), bit-exact and integer-defined.
 *
 * Spec: docs/traversal.md §17.  Source: rtl-model/src/units/ray_box_incr.c.
 *
 * Unlike unit 6 (cbvh_ray_box: every plane distance exact, rounded once),
 * this unit computes a child's plane distances from its parent's:
 *     t_lb = t_lb^parent + r  2^e d^-1        (the child's lower plane)
 *     t_ub = t_ub^parent - s' 2^e d^-1        (its upper plane, s' counted down
 *                                              from the parent's upper plane)
 * with d^-1 an M-bit reciprocal of the ray direction (per ray), exact
 * M x N-bit products, and one outward rounding per step into a plane-distance
 * format of M significant bits and X exponent bits.  Every value of that
 * format is a binary32 value, so every port is a binary32 bit pattern.
 *
 * Per ray:   cbvh_rbi_reciprocal (three times) and cbvh_rbi_anchor (the root
 *            box's plane distances, exact quotients rounded outward once).
 * Per child: cbvh_ray_box_incr (this is the unit of the unit table, the
 *            vectors and gateware/rtl/ray_box_incr.v).
 * The unit never rejects a box that the exact unit at full precision (M = 24)
 * accepts (proof: docs/traversal.md §17.5 and ray_box_incr.c). */
#ifndef CBVH_RAY_BOX_INCR_H
#define CBVH_RAY_BOX_INCR_H

#include <stdint.h>

#include "cbvh/traversal_units.h"

#define CBVH_RBI_TEXP_MIN 3 /* X: exponent bits of the plane-distance format */
#define CBVH_RBI_TEXP_MAX 8
#define CBVH_RBI_TEXP_DEFAULT 8 /* X = 8: binary32's normal range */

/* The design point of the unit: M (significant bits of the reciprocal and of
 * every plane distance, 3..24), X (exponent bits of the plane-distance
 * format, 3..8) and N (code bits, 3..10; only codes and their sum are
 * checked against it). */
typedef struct {
    int quant_bits; /* N */
    int mant;       /* M */
    int texp;       /* X */
} cbvh_rbi_params;

/* The plane-distance format F(M, X): +-0, +-Inf and the normal binary32
 * values with at most M significant bits whose binade exponent lies in
 * [emin, emax] = [2 - 2^(X-1), 2^(X-1) - 1] (no subnormals). */
static inline int cbvh_rbi_emax(int texp) { return (1 << (texp - 1)) - 1; }
static inline int cbvh_rbi_emin(int texp) { return 2 - (1 << (texp - 1)); }

/* A node's plane distances: per axis, the distance to its lower plane (t_lb)
 * and to its upper plane (t_ub), values of F(M, X).  For a ray with d_a > 0
 * the lower plane is the near one; for d_a < 0 the upper.  On a parallel axis
 * (reciprocal port +-0: d_a = +-0 or |d_a| > 2^126) they are the offsets
 * lower - o_a and upper - o_a instead, and the box needs t_lb <= 0 <= t_ub. */
typedef struct {
    cbvh_f32 t_lb[3], t_ub[3];
} cbvh_rbi_planes;

/* One axis of a child: its planes are the parent's lower plane + r 2^e and
 * the parent's upper plane - sp 2^e (sp = s' of Eq. 5, from the parent's
 * upper bound), with e the parent's child-grid scale; 0 <= r, sp, r + sp < 2^N. */
typedef struct {
    int e;
    uint32_t r, sp;
} cbvh_rbi_axis;

/* The unit's per-ray inputs (ports rcp_x..z, tmin, tmax). */
typedef struct {
    cbvh_f32 rcp[3];
    cbvh_f32 tmin, tmax;
} cbvh_rbi_ray;

typedef struct {
    int hit;
    cbvh_f32 t_near, t_far; /* max(tmin, near distances), min(tmax, far distances); +0 on a miss */
    cbvh_rbi_planes planes; /* the child's plane distances (the next level's parent); +0 on a miss */
} cbvh_rbi_result;

/* 0 or CBVH_ST_BAD_PARAM: N in [3, 10], M in [3, 24], X in [3, 8]. */
uint32_t cbvh_rbi_params_check(const cbvh_rbi_params *p);

/* Per ray, per axis (§17.2): the reciprocal port for direction d: sign(d) x
 * the truncation of 1/|d| to M significant bits, clamped below 2^128; +0 for
 * d = +-0 and +-0 (sign kept) for |d| > 2^126.  NAN_INF for a NaN/Inf d,
 * BAD_PARAM for M outside [3, 24]; *rcp = 0 then. */
uint32_t cbvh_rbi_reciprocal(cbvh_f32 d, int mant, cbvh_f32 *rcp);

/* Per ray (§17.3): the ports rcp and tmin/tmax of a ray; status as the exact
 * unit's ray checks (NAN_INF, ZERO_DIR, BAD_PARAM). */
uint32_t cbvh_rbi_ray_setup(const cbvh_ray *ray, const cbvh_rbi_params *p, cbvh_rbi_ray *out);

/* Per ray (§17.3), the anchor: the plane distances of the grid box `box` (as
 * the exact unit takes it: planes u + r 2^e and u + s 2^e), each the exact
 * quotient (plane - o) / d rounded once, outward, into F(M, X); for d_a = +-0
 * the offsets RD_F(lower - o_a), RU_F(upper - o_a); for |d_a| > 2^126
 * (-Inf, +Inf).  Status and rejects as cbvh_ray_box's (the ray, then the
 * box's NAN_INF, BAD_SCALE, BAD_CODE, INVERTED; M, X and N as
 * cbvh_rbi_params_check); every output +0 on a reject. */
uint32_t cbvh_rbi_anchor(const cbvh_ray *ray, const cbvh_rbi_params *p, const cbvh_grid_axis box[3],
                         cbvh_rbi_planes *out);

/* The unit (§17.4): a child's plane distances from its parent's, its
 * [t_near, t_far] and hit.  Status bits (all that apply, ORed): BAD_PARAM,
 * NAN_INF (a NaN anywhere, an infinite rcp or tmin, tmax = -Inf),
 * BAD_FORMAT (an rcp, t_lb or t_ub that is not a value of its format),
 * BAD_SCALE (e outside [-126, 126]), BAD_CODE (r or sp >= 2^N), INVERTED
 * (r + sp >= 2^N, on an axis whose codes are both < 2^N).  With any of them
 * every output is +0. */
uint32_t cbvh_ray_box_incr(const cbvh_rbi_params *p, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *parent,
                           const cbvh_rbi_axis child[3], cbvh_rbi_result *out);

/* RND_F: the exact value (-1)^neg (mag + sticky/2) 2^exp, where sticky = 1
 * stands for "strictly between mag and mag + 1", rounded once toward -Inf
 * (CBVH_RND_DOWN) or +Inf into F(M, X) (§17.1).  Exposed for the tests. */
cbvh_f32 cbvh_rbi_round(int neg, uint64_t mag, int exp, int sticky, cbvh_rnd mode, int mant, int texp);

/* 1 if x is a value of F(M, X) (any sign of zero, +-Inf included). */
int cbvh_rbi_in_format(cbvh_f32 x, int mant, int texp);

#endif
