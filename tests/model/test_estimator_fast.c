/* The constant-time scale estimator (rtl-model/src/units/scale_estimator.c) against
 * the binary search over [min_scale, 126] it replaced, kept here verbatim as
 * the oracle (same fit predicate, built from grid.h), and against an FPU
 * check of the fit predicate at the result and one below.  Status and scale
 * must be identical for every input: structured x structured bound pairs,
 * random pairs (wide, narrow, straddling zero, subnormal, +-FLT_MAX, zeros),
 * every N in 3..10 and every min_scale in -126..126, plus invalid params,
 * NaN/Inf and inverted boxes.
 *
 * usage: test_estimator_fast [--scale S]   (S multiplies the random counts) */
#include "units/grid.h"
#include "prop_util.h"

/* ---- the oracle: the previous model, verbatim ---- */
static int old_fits(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e) {
    int hl, hu;
    int64_t kl = cbvh_grid_floor(lb, e, &hl);
    int64_t ku = cbvh_grid_floor(ub, e, &hu);
    if (hl || hu) return cbvh_f32_cmp(lb, ub) == 0; /* see cbvh_grid_floor */
    return ku + 1 - kl <= (INT64_C(1) << p->quant_bits);
}

static uint32_t old_estimate(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int *scale) {
    *scale = 0;
    uint32_t st = cbvh_params_check(p);
    if (st) return st;
    if (cbvh_f32_is_nan_or_inf(lb) || cbvh_f32_is_nan_or_inf(ub)) return CBVH_ST_NAN_INF;
    if (cbvh_f32_cmp(lb, ub) > 0) return CBVH_ST_INVERTED;
    int lo = p->min_scale, hi = CBVH_SCALE_CEIL; /* fits(hi) always holds */
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (old_fits(p, lb, ub, mid))
            hi = mid;
        else
            lo = mid + 1;
    }
    *scale = lo;
    return 0;
}

/* FPU fit predicate: floor(x / 2^e) is exact in double for every finite
 * binary32 x and e in [-126, 126]; a difference below 2^N is exact. */
static int fpu_fits(int n, cbvh_f32 lb, cbvh_f32 ub, int e) { return oracle_cells(lb, ub, e) <= ldexp(1.0, n); }

static long n_cases;

static void check(int n, int ms, cbvh_f32 lb, cbvh_f32 ub) {
    cbvh_params p = {n, ms};
    int e_new = -999, e_old = -999;
    uint32_t st_new = cbvh_scale_estimate(&p, lb, ub, &e_new);
    uint32_t st_old = old_estimate(&p, lb, ub, &e_old);
    n_cases++;
    if (st_new != st_old || e_new != e_old) {
        prop_fail("N=%d ms=%d [%08x,%08x]: new st %#x e %d, old st %#x e %d", n, ms, lb, ub, st_new, e_new, st_old,
                  e_old);
        return;
    }
    if (st_new) return;
    if (!fpu_fits(n, lb, ub, e_new) || (e_new > ms && fpu_fits(n, lb, ub, e_new - 1)))
        prop_fail("N=%d ms=%d [%08x,%08x]: e %d is not the smallest fitting scale (FPU)", n, ms, lb, ub, e_new);
}

static void check_both_orders(int n, int ms, cbvh_f32 a, cbvh_f32 b) {
    check(n, ms, a, b);
    check(n, ms, b, a); /* one order is inverted unless a == b */
}

static int random_ms(prng *r) {
    switch (prng_below(r, 4)) {
    case 0: return CBVH_MIN_SCALE_DEFAULT;
    case 1: return prng_below(r, 2) ? CBVH_SCALE_FLOOR : CBVH_SCALE_CEIL - (int)prng_below(r, 3);
    default: return prng_range(r, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL);
    }
}

