/* Unit 10: the incremental reduced-precision ray-box test (docs/traversal.md
 * §17; seed 003's Eq. 5 after Vaidyanathan et al. 2016).  Integer-only.
 *
 * Per ray and axis a, rho_a = the reciprocal port: sign(d_a) x RZ_M(1/|d_a|)
 * (truncated to M significant bits), clamped to (2^M - 1) 2^(128-M) when
 * 1/|d_a| >= 2^128, and +-0 when d_a = +-0 or |d_a| > 2^126: the axis is
 * then parallel (below) (§17.2).  Per child
 * and axis, with the parent's plane distances T_lb, T_ub (values of the
 * format F(M, X), §17.1), the parent's child-grid scale e and the child's
 * codes r (from the parent's lower plane) and s' (from its upper plane):
 *
 *     T_lb' = RND_lb(T_lb + r  2^e rho_a)     RND_lb = RD_F if rho_a >= +0, else RU_F
 *     T_ub' = RND_ub(T_ub - s' 2^e rho_a)     RND_ub = RU_F if rho_a >= +0, else RD_F
 *
 * (the sign of rho_a is the sign bit of its port, so -0 counts as negative:
 * it comes from a huge negative d_a).  Each sum is exact before its one
 * rounding: an M x N-bit product r x sig(rho) and one aligned addition.  The
 * near distance of an axis is T_lb' when rho_a >= +0, else T_ub'; the far one
 * the other; t_near = max(tmin, near_x, near_y, near_z), t_far = min(tmax,
 * far_x, far_y, far_z), hit = t_near <= t_far (values: -0 == +0).
 *
 * Why it never rejects a box the exact unit accepts (§17.5).  Let the box on
 * axis a have the exact planes L <= H, and let its parent's be Lp <= Hp with
 * L = Lp + r 2^e, H = Hp - s' 2^e (r, s' >= 0: the child lies inside its
 * parent).  Write t(P) = (P - o_a) / d_a.  Claim (for d_a != 0): T_lb <= t(L)
 * and T_ub >= t(H) when d_a > 0, T_lb >= t(L) and T_ub <= t(H) when d_a < 0 —
 * every near distance is a lower bound and every far distance an upper bound
 * of the exact one.  The anchor (cbvh_rbi_anchor) rounds the exact quotients
 * of the root box outward, so the claim holds there.  Step, d_a > 0: the port
 * holds rho with 0 <= rho <= 1/d_a (truncation and clamps only ever shrink
 * it), and r 2^e >= 0, so
 *     t(L) = t(Lp) + r 2^e / d_a >= t(Lp) + r 2^e rho >= T_lb + r 2^e rho >= RD_F(...) = T_lb',
 *     t(H) = t(Hp) - s' 2^e / d_a <= t(Hp) - s' 2^e rho <= T_ub - s' 2^e rho <= RU_F(...) = T_ub'.
 * d_a < 0: the port holds -rho with 0 <= rho <= 1/|d_a|, and the same lines
 * with the inequalities reversed give T_lb' >= t(L) and T_ub' <= t(H).  An
 * infinite T stays itself (T + finite), which keeps each inequality (a lower
 * bound is never +Inf, an upper bound never -Inf, by induction).  So the
 * increments may only be underestimated, never overestimated: that is why
 * both the reciprocal and its product are truncated, and why s' must count
 * from the parent's *upper* plane (seed 003, Sec. 3): from the lower plane,
 * t(H) = t(Lp) + s 2^e / d_a would need an upper bound of t(Lp), which the
 * parent carries only as a lower bound.
 * A parallel axis (the port is +-0: d_a = +-0, or |d_a| > 2^126): the
 * distances are spatial offsets lower - o_a and upper - o_a instead, stepped
 * with rho = 1 exactly (the same lines with 1/d_a replaced by 1: the lower
 * offset rounds down, the upper up), and the axis passes iff
 * T_lb' <= 0 <= T_ub'.  By the same induction T_lb <= L - o_a and
 * T_ub >= H - o_a, so a box the exact unit accepts (L <= o_a <= H) passes.
 * For |d_a| > 2^126 the anchor gives (-Inf, +Inf): no constraint at all,
 * which is conservative for any ray.
 * Then near_a <= the exact near distance n_a and far_a >= f_a on every axis,
 * max and min are monotone, and [t_near, t_far] contains the exact interval
 * [max(tmin, n_a), min(tmax, f_a)]: if the real-number slab test hits, so
 * does this unit.  The exact unit at M = 24 (cbvh_ray_box) returns RD(n_a)
 * and RU(f_a) on the binary32 grid (saturation included); every value of F
 * is a binary32 value or +-Inf, so near_a <= n_a implies near_a <= RD(n_a)
 * (RD(x) is the largest such value <= x) and far_a >= RU(f_a): its interval
 * contains the exact unit's, and it hits whenever the exact unit does, at
 * every M of the exact unit (a coarser M only widens that one).
 * tests/traversal/test_ray_box_incr.c checks this on 10^7 chains of boxes
 * (10^8 with --long) and every structured case, and the roundings bit for bit
 * against a GMP oracle. */
