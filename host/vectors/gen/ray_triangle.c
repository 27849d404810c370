/* Vectors of the watertight ray-triangle unit (docs/traversal.md §4). */
#include "vectors/gen/gen.h"

#include <string.h>

static void emit_ray_tri(gen_t *g, const cbvh_f32 o[3], const cbvh_f32 d[3], const cbvh_f32 v[9]) {
    uint32_t in[15];
    for (int a = 0; a < 3; a++) {
        in[a] = o[a];
        in[3 + a] = d[a];
    }
    for (int i = 0; i < 9; i++) in[6 + i] = v[i];
    vg_emit(g, in);
}

static void gen_ray_triangle(gen_t *g, size_t target) {
    if (!g->random_only) {
        /* unit right triangle in z = 0; rays down -z through vertices, edges, inside, just outside */
        const cbvh_f32 tri[9] = {0, 0, 0, F_ONE, 0, 0, 0, F_ONE, 0};
        static const cbvh_f32 xy[] = {0, CBVH_F32_SIGN, F_HALF, F_ONE, 0x3F000001u, 0x3E800000u /* .25 */,
                                      0x3F7FFFFFu, 0xBF800000u};
        const int nxy = (int)(sizeof xy / sizeof xy[0]);
        static const cbvh_f32 dz[] = {0xBF800000u, F_ONE, CBVH_F32_SIGN | 0x00000001u, 0xC0400000u};
        for (int i = 0; i < nxy; i++)
            for (int j = 0; j < nxy; j++)
                for (int k = 0; k < 4; k++) {
                    const cbvh_f32 o[3] = {xy[i], xy[j], 0x40000000u}, d[3] = {0, CBVH_F32_SIGN, dz[k]};
                    emit_ray_tri(g, o, d, tri);
                    const cbvh_f32 d2[3] = {F_THIRD, 0xBE800000u, dz[k]};
                    emit_ray_tri(g, o, d2, tri);
                }
        /* grazing: rays in the plane z = 0 and one subnormal above it */
        for (int i = 0; i < nxy; i++) {
            const cbvh_f32 o[3] = {0xBF800000u, xy[i], 0}, d[3] = {F_ONE, 0, 0};
            emit_ray_tri(g, o, d, tri);
            const cbvh_f32 o2[3] = {0xBF800000u, xy[i], 1}, d2[3] = {F_ONE, F_THIRD, CBVH_F32_SIGN};
            emit_ray_tri(g, o2, d2, tri);
        }
        /* far from the origin */
        const cbvh_f32 far[9] = {0x497423F0u, 0xC9F42408u, 0, 0x49742420u, 0xC9F42408u, 0, 0x49742400u, 0xC9F423F0u, 0};
        const cbvh_f32 fo[3] = {0x49742400u, 0xC9F42400u, 0x49800000u}, fd[3] = {0, 0, 0xBF800000u};
        emit_ray_tri(g, fo, fd, far);
        /* rejects: NaN/Inf in each port, zero direction */
        for (int k = 0; k < N_NAN_INF; k++)
            for (int port = 0; port < 15; port++) {
                cbvh_f32 o[3] = {0x3E800000u, 0x3E800000u, 0x40000000u}, d[3] = {0, 0, 0xBF800000u}, v[9];
                memcpy(v, tri, sizeof v);
                cbvh_f32 *w = port < 3 ? &o[port] : port < 6 ? &d[port - 3] : &v[port - 6];
                *w = vg_nan_inf[k];
                emit_ray_tri(g, o, d, v);
            }
        const cbvh_f32 o[3] = {0x3E800000u, 0x3E800000u, 0x40000000u}, d0[3] = {CBVH_F32_SIGN, 0, CBVH_F32_SIGN};
        emit_ray_tri(g, o, d0, tri);
    }
    while (g->n < target && !g->oom) {
        cbvh_f32 o[3], d[3], v[9];
        for (int i = 0; i < 9; i++) v[i] = vg_rnd_float(&g->rng);
        uint64_t kind = rnd_below(&g->rng, 3);
        for (int a = 0; a < 3; a++) {
            o[a] = vg_rnd_float(&g->rng);
            if (kind == 0) { /* aim at a vertex: d = v - o rounded down */
                int s1, e1, s2, e2;
                uint32_t m1, m2;
                cbvh_f32_break(v[a], &s1, &m1, &e1);
                cbvh_f32_break(o[a], &s2, &m2, &e2);
                d[a] = cbvh_f32_add_dyadic(s1 ? -(int64_t)m1 : (int64_t)m1, e1, s2 ? (int64_t)m2 : -(int64_t)m2, e2,
                                           CBVH_RND_DOWN);
                if (cbvh_f32_is_nan_or_inf(d[a])) d[a] = F_ONE;
            } else if (kind == 1 && rnd_below(&g->rng, 3) == 0) {
                d[a] = rnd_below(&g->rng, 2) ? 0 : CBVH_F32_SIGN;
            } else {
                d[a] = vg_rnd_float(&g->rng);
            }
        }
        if (cbvh_f32_is_zero(d[0]) && cbvh_f32_is_zero(d[1]) && cbvh_f32_is_zero(d[2])) d[2] = F_ONE;
        emit_ray_tri(g, o, d, v);
    }
}

