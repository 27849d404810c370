/* Vectors of the incremental ray-box unit (unit 10, docs/traversal.md §17).
 *
 * A file holds one N (its header) and the design points (M, X) = (6, 8),
 * (8, 8), (12, 8), (16, 8), (24, 8) and (8, 5) in its mant and texp fields:
 * an RTL instance is built for one of them and runs its vectors
 * (gateware/tb/tb_ray_box_incr.v).  Per design point: chains of boxes down
 * from anchored roots (every level's parent distances are the unit's own
 * outputs one level up, as a traversal carries them) for rays with
 * structured directions (+-1, 3, 0.1, 1/3, powers of two near 2^+-20 and
 * 2^+-126, the subnormal 2^-149, huge 2^127 and +-0, whose axes are
 * parallel); F's edges (parent distances at +-max, +-2^emin and one unit
 * inside, steps of 1/2, 1 and 3/2 units and up to 2^(emax+1)); parallel axes
 * inside, outside and on a face; infinite distances; exact cancellation to 0;
 * tmin/tmax at +-0, +-2^-149, -FLT_MAX, +Inf and tmin > tmax; then random
 * inputs; appended, every reject alone and ORed.  Integer-only, like the
 * other generators: the unit and its per-ray functions are integer-defined. */
#include "vectors/gen/gen.h"

#include "cbvh/ray_box_incr.h"

#define NDP 6
static const int dp_m[NDP] = {6, 8, 12, 16, 24, 8}, dp_x[NDP] = {8, 8, 8, 8, 8, 5};

/* Input words: rcp[3] tmin tmax mant texp, then per axis t_lb t_ub scale r sp. */
static void emit_incr(gen_t *g, int M, int X, const cbvh_rbi_ray *ray, const cbvh_rbi_planes *par,
                      const cbvh_rbi_axis ax[3]) {
    uint32_t in[22];
    for (int a = 0; a < 3; a++) {
        in[a] = ray->rcp[a];
        in[7 + 5 * a] = par->t_lb[a];
        in[8 + 5 * a] = par->t_ub[a];
        in[9 + 5 * a] = cbvh_scale_to_word(ax[a].e);
        in[10 + 5 * a] = ax[a].r;
        in[11 + 5 * a] = ax[a].sp;
    }
    in[3] = ray->tmin;
    in[4] = ray->tmax;
    in[5] = (uint32_t)M;
    in[6] = (uint32_t)X;
    vg_emit(g, in);
}

/* Direction components, and origins, as binary32 patterns. */
#define N_DIRS 15
static const cbvh_f32 dirs[N_DIRS] = {
    F_ONE,       0xBF800000u /* -1 */, 0x40400000u /* 3 */, 0xBF400000u /* -0.75 */, 0x3DCCCCCDu /* 0.1 */,
    F_THIRD,     0x35800000u /* 2^-20 */, 0xC9800000u /* -2^20 */, 0x00800000u /* 2^-126 */,
    0x00000001u /* 2^-149 */, 0x80000001u, 0x7E800000u /* 2^126 */, 0x7F000000u /* 2^127: parallel */,
    0u,          CBVH_F32_SIGN};
#define N_ORIG 5
static const cbvh_f32 origs[N_ORIG] = {0u, 0xC1200000u /* -10 */, 0x40A00000u /* 5 */, 0x3E800000u /* 0.25 */,
                                       0xC6FA0000u /* -32000 */};

/* Child codes of a node spanning S cells: r in [0, S), s' in [0, S - r). */
static void codes(rng_t *r, uint32_t S, int kind, uint32_t *lo, uint32_t *sp) {
    switch (kind) {
    case 0: *lo = 0, *sp = 0; break;                     /* the whole node: distances unchanged */
    case 1: *lo = S - 1, *sp = 0; break;                 /* the last cell */
    case 2: *lo = 0, *sp = S - 1; break;                 /* the first cell */
    default:
        *lo = (uint32_t)rnd_below(r, S);
        *sp = (uint32_t)rnd_below(r, S - *lo);
        break;
    }
}

/* A chain of `levels` levels below an anchored root: three children per
 * level (codes of kinds 0..3 in turn, random in between), the walk going on
 * into the first child hit. */
