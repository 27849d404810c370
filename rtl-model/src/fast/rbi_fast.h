/* Binary64 fast path of the incremental ray-box unit (unit 10,
 * docs/traversal.md §17.7).  Internal to rtl-model: the unit and the
 * traversals use it; it returns exactly the integer path's bits.
 *
 * One step of the unit is RND_F(t + i), t a value of F(M, X) and i = c 2^e rho
 * with c < 2^10 and rho a binary32 normal (or 0).  In binary64:
 *   - t and rho are exact (binary32 values); c 2^e is exact (e in [-126, 126]);
 *     i = (c 2^e) rho is exact: a 34-bit product whose magnitude lies in
 *     [2^-252, 2^264] when it is not 0, far inside binary64's normal range;
 *   - s = fl(t + i) and err = (t - (s - bb)) + (i - bb), bb = s - t, is
 *     Knuth's TwoSum: s + err = t + i exactly, |err| <= ulp53(s)/2, in
 *     round-to-nearest binary64 without overflow (|t + i| < 2^265), and with
 *     no underflow issue (sums and differences that land in binary64's
 *     subnormal range are exact, and none do: every nonzero operand is a
 *     multiple of 2^-276).
 * RND_F of s + err, on the bits of s: with K = 53 - M, the M-bit grid in s's
 * binade is every 2^K units of s's last place; m = s with its low K bits
 * cleared (toward zero), u = 2^K units.
 *   - low K bits of s nonzero: s lies at least one ulp53 inside the open cell
 *     (m, m + u), and s + err within half an ulp53 of s: the exact value is
 *     strictly inside that cell;
 *   - low bits zero, err = 0: the exact value is m (on the grid);
 *   - low bits zero, err of s's sign: the exact value is in (m, m + u);
 *   - low bits zero, err of the other sign: the exact value is in (m - u', m)
 *     where m - u' is the grid point below m (m - u on the bits: a borrow
 *     out of the significand lands on the top of the binade below, which is
 *     that point also when m is a power of two).
 * The toward-zero end of the cell is in the exact value's binade, so the
 * range rules of §17.1 are decided on it: below 2^emin -> 0 or 2^emin, above
 * the largest binade -> the largest value or Inf, and an away-rounded carry
 * past it -> Inf.  The result is a value of F, so converting it to binary32
 * is exact.  Needs binary64 without excess precision (FLT_EVAL_METHOD 0) in
 * round-to-nearest; elsewhere (and with -DCBVH_NO_FAST_PATHS) the integer
 * path runs.  Files using it are compiled with -ffp-contract=off (a fused
 * multiply-add could only remove the rounding of an exact product). */
#ifndef CBVH_RBI_FAST_H
#define CBVH_RBI_FAST_H

#include <float.h>
#include <stdint.h>
#include <string.h>

#include "cbvh/ray_box_incr.h"
#include "fast/fast_paths.h"
#include "fast/ray_box_f64.h" /* cbvh_rbf_bits, cbvh_rbf_from_bits, cbvh_rbf_pow2 */

#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0 && CBVH_FAST_PATHS
#define CBVH_RBI_FAST 1
#else
#define CBVH_RBI_FAST 0
#endif

/* Both planes of an axis in the two lanes of an SSE2 register (x86-64), or
 * the same steps one plane at a time (elsewhere, and with -DCBVH_NO_SSE2). */
#if defined(__SSE2__) && !defined(CBVH_NO_SSE2)
#define CBVH_RBI_SSE2 1
#include <emmintrin.h>
#else
#define CBVH_RBI_SSE2 0
#endif

typedef struct {
    double rho[3];         /* the reciprocal ports' values; 1 on a parallel axis (port +-0) */
    int up_lb[3];          /* the lower plane rounds up (RU_F): the port's sign bit, 0 on a parallel axis */
    int par[3], any_par;   /* parallel axes: offsets, inside iff t_lb <= 0 <= t_ub */
    double tmin;
    uint64_t mask, unit;   /* low 53 - M bits; one M-bit unit, on binary64 bits */
    uint64_t emin_b, emax_b; /* biased binary64 exponents of 2^emin and 2^emax */
    uint64_t min_bits, max_bits; /* 2^emin and the largest value of F, as binary64 bits */
    /* the SSE2 step's operands, in both lanes: all bits but the low 53 - M, one unit,
     * 2^emin, the largest value of F; per axis, lanes (lower, upper): -0
     * where the plane rounds up, else +0 */
    _Alignas(16) double keep2[2], unit2[2], lo2[2], max2[2], upsign[3][2];
} cbvh_rbi_fray;