/* Triangle vertices as 4x integers V[3][3], a point P4 (4x) on it and a ray
 * o = P - k D, d = D 2^sd (t = k 2^-sd exactly, k = 0 included), all scaled
 * by 2^(s-2). */
static void exact_tri_lattice(gen_t *g, rng_t *rng, int kind) {
    int64_t V[3][3], P4[3], D[3];
    int s = (int)rnd_range(rng, -24, 24), sd = (int)rnd_range(rng, -8, 8);
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) V[i][a] = 4 * rnd_range(rng, -64, 64);
    int i0 = (int)rnd_below(rng, 3), i1 = (i0 + 1) % 3, i2 = (i0 + 2) % 3;
    for (int a = 0; a < 3; a++) {
        if (kind == 0) P4[a] = V[i0][a];                                     /* a vertex */
        else if (kind == 1) P4[a] = (V[i0][a] + V[i1][a]) / 2;               /* an edge's midpoint */
        else if (kind == 2) P4[a] = (V[i0][a] + V[i1][a] + 2 * V[i2][a]) / 4; /* inside, exact */
        else P4[a] = (3 * V[i0][a] + V[i1][a]) / 4;                          /* on an edge, off centre */
    }
    do
        for (int a = 0; a < 3; a++) D[a] = rnd_range(rng, -8, 8);
    while (!D[0] && !D[1] && !D[2]);
    int64_t k = rnd_range(rng, 0, 16); /* k = 0: the origin on the triangle, t = 0 (not a hit) */
    int64_t off = rnd_below(rng, 4) == 0 ? rnd_range(rng, 1 << 20, 1 << 21) : 0; /* far along axis ax */
    int ax = (int)rnd_below(rng, 3);
    cbvh_f32 o[3], d[3], v[9];
    for (int a = 0; a < 3; a++) {
        int64_t sh = a == ax ? off : 0;
        for (int i = 0; i < 3; i++) v[3 * i + a] = dyadic(V[i][a] + sh, s - 2);
        o[a] = dyadic(P4[a] - 4 * k * D[a] + sh, s - 2);
        d[a] = dyadic(4 * D[a], s - 2 + sd);
    }
    if (rnd_below(rng, 3) == 0) { /* an ulp off: tiny nonzero edge functions */
        int a = (int)rnd_below(rng, 3);
        if (!cbvh_f32_is_zero(d[a])) d[a] = vg_nudge(rng, d[a]);
    }
    emit_ray_tri(g, o, d, v);
}