#include "cbvh/ray_box_incr.h"

#include <string.h>

#include "fast/ray_prep.h"
#include "fast/rbi_fast.h"
#include "units/exact_wide.h"
#include "units/grid.h"

uint32_t cbvh_rbi_params_check(const cbvh_rbi_params *p) {
    if (p->quant_bits < CBVH_N_MIN || p->quant_bits > CBVH_N_MAX) return CBVH_ST_BAD_PARAM;
    if (p->mant < CBVH_MANT_MIN || p->mant > CBVH_MANT_MAX) return CBVH_ST_BAD_PARAM;
    if (p->texp < CBVH_RBI_TEXP_MIN || p->texp > CBVH_RBI_TEXP_MAX) return CBVH_ST_BAD_PARAM;
    return 0;
}

/* RND_F (§17.1).  The callers pass sticky = 1 only with bitlen(mag) > M, so
 * the open cell (mag, mag + 1) holds no value of the M-bit grid and rounding
 * any of its points is rounding (mag + 1/2). */
cbvh_f32 cbvh_rbi_round(int neg, uint64_t mag, int exp, int sticky, cbvh_rnd mode, int M, int X) {
    if (mag == 0 && !sticky) return 0;
    int emax = cbvh_rbi_emax(X), emin = cbvh_rbi_emin(X);
    int away = neg ? (mode == CBVH_RND_DOWN) : (mode == CBVH_RND_UP);
    uint32_t sign = neg ? CBVH_F32_SIGN : 0u;
    int len = cbvh_grid_bitlen(mag);
    int top = exp + len - 1; /* binade: |value| in [2^top, 2^(top+1)) */
    if (top < emin) return away ? (sign | (uint32_t)(emin + 127) << 23) : 0u; /* below 2^emin: 0 or 2^emin */
    if (top > emax) /* above the largest binade: +-Inf toward the direction, else the largest value */
        return away ? (sign | CBVH_F32_POS_INF)
                    : (sign | (uint32_t)(emax + 127) << 23 | (((UINT32_C(1) << M) - 1u) << (24 - M) & CBVH_F32_FRAC));
    int drop = len - M;
    uint64_t q;
    int rem;
    if (drop > 0) {
        q = mag >> drop;
        rem = sticky || (mag & ((UINT64_C(1) << drop) - 1u)) != 0;
    } else {
        q = mag << -drop;
        rem = sticky;
    }
    if (rem && away) {
        q++;
        if (q >> M) { /* carry into the next binade */
            q >>= 1;
            if (++top > emax) return sign | CBVH_F32_POS_INF;
        }
    }
    return sign | (uint32_t)(top + 127) << 23 | ((uint32_t)q << (24 - M) & CBVH_F32_FRAC);
}

