/* Vectors of the ray-sphere unit (docs/traversal.md §10). */
#include "vectors/gen/gen.h"

/* Input words: o[3] d[3] tmin tmax, then cx cy cz r. */
static void emit_ray_sphere(gen_t *g, const cbvh_f32 o[3], const cbvh_f32 d[3], cbvh_f32 tmin, cbvh_f32 tmax,
                            const cbvh_f32 c[3], cbvh_f32 r) {
    uint32_t in[12];
    for (int a = 0; a < 3; a++) {
        in[a] = o[a];
        in[3 + a] = d[a];
        in[8 + a] = c[a];
    }
    in[6] = tmin;
    in[7] = tmax;
    in[11] = r;
    vg_emit(g, in);
}

static void gen_ray_sphere(gen_t *g, size_t target) {
    if (!g->random_only) {
        /* the unit sphere at the origin; rays along +-x at heights y through the
         * centre, inside, tangent (y = 1) and one ulp either side of it */
        static const cbvh_f32 ys[] = {0, CBVH_F32_SIGN, F_HALF, F_ONE, 0x3F800001u, 0x3F7FFFFFu, 0xBF800000u,
                                      0x00000001u};
        static const cbvh_f32 xs[] = {0xC0A00000u /* -5 */, 0xBF800000u /* on the surface */, 0, 0x40A00000u};
        /* segments: unbounded, ending at the tangent point x = 0 and just before, a point, empty */
        static const cbvh_f32 ts[][2] = {{0, CBVH_F32_POS_INF},
                                         {0, 0x40A00000u /* 5 */},
                                         {0, 0x409FFFFFu},
                                         {0x40A00000u, CBVH_F32_POS_INF},
                                         {0x40A00001u, CBVH_F32_POS_INF},
                                         {0x40800000u /* 4 */, 0x40800000u},
                                         {CBVH_F32_MAX | CBVH_F32_SIGN, CBVH_F32_POS_INF},
                                         {0x40000000u, F_ONE /* empty */}};
        const cbvh_f32 c0[3] = {0, 0, 0};
        for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++)
            for (size_t j = 0; j < sizeof ys / sizeof ys[0]; j++)
                for (size_t k = 0; k < sizeof ts / sizeof ts[0]; k++)
                    for (int sgn = 0; sgn < 2; sgn++) {
                        const cbvh_f32 o[3] = {xs[i], ys[j], 0}, d[3] = {sgn ? 0xBF800000u : F_ONE, 0, 0};
                        emit_ray_sphere(g, o, d, ts[k][0], ts[k][1], c0, F_ONE);
                    }
        /* radii: 0, -0 (a point), subnormal, 2^127, FLT_MAX; direction patterns as the box unit's */
        static const cbvh_f32 rs[] = {0, CBVH_F32_SIGN, 0x00000001u, 0x7F000000u, CBVH_F32_MAX};
        for (size_t i = 0; i < sizeof rs / sizeof rs[0]; i++)
            for (int j = 0; j < N_RB_DIR; j++) {
                cbvh_f32 o[3] = {vg_ray_orig[j], 0x40000000u, F_HALF}, d[3] = {vg_ray_dir[j], vg_ray_dir[(j + 1) % N_RB_DIR],
                                                                         vg_ray_dir[(j + 3) % N_RB_DIR]};
                if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[2] = F_ONE;
                const cbvh_f32 c[3] = {F_HALF, F_HALF, F_HALF};
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, rs[i]);
                emit_ray_sphere(g, o, d, 0, F_TWO24, c, rs[i]);
            }
        /* exact tangents in 3D (d . w = 0, |w| = r integer), scaled to huge and tiny
         * exponents, with the tangent point at tmin, at tmax, and one ulp off */
        static const int perp[][7] = {{3, 4, 12, 4, -3, 0, 5}, {1, 2, 2, 2, 1, -2, 3}, {2, 3, 6, 3, -6, 2, 7},
                                      {1, 4, 8, 4, 7, -4, 9}};
        static const int scales[][2] = {{0, 0}, {-20, 3}, {90, -10}, {-149, -149}, {-100, 0}, {60, 60}, {-140, -40}};
        for (size_t p = 0; p < sizeof perp / sizeof perp[0]; p++)
            for (size_t sc = 0; sc < sizeof scales / sizeof scales[0]; sc++) {
                int es = scales[sc][0], ed = scales[sc][1], m = 3;
                cbvh_f32 o[3], d[3], c[3];
                for (int a = 0; a < 3; a++) {
                    int64_t C = 100 * (a + 1);
                    c[a] = dyadic(C, es);
                    o[a] = dyadic(C - perp[p][3 + a] - m * perp[p][a], es);
                    d[a] = dyadic(perp[p][a], ed);
                }
                cbvh_f32 r = dyadic(perp[p][6], es), tm = dyadic(m, es - ed);
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, r);
                emit_ray_sphere(g, o, d, 0, tm, c, r);
                emit_ray_sphere(g, o, d, 0, down(tm), c, r);
                emit_ray_sphere(g, o, d, tm, CBVH_F32_POS_INF, c, r);
                emit_ray_sphere(g, o, d, up(tm), CBVH_F32_POS_INF, c, r);
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, down(r));
                emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c, up(r));
            }
        /* rejects: NaN/Inf in every port, zero direction, negative radius */
        const cbvh_f32 o[3] = {0xC0A00000u, 0, 0}, d[3] = {F_ONE, 0, 0};
        for (int k = 0; k < N_NAN_INF; k++)
            for (int port = 0; port < 12; port++) {
                cbvh_f32 oo[3] = {o[0], o[1], o[2]}, dd[3] = {d[0], d[1], d[2]}, c[3] = {0, 0, 0}, r = F_ONE,
                         tmin = 0, tmax = CBVH_F32_POS_INF;
                cbvh_f32 *w = port < 3    ? &oo[port]
                              : port < 6  ? &dd[port - 3]
                              : port == 6 ? &tmin
                              : port == 7 ? &tmax
                              : port < 11 ? &c[port - 8]
                                          : &r;
                *w = vg_nan_inf[k];
                emit_ray_sphere(g, oo, dd, tmin, tmax, c, r);
            }
        const cbvh_f32 dz[3] = {CBVH_F32_SIGN, 0, CBVH_F32_SIGN};
        emit_ray_sphere(g, o, dz, 0, CBVH_F32_POS_INF, c0, F_ONE);
        emit_ray_sphere(g, o, dz, 0, CBVH_F32_POS_INF, c0, 0xBF800000u);
        emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c0, 0x80000001u);
        emit_ray_sphere(g, o, d, 0, CBVH_F32_POS_INF, c0, CBVH_F32_MAX | CBVH_F32_SIGN);
    }
    while (g->n < target && !g->oom) {
        cbvh_f32 o[3], d[3], c[3], r;
        uint64_t kind = rnd_below(&g->rng, 4);
        if (kind == 0) { /* independent floats */
            for (int a = 0; a < 3; a++) {
                o[a] = vg_rnd_float(&g->rng);
                d[a] = vg_rnd_float(&g->rng);
                c[a] = vg_rnd_float(&g->rng);
            }
            r = vg_rnd_float(&g->rng) & ~CBVH_F32_SIGN;
        } else { /* a scene-like sphere near the ray: aimed at it, past it, or anywhere */
            int e = (int)rnd_range(&g->rng, -20, 20);
            for (int a = 0; a < 3; a++) {
                int64_t oi = rnd_range(&g->rng, -(1 << 20), 1 << 20);
                int64_t off = rnd_range(&g->rng, -(1 << 20), 1 << 20);
                int64_t dd = kind == 1   ? off + rnd_range(&g->rng, -(1 << 16), 1 << 16)
                             : kind == 2 ? -off
                                         : rnd_range(&g->rng, -(1 << 20), 1 << 20);
                o[a] = dyadic(oi, e);
                c[a] = dyadic(oi + off, e);
                d[a] = dyadic(dd, (int)rnd_range(&g->rng, -30, 0));
            }
            r = dyadic(rnd_range(&g->rng, 0, 1 << 21), e);
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[0] = F_ONE;
        uint64_t tk = rnd_below(&g->rng, 3);
        cbvh_f32 tmin = tk == 0 ? vg_rnd_float(&g->rng) : 0;
        cbvh_f32 tmax = tk == 2 ? vg_rnd_float(&g->rng) : CBVH_F32_POS_INF;
        emit_ray_sphere(g, o, d, tmin, tmax, c, r);
    }
}