static void exact_ray_triangle(gen_t *g, rng_t *rng, int count) {
    for (int i = 0; i < count && !g->oom; i++) {
        int fam = i % 6;
        if (fam < 4) {
            exact_tri_lattice(g, rng, fam);
            continue;
        }
        /* the binary32 subnormal border: t (family 4) or b1, b2 (family 5) just
         * below or above 2^-126, as truncations of inexact quotients */
        int ax = (int)rnd_below(rng, 3), bx = (ax + 1) % 3, cx = (ax + 2) % 3; /* the plane's normal is ax */
        int j = (int)rnd_range(rng, -2, 2);
        int64_t m = 3; /* legs of 3 2^j: inexact barycentrics */
        cbvh_f32 o[3], d[3], v[9] = {0};
        v[3 + bx] = dyadic(m, j); /* v0 = 0, v1 = m 2^j e_b, v2 = m 2^j e_c */
        v[6 + cx] = dyadic(m, j);
        int64_t dm = vg_rnd_odd_bits(rng, (int)rnd_range(rng, 2, 3)); /* 3, 5, 7 */
        if (rnd_below(rng, 4) == 0) dm = 1;
        int dj = (int)rnd_range(rng, -2, 2);
        /* the small input: anywhere below 2^-121, or a full significand that puts
         * the quotient within a factor 4 of 2^-126 (divisor dm 2^dj or m 2^j) */
        int64_t tiny;
        int te;
        if (rnd_below(rng, 2)) {
            int bits = (int)rnd_range(rng, 1, 24);
            tiny = (int64_t)((uint64_t)1 << (bits - 1) | (rng_next(rng) & (((uint64_t)1 << (bits - 1)) - 1)));
            te = -149 + (int)rnd_range(rng, 0, 4);
        } else {
            tiny = vg_rnd_odd_bits(rng, 24);
            te = -150 + (fam == 4 ? (dm > 4 ? 3 : dm > 1 ? 2 : 0) + dj : 2 + j) + (int)rnd_range(rng, -2, 1);
            if (te < -149) te = -149;
        }
        int sgn = rnd_below(rng, 5) == 0; /* sometimes the other side: a miss decided by an exact sign */
        if (fam == 4) {
            o[bx] = dyadic(1, j - 2);
            o[cx] = dyadic(1, j - 2);
            o[ax] = dyadic(sgn ? -tiny : tiny, te);
            d[bx] = d[cx] = 0;
            d[ax] = dyadic(-dm, dj);
        } else {
            int which = (int)rnd_below(rng, 2);
            o[which ? cx : bx] = dyadic(sgn ? -tiny : tiny, te);
            o[which ? bx : cx] = dyadic(1, j - 2);
            o[ax] = F_ONE;
            d[bx] = d[cx] = 0;
            d[ax] = dyadic(-dm, dj); /* t = 1 / (dm 2^dj): inexact but for dm = 1 */
        }
        emit_ray_tri(g, o, d, v);
    }
}

/* Emits the ray o0 + t d0 and the triangle (0, p1, p2), given in a frame
 * (x, y, z), with frame axis k moved to axis (k + rot) % 3 and, when mirror,
 * every nonzero coordinate negated (a point reflection; a zero stays +0). */
static void emit_tri_frame(gen_t *g, const cbvh_f32 o0[3], const cbvh_f32 d0[3], const cbvh_f32 p1[3],
                           const cbvh_f32 p2[3], int rot, int mirror) {
    const cbvh_f32 m = mirror ? CBVH_F32_SIGN : 0;
    cbvh_f32 o[3], d[3], v[9] = {0};
    for (int k = 0; k < 3; k++) {
        int a = (k + rot) % 3;
        o[a] = o0[k] ? o0[k] ^ m : 0;
        d[a] = d0[k] ? d0[k] ^ m : 0;
        v[3 + a] = p1[k] ? p1[k] ^ m : 0;
        v[6 + a] = p2[k] ? p2[k] ^ m : 0;
    }
    emit_ray_tri(g, o, d, v);
}

/* Generator 8: a barycentric weight just below 1/2 while det' spans more
 * than 765 bits, with bits in its lowest 32-bit words.  An RTL whose shift
 * pass starts at word 1 (word 0 never written, words 1 and 2 from the wrong
 * source words) passed every level-1 and level-2 vector (a sixth mutation
 * run, docs/gateware.md): the lost bits lower det' by less than one unit in
 * its top 25 bits, which shows only at a rounding boundary.  v0 = 0,
 * v1 = (h, -2^-149, 0), v2 = (0, h, -w), d = (-2^-149, 0, -H), o = (x, 0, 0):
 * with h = 2^112, H = 2^127, w = 2^-149, x = 2^111, det' = 2^351 + 2^-447 and
 * V' = 2^350, so b1 = RD(V'/det') = pred(1/2), where det' without its
 * lowest term gives exactly 1/2; the FLT_MAX-sized version (h = H = FLT_MAX,
 * w = 2^-117, x = FLT_MAX/2) has det' leading at bit 830 and a 2^-415 term.
 * The axes rotated, the winding swapped (the weight is then b2), the scene
 * mirrored through the origin. */
