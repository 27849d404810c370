/* Vectors of the reduced-precision ray-box unit (docs/traversal.md §3). */
#include "vectors/gen/gen.h"

#include "cbvh/traversal_units.h"

/* Input words: o[3] d[3] tmin tmax mant, then per axis u scale r s. */
static void emit_ray_box(gen_t *g, const cbvh_f32 o[3], const cbvh_f32 d[3], cbvh_f32 tmin, cbvh_f32 tmax, int mant,
                         const cbvh_f32 u[3], const int e[3], const uint32_t r[3], const uint32_t s[3]) {
    uint32_t in[21];
    for (int a = 0; a < 3; a++) {
        in[a] = o[a];
        in[3 + a] = d[a];
        in[9 + 4 * a] = u[a];
        in[10 + 4 * a] = cbvh_scale_to_word(e[a]);
        in[11 + 4 * a] = r[a];
        in[12 + 4 * a] = s[a];
    }
    in[6] = tmin;
    in[7] = tmax;
    in[8] = (uint32_t)mant;
    vg_emit(g, in);
}

static const int rb_mant[] = {3, 8, 12, 24};

static void gen_ray_box(gen_t *g, size_t target) {
    if (!g->random_only) {
        /* the box [0,1]^3 as u = 0, e = -3, r = 0, s = 8; axis x structured, y/z through the middle */
        const cbvh_f32 u[3] = {0, 0, 0};
        const int e[3] = {-3, -3, -3};
        const uint32_t r[3] = {0, 0, 0}, sc[3] = {8, 8, 8};
        for (int m = 0; m < 4; m++)
            for (int i = 0; i < N_RB_ORIG; i++)
                for (int j = 0; j < N_RB_DIR; j++) {
                    cbvh_f32 o[3] = {vg_ray_orig[i], F_HALF, F_HALF}, d[3] = {vg_ray_dir[j], vg_ray_dir[(j + 1) % N_RB_DIR],
                                                                          vg_ray_dir[(j + 3) % N_RB_DIR]};
                    if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[2] = F_ONE;
                    emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, rb_mant[m], u, e, r, sc);
                    o[1] = F_ONE; /* on the face y = 1 (grazing when d_y = +-0) */
                    emit_ray_box(g, o, d, 0, F_TWO24, rb_mant[m], u, e, r, sc);
                }
        /* extreme grids: -2^128 lower bound, scale 126, s = 2^10; tiny scale -126 */
        const cbvh_f32 ue[3] = {CBVH_F32_NEG_INF, CBVH_F32_NEG_INF, 0x00000001u};
        const int ee[3] = {126, 105, -126};
        const uint32_t re[3] = {0, 1000, 3}, se[3] = {1024, 1024, 4};
        for (int j = 0; j < N_RB_DIR; j++) {
            cbvh_f32 o[3] = {CBVH_F32_MAX | CBVH_F32_SIGN, 0, 0x00000004u};
            cbvh_f32 d[3] = {vg_ray_dir[j], vg_ray_dir[(j + 2) % N_RB_DIR], 0};
            if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1])) d[0] = F_ONE;
            for (int m = 0; m < 4; m++) emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, rb_mant[m], ue, ee, re, se);
        }
        /* rejects: NaN/Inf in every ray port, zero direction, bad M, scale, codes, inverted, u = +Inf */
        for (int k = 0; k < N_NAN_INF; k++)
            for (int port = 0; port < 8; port++) {
                cbvh_f32 o[3] = {vg_ray_orig[0], F_HALF, F_HALF}, d[3] = {F_ONE, 0, 0}, tmin = 0,
                         tmax = CBVH_F32_POS_INF;
                cbvh_f32 *w = port < 3 ? &o[port] : port < 6 ? &d[port - 3] : port == 6 ? &tmin : &tmax;
                *w = vg_nan_inf[k];
                emit_ray_box(g, o, d, tmin, tmax, 24, u, e, r, sc);
            }
        {
            const cbvh_f32 o[3] = {vg_ray_orig[0], F_HALF, F_HALF}, dz[3] = {0, CBVH_F32_SIGN, 0}, d[3] = {F_ONE, 0, 0};
            emit_ray_box(g, o, dz, 0, CBVH_F32_POS_INF, 24, u, e, r, sc);
            static const int bad_m[] = {0, 2, 25, 255};
            for (int k = 0; k < 4; k++) emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, bad_m[k], u, e, r, sc);
            const int be[3] = {-127, 127, -128};
            emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, 24, u, be, r, sc);
            const uint32_t br[3] = {1025, 5, 0}, bs[3] = {1025, 5, 0};
            emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, 24, u, e, br, bs);
            const cbvh_f32 bu[3] = {CBVH_F32_POS_INF, 0x7FC00000u, 0};
            emit_ray_box(g, o, d, 0, CBVH_F32_POS_INF, 24, bu, e, r, sc);
        }
    }
    while (g->n < target && !g->oom) {
        cbvh_f32 o[3], d[3], u[3];
        int e[3];
        uint32_t r[3], s[3];
        for (int a = 0; a < 3; a++) {
            u[a] = vg_rnd_float(&g->rng);
            uint64_t wide = rnd_below(&g->rng, 8);
            e[a] = wide == 0 ? (int)rnd_range(&g->rng, -126, 126) : (int)rnd_range(&g->rng, -30, 10);
            int bits = (int)rnd_range(&g->rng, 3, 10);
            r[a] = (uint32_t)rnd_below(&g->rng, (uint64_t)1 << bits);
            s[a] = r[a] + 1 + (uint32_t)rnd_below(&g->rng, ((uint64_t)1 << bits) - r[a]);
            o[a] = vg_rnd_float(&g->rng);
            uint64_t kind = rnd_below(&g->rng, 6);
            if (kind == 0) d[a] = rnd_below(&g->rng, 2) ? 0 : CBVH_F32_SIGN;
            else if (kind == 1) { /* aim at the box's lower plane (when representable) */
                d[a] = cbvh_f32_add_dyadic((int64_t)r[a], e[a], 0, 0, CBVH_RND_DOWN);
            } else d[a] = vg_rnd_float(&g->rng);
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[0] = F_ONE;
        uint64_t tk = rnd_below(&g->rng, 3);
        cbvh_f32 tmin = tk == 0 ? vg_rnd_float(&g->rng) : 0;
        cbvh_f32 tmax = tk == 2 ? vg_rnd_float(&g->rng) : CBVH_F32_POS_INF;
        int mant = (int)rnd_range(&g->rng, CBVH_MANT_MIN, CBVH_MANT_MAX);
        emit_ray_box(g, o, d, tmin, tmax, mant, u, e, r, s);
    }
}