/* Pythagorean triples a^2 + b^2 = c^2: exact distances from small integers. */
static const int pyth[][3] = {{3, 4, 5}, {5, 12, 13}, {8, 15, 17}, {7, 24, 25}, {20, 21, 29}};

static void exact_ray_sphere(gen_t *g, rng_t *rng, int count) {
    for (int i = 0; i < count && !g->oom; i++) {
        const int *tr = pyth[rnd_below(rng, sizeof pyth / sizeof pyth[0])];
        int ax = (int)rnd_below(rng, 3), bx = (ax + 1) % 3, cx = (ax + 2) % 3;
        int s = (int)rnd_range(rng, -20, 20), sd = (int)rnd_range(rng, -6, 6);
        int64_t C[3], k = rnd_range(rng, 1, 8), Dv[3] = {0, 0, 0}, Ov[3];
        for (int a = 0; a < 3; a++) C[a] = rnd_range(rng, -100, 100);
        cbvh_f32 tmin = 0, tmax = CBVH_F32_POS_INF;
        if (i % 2 == 0) { /* a tangent line: d = (a, b, 0), offset k c along the third axis or (-b, a, 0) */
            Dv[ax] = tr[0];
            Dv[bx] = tr[1];
            int64_t jj = rnd_range(rng, -10, 10);
            for (int a = 0; a < 3; a++) Ov[a] = C[a] - jj * Dv[a];
            if (rnd_below(rng, 2)) Ov[cx] += k * tr[2];
            else {
                Ov[ax] -= k * tr[1];
                Ov[bx] += k * tr[0];
            }
            /* t* = jj 2^(s-(s+sd)); put a segment end on it, beside it, or none */
            cbvh_f32 ts = dyadic(jj, -sd);
            switch (rnd_below(rng, 4)) {
            case 1: tmax = jj >= 0 ? ts : CBVH_F32_POS_INF; break;
            case 2: tmin = ts; break;
            default: break;
            }
        } else { /* a segment that ends (or starts) exactly on the sphere: P = C + k (a, b, 0) */
            do
                for (int a = 0; a < 3; a++) Dv[a] = rnd_range(rng, -8, 8);
            while (!Dv[0] && !Dv[1] && !Dv[2]);
            /* at P the segment must only touch: heading in at its end (tmax), out at its start (tmin) */
            int at_end = (int)rnd_below(rng, 2);
            int64_t dot = Dv[ax] * tr[0] + Dv[bx] * tr[1];
            if ((at_end && dot > 0) || (!at_end && dot < 0))
                for (int a = 0; a < 3; a++) Dv[a] = -Dv[a];
            int64_t t0 = rnd_range(rng, 1, 8);
            for (int a = 0; a < 3; a++) Ov[a] = C[a] - t0 * Dv[a];
            Ov[ax] += k * tr[0];
            Ov[bx] += k * tr[1];
            cbvh_f32 te = dyadic(t0, -sd);
            if (at_end) tmax = te;
            else tmin = te;
        }
        cbvh_f32 o[3], d[3], c[3];
        for (int a = 0; a < 3; a++) {
            o[a] = dyadic(Ov[a], s);
            c[a] = dyadic(C[a], s);
            d[a] = dyadic(Dv[a], s + sd);
        }
        cbvh_f32 r = dyadic(k * tr[2], s);
        if (rnd_below(rng, 5) == 0) r = vg_nudge(rng, r);
        emit_ray_sphere(g, o, d, tmin, tmax, c, r);
    }
}