static void tri_low_word_ties(gen_t *g) {
    /* o_x, h, d_z, v2's last coordinate */
    static const cbvh_f32 cfg[][4] = {{0x77000000u, 0x77800000u, 0xFF000000u, 0x80000001u},
                                      {0x7EFFFFFFu, 0x7F7FFFFFu, 0xFF7FFFFFu, 0x85000000u}};
    for (size_t c = 0; c < 2; c++)
        for (int rot = 0; rot < 3; rot++)
            for (int swap = 0; swap < 2; swap++)
                for (int mirror = 0; mirror < 2; mirror++) {
                    const cbvh_f32 o0[3] = {cfg[c][0], 0, 0}, d0[3] = {0x80000001u, 0, cfg[c][2]};
                    const cbvh_f32 a0[3] = {cfg[c][1], 0x80000001u, 0}, b0[3] = {0, cfg[c][1], cfg[c][3]};
                    emit_tri_frame(g, o0, d0, swap ? b0 : a0, swap ? a0 : b0, rot, mirror);
                }
}

/* Generator 7: quotients that tie exactly while det' and Nt span more than
 * 800 bits, above 2^380 and below 2^-415 at once.  Two RTL slips that touch
 * only the lowest words of the 27-word operands (the shift pass dropping the
 * first word, the divider reading word 1 for word 0) passed every level-1
 * and level-2 vector (a fourth mutation run, docs/gateware.md): no vector had
 * both ends in one sum.  With v0 = 0, v1 = (h, tau, 0), v2 = (0, h, tau) and
 * d = (k tau, 0, h), d . (v1 x v2) = k tau^3 + h^3, and o = -d (t = 1) or
 * o = -d/2 (k = 2, t = 1/2) puts the hit on v0 with Nt = t det' exactly;
 * tau = 2^-149 or 3 2^-149, h = 2^127 or 1.5 2^127, the axes rotated, the
 * winding swapped and the scene mirrored through the origin. */
static void tri_wide_ties(gen_t *g) {
    static const cbvh_f32 taus[] = {0x00000001u, 0x00000003u}, hs[] = {0x7F000000u, 0x7F400000u};
    for (size_t ti = 0; ti < 2; ti++)
        for (size_t hi = 0; hi < 2; hi++)
            for (int half = 0; half < 2; half++)
                for (int rot = 0; rot < 3; rot++)
                    for (int swap = 0; swap < 2; swap++)
                        for (int mirror = 0; mirror < 2; mirror++) {
                            const cbvh_f32 tau = taus[ti], h = hs[hi];
                            /* in the unrotated frame (x, y, z); h - 2^23 halves h */
                            const cbvh_f32 d0[3] = {half ? tau * 2 : tau, 0, h};
                            const cbvh_f32 o0[3] = {neg(tau), 0, neg(half ? h - (1u << CBVH_F32_FRAC_BITS) : h)};
                            const cbvh_f32 a0[3] = {h, tau, 0}, b0[3] = {0, h, tau};
                            emit_tri_frame(g, o0, d0, swap ? b0 : a0, swap ? a0 : b0, rot, mirror);
                        }
}

/* Generator 7: as for the sphere below, every input of a ray-triangle in
 * turn is +-2^-149 (e) and decides the hit: read as 0 (a zero factor's
 * monomials skipped) the answer flips.  In a frame (P, Q, N) of rotated axes,
 * the triangle A = 0, B = sp e_P, C = sq e_Q in the plane N = 0, the ray
 * along N through a point of the edge AC (P = 0) or AB (Q = 0) or inside:
 * o_P, d_P (or o_Q, d_Q) = e move the hit point off the edge, outward (a
 * miss); o_N = e starts the ray e before the plane (t = 2^-149 > 0, a hit;
 * t = 0 is not); d = e e_N alone gives t = 2^149 (a hit; d_N = 0 gives
 * det' = 0); A_P = e (A_Q) moves the edge past the hit point (a miss), and
 * A_N = e lifts the plane to t = 2^-150 (a hit), with A each of v0, v1, v2. */
static void tri_place(cbvh_f32 out[3], int rot, cbvh_f32 p, cbvh_f32 q, cbvh_f32 n) {
    out[rot] = p, out[(rot + 1) % 3] = q, out[(rot + 2) % 3] = n;
}