/* A node as its children's tests read it: its plane distances as binary64
 * (exact), lanes (lower, upper) per axis, and per axis 2^e rho for its child
 * grid e and its negation, (2^e rho, -2^e rho) (exact: a binary32
 * significand times a power of two in range): a child's offsets are
 * (r, s') times them. */
typedef struct {
    _Alignas(16) double t[3][2];
    _Alignas(16) double se[3][2];
} cbvh_rbi_fnode;

static inline double cbvh_rbi_d(cbvh_f32 b) { return (double)cbvh_float_of(b); }
/* exact for the values it is given (binary32 values); -0 -> +0 */
static inline cbvh_f32 cbvh_rbi_f(double x) { return x == 0 ? 0u : cbvh_f32_of((float)x); }

static inline void cbvh_rbi_fprep(const cbvh_rbi_params *p, const cbvh_rbi_ray *r, cbvh_rbi_fray *f) {
    int M = p->mant, emin = cbvh_rbi_emin(p->texp), emax = cbvh_rbi_emax(p->texp);
    f->any_par = 0;
    for (int a = 0; a < 3; a++) {
        f->par[a] = cbvh_f32_is_zero(r->rcp[a]);
        f->any_par |= f->par[a];
        f->rho[a] = f->par[a] ? 1.0 : cbvh_rbi_d(r->rcp[a]);
        f->up_lb[a] = f->par[a] ? 0 : (int)(r->rcp[a] >> 31);
    }
    f->tmin = cbvh_rbi_d(r->tmin);
    f->unit = UINT64_C(1) << (53 - M);
    f->mask = f->unit - 1u;
    f->emin_b = (uint64_t)(emin + 1023);
    f->emax_b = (uint64_t)(emax + 1023);
    f->min_bits = f->emin_b << 52;
    f->max_bits = (f->emax_b << 52) | ((UINT64_C(1) << 52) - f->unit);
    for (int l = 0; l < 2; l++) {
        f->keep2[l] = cbvh_rbf_from_bits(~f->mask);
        f->unit2[l] = cbvh_rbf_from_bits(f->unit);
        f->lo2[l] = cbvh_rbf_from_bits(f->min_bits);
        f->max2[l] = cbvh_rbf_from_bits(f->max_bits);
    }
    for (int a = 0; a < 3; a++) {
        f->upsign[a][0] = f->up_lb[a] ? -0.0 : 0.0;
        f->upsign[a][1] = f->up_lb[a] ? 0.0 : -0.0;
    }
}

/* Node n's child grid on axis a is 2^e. */
static inline void cbvh_rbi_fnode_scale(const cbvh_rbi_fray *f, int a, int e, cbvh_rbi_fnode *n) {
    n->se[a][0] = cbvh_rbf_pow2(e) * f->rho[a];
    n->se[a][1] = -n->se[a][0];
}

/* The node with plane distances pl and child grid scales e[3] (in [-126, 126]). */
static inline void cbvh_rbi_fnode_of(const cbvh_rbi_fray *f, const cbvh_rbi_planes *pl, const int e[3],
                                     cbvh_rbi_fnode *n) {
    for (int a = 0; a < 3; a++) {
        n->t[a][0] = cbvh_rbi_d(pl->t_lb[a]);
        n->t[a][1] = cbvh_rbi_d(pl->t_ub[a]);
        cbvh_rbi_fnode_scale(f, a, e[a], n);
    }
}

/* The unit's integer path alone (test hook; ray_box_incr.c). */
uint32_t cbvh_ray_box_incr_int(const cbvh_rbi_params *p, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *parent,
                               const cbvh_rbi_axis child[3], cbvh_rbi_result *out);

/* RND_F(t + i) (see the top of the file); up: toward +Inf.  Branch-free
 * but for an infinite t and the rare range cases. */