int cbvh_rbi_in_format(cbvh_f32 x, int M, int X) {
    if (cbvh_f32_is_nan(x)) return 0;
    if (cbvh_f32_is_nan_or_inf(x) || cbvh_f32_is_zero(x)) return 1;
    int be = (int)((x >> 23) & 0xFFu);
    if (be == 0) return 0; /* subnormal */
    int top = be - 127;
    return top >= cbvh_rbi_emin(X) && top <= cbvh_rbi_emax(X) && (x & ((UINT32_C(1) << (24 - M)) - 1u)) == 0;
}

/* A reciprocal port: +-0, or a normal binary32 with at most M significant bits. */
static int rcp_in_format(cbvh_f32 x, int M) {
    if (cbvh_f32_is_zero(x)) return 1;
    return (x & CBVH_F32_EXP) != 0 && (x & ((UINT32_C(1) << (24 - M)) - 1u)) == 0;
}

uint32_t cbvh_rbi_reciprocal(cbvh_f32 d, int M, cbvh_f32 *rcp) {
    *rcp = 0;
    if (M < CBVH_MANT_MIN || M > CBVH_MANT_MAX) return CBVH_ST_BAD_PARAM;
    if (cbvh_f32_is_nan_or_inf(d)) return CBVH_ST_NAN_INF;
    if (cbvh_f32_is_zero(d)) return 0; /* -0 is the value 0: +0, the lower plane is near */
    uint32_t sign = d & CBVH_F32_SIGN;
    int s, e;
    uint32_t sig;
    cbvh_grid_break(d, &s, &sig, &e);
    int sh = 24 - cbvh_grid_bitlen(sig); /* |d| = ds 2^de, ds in [2^23, 2^24) */
    uint64_t ds = (uint64_t)sig << sh;
    int de = e - sh;
    uint64_t q;
    int top; /* 1/|d| = 2^-de / ds; q = its M-bit truncation's significand, 2^top its binade */
    if (ds == (UINT64_C(1) << 23)) {
        q = UINT64_C(1) << (M - 1);
        top = -de - 23;
    } else {
        q = (UINT64_C(1) << (23 + M)) / ds; /* in (2^(M-1), 2^M): floor of 2^(23+M) / ds */
        top = -de - 24;
    }
    if (top < -126) { /* |d| > 2^126: 1/|d| below binary32's normal range -> 0, keeping the sign */
        *rcp = sign;
        return 0;
    }
    if (top > 127) { /* 1/|d| >= 2^128: the largest M-bit value below it */
        q = (UINT64_C(1) << M) - 1u;
        top = 127;
    }
    *rcp = sign | (uint32_t)(top + 127) << 23 | ((uint32_t)q << (24 - M) & CBVH_F32_FRAC);
    return 0;
}

uint32_t cbvh_rbi_ray_setup(const cbvh_ray *ray, const cbvh_rbi_params *p, cbvh_rbi_ray *out) {
    memset(out, 0, sizeof *out);
    uint32_t st = cbvh_rbi_params_check(p) | cbvh_rb_ray_status(ray, CBVH_MANT_MAX);
    if (st) return st;
    for (int a = 0; a < 3; a++) cbvh_rbi_reciprocal(ray->d[a], p->mant, &out->rcp[a]);
    out->tmin = ray->tmin;
    out->tmax = ray->tmax;
    return 0;
}

/* RND_F of a binary32 value that is already a directed rounding of x in the
 * same direction: that is RND_F(x), because F's values are binary32 values
 * (nested grids: RD_F(x) <= RD_32(x) <= x, so RD_F(RD_32(x)) = RD_F(x)). */
static cbvh_f32 round_f32(cbvh_f32 v, cbvh_rnd mode, int M, int X) {
    if (cbvh_f32_is_nan_or_inf(v)) return v;
    int s, e;
    uint32_t sig;
    cbvh_grid_break(v, &s, &sig, &e);
    return cbvh_rbi_round(s, sig, e, 0, mode, M, X);
}