static void tri_emit_roles(gen_t *g, int rot, const cbvh_f32 o[3], const cbvh_f32 d[3], const cbvh_f32 a[3],
                           int sp, int sq, int cyc) {
    cbvh_f32 oo[3], dd[3], r[3][3], v[9];
    tri_place(oo, rot, o[0], o[1], o[2]);
    tri_place(dd, rot, d[0], d[1], d[2]);
    tri_place(r[0], rot, a[0], a[1], a[2]);
    tri_place(r[1], rot, sp < 0 ? neg(F_ONE) : F_ONE, 0, 0);
    tri_place(r[2], rot, 0, sq < 0 ? neg(F_ONE) : F_ONE, 0);
    for (int k = 0; k < 3; k++) /* v_k = role (k + cyc) mod 3: the winding is kept */
        for (int c = 0; c < 3; c++) v[3 * k + c] = r[(k + cyc) % 3][c];
    emit_ray_tri(g, oo, dd, v);
}

static void tri_smallest_deciders(gen_t *g) {
    const cbvh_f32 half = 0x3F000000u, quarter = 0x3E800000u, one = F_ONE, m1 = 0xBF800000u;
    const cbvh_f32 zero3[3] = {0, 0, 0};
    for (int rot = 0; rot < 3; rot++)
        for (int si = 0; si < 2; si++) {
            const int s = si ? -1 : 1;
            const cbvh_f32 e = si ? 0x80000001u : 0x00000001u, sone = si ? m1 : one, msone = si ? one : m1;
            const cbvh_f32 up[3] = {0, 0, one};
            /* the ray's inputs, v0 = A = 0 */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){e, half, m1}, up, zero3, -s, 1, 0);          /* o_P */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){half, e, m1}, up, zero3, 1, -s, 0);          /* o_Q */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){quarter, quarter, e}, (const cbvh_f32[3]){0, 0, msone},
                           zero3, 1, 1, 0);                                                         /* o_N */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){0, half, m1}, (const cbvh_f32[3]){e, 0, one}, zero3, -s, 1,
                           0);                                                                      /* d_P */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){half, 0, m1}, (const cbvh_f32[3]){0, e, one}, zero3, 1, -s,
                           0);                                                                      /* d_Q */
            tri_emit_roles(g, rot, (const cbvh_f32[3]){quarter, quarter, msone}, (const cbvh_f32[3]){0, 0, e}, zero3,
                           1, 1, 0);                                                                /* d_N */
            /* the vertex A = v0, v1, v2 in turn */
            for (int cyc = 0; cyc < 3; cyc++) {
                tri_emit_roles(g, rot, (const cbvh_f32[3]){0, half, m1}, up, (const cbvh_f32[3]){e, 0, 0}, s, 1,
                               cyc);                                                                /* A_P */
                tri_emit_roles(g, rot, (const cbvh_f32[3]){half, 0, m1}, up, (const cbvh_f32[3]){0, e, 0}, 1, s,
                               cyc);                                                                /* A_Q */
                tri_emit_roles(g, rot, (const cbvh_f32[3]){quarter, quarter, 0}, (const cbvh_f32[3]){0, 0, sone},
                               (const cbvh_f32[3]){0, 0, e}, 1, 1, cyc);                            /* A_N */
            }
        }
}

/* Ray-triangle (traversal.md §4: one bit, NAN_INF before ZERO_DIR) and
 * ray-sphere (§10.2: BAD_PARAM ORed with NAN_INF or ZERO_DIR, ZERO_DIR only for
 * a ray without NaN/Inf): every combination of a NaN or Inf in the ray, a zero
 * direction (also -0 components) and a bad vertex, centre or radius. */