/* A binary32 with an exponent in 120..hi and a random significand, of random
 * sign when `signed_`: one draw per statement (the order of function
 * arguments is unspecified in C). */
static cbvh_f32 huge_f(rng_t *r, int signed_, int hi) {
    uint32_t frac = (uint32_t)rng_next(r);
    int e = (int)rnd_range(r, 120, hi);
    int sign = signed_ ? (int)rnd_below(r, 2) : 0;
    return cbvh_f32_make(sign, e, frac);
}

/* Generator 7, after RTL mutation (docs/gateware.md): a unit that skips the
 * monomials of a zero factor passed every vector when it took 2^-149 for 0 in
 * r or o_x.  Here each of the 12 inputs in turn is +-2^-149 (e) and decides
 * the hit: with that input read as 0 the answer flips.  Along axis a, across
 * axis b, d = e_a unless said otherwise, segment [0, +Inf) unless said. */
static void sphere_reset(cbvh_f32 o[3], cbvh_f32 d[3], cbvh_f32 c[3], int a) {
    for (int i = 0; i < 3; i++) o[i] = d[i] = c[i] = 0;
    d[a] = F_ONE;
}

static void sphere_smallest_deciders(gen_t *g) {
    const cbvh_f32 pinf = CBVH_F32_POS_INF, five = 0x40A00000u;
    const cbvh_f32 p2m140 = 0x00000200u, p2m140_less_e = 0x000001FFu; /* 2^-140, 2^-140 - e */
    for (int a = 0; a < 3; a++)
        for (int s = 0; s < 2; s++) {
            const int b = (a + 1) % 3;
            const cbvh_f32 e = s ? 0x80000001u : 0x00000001u, e2 = e + 1; /* +-2^-149, +-2^-148 */
            cbvh_f32 o[3], d[3], c[3];
            /* r = e: tangent at distance e (hit; r = 0 misses), at 2e (miss) */
            sphere_reset(o, d, c, a);
            c[a] = five, c[b] = e;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0x00000001u);
            c[b] = e2;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0x00000001u);
            /* r = e, c behind the origin by e: the end point t = 0 decides */
            sphere_reset(o, d, c, a);
            c[a] = 0x80000001u;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0x00000001u);
            /* c_b = e, r = 0: the line misses c by e (miss; c_b = 0 hits) */
            sphere_reset(o, d, c, a);
            c[a] = five, c[b] = e;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            /* c_a = e on the point segment [0, 0] (miss; c_a = 0 hits) */
            sphere_reset(o, d, c, a);
            c[a] = e;
            emit_ray_sphere(g, o, d, 0, 0, c, 0);
            /* o_b = e across the ray (miss); o_a = e with c = 0 (+e: miss,
             * the origin is past c; -e: before it, a hit) */
            sphere_reset(o, d, c, a);
            o[b] = e, c[a] = five;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            sphere_reset(o, d, c, a);
            o[a] = e;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            /* d_b = e: the line leans off c = 5 e_a by 5e (miss; d_b = 0 hits) */
            sphere_reset(o, d, c, a);
            d[b] = e, c[a] = five;
            emit_ray_sphere(g, o, d, 0, pinf, c, 0);
            /* d = e e_a alone on [0, 1]: it reaches c = e e_a (hit) but not
             * c = 2e e_a (miss; d = 0 would give A = 0 and |w x d|^2 = 0 <= 0) */
            sphere_reset(o, d, c, a);
            d[a] = e, c[a] = e;
            emit_ray_sphere(g, o, d, 0, F_ONE, c, 0);
            c[a] = e2;
            emit_ray_sphere(g, o, d, 0, F_ONE, c, 0);
            /* tmin = e beyond t* = -1 (c = -e_a, r = 1): the end point is at
             * 1 + e (miss) for +e, 1 - e (hit) for -e; and c = -2^-140 e_a
             * with r = 2^-140 - e: tmin = -e reaches it exactly (hit) */
            sphere_reset(o, d, c, a);
            c[a] = 0xBF800000u;
            emit_ray_sphere(g, o, d, e, pinf, c, F_ONE);
            c[a] = p2m140 | CBVH_F32_SIGN;
            emit_ray_sphere(g, o, d, e, pinf, c, p2m140_less_e);
            /* tmax = e before t* = 2^-140 (c = 2^-140 e_a, r = 2^-140 - e):
             * tmax = +e reaches the sphere exactly (hit), t = 0 does not;
             * tmax = -e < tmin is an empty segment */
            sphere_reset(o, d, c, a);
            c[a] = p2m140;
            emit_ray_sphere(g, o, d, 0, e, c, p2m140_less_e);
        }
}