uint32_t cbvh_rbi_anchor(const cbvh_ray *ray, const cbvh_rbi_params *p, const cbvh_grid_axis box[3],
                         cbvh_rbi_planes *out) {
    memset(out, 0, sizeof *out);
    uint32_t st = cbvh_rbi_params_check(p) | cbvh_rb_ray_status(ray, CBVH_MANT_MAX);
    for (int a = 0; a < 3; a++) { /* the box checks of cbvh_ray_box */
        const cbvh_grid_axis *g = &box[a];
        if (cbvh_f32_is_nan(g->u) || g->u == CBVH_F32_POS_INF) st |= CBVH_ST_NAN_INF;
        if (g->e < CBVH_SCALE_FLOOR || g->e > CBVH_SCALE_CEIL) st |= CBVH_ST_BAD_SCALE;
        if (g->r > CBVH_CODE_MAX || g->s > CBVH_CODE_MAX) st |= CBVH_ST_BAD_CODE;
        else if (g->r >= g->s) st |= CBVH_ST_INVERTED;
    }
    if (st) return st;
    for (int a = 0; a < 3; a++) {
        cbvh_xw u, step, lo, hi, o, d, num;
        if (box[a].u == CBVH_F32_NEG_INF) cbvh_xw_from_int(&u, -1, 128); /* -Inf encodes -2^128 */
        else cbvh_xw_from_f32(&u, box[a].u);
        cbvh_xw_from_int(&step, (int64_t)box[a].r, box[a].e);
        cbvh_xw_add(&lo, &u, &step);
        cbvh_xw_from_int(&step, (int64_t)box[a].s, box[a].e);
        cbvh_xw_add(&hi, &u, &step);
        cbvh_xw_from_f32(&o, ray->o[a]);
        cbvh_f32 rc;
        cbvh_rbi_reciprocal(ray->d[a], p->mant, &rc);
        if (cbvh_f32_is_zero(rc) && !cbvh_f32_is_zero(ray->d[a])) { /* |d| > 2^126: parallel, unconstrained */
            out->t_lb[a] = CBVH_F32_NEG_INF;
            out->t_ub[a] = CBVH_F32_POS_INF;
            continue;
        }
        int neg = (ray->d[a] & CBVH_F32_SIGN) != 0 && !cbvh_f32_is_zero(ray->d[a]);
        cbvh_rnd m_lb = neg ? CBVH_RND_UP : CBVH_RND_DOWN, m_ub = neg ? CBVH_RND_DOWN : CBVH_RND_UP;
        if (cbvh_f32_is_zero(ray->d[a])) cbvh_xw_from_int(&d, 1, 0); /* d = 0: offsets lower - o, upper - o */
        else cbvh_xw_from_f32(&d, ray->d[a]);
        cbvh_xw_sub(&num, &lo, &o);
        out->t_lb[a] = round_f32(cbvh_xw_div_round(&num, &d, p->mant, m_lb), m_lb, p->mant, p->texp);
        cbvh_xw_sub(&num, &hi, &o);
        out->t_ub[a] = round_f32(cbvh_xw_div_round(&num, &d, p->mant, m_ub), m_ub, p->mant, p->texp);
    }
    return 0;
}

/* RND_F(t + (-1)^ineg B 2^eb), exactly: t a value of F, B < 2^35.
 *
 * The operand with the higher top bit ("big", at most 35 bits) is placed with
 * its top bit at bit 61 of a 64-bit window whose unit is 2^e0; the other
 * ("small") is aligned to that unit.  If it reaches below the unit, it lies
 * entirely below 2^(e0 + 35) while big >= 2^(e0 + 61): the sum is at least
 * 2^(e0 + 60), so its M-bit rounding position (M <= 24) is at least 2^36
 * units, and replacing small by its floor in units plus "a bit more" (sticky)
 * leaves the sum strictly inside the same unit cell (mag, mag + 1), which no
 * rounding boundary splits: the directed rounding is that of the exact sum.
 * (For a difference, big - small lies in (big - fl - 1, big - fl): floor
 * big - fl - 1, sticky.)  Otherwise the aligned small is below 2^62 and the
 * sum or difference is exact in the window. */