static void chain(gen_t *g, int M, int X, const cbvh_ray *ray, const cbvh_grid_axis root[3], int levels) {
    cbvh_rbi_params p = {g->N, M, X};
    cbvh_rbi_ray rr;
    cbvh_rbi_planes T;
    if (cbvh_rbi_ray_setup(ray, &p, &rr) || cbvh_rbi_anchor(ray, &p, root, &T)) return;
    uint32_t S[3] = {root[0].s, root[1].s, root[2].s};
    int e[3] = {root[0].e, root[1].e, root[2].e};
    for (int lv = 0; lv < levels && !g->oom; lv++) {
        int descend = -1;
        cbvh_rbi_result keep;
        cbvh_rbi_axis kax[3];
        memset(&keep, 0, sizeof keep);
        memset(kax, 0, sizeof kax);
        for (int c = 0; c < 3; c++) {
            cbvh_rbi_axis ax[3];
            for (int a = 0; a < 3; a++) {
                ax[a].e = e[a];
                codes(&g->rng, S[a], (lv + c + a) % 5, &ax[a].r, &ax[a].sp);
            }
            emit_incr(g, M, X, &rr, &T, ax);
            cbvh_rbi_result res;
            if (descend < 0 && cbvh_ray_box_incr(&p, &rr, &T, ax, &res) == 0 && res.hit) {
                descend = c;
                keep = res;
                memcpy(kax, ax, sizeof kax);
            }
        }
        if (descend < 0) return;
        for (int a = 0; a < 3; a++) { /* the child's own grid: one or two bits finer, Eq. 2's clamp at -126 */
            uint32_t cells = S[a] - kax[a].r - kax[a].sp;
            int k = 0;
            while ((cells << (k + 1)) <= (1u << g->N) && k < 2) k++;
            if (e[a] - k < -126) k = e[a] + 126;
            e[a] -= k;
            S[a] = cells << k;
        }
        T = keep.planes;
    }
}

/* One plane of axis 0 at the parent distance t, the step c 2^e rho (rho =
 * +-2^x), the other planes finite (+-max) and open. */