static inline double cbvh_rbi_fstep(const cbvh_rbi_fray *f, double t, double i, uint64_t up) {
    if (!(t - t == 0)) return t; /* +-Inf + finite */
    double s = t + i, bb = s - t;
    double err = (t - (s - bb)) + (i - bb);
    uint64_t b = cbvh_rbf_bits(s), eb = cbvh_rbf_bits(err);
    uint64_t sign = b & (UINT64_C(1) << 63), mag = b ^ sign;
    uint64_t enz = (eb << 1) != 0;                  /* err != 0 */
    uint64_t eopp = enz & ((eb ^ b) >> 63);        /* ... and of the other sign than s */
    uint64_t lownz = (mag & f->mask) != 0;
    uint64_t m = mag & ~f->mask;
    uint64_t tz = m - ((lownz ^ 1u) & eopp) * f->unit; /* toward-zero end of the exact value's cell */
    uint64_t away = (b >> 63) ^ up;
    uint64_t r = tz + ((lownz | enz) & away) * f->unit;
    uint64_t ez = tz >> 52;
    if (ez - f->emin_b > f->emax_b - f->emin_b || (r >> 52) > f->emax_b) { /* outside F's binades, or s = 0 */
        if (mag == 0) return 0.0; /* then err = 0 too: t + i = 0 exactly */
        if (ez < f->emin_b) r = away ? f->min_bits : 0u;
        else r = away ? UINT64_C(0x7FF0000000000000) : f->max_bits;
        if (r == 0) return 0.0;
    }
    return cbvh_rbf_from_bits(r | sign);
}

#if CBVH_RBI_SSE2
/* cbvh_rbi_fstep on both lanes, for a finite t and results inside F's
 * binades, with the selections as lane masks.  It works on s's bit pattern
 * with its sign: clearing the low bits, and adding or taking one unit, move
 * the magnitude and never reach the sign bit (the magnitude stays between a
 * grid point >= 2^emin and the largest value of F, below).  The masks come
 * from comparisons:
 *   - err != 0 and of the other sign than s  <=>  err * s < 0: both are
 *     multiples of 2^-276 (top of the file) of magnitude at most 2^265, so the
 *     product, when not 0, lies in [2^-552, 2^530] and keeps its sign;
 *   - away (the rounding moves the magnitude up)  <=>  (s with its sign bit
 *     flipped on the up lanes) < 0, for s != 0 (s = 0 is special);
 *   - the lane is special where |tz| < 2^emin (s = 0 included: then err = 0
 *     and tz = 0) or |tz| >= the largest value of F (then r may reach
 *     2^(emax + 1); an infinite t gives s infinite, |tz| >= its binade's top,
 *     and err NaN, read nowhere).  |tz| is the bit pattern of a value in
 *     [0, Inf], so binary64 comparisons order it as the integers; the caller
 *     keeps the least and the largest |tz| of the box in *lo, *hi, and runs
 *     the scalar steps on the whole box when either is out of range. */
static inline __m128d cbvh_rbi_fstep2(const cbvh_rbi_fray *f, __m128d t, __m128d i, __m128d upsign, __m128d *lo,
                                      __m128d *hi) {
    __m128d s = _mm_add_pd(t, i), bb = _mm_sub_pd(s, t);
    __m128d err = _mm_add_pd(_mm_sub_pd(t, _mm_sub_pd(s, bb)), _mm_sub_pd(i, bb));
    __m128d zero = _mm_setzero_pd(), unit = _mm_load_pd(f->unit2);
    __m128d m = _mm_and_pd(s, _mm_load_pd(f->keep2)); /* s with its low 53 - M bits cleared */
    __m128d lowz = _mm_cmpeq_pd(m, s);
    __m128d eopp = _mm_cmplt_pd(_mm_mul_pd(err, s), zero);
    __m128d exact = _mm_andnot_pd(_mm_cmpneq_pd(err, zero), lowz); /* s + err on the grid */
    __m128d away = _mm_cmplt_pd(_mm_xor_pd(s, upsign), zero);
    __m128i tz = _mm_sub_epi64(_mm_castpd_si128(m), _mm_castpd_si128(_mm_and_pd(_mm_and_pd(lowz, eopp), unit)));
    __m128i r = _mm_add_epi64(tz, _mm_castpd_si128(_mm_andnot_pd(exact, _mm_and_pd(away, unit))));
    __m128d atz = _mm_andnot_pd(_mm_set1_pd(-0.0), _mm_castsi128_pd(tz));
    *lo = _mm_min_pd(*lo, atz);
    *hi = _mm_max_pd(*hi, atz);
    return _mm_castsi128_pd(r);
}
#endif