static cbvh_f32 add_round(cbvh_f32 t, int ineg, uint64_t B, int eb, cbvh_rnd mode, int M, int X) {
    if (B == 0 || cbvh_f32_is_nan_or_inf(t)) return cbvh_f32_is_zero(t) ? 0u : t; /* t itself (+-Inf + finite) */
    if (cbvh_f32_is_zero(t)) return cbvh_rbi_round(ineg, B, eb, 0, mode, M, X);
    int tneg, ea;
    uint32_t A;
    cbvh_grid_break(t, &tneg, &A, &ea);
    int la = cbvh_grid_bitlen(A), lb = cbvh_grid_bitlen(B);
    uint64_t big = A, small = B;
    int eg = ea, es = eb, gneg = tneg, sneg = ineg, lg = la;
    if (eb + lb > ea + la) {
        big = B, small = A, eg = eb, es = ea, gneg = ineg, sneg = tneg, lg = lb;
    }
    int sh = 62 - lg, e0 = eg - sh, k = es - e0;
    uint64_t gm = big << sh, sm;
    int lost = 0;
    if (k >= 0) sm = small << k; /* small's top <= big's: below 2^62 */
    else if (k > -64) {
        sm = small >> -k;
        lost = (small & ((UINT64_C(1) << -k) - 1u)) != 0;
    } else {
        sm = 0;
        lost = 1;
    }
    uint64_t mag;
    int neg;
    if (gneg == sneg) {
        mag = gm + sm;
        neg = gneg;
    } else if (gm >= sm) {
        mag = gm - sm - (uint64_t)lost;
        neg = gneg;
    } else { /* only without lost bits (then small's top is far below big's) */
        mag = sm - gm;
        neg = sneg;
    }
    return cbvh_rbi_round(neg, mag, e0, lost, mode, M, X);
}

static uint32_t unit_status(const cbvh_rbi_params *p, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *par,
                            const cbvh_rbi_axis ch[3]) {
    uint32_t st = cbvh_rbi_params_check(p);
    int fmt_ok = cbvh_rbi_params_check(&(cbvh_rbi_params){CBVH_N_MIN, p->mant, p->texp}) == 0;
    int n_ok = p->quant_bits >= CBVH_N_MIN && p->quant_bits <= CBVH_N_MAX;
    if (cbvh_f32_is_nan_or_inf(ray->tmin) || cbvh_f32_is_nan(ray->tmax) || ray->tmax == CBVH_F32_NEG_INF)
        st |= CBVH_ST_NAN_INF;
    for (int a = 0; a < 3; a++) {
        cbvh_f32 rc = ray->rcp[a], lb = par->t_lb[a], ub = par->t_ub[a];
        if (cbvh_f32_is_nan_or_inf(rc) || cbvh_f32_is_nan(lb) || cbvh_f32_is_nan(ub)) st |= CBVH_ST_NAN_INF;
        if (fmt_ok) {
            if (!cbvh_f32_is_nan_or_inf(rc) && !rcp_in_format(rc, p->mant)) st |= CBVH_ST_BAD_FORMAT;
            if (!cbvh_f32_is_nan(lb) && !cbvh_rbi_in_format(lb, p->mant, p->texp)) st |= CBVH_ST_BAD_FORMAT;
            if (!cbvh_f32_is_nan(ub) && !cbvh_rbi_in_format(ub, p->mant, p->texp)) st |= CBVH_ST_BAD_FORMAT;
        }
        if (ch[a].e < CBVH_SCALE_FLOOR || ch[a].e > CBVH_SCALE_CEIL) st |= CBVH_ST_BAD_SCALE;
        if (n_ok) {
            uint32_t lim = UINT32_C(1) << p->quant_bits;
            if (ch[a].r >= lim || ch[a].sp >= lim) st |= CBVH_ST_BAD_CODE;
            else if (ch[a].r + ch[a].sp >= lim) st |= CBVH_ST_INVERTED;
        }
    }
    return st;
}