static void edge_case(gen_t *g, int M, int X, cbvh_f32 t, int upper, int rneg, uint32_t c, int step_exp) {
    int emax = cbvh_rbi_emax(X);
    cbvh_f32 big = (uint32_t)(emax + 127) << 23 | ((((uint32_t)1 << M) - 1u) << (24 - M) & CBVH_F32_FRAC);
    int x = step_exp, e = 0;
    if (x > 127) e = x - 127, x = 127;
    if (x < -126) e = x + 126, x = -126;
    if (e < -126 || e > 126) return;
    cbvh_rbi_ray ray = {{(uint32_t)(x + 127) << 23 | (rneg ? CBVH_F32_SIGN : 0u), 0, 0}, 0xFF7FFFFFu,
                        CBVH_F32_POS_INF};
    cbvh_rbi_planes par = {{big | CBVH_F32_SIGN, big | CBVH_F32_SIGN, big | CBVH_F32_SIGN}, {big, big, big}};
    cbvh_rbi_axis ax[3] = {{e, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    int near_is_lb = !rneg;
    cbvh_f32 other = (!upper) == near_is_lb ? big : big | CBVH_F32_SIGN;
    if (!upper) par.t_lb[0] = t, par.t_ub[0] = other, ax[0].r = c;
    else par.t_ub[0] = t, par.t_lb[0] = other, ax[0].sp = c;
    emit_incr(g, M, X, &ray, &par, ax);
}

static void structured(gen_t *g, int M, int X) {
    /* chains for rays with structured directions through a root box around the origin */
    for (int i = 0; i < N_DIRS && !g->oom; i++) {
        cbvh_ray ray;
        for (int a = 0; a < 3; a++) {
            ray.d[a] = dirs[(i + 5 * a) % N_DIRS];
            ray.o[a] = origs[(i + a) % N_ORIG];
        }
        if (cbvh_f32_is_zero(ray.d[0]) && cbvh_f32_is_zero(ray.d[1]) && cbvh_f32_is_zero(ray.d[2])) ray.d[0] = F_ONE;
        ray.tmin = 0;
        ray.tmax = CBVH_F32_POS_INF;
        uint32_t S = 1u << g->N;
        cbvh_grid_axis root[3];
        for (int a = 0; a < 3; a++) { /* [-16, 16) on a grid of 32 / 2^N, the origin often inside */
            root[a].u = 0xC1800000u;
            root[a].e = 5 - g->N;
            root[a].r = 0;
            root[a].s = S;
        }
        chain(g, M, X, &ray, root, i % 3 == 0 ? 12 : 4);
    }
    /* a long chain: one bit finer per level from 2^20 */
    {
        cbvh_ray ray = {{0x3F000000u, 0xBE800000u, 0x3D800000u}, {0x3F3504F3u, 0xBF000000u, 0x3E99999Au}, 0,
                        CBVH_F32_POS_INF};
        cbvh_grid_axis root[3];
        for (int a = 0; a < 3; a++) root[a] = (cbvh_grid_axis){(uint32_t)(127 + 19) << 23 | CBVH_F32_SIGN, 21 - g->N, 0, 1u << g->N};
        chain(g, M, X, &ray, root, 40);
    }
    /* F's edges, both planes and both signs of rho */
    int emax = cbvh_rbi_emax(X), emin = cbvh_rbi_emin(X);
    uint32_t qmax = ((uint32_t)1 << M) - 1u;
    const cbvh_f32 ts[6] = {(uint32_t)(emax + 127) << 23 | (qmax << (24 - M) & CBVH_F32_FRAC),
                            (uint32_t)(emax + 127) << 23 | (qmax << (24 - M) & CBVH_F32_FRAC) | CBVH_F32_SIGN,
                            (uint32_t)(emin + 127) << 23, (uint32_t)(emin + 127) << 23 | CBVH_F32_SIGN,
                            (uint32_t)(emin + 127) << 23 | (1u << (24 - M)),
                            (uint32_t)(emax + 127) << 23 | ((qmax - 1u) << (24 - M) & CBVH_F32_FRAC)};
    for (int k = 0; k < 6; k++)
        for (int s = 0; s < 4; s++) {
            int ulp = (k < 2 || k == 5 ? emax : emin) - (M - 1);
            edge_case(g, M, X, ts[k], s & 1, s >> 1, 1, ulp - 1);
            edge_case(g, M, X, ts[k], s & 1, s >> 1, 1, ulp);
            edge_case(g, M, X, ts[k], s & 1, s >> 1, 3, ulp - 1);
            edge_case(g, M, X, ts[k], s & 1, s >> 1, 1, emin);
            edge_case(g, M, X, ts[k], s & 1, s >> 1, 1, emax + 1 - M);
        }
    /* parallel axes (rcp +-0): offsets inside, on a face, outside by a cell; infinite distances */
    {
        cbvh_rbi_ray ray = {{0, CBVH_F32_SIGN, F_ONE}, 0, CBVH_F32_POS_INF};
        const cbvh_f32 lb[4] = {0xC0000000u /* -2 */, 0, 0x3F800000u /* 1 */, CBVH_F32_NEG_INF};
        const cbvh_f32 ub[4] = {0x40000000u, 0x3E800000u, 0x40400000u, CBVH_F32_POS_INF};
        for (int k = 0; k < 4; k++)
            for (uint32_t c = 0; c < 3; c++) {
                cbvh_rbi_planes par = {{lb[k], lb[(k + 1) % 4], 0xBF800000u}, {ub[k], ub[(k + 3) % 4], 0x40800000u}};
                cbvh_rbi_axis ax[3] = {{-2, c, 2 - c}, {-3, 2 * c, c}, {-1, c, 0}}; /* valid at N = 3 */
                emit_incr(g, M, X, &ray, &par, ax);
            }
        cbvh_rbi_ray rinf = {{F_ONE, 0xBF800000u, 0x40000000u}, CBVH_F32_SIGN, CBVH_F32_POS_INF};
        cbvh_rbi_planes pinf = {{CBVH_F32_NEG_INF, CBVH_F32_POS_INF, 0xC0000000u}, {CBVH_F32_POS_INF, CBVH_F32_NEG_INF,
                                                                                   CBVH_F32_POS_INF}};
        cbvh_rbi_axis ainf[3] = {{3, 2, 5}, {-3, 1, 1}, {0, 2, 0}};
        emit_incr(g, M, X, &rinf, &pinf, ainf);
    }
    /* one parallel axis a (rcp +0 or -0) at a time, the other two crossing a box [1, 2]: the child's
     * offsets on a wholly below, wholly above, inside and on either face of the origin, so each
     * axis's own offsets decide the hit (generator 10: the RTL's axis-1 test reading axis 2's
     * upper offset passed every earlier vector) */
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < 5; k++) {
            static const cbvh_f32 off[5][2] = {{0xC0000000u, 0xBF800000u},
                                               {0x3F800000u, 0x40000000u},
                                               {0xBF800000u, 0x3F800000u},
                                               {0xBF800000u, 0},
                                               {0, 0x3F800000u}};
            cbvh_rbi_ray ray = {{F_ONE, F_ONE, F_ONE}, 0, CBVH_F32_POS_INF};
            ray.rcp[a] = (k & 1) ? CBVH_F32_SIGN : 0u;
            cbvh_rbi_planes par = {{F_ONE, F_ONE, F_ONE}, {0x40000000u, 0x40000000u, 0x40000000u}};
            par.t_lb[a] = off[k][0];
            par.t_ub[a] = off[k][1];
            cbvh_rbi_axis ax[3] = {{0, 0, 0}, {-1, 0, 0}, {-2, 0, 0}};
            emit_incr(g, M, X, &ray, &par, ax);
        }
    /* exact cancellation: t_lb = -c 2^e rho, so the child's lower distance is exactly 0 (+0) */
    for (uint32_t c = 1; c < 4; c++) {
        cbvh_rbi_ray ray = {{F_ONE, F_HALF, 0x40000000u}, 0, CBVH_F32_POS_INF};
        cbvh_rbi_planes par = {{(uint32_t)(127 - 1) << 23 | CBVH_F32_SIGN, 0xBF800000u, 0xC0000000u},
                               {0x41000000u, 0x41000000u, 0x41000000u}};
        cbvh_rbi_axis ax[3] = {{-1, 1, 0}, {1, c, 1}, {0, 1, c}};
        emit_incr(g, M, X, &ray, &par, ax);
    }
    /* tmin and tmax at the edges, around a box [1, 2] on every axis */
    {
        static const cbvh_f32 tm[8][2] = {{CBVH_F32_SIGN, CBVH_F32_POS_INF}, {1u, CBVH_F32_POS_INF},
                                          {0x80000001u, 0x3F800000u},        {0xFF7FFFFFu, 0x3FC00000u},
                                          {0x40000000u, 0x3F800000u},        {0x3F800000u, 0x3F800000u},
                                          {0x40400000u, CBVH_F32_POS_INF},   {0, CBVH_F32_SIGN}};
        for (int k = 0; k < 8; k++) {
            cbvh_rbi_ray ray = {{F_ONE, F_ONE, F_ONE}, tm[k][0], tm[k][1]};
            cbvh_rbi_planes par = {{F_ONE, F_ONE, F_ONE}, {0x40000000u, 0x40000000u, 0x40000000u}};
            cbvh_rbi_axis ax[3] = {{0, 0, 0}, {-1, 0, 0}, {-2, 0, 0}};
            emit_incr(g, M, X, &ray, &par, ax);
        }
    }
}

/* Random valid inputs: reciprocals of random directions, distances of F near
 * a common binade (near ones of either sign, far ones positive and larger, or
 * anywhere), increments a few bits below them or anywhere. */
static void random_case(gen_t *g) {
    int k = (int)rnd_below(&g->rng, NDP), M = dp_m[k], X = dp_x[k];
    int emax = cbvh_rbi_emax(X), emin = cbvh_rbi_emin(X);
    cbvh_rbi_ray ray;
    int rexp[3];
    for (int a = 0; a < 3; a++) {
        cbvh_f32 d = rnd_below(&g->rng, 6) ? vg_rnd_f32_in(&g->rng, -3, 3) : vg_rnd_float(&g->rng);
        cbvh_rbi_reciprocal(d, M, &ray.rcp[a]);
        rexp[a] = cbvh_f32_is_zero(ray.rcp[a]) ? 0 : (int)((ray.rcp[a] >> 23) & 0xFFu) - 127;
    }
    int base = (int)rnd_range(&g->rng, emin, emax);
    int wild = rnd_below(&g->rng, 3) == 0;
    ray.tmin = rnd_below(&g->rng, 4) ? 0 : vg_rnd_float(&g->rng);
    ray.tmax = rnd_below(&g->rng, 3) ? CBVH_F32_POS_INF : vg_rnd_float(&g->rng) & ~CBVH_F32_SIGN;
    cbvh_rbi_planes par;
    cbvh_rbi_axis ax[3];
    uint32_t lim = 1u << g->N;
    for (int a = 0; a < 3; a++) {
        cbvh_f32 v[2];
        for (int w = 0; w < 2; w++) {
            int E = wild ? (int)rnd_range(&g->rng, emin, emax) : base + (w ? 1 : -2) + (int)rnd_range(&g->rng, -1, 1);
            E = E < emin ? emin : E > emax ? emax : E;
            uint32_t q = (1u << (M - 1)) | ((uint32_t)rng_next(&g->rng) & ((1u << (M - 1)) - 1u));
            int neg = wild ? (int)rnd_below(&g->rng, 2) : (w == 0 && rnd_below(&g->rng, 4) == 0);
            v[w] = (neg ? CBVH_F32_SIGN : 0u) | (uint32_t)(E + 127) << 23 | (q << (24 - M) & CBVH_F32_FRAC);
            if (wild && rnd_below(&g->rng, 16) == 0) v[w] = rnd_below(&g->rng, 2) ? CBVH_F32_POS_INF : 0;
        }
        int rneg = (ray.rcp[a] >> 31) != 0 && !cbvh_f32_is_zero(ray.rcp[a]);
        par.t_lb[a] = rneg ? v[1] : v[0];
        par.t_ub[a] = rneg ? v[0] : v[1];
        ax[a].r = (uint32_t)rnd_below(&g->rng, lim);
        ax[a].sp = (uint32_t)rnd_below(&g->rng, lim - ax[a].r);
        int e = base - rexp[a] - g->N - (int)rnd_range(&g->rng, 0, 4);
        if (wild) e = (int)rnd_range(&g->rng, -126, 126);
        ax[a].e = e < -126 ? -126 : e > 126 ? 126 : e;
    }
    emit_incr(g, M, X, &ray, &par, ax);
}

static void gen_ray_box_incr(gen_t *g, size_t target) {
    if (!g->random_only)
        for (int k = 0; k < NDP; k++) structured(g, dp_m[k], dp_x[k]);
    while (g->n < target && !g->oom) random_case(g);
}

/* Every reject alone, then several at once (all bits ORed, every output
 * zero), on a valid input at M = 8, X = 8 (and N's code limits). */
static void rejects_incr(gen_t *g) {
    const cbvh_rbi_ray ok_ray = {{F_ONE, 0xBF000000u, 0}, 0, CBVH_F32_POS_INF};
    const cbvh_rbi_planes ok_par = {{F_ONE, 0x41000000u, 0xBF800000u}, {0x41000000u, F_ONE, F_ONE}};
    const cbvh_rbi_axis ok_ax[3] = {{-2, 1, 1}, {-2, 1, 1}, {-2, 1, 1}};
    uint32_t lim = 1u << g->N;
    for (int k = 0; k < 24 && !g->oom; k++) {
        cbvh_rbi_ray ray = ok_ray;
        cbvh_rbi_planes par = ok_par;
        cbvh_rbi_axis ax[3];
        memcpy(ax, ok_ax, sizeof ax);
        int M = 8, X = 8;
        switch (k) {
        case 0: M = 2; break;                                /* BAD_PARAM */
        case 1: M = 25; break;
        case 2: X = 9; break;
        case 3: X = 2; break;
        case 4: ray.rcp[1] = F_QNAN; break;                  /* NAN_INF */
        case 5: ray.rcp[2] = CBVH_F32_NEG_INF; break;
        case 6: par.t_ub[1] = F_QNAN; break;
        case 7: ray.tmin = CBVH_F32_POS_INF; break;
        case 8: ray.tmax = CBVH_F32_NEG_INF; break;
        case 9: ray.tmax = F_QNAN; break;
        case 10: ray.rcp[0] = 0x3F800001u; break;            /* BAD_FORMAT: 24 bits at M = 8 */
        case 11: ray.rcp[0] = 0x00000100u; break;            /* a subnormal reciprocal */
        case 12: par.t_lb[2] = 0x3F808000u; break;           /* 9 significant bits */
        case 13: par.t_lb[0] = 0x00400000u; break;           /* subnormal */
        case 14: ax[0].e = -127; break;                      /* BAD_SCALE */
        case 15: ax[1].e = 127; break;
        case 16: ax[2].e = -128; break;
        case 17: ax[0].r = lim; break;                       /* BAD_CODE */
        case 18: ax[1].sp = 0xFFFu; break;
        case 19: ax[2].r = lim - 1u, ax[2].sp = 1; break;    /* INVERTED: r + s' = 2^N */
        case 20: ax[2].r = lim - 2u, ax[2].sp = 1; break;    /* r + s' = 2^N - 1: valid */
        case 21: /* several at once: NaN, off format, scale, code, inverted */
            ray.rcp[0] = F_QNAN, par.t_lb[1] = 1u, ax[0].e = 127, ax[1].sp = lim, ax[2].r = lim - 1u, ax[2].sp = 3;
            break;
        case 22: /* a bad M hides the format checks but not the others */
            M = 0xFF, par.t_lb[1] = 1u, ax[2].e = -127;
            break;
        default: /* X = 5 makes 2^20 off format */
            X = 5, par.t_ub[0] = 0x49800000u;
            break;
        }
        emit_incr(g, M, X, &ray, &par, ax);
    }
}

const vg_unit vg_ray_box_incr = {"ray_box_incr", 2400, gen_ray_box_incr, NULL, 0, rejects_incr, 1, 0};