/* The unit's computation for valid inputs, for a child with codes r[a],
 * sp[a] of node n: 1 on a hit, with the child's plane distances (ch->t; its
 * se is not set) and t_near, t_far as binary64; 0 on a miss (then the outputs
 * are not all set: a miss has every output +0). */
static inline int cbvh_rbi_ftest1(const cbvh_rbi_fray *f, double tmax, const cbvh_rbi_fnode *n, const uint32_t r[3],
                                  const uint32_t sp[3], cbvh_rbi_fnode *ch, double *t_near, double *t_far) {
    double tn = f->tmin, tf = tmax;
    for (int a = 0; a < 3; a++) {
        uint64_t up = (uint64_t)f->up_lb[a];
        double lb = cbvh_rbi_fstep(f, n->t[a][0], (double)r[a] * n->se[a][0], up);
        double ub = cbvh_rbi_fstep(f, n->t[a][1], (double)sp[a] * n->se[a][1], up ^ 1u);
        ch->t[a][0] = lb;
        ch->t[a][1] = ub;
        if (f->par[a]) {
            if (lb > 0 || ub < 0) return 0;
            continue;
        }
        double nn = up ? ub : lb, fa = up ? lb : ub;
        tn = nn > tn ? nn : tn;
        tf = fa < tf ? fa : tf;
        if (tn > tf) return 0;
    }
    *t_near = tn;
    *t_far = tf;
    return 1;
}

static inline int cbvh_rbi_ftest(const cbvh_rbi_fray *f, double tmax, const cbvh_rbi_fnode *n, const uint32_t r[3],
                                 const uint32_t sp[3], cbvh_rbi_fnode *ch, double *t_near, double *t_far) {
#if CBVH_RBI_SSE2
    /* lanes (near, -far): one max accumulates both t_near and t_far; a box
     * with a special lane is redone one plane at a time */
    if (f->any_par) return cbvh_rbi_ftest1(f, tmax, n, r, sp, ch, t_near, t_far); /* axis-parallel rays */
    __m128d acc = _mm_set_pd(-tmax, f->tmin), neg1 = _mm_set_pd(-0.0, 0.0);
    __m128d lo = _mm_load_pd(f->max2), hi = _mm_setzero_pd();
    for (int a = 0; a < 3; a++) {
        __m128d t2 = _mm_load_pd(n->t[a]);
        __m128d i2 = _mm_mul_pd(_mm_cvtepi32_pd(_mm_setr_epi32((int)r[a], (int)sp[a], 0, 0)), _mm_load_pd(n->se[a]));
        __m128d r2 = cbvh_rbi_fstep2(f, t2, i2, _mm_load_pd(f->upsign[a]), &lo, &hi);
        _mm_store_pd(ch->t[a], r2);
        __m128d nf = f->up_lb[a] ? _mm_shuffle_pd(r2, r2, 1) : r2; /* (near, far) */
        acc = _mm_max_pd(_mm_xor_pd(nf, neg1), acc);
    }
    if (_mm_movemask_pd(_mm_or_pd(_mm_cmplt_pd(lo, _mm_load_pd(f->lo2)), _mm_cmpge_pd(hi, _mm_load_pd(f->max2)))))
        return cbvh_rbi_ftest1(f, tmax, n, r, sp, ch, t_near, t_far);
    double tn = _mm_cvtsd_f64(acc), tf = -_mm_cvtsd_f64(_mm_unpackhi_pd(acc, acc));
    *t_near = tn;
    *t_far = tf;
    return tn <= tf;
#else
    return cbvh_rbi_ftest1(f, tmax, n, r, sp, ch, t_near, t_far);
#endif
}

#endif