static void exact_ray_box(gen_t *g, rng_t *rng, int count) {
    for (int i = 0; i < count && !g->oom; i++) {
        cbvh_f32 o[3], d[3], u[3], tmin = 0, tmax = CBVH_F32_POS_INF;
        int e[3];
        uint32_t r[3], s[3];
        int mant = (int)rnd_range(rng, CBVH_MANT_MIN, CBVH_MANT_MAX);
        switch (i % 3) {
        case 0: { /* plane distances that are exact multiples of a non-power-of-two d:
                   * t = j 2^p, on the M-bit grid whenever j has <= M bits */
            int p = (int)rnd_range(rng, -20, 20);
            int64_t jn[3] = {0, 0, 0};
            for (int a = 0; a < 3; a++) {
                e[a] = (int)rnd_range(rng, -30, 10);
                int64_t ui = rnd_below(rng, 2) ? rnd_range(rng, -(1 << 16), 1 << 16) : 0;
                u[a] = dyadic(ui, e[a]);
                if (rnd_below(rng, 4) == 0) { /* parallel, origin inside the slab or on a face */
                    r[a] = (uint32_t)rnd_range(rng, 0, 1000);
                    s[a] = r[a] + (uint32_t)rnd_range(rng, 1, 1024 - r[a]);
                    int64_t c = rnd_range(rng, r[a], s[a]);
                    o[a] = dyadic(ui + c, e[a]);
                    d[a] = rnd_below(rng, 2) ? 0 : CBVH_F32_SIGN;
                    continue;
                }
                int64_t m = vg_rnd_odd_bits(rng, (int)rnd_range(rng, 2, 7));
                int64_t j1 = rnd_range(rng, 0, 4), j2 = j1 + rnd_range(rng, 1, 8);
                while (m * (j2 - j1) > 1024) m = 3;
                r[a] = (uint32_t)rnd_range(rng, 0, 1024 - m * (j2 - j1));
                s[a] = r[a] + (uint32_t)(m * (j2 - j1));
                int neg = (int)rnd_below(rng, 2);
                int64_t c = neg ? (int64_t)s[a] + m * j1 : (int64_t)r[a] - m * j1;
                o[a] = dyadic(ui + c, e[a]);
                d[a] = dyadic(neg ? -m : m, e[a] - p);
                jn[a] = j1;
            }
            uint64_t tk = rnd_below(rng, 4);
            if (tk == 1) tmin = dyadic(jn[rnd_below(rng, 3)], p); /* tmin on an entry distance */
            if (tk == 2) tmax = dyadic(jn[rnd_below(rng, 3)], p); /* tmax on one */
            break;
        }
        case 1: { /* an origin far from a box around 0: L - O needs more than 62 bits */
            uint32_t k = (uint32_t)rnd_range(rng, 0, 6); /* the far axes' d = -o 2^(k-3): all at t = 2^(3-k) */
            for (int a = 0; a < 3; a++) {
                e[a] = (int)rnd_range(rng, -30, 0);
                r[a] = (uint32_t)rnd_range(rng, 0, 500);
                s[a] = r[a] + 2 * (uint32_t)rnd_range(rng, 1, 250);
                u[a] = dyadic(-(int64_t)(r[a] + s[a]) / 2, e[a]); /* 0 is the box's centre */
                uint64_t kind = rnd_below(rng, 3);
                if (kind == 0 && a != 0) { /* inside, slow */
                    o[a] = dyadic(rnd_range(rng, -(int64_t)(s[a] - r[a]) / 2, (int64_t)(s[a] - r[a]) / 2), e[a]);
                    d[a] = vg_rnd_f32_in(rng, -40, -10);
                } else { /* far, aimed back at 0 (t = 2^(3-k)), sometimes an ulp off */
                    o[a] = vg_rnd_f32_in(rng, 40, 123);
                    d[a] = vg_nudge(rng, (o[a] ^ CBVH_F32_SIGN) + ((k << CBVH_F32_FRAC_BITS) - (3u << CBVH_F32_FRAC_BITS)));
                }
            }
            break;
        }
        default: { /* planes at the ends of the range: grids from u = -Inf (-2^128) or
                    * -FLT_MAX at scale 2^126 around an origin up to 2^126 (distances
                    * that overflow binary32), or planes past +FLT_MAX */
            for (int a = 0; a < 3; a++) {
                uint64_t kind = rnd_below(rng, 5);
                o[a] = vg_rnd_f32_in(rng, 100, 125);
                d[a] = vg_rnd_f32_in(rng, -20, 20);
                if (kind < 4) { /* [u + r 2^126, u + s 2^126] contains o */
                    u[a] = kind < 2 ? CBVH_F32_NEG_INF : CBVH_F32_MAX | CBVH_F32_SIGN;
                    e[a] = 126;
                    r[a] = (uint32_t)rnd_range(rng, 0, 3);
                    s[a] = (uint32_t)rnd_range(rng, 5, 16);
                } else { /* past FLT_MAX, the ray heading there */
                    u[a] = CBVH_F32_MAX;
                    e[a] = (int)rnd_range(rng, 100, 126);
                    r[a] = (uint32_t)rnd_range(rng, 0, 16);
                    s[a] = r[a] + (uint32_t)rnd_range(rng, 1, 16);
                    d[a] &= ~CBVH_F32_SIGN;
                }
            }
            break;
        }
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[0] = F_ONE;
        emit_ray_box(g, o, d, tmin, tmax, mant, u, e, r, s);
    }
}

/* Ray-box (traversal.md §3: every applicable reject bit is ORed): each
 * combination of a NaN origin, a zero direction, a bad M, a bad scale, a NaN
 * plane base and bad codes (r = s; codes >= 2^11, which an 11-bit port would
 * cut off); then rays whose t_near or t_far is decided by a tmin or tmax of
 * -0 against a +0 plane distance or one inside the box (the unit's max/min
 * keep the first of equal values, so -0 can come out). */
static void reject_combinations_ray_box(gen_t *g) {
    const cbvh_f32 half = 0x3F000000u, quarter = 0x3E800000u, pinf = CBVH_F32_POS_INF;
    static const uint32_t rs[][2] = {{0, 8}, {5, 5}, {0x800, 0x801}, {0xFFF, 0}};
    for (int k = 0; k < 128; k++) {
        cbvh_f32 o[3] = {(k & 1) ? F_QNAN : half, half, half};
        cbvh_f32 d[3] = {F_ONE, half, quarter};
        if (k & 2) d[0] = d[1] = d[2] = 0;
        int mant = (k & 4) ? 2 : 24;
        int e[3] = {-3, -3, (k & 8) ? 127 : -3};
        cbvh_f32 u[3] = {0, (k & 16) ? F_QNAN : 0, 0};
        uint32_t r[3] = {0, 0, rs[(k >> 5) & 3][0]}, sv[3] = {8, 8, rs[(k >> 5) & 3][1]};
        emit_ray_box(g, o, d, 0, pinf, mant, u, e, r, sv);
    }
    const int e[3] = {-3, -3, -3};
    const cbvh_f32 u[3] = {0, 0, 0};
    const uint32_t r[3] = {0, 0, 0}, sv[3] = {8, 8, 8}; /* the box [0, 1]^3 */
    const cbvh_f32 inside[3] = {half, half, half}, on_face[3] = {0, half, half}, far_face[3] = {F_ONE, half, half};
    const cbvh_f32 dpos[3] = {F_ONE, half, quarter}, dneg[3] = {0xBF800000u, half, quarter};
    for (int m = 3; m <= 24; m += 21) {
        emit_ray_box(g, inside, dpos, CBVH_F32_SIGN, pinf, m, u, e, r, sv);   /* t_near = tmin = -0 */
        emit_ray_box(g, on_face, dpos, CBVH_F32_SIGN, pinf, m, u, e, r, sv);  /* n_x = +0 against tmin -0 */
        emit_ray_box(g, on_face, dpos, 0, pinf, m, u, e, r, sv);              /* n_x = +0 against tmin +0 */
        emit_ray_box(g, far_face, dneg, CBVH_F32_SIGN, pinf, m, u, e, r, sv); /* the same from the far face */
        emit_ray_box(g, on_face, dneg, CBVH_F32_SIGN, CBVH_F32_SIGN, m, u, e, r, sv); /* f_x = +0, tmax -0 */
        emit_ray_box(g, on_face, dneg, CBVH_F32_SIGN, 0, m, u, e, r, sv);
        emit_ray_box(g, inside, dpos, CBVH_F32_SIGN, CBVH_F32_SIGN, m, u, e, r, sv); /* empty interval [-0, -0] */
    }
    /* Generator 6: the code range's upper end, 1024 (s = 2^N at N = 10) valid
     * and 1025 BAD_CODE (not INVERTED), on each axis.  The codes above were
     * 8, 0x800, 0x801 and 0xFFF only, so an RTL whose range check let
     * s = 1025 through passed (gateware/scripts/mutate-rtl, docs/gateware.md).
     * Grid 2^-10 from u = 0 on the axis under test, so [r, s] is inside
     * [0, 1.0009765625]; the ray crosses the box. */
    static const uint32_t lim[][2] = {{0, 1024}, {1023, 1024}, {0, 1025}, {1024, 1025}, {1025, 1024}, {1024, 1024}};
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < sizeof lim / sizeof lim[0]; i++) {
            int ea[3] = {-3, -3, -3};
            uint32_t ra[3] = {0, 0, 0}, sa[3] = {8, 8, 8};
            ea[a] = -10, ra[a] = lim[i][0], sa[a] = lim[i][1];
            const cbvh_f32 o[3] = {0xBF800000u, 0xBF800000u, 0xBF800000u} /* -1 */, d[3] = {F_ONE, F_ONE, F_ONE};
            emit_ray_box(g, o, d, 0, pinf, 24, u, ea, ra, sa);
        }
    /* Generator 6: subnormal plane bases u and origins o that decide t: the
     * box [U, U + 8 2^-126]^3 (r = 0), o = (O, O, O), d = (1, 1, 1), so
     * t_near = U - O, a multiple of 2^-149.  The subnormal u and o above only
     * ever added 2^-149-sized amounts to larger terms, and an RTL placing a
     * subnormal's significand one bit low passed (gateware/scripts/mutate-rtl). */
    static const cbvh_f32 uo[][2] = {{3u, 0}, {0x007FFFFFu, 0}, {0, CBVH_F32_SIGN | 5u}, {7u, 2u}, {0x00400000u, 1u}};
    for (size_t i = 0; i < sizeof uo / sizeof uo[0]; i++)
        for (int m = 3; m <= 24; m += 21) {
            const int es[3] = {-126, -126, -126};
            const uint32_t rz[3] = {0, 0, 0}, s8[3] = {8, 8, 8};
            const cbvh_f32 ub[3] = {uo[i][0], uo[i][0], uo[i][0]}, o[3] = {uo[i][1], uo[i][1], uo[i][1]};
            const cbvh_f32 d[3] = {F_ONE, F_ONE, F_ONE};
            emit_ray_box(g, o, d, 0, pinf, m, ub, es, rz, s8);
        }
    /* Generator 7: INVERTED at r = s on each axis.  The x and y axes had one
     * such vector each ((1024, 1024) above), so an RTL testing r > s there
     * failed one vector (a third mutation run); r = s at 0, 1, 8 and 1023 and
     * r = s + 1, in range, on each axis, the box otherwise [0, 1]^3.  And the
     * range ends again with M = 3 (a fourth run killed the limits r <= 1024 in
     * BAD_CODE and s <= 1024 in INVERTED by one vector each): r = 1025 with
     * s = 0 and 1025, s = 1026, and (1024, 1024). */
    static const uint32_t eq[][2] = {{0, 0}, {1, 1}, {8, 8}, {1023, 1023}, {9, 8},
                                     {1025, 0}, {1025, 1025}, {0, 1026}, {1024, 1024}};
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < sizeof eq / sizeof eq[0]; i++) {
            int ea[3] = {-3, -3, -3};
            uint32_t ra[3] = {0, 0, 0}, sa[3] = {8, 8, 8};
            ea[a] = -10, ra[a] = eq[i][0], sa[a] = eq[i][1];
            emit_ray_box(g, inside, dpos, 0, pinf, i < 5 ? 24 : 3, u, ea, ra, sa);
        }
    /* Generator 8: plane distances of 0 and +-2^-149 against tmin and tmax of
     * +-0 and +-2^-149.  The comparator orders binary32 by a key in which -0
     * and +0 are equal; an RTL keying 2^-149 like 0 (and -0 below +0) passed
     * every vector (a sixth mutation run, docs/gateware.md): no entry or exit
     * distance was ever 2^-149.  The box [0, 1]^3, the ray along axis a
     * (the other direction components +0, origin 1/2 there): from
     * o_a = -2^-149 forward (entry at 2^-149), from +2^-149 backward (exit at
     * 2^-149), from 0 either way (entry or exit at 0). */
    static const cbvh_f32 od[][2] = {{CBVH_F32_SIGN | 1u, F_ONE}, {1u, 0xBF800000u}, {0, F_ONE}, {0, 0xBF800000u}};
    static const cbvh_f32 tmins[] = {0, CBVH_F32_SIGN, 1u, CBVH_F32_SIGN | 1u}, tmaxs[] = {pinf, 0, 1u};
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < sizeof od / sizeof od[0]; i++)
            for (size_t j = 0; j < sizeof tmins / sizeof tmins[0]; j++)
                for (size_t k = 0; k < sizeof tmaxs / sizeof tmaxs[0]; k++) {
                    cbvh_f32 o[3] = {half, half, half}, d[3] = {0, 0, 0};
                    o[a] = od[i][0];
                    d[a] = od[i][1];
                    emit_ray_box(g, o, d, tmins[j], tmaxs[k], 3, u, e, r, sv);
                }
}

const vg_unit vg_ray_box = {"ray_box", 1500, gen_ray_box, exact_ray_box, 400, reject_combinations_ray_box, 0, 0};