/* The integer path: the unit's definition, step by step. */
uint32_t cbvh_ray_box_incr_int(const cbvh_rbi_params *p, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *parent,
                               const cbvh_rbi_axis child[3], cbvh_rbi_result *out) {
    memset(out, 0, sizeof *out);
    uint32_t st = unit_status(p, ray, parent, child);
    if (st) return st;
    const int M = p->mant, X = p->texp;
    int64_t kn = cbvh_f32_key(ray->tmin), kf = cbvh_f32_key(ray->tmax);
    cbvh_f32 tn = ray->tmin, tf = ray->tmax;
    cbvh_rbi_planes pl;
    int outside = 0;
    for (int a = 0; a < 3; a++) {
        cbvh_f32 rc = ray->rcp[a];
        int par = cbvh_f32_is_zero(rc); /* a parallel axis: distances are offsets, rho = 1 */
        int rneg = !par && (rc & CBVH_F32_SIGN) != 0;
        uint64_t rsig = UINT64_C(1) << (M - 1); /* rho = rsig 2^rexp, rsig < 2^M */
        int rexp = -(M - 1);
        if (!par) {
            rsig = ((rc & CBVH_F32_FRAC) | 0x800000u) >> (24 - M);
            rexp = (int)((rc >> 23) & 0xFFu) - 127 - (M - 1);
        }
        cbvh_rnd m_lb = rneg ? CBVH_RND_UP : CBVH_RND_DOWN, m_ub = rneg ? CBVH_RND_DOWN : CBVH_RND_UP;
        pl.t_lb[a] = add_round(parent->t_lb[a], rneg, child[a].r * rsig, child[a].e + rexp, m_lb, M, X);
        pl.t_ub[a] = add_round(parent->t_ub[a], !rneg, child[a].sp * rsig, child[a].e + rexp, m_ub, M, X);
        if (par) { /* inside iff lower - o <= 0 <= upper - o */
            outside |= cbvh_f32_key(pl.t_lb[a]) > 0 || cbvh_f32_key(pl.t_ub[a]) < 0;
            continue;
        }
        cbvh_f32 n = rneg ? pl.t_ub[a] : pl.t_lb[a], f = rneg ? pl.t_lb[a] : pl.t_ub[a];
        if (cbvh_f32_key(n) > kn) kn = cbvh_f32_key(n), tn = n;
        if (cbvh_f32_key(f) < kf) kf = cbvh_f32_key(f), tf = f;
    }
    if (outside || kn > kf) return 0;
    out->hit = 1;
    out->t_near = cbvh_f32_is_zero(tn) ? 0u : tn;
    out->t_far = cbvh_f32_is_zero(tf) ? 0u : tf;
    out->planes = pl;
    return 0;
}

/* The unit: its status, then the binary64 path of fast/rbi_fast.h, which
 * gives the integer path's bits (proof there), or the integer path. */
uint32_t cbvh_ray_box_incr(const cbvh_rbi_params *p, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *parent,
                           const cbvh_rbi_axis child[3], cbvh_rbi_result *out) {
    if (!CBVH_RBI_FAST) return cbvh_ray_box_incr_int(p, ray, parent, child, out);
    memset(out, 0, sizeof *out);
    uint32_t st = unit_status(p, ray, parent, child);
    if (st) return st;
    cbvh_rbi_fray f;
    cbvh_rbi_fnode par, ch;
    double tn, tf;
    int e[3] = {child[0].e, child[1].e, child[2].e};
    uint32_t r[3] = {child[0].r, child[1].r, child[2].r}, sp[3] = {child[0].sp, child[1].sp, child[2].sp};
    cbvh_rbi_fprep(p, ray, &f);
    cbvh_rbi_fnode_of(&f, parent, e, &par);
    if (!cbvh_rbi_ftest(&f, cbvh_rbi_d(ray->tmax), &par, r, sp, &ch, &tn, &tf)) return 0;
    out->hit = 1;
    out->t_near = cbvh_rbi_f(tn);
    out->t_far = cbvh_rbi_f(tf);
    for (int a = 0; a < 3; a++) {
        out->planes.t_lb[a] = cbvh_rbi_f(ch.t[a][0]);
        out->planes.t_ub[a] = cbvh_rbi_f(ch.t[a][1]);
    }
    return 0;
}