/* A box [lb, ub] of one of several shapes. */
static void random_box(prng *r, cbvh_f32 *lb, cbvh_f32 *ub) {
    cbvh_f32 a, b;
    switch (prng_below(r, 6)) {
    case 0: /* two independent floats */
        a = prop_random_float(r);
        b = prop_random_float(r);
        break;
    case 1: { /* narrow: a few ulps to 2^20 ulps apart */
        a = prop_random_float(r);
        int64_t k = cbvh_f32_key(a) + (int64_t)(prng_next(r) % (UINT64_C(1) << prng_range(r, 0, 20)));
        if (k > (int64_t)CBVH_F32_MAX) k = CBVH_F32_MAX;
        b = unkey(k);
        break;
    }
    case 2: { /* straddling zero, independent magnitudes */
        a = prop_random_float(r) | CBVH_F32_SIGN;
        b = prop_random_float(r) & ~CBVH_F32_SIGN;
        break;
    }
    case 3: /* subnormals and zeros against anything */
        a = prng_below(r, 4) ? (cbvh_f32)prng_below(r, 0x800000u) | ((cbvh_f32)prng_below(r, 2) << 31)
                             : ((cbvh_f32)prng_below(r, 2) << 31);
        b = prng_below(r, 2) ? prop_random_float(r) : (cbvh_f32)prng_below(r, 0x1000000u);
        break;
    case 4: /* +-FLT_MAX and its neighbours against anything */
        a = (CBVH_F32_MAX - prng_below(r, 4)) | ((cbvh_f32)prng_below(r, 2) << 31);
        b = prop_random_float(r);
        break;
    default: /* the same binade or neighbouring ones, scene-like */
        a = ((cbvh_f32)prng_below(r, 2) << 31) | ((cbvh_f32)prng_range(r, 100, 160) << CBVH_F32_FRAC_BITS) |
            ((cbvh_f32)prng_next(r) & CBVH_F32_FRAC);
        b = (a & CBVH_F32_SIGN) | ((cbvh_f32_exp_field(a) + (cbvh_f32)prng_below(r, 3)) << CBVH_F32_FRAC_BITS) |
            ((cbvh_f32)prng_next(r) & CBVH_F32_FRAC);
        if (prng_below(r, 2)) b ^= CBVH_F32_SIGN;
        break;
    }
    if (cbvh_f32_key(a) > cbvh_f32_key(b)) {
        cbvh_f32 t = a;
        a = b;
        b = t;
    }
    *lb = a;
    *ub = b;
}

int main(int argc, char **argv) {
    double scale = 1.0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--scale") && i + 1 < argc) {
            scale = atof(argv[++i]);
        } else {
            fprintf(stderr, "usage: test_estimator_fast [--scale S]\n");
            return 2;
        }
    }
    if (!(scale > 0.0 && scale <= 100.0)) {
        fprintf(stderr, "test_estimator_fast: --scale must be in (0, 100]\n");
        return 2;
    }
    prng r = {UINT64_C(0x5CA1E5713A7E0001)};

    /* 1. structured x structured, both orders, N cycling 3..10, min_scale
     * cycling over the default, the extremes and values in between. */
    static const int ms_list[] = {-30, -126, 126, -125, 125, 0, -60, 10, -100, 60, -1, 100};
    int nms = (int)(sizeof ms_list / sizeof ms_list[0]);
    long k = 0;
    for (int i = 0; i < PROP_N_STRUCT; i++)
        for (int j = i; j < PROP_N_STRUCT; j++, k++)
            check_both_orders(3 + (int)(k % 8), ms_list[k % nms], prop_structured(i), prop_structured(j));
    long structured = n_cases;

    /* 2. every (N, min_scale) on a fresh set of random boxes. */
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++)
        for (int ms = CBVH_SCALE_FLOOR; ms <= CBVH_SCALE_CEIL; ms++) {
            int per = (int)(64 * scale) + 1;
            for (int i = 0; i < per; i++) {
                cbvh_f32 lb, ub;
                random_box(&r, &lb, &ub);
                check(n, ms, lb, ub);
            }
        }

    /* 3. random boxes with random parameters. */
    long iters = (long)(2000000 * scale);
    for (long i = 0; i < iters; i++) {
        cbvh_f32 lb, ub;
        random_box(&r, &lb, &ub);
        check(prng_range(&r, CBVH_N_MIN, CBVH_N_MAX), random_ms(&r), lb, ub);
    }

    /* 4. bad parameters, NaN/Inf and inverted boxes: same status as before. */
    static const cbvh_f32 specials[] = {CBVH_F32_POS_INF, CBVH_F32_NEG_INF, 0x7FC00000u, 0xFFC00001u, 0x7F800001u,
                                        0u, CBVH_F32_SIGN, 1u, 0x3F800000u, 0xBF800000u, CBVH_F32_MAX};
    int nsp = (int)(sizeof specials / sizeof specials[0]);
    static const int bad_n[] = {2, 3, 10, 11, 0, -1};
    static const int bad_ms[] = {-127, -126, 126, 127, -30};
    for (int a = 0; a < nsp; a++)
        for (int b = 0; b < nsp; b++)
            for (int x = 0; x < 6; x++)
                for (int y = 0; y < 5; y++) check(bad_n[x], bad_ms[y], specials[a], specials[b]);

    printf("test_estimator_fast: %ld cases (%ld structured), %ld failures\n", n_cases, structured, prop_failures);
    return prop_failures ? 1 : 0;
}