static void reject_combinations_ray_sphere(gen_t *g) {
    const cbvh_f32 pinf = CBVH_F32_POS_INF;
    for (int k = 0; k < 32; k++) {
        cbvh_f32 o[3] = {(k & 1) ? F_QNAN : 0, 0, 0xC0000000u /* -2 */};
        cbvh_f32 d[3] = {0, 0, (k & 2) ? CBVH_F32_SIGN : F_ONE};
        cbvh_f32 tmin = (k & 16) ? pinf : 0, tmax = pinf;
        cbvh_f32 c[3] = {0, (k & 4) ? F_QNAN : 0, 0};
        cbvh_f32 r = (k & 8) ? 0xBF800000u /* -1 */ : F_ONE;
        emit_ray_sphere(g, o, d, tmin, tmax, c, r);
    }
    /* Generator 4, after a clean-room RTL (docs/gateware.md): neither reading
     * below was pinned by a level-1 vector.  (1) A segment's ends compare as
     * values, -0 = +0: [+0, -0] and [-0, +0] are the point t = 0, not empty;
     * the origin is inside the ball, on its surface, or outside it.  (2) The
     * status does not depend on the segment: every fault with an empty segment
     * [2, 1], next to the valid ray with it (hit 0, status 0). */
    const cbvh_f32 zeros[][2] = {{0, CBVH_F32_SIGN}, {CBVH_F32_SIGN, 0}, {CBVH_F32_SIGN, CBVH_F32_SIGN}};
    const cbvh_f32 centre_z[] = {0xBF000000u /* -0.5: o inside */, F_ONE /* on the surface */,
                                 0x40000000u /* 2: outside */};
    for (size_t z = 0; z < sizeof zeros / sizeof zeros[0]; z++)
        for (size_t i = 0; i < sizeof centre_z / sizeof centre_z[0]; i++) {
            cbvh_f32 o[3] = {0, 0, 0}, d[3] = {0, 0, F_ONE}, c[3] = {0, 0, centre_z[i]};
            emit_ray_sphere(g, o, d, zeros[z][0], zeros[z][1], c, F_ONE);
        }
    for (int k = 0; k < 5; k++) {
        cbvh_f32 o[3] = {k == 1 ? F_QNAN : 0, 0, 0xC0000000u}, d[3] = {0, 0, k == 2 ? 0 : F_ONE};
        cbvh_f32 c[3] = {0, k == 3 ? pinf : 0, 0};
        cbvh_f32 r = k == 4 ? 0xBF800000u : F_ONE;
        emit_ray_sphere(g, o, d, 0x40000000u /* 2 */, F_ONE, c, r);
    }
    /* Generator 6: the accumulator's top words.  A 33-word (1,056-bit)
     * accumulator failed one level-1 vector and a 32-word one three
     * (docs/gateware.md): few vectors had an exact sum near the 1,115 bits of
     * §10.1.  Every input here has an exponent in 120..127 (tmin, tmax too),
     * so |w x d|^2, R A and |t d - w|^2 are near 2^510, 2^1106 in the unit of
     * 2^-596: the sign of each decision sits in the top words.  A stream of
     * its own (fixed seed); every fourth a segment [0, +Inf), otherwise a
     * segment around, before or after t*; every other one with o and c
     * within 2^122 of the origin and r >= 2^126 (mostly hits). */
    rng_t hr;
    rng_seed(&hr, UINT64_C(0x5A1E5C0FFEE00006));
    for (int k = 0; k < 48; k++) {
        cbvh_f32 o[3], d[3], c[3], r, t0, t1;
        int top = k % 2 ? 121 : 127; /* odd k: |w| < 2^123 <= r, mostly hits */
        for (int a = 0; a < 3; a++) {
            o[a] = huge_f(&hr, 1, top);
            d[a] = huge_f(&hr, 1, 127);
            c[a] = huge_f(&hr, 1, top);
        }
        if (k % 2) r = cbvh_f32_make(0, 126, (uint32_t)rng_next(&hr));
        else r = huge_f(&hr, 0, 127);
        t0 = huge_f(&hr, 1, 127);
        t1 = huge_f(&hr, 0, 127);
        if (k % 4 == 0) t0 = 0, t1 = CBVH_F32_POS_INF;
        else if (cbvh_f32_cmp(t0, t1) > 0) {
            cbvh_f32 x = t0;
            t0 = t1, t1 = x;
        }
        emit_ray_sphere(g, o, d, t0, t1, c, r);
    }
    sphere_smallest_deciders(g);
}

const vg_unit vg_ray_sphere = {"ray_sphere", 1500, gen_ray_sphere, exact_ray_sphere, 300, reject_combinations_ray_sphere, 0, 0};