static void reject_combinations_ray_tri(gen_t *g) {
    const cbvh_f32 pinf = CBVH_F32_POS_INF;
    for (int k = 0; k < 16; k++) {
        cbvh_f32 o[3] = {(k & 1) ? F_QNAN : 0x3E800000u, 0x3E800000u, 0xBF800000u};
        cbvh_f32 d[3] = {0, 0, F_ONE};
        if (k & 2) d[2] = (k & 8) ? CBVH_F32_SIGN : 0; /* (0, 0, +-0) */
        cbvh_f32 v[9] = {0, 0, 0, F_ONE, 0, 0, 0, F_ONE, 0};
        if (k & 4) v[4] = (k & 8) ? pinf : F_QNAN;
        if ((k & 8) && !(k & 2)) d[0] = pinf; /* an Inf direction component */
        emit_ray_tri(g, o, d, v);
    }
    /* Generator 5, after a clean-room RTL (docs/gateware.md): no level-1
     * vector needed more than 807 bits for an exact sum, so an 832-bit
     * accumulator passed them all.  Vertices +-a along the rows of
     * [[1, 1, -1], [-1, 1, 1], [1, -1, 1]] (determinant 4) with a near 2^127:
     * the triple product [v0, v2, v1] is 4 a^3 (about 2^386, 834 bits in the
     * units' 2^-447 grid); rays from o = 0 along +-(1, 1, 1) s through the
     * centroid (hit, or t < 0) with s = 1 and s = a (det ~ a^3 too), with the
     * vertices negated, and with v1, v2 swapped (the other winding). */
    const cbvh_f32 big[] = {0x7F7FFFFFu /* FLT_MAX */, 0x7F000000u /* 2^127 */, 0x7EC00000u /* 1.5 2^126 */};
    static const int rows[3][3] = {{1, 1, -1}, {-1, 1, 1}, {1, -1, 1}};
    for (size_t bi = 0; bi < sizeof big / sizeof big[0]; bi++)
        for (int var = 0; var < 8; var++) {
            int neg = var & 1, swap = (var >> 1) & 1, dneg = (var >> 2) & 1;
            cbvh_f32 v[9], o[3] = {0, 0, 0}, d[3];
            for (int i = 0; i < 3; i++) {
                int src = swap && i ? 3 - i : i;
                for (int a = 0; a < 3; a++)
                    v[3 * i + a] = big[bi] | ((rows[src][a] < 0) != neg ? CBVH_F32_SIGN : 0);
            }
            for (int a = 0; a < 3; a++) d[a] = (bi == 0 ? F_ONE : big[bi]) | (dneg ? CBVH_F32_SIGN : 0);
            emit_ray_tri(g, o, d, v);
        }
    /* Generator 6: two readings were pinned by one and two vectors only
     * (docs/gateware.md).  (1) A hit is decided on the exact t, whose RD may
     * be +0: the unit triangle in the plane x_k = 0 of each axis k, the
     * origin a distance delta in front of it (or behind: a miss, or on it:
     * t = 0, a miss) and |d_k| = D, so t = delta / D; delta / D = 2^-149
     * exactly (t = 2^-149), just below it and far below (t = +0).
     * (2) NaN/Inf vertices suppress ZERO_DIR: a zero direction (+-0
     * components) with a NaN or +-Inf vertex coordinate in each vertex
     * (below). */
    static const struct {
        cbvh_f32 delta, dk;
    } tiny[] = {
        {0x00000001u /* 2^-149 */, F_ONE},         {0x00000001u, 0x40000000u /* 2 */},
        {0x00000001u, 0x7F7FFFFFu /* FLT_MAX */},    {0x00800000u /* 2^-126 */, 0x4B800000u /* 2^24 */},
        {0x00800000u, 0x4B7FFFFFu /* pred 2^24 */}, {0x00C00000u /* 1.5 2^-126 */, 0x4B800001u},
        {0x3F800000u /* 1 */, 0x7F7FFFFFu},          {0x00000003u /* 3 2^-149 */, 0x40400001u /* succ 3 */},
        {0, 0x40000000u /* on the plane: t = 0 */},
    };
    for (int k = 0; k < 3; k++)
        for (size_t i = 0; i < sizeof tiny / sizeof tiny[0]; i++)
            for (int side = 0; side < 2; side++) {
                if (side && !tiny[i].delta) continue;
                int ka = (k + 1) % 3, kb = (k + 2) % 3;
                cbvh_f32 v[9] = {0}, o[3], d[3] = {0, 0, 0};
                v[3 + ka] = F_ONE; /* v1 = e_ka, v2 = e_kb, v0 = 0 */
                v[6 + kb] = F_ONE;
                o[ka] = 0x3E800000u; /* 0.25 */
                o[kb] = 0x3E800000u;
                /* side 0: origin at -delta, direction +D (t > 0); side 1: behind it */
                o[k] = tiny[i].delta | (side ? 0 : CBVH_F32_SIGN);
                d[k] = tiny[i].dk;
                if (i % 2) o[k] ^= CBVH_F32_SIGN, d[k] |= CBVH_F32_SIGN; /* the mirrored ray */
                emit_ray_tri(g, o, d, v);
            }
    /* (3) Every monomial at the bottom of the units' 2^-447 grid: triangles
     * and rays of subnormals only (multiples of 2^-149), so every exact sum
     * lies in the accumulator's two lowest 32-bit words; an RTL whose shift
     * pass read those words as 0 passed every earlier vector
     * (gateware/scripts/mutate-rtl).  Origin 0, the triangle in the plane
     * z = 2^-149 k around the z axis, d = (0, 0, 2^-149 m): t = k / m. */
    static const int km[][2] = {{1, 1}, {1, 2}, {3, 1}, {2, 3}, {5, 4}, {7, 7}};
    for (size_t i = 0; i < sizeof km / sizeof km[0]; i++)
        for (int w = 0; w < 2; w++) {
            cbvh_f32 o[3] = {0, 0, 0}, d[3] = {0, 0, (cbvh_f32)km[i][1]};
            cbvh_f32 z = (cbvh_f32)km[i][0];
            cbvh_f32 v[9] = {CBVH_F32_SIGN | 3u, CBVH_F32_SIGN | 3u, z, 5u, CBVH_F32_SIGN | 3u, z,
                             CBVH_F32_SIGN | 3u, 5u, z};
            if (w) { /* the other winding, and the direction's x and y tiny too */
                cbvh_f32 t0 = v[3], t1 = v[4];
                v[3] = v[6], v[4] = v[7], v[6] = t0, v[7] = t1;
                d[0] = 1u, d[1] = CBVH_F32_SIGN | 1u;
            }
            emit_ray_tri(g, o, d, v);
        }
    /* (4) t with exponent 127, in [2^127, 2^128): the largest finite range,
     * next to §2's directed overflow (t >= 2^128 gives FLT_MAX); no earlier
     * vector had one, and an RTL that took exponent 127 for an overflow
     * failed level 2 only.  The unit triangle around the z axis in the plane
     * z = Z, d = (0, 0, D): t = Z / D. */
    static const cbvh_f32 zd[][2] = {
        {0x7E800000u /* 2^126 */, 0x3F000000u /* 0.5: t = 2^127 */},  {0x7E800000u, 0x3EC00000u /* 0.375 */},
        {0x7E800000u, 0x3EFFFFFFu /* pred 0.5 */},                      {0x7F7FFFFFu /* FLT_MAX */, F_ONE},
        {0x7F7FFFFFu, 0x3F800001u /* succ 1 */},                         {0x7F7FFFFFu, 0x3FC00000u /* 1.5 */},
    };
    for (size_t i = 0; i < sizeof zd / sizeof zd[0]; i++) {
        cbvh_f32 o[3] = {0, 0, 0}, d[3] = {0, 0, zd[i][1]}, z = zd[i][0];
        cbvh_f32 v[9] = {0xBF800000u, 0xBF800000u, z, 0x40000000u, 0xBF800000u, z, 0xBF800000u, 0x40000000u, z};
        emit_ray_tri(g, o, d, v);
    }
    static const cbvh_f32 bad[] = {F_QNAN, CBVH_F32_POS_INF, CBVH_F32_NEG_INF, 0x7F800001u /* sNaN */};
    for (int pos = 0; pos < 9; pos += 4)
        for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++)
            for (int z = 0; z < 2; z++) {
                cbvh_f32 o[3] = {0x3E800000u, 0x3E800000u, 0xBF800000u};
                cbvh_f32 d[3] = {z ? CBVH_F32_SIGN : 0, 0, z ? CBVH_F32_SIGN : 0};
                cbvh_f32 v[9] = {0, 0, 0, F_ONE, 0, 0, 0, F_ONE, 0};
                v[pos] = bad[b];
                emit_ray_tri(g, o, d, v);
            }
    tri_wide_ties(g);
    tri_smallest_deciders(g);
    tri_low_word_ties(g);
}

const vg_unit vg_ray_triangle = {"ray_triangle", 1500, gen_ray_triangle, exact_ray_triangle, 400, reject_combinations_ray_tri, 0, 0};
