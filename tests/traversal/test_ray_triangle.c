/* Ray-triangle unit (docs/traversal.md §4):
 *   leak      rays shot from inside closed meshes (tetrahedron, cube,
 *             icosahedron) through their vertices, through points on shared
 *             edges and anywhere: every ray hits at least one triangle
 *             (>= 1M rays, zero leaks);
 *   oracle    random rays/triangles vs an exact rational solve (GMP, Cramer's
 *             rule): same hit decision, t = RD(exact t), barycentrics RD;
 *   named     axis-parallel rays (+0 / -0 components), grazing rays in the
 *             triangle's plane, rays through a vertex / an edge, NaN/Inf rays. */
#include <gmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/traversal_units.h"
#include "test_util.h"

#ifdef CBVH_SANITIZE
#define LEAK_RAYS 120000
#define ORACLE_CASES 20000
#else
#define LEAK_RAYS 1000000
#define ORACLE_CASES 100000
#endif

static long failures;
static uint64_t rs = 0x2545F4914F6CDD1Du;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static uint64_t below(uint64_t n) { return rnd() % n; }
static double unit(void) { return tu_unit_d(&rs); }

typedef struct {
    int nv, nt;
    float v[16][3];
    int t[24][3];
} mesh;

static void tetra(mesh *m) {
    static const float v[4][3] = {{1.1f, 0.3f, -0.2f}, {-0.7f, 1.3f, 0.1f}, {-0.4f, -0.9f, 1.2f}, {0.2f, -0.6f, -1.4f}};
    static const int t[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    m->nv = 4;
    m->nt = 4;
    memcpy(m->v, v, sizeof v);
    memcpy(m->t, t, sizeof t);
}
static void cube(mesh *m) {
    m->nv = 8;
    for (int i = 0; i < 8; i++)
        for (int a = 0; a < 3; a++) m->v[i][a] = (i >> a & 1) ? 0.7f : -0.3f; /* not centred on the origin */
    static const int f[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    m->nt = 12;
    for (int i = 0; i < 6; i++) {
        int q[4] = {f[i][0], f[i][1], f[i][2], f[i][3]};
        int t0[3] = {q[0], q[1], q[2]}, t1[3] = {q[0], q[2], q[3]};
        memcpy(m->t[2 * i], t0, sizeof t0);
        memcpy(m->t[2 * i + 1], t1, sizeof t1);
    }
}
static void icosa(mesh *m) {
    const float p = 1.6180339887f, s = 0.3f; /* scaled, offset: float vertices, not symmetric bits */
    static const float b[12][3] = {{-1, 1, 0}, {1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, {0, -1, 1}, {0, 1, 1},
                                   {0, -1, -1}, {0, 1, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, -1}, {-1, 0, 1}};
    m->nv = 12;
    for (int i = 0; i < 12; i++)
        for (int a = 0; a < 3; a++) {
            float x = b[i][a];
            int phi_axis = (i < 4) ? 1 : (i < 8) ? 2 : 0;
            m->v[i][a] = (a == phi_axis ? x * p : x) * s + 0.01f * (float)(a + 1);
        }
    static const int t[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    m->nt = 20;
    memcpy(m->t, t, sizeof t);
}

static int count_hits(const mesh *m, const cbvh_ray *r) {
    int n = 0;
    for (int i = 0; i < m->nt; i++) {
        cbvh_f32 v[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) v[k][a] = fb(m->v[m->t[i][k]][a]);
        cbvh_tri_result res;
        if (cbvh_ray_triangle(r, v[0], v[1], v[2], &res)) failures++;
        n += res.hit;
    }
    return n;
}

/* Rays from inside through vertices, shared-edge points and random targets. */
static void leak_test(void) {
    mesh ms[3];
    tetra(&ms[0]);
    cube(&ms[1]);
    icosa(&ms[2]);
    const char *names[3] = {"tetrahedron", "cube", "icosahedron"};
    static const long share[3] = {40, 40, 20}; /* percent of the rays */
    long total = 0, leaks = 0, through_vertex = 0, through_edge = 0;
    for (int mi = 0; mi < 3; mi++) {
        const mesh *m = &ms[mi];
        float c[3] = {0, 0, 0};
        for (int i = 0; i < m->nv; i++)
            for (int a = 0; a < 3; a++) c[a] += m->v[i][a] / (float)m->nv;
        long n = LEAK_RAYS * share[mi] / 100, mleaks = 0;
        for (long k = 0; k < n; k++) {
            cbvh_ray r;
            /* origin: the centroid or a random interior point (convex mesh) */
            float w[16], sw = 0;
            int kind = (int)below(4);
            for (int i = 0; i < m->nv; i++) sw += (w[i] = (float)unit() + 0.05f);
            int centroid = below(4) == 0; /* one choice per ray: mixing axes could leave the hull */
            for (int a = 0; a < 3; a++) {
                float o = 0;
                for (int i = 0; i < m->nv; i++) o += w[i] / sw * m->v[i][a];
                r.o[a] = fb(centroid ? c[a] : o);
            }
            float target[3];
            if (kind == 0) { /* a vertex */
                int i = (int)below((uint64_t)m->nv);
                memcpy(target, m->v[i], sizeof target);
                through_vertex++;
            } else if (kind <= 2) { /* a point on an edge (shared by two triangles) */
                const int *t = m->t[below((uint64_t)m->nt)];
                int e = (int)below(3);
                const float *a = m->v[t[e]], *b = m->v[t[(e + 1) % 3]];
                float s = kind == 1 ? 0.5f : (float)unit();
                for (int x = 0; x < 3; x++) target[x] = a[x] + s * (b[x] - a[x]);
                through_edge++;
            } else {
                for (int x = 0; x < 3; x++) target[x] = (float)(unit() * 2 - 1);
            }
            for (int a = 0; a < 3; a++) {
                r.d[a] = fb(target[a] - bf(r.o[a]));
                if (below(50) == 0) r.d[a] = below(2) ? 0 : CBVH_F32_SIGN; /* axis-parallel components */
            }
            if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[2] = fb(1.0f);
            r.tmin = 0;
            r.tmax = CBVH_F32_POS_INF;
            if (count_hits(m, &r) == 0) {
                if (mleaks++ < 5)
                    fprintf(stderr, "LEAK %s: o=%08X %08X %08X d=%08X %08X %08X\n", names[mi], r.o[0], r.o[1], r.o[2],
                            r.d[0], r.d[1], r.d[2]);
            }
        }
        total += n;
        leaks += mleaks;
    }
    printf("leak: %ld rays from inside (%ld through vertices, %ld through shared edges), leaks %ld\n", total,
           through_vertex, through_edge, leaks);
    if (leaks) failures++;
}

/* ---- exact oracle ---- */
static void q_f32(mpq_t q, cbvh_f32 f) {
    int s, e;
    uint32_t sig;
    cbvh_f32_break(f, &s, &sig, &e);
    mpq_set_si(q, s ? -(long)sig : (long)sig, 1);
    if (e > 0) mpq_mul_2exp(q, q, (unsigned)e);
    else if (e < 0) mpq_div_2exp(q, q, (unsigned)-e);
}
static void det3(mpq_t out, mpq_t m[3][3]) {
    mpq_t a, b;
    mpq_inits(a, b, NULL);
    mpq_set_ui(out, 0, 1);
    for (int i = 0; i < 3; i++) {
        mpq_mul(a, m[0][i], m[1][(i + 1) % 3]);
        mpq_mul(a, a, m[2][(i + 2) % 3]);
        mpq_add(out, out, a);
        mpq_mul(b, m[0][i], m[1][(i + 2) % 3]);
        mpq_mul(b, b, m[2][(i + 1) % 3]);
        mpq_sub(out, out, b);
    }
    mpq_clears(a, b, NULL);
}
/* RD check: x_out <= exact < next_up(x_out) */
static int rd_ok(cbvh_f32 out, mpq_t exact) {
    mpq_t t;
    mpq_init(t);
    q_f32(t, out);
    int ok = mpq_cmp(t, exact) <= 0;
    cbvh_f32 nx = cbvh_f32_next_up(out);
    if (ok && !cbvh_f32_is_nan_or_inf(nx)) {
        q_f32(t, nx);
        ok = mpq_cmp(t, exact) > 0;
    }
    mpq_clear(t);
    return ok;
}
static cbvh_f32 rcoord(void) {
    int k = (int)below(8);
    if (k == 0) return below(2) ? 0 : CBVH_F32_SIGN;
    int e = k <= 5 ? (int)below(9) - 4 : (int)below(120) - 60;
    int sign = below(2) != 0;
    return cbvh_f32_make(sign, e, (uint32_t)rnd());
}
static void oracle_test(void) {
    long hits = 0;
    mpq_t M[3][3], col[3], det, dt, d1, d2, sol[3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) mpq_init(M[i][j]);
    for (int i = 0; i < 3; i++) mpq_inits(col[i], sol[i], NULL);
    mpq_inits(det, dt, d1, d2, NULL);
    for (long k = 0; k < ORACLE_CASES; k++) {
        cbvh_ray r;
        cbvh_f32 v[3][3];
        for (int i = 0; i < 3; i++)
            for (int a = 0; a < 3; a++) v[i][a] = rcoord();
        for (int a = 0; a < 3; a++) r.o[a] = rcoord();
        int aim = below(2) == 0;
        for (int a = 0; a < 3; a++) {
            if (aim) { /* toward a point near the triangle */
                double w1 = unit() * 1.2 - 0.1, w2 = unit() * 1.2 - 0.1;
                float p = bf(v[0][a]) + (float)w1 * (bf(v[1][a]) - bf(v[0][a])) + (float)w2 * (bf(v[2][a]) - bf(v[0][a]));
                r.d[a] = fb(p - bf(r.o[a]));
                if (cbvh_f32_is_nan_or_inf(r.d[a])) r.d[a] = rcoord();
            } else
                r.d[a] = rcoord();
        }
        if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[0] = fb(1.0f);
        r.tmin = 0;
        r.tmax = CBVH_F32_POS_INF;
        cbvh_tri_result res;
        if (cbvh_ray_triangle(&r, v[0], v[1], v[2], &res)) {
            failures++;
            continue;
        }
        /* o + t d = v0 + b1 (v1 - v0) + b2 (v2 - v0):  [-d, e1, e2] (t, b1, b2) = o - v0 */
        for (int a = 0; a < 3; a++) {
            mpq_t o, x0, x1, x2;
            mpq_inits(o, x0, x1, x2, NULL);
            q_f32(o, r.o[a]);
            q_f32(x0, v[0][a]);
            q_f32(x1, v[1][a]);
            q_f32(x2, v[2][a]);
            q_f32(M[a][0], r.d[a]);
            mpq_neg(M[a][0], M[a][0]);
            mpq_sub(M[a][1], x1, x0);
            mpq_sub(M[a][2], x2, x0);
            mpq_sub(col[a], o, x0);
            mpq_clears(o, x0, x1, x2, NULL);
        }
        det3(det, M);
        int ehit = 0;
        if (mpq_sgn(det) != 0) {
            for (int c = 0; c < 3; c++) {
                mpq_t save[3];
                for (int a = 0; a < 3; a++) {
                    mpq_init(save[a]);
                    mpq_set(save[a], M[a][c]);
                    mpq_set(M[a][c], col[a]);
                }
                det3(sol[c], M);
                mpq_div(sol[c], sol[c], det);
                for (int a = 0; a < 3; a++) {
                    mpq_set(M[a][c], save[a]);
                    mpq_clear(save[a]);
                }
            }
            mpq_t b0;
            mpq_init(b0);
            mpq_set_ui(b0, 1, 1);
            mpq_sub(b0, b0, sol[1]);
            mpq_sub(b0, b0, sol[2]);
            ehit = mpq_sgn(sol[0]) > 0 && mpq_sgn(b0) >= 0 && mpq_sgn(sol[1]) >= 0 && mpq_sgn(sol[2]) >= 0;
            mpq_clear(b0);
        }
        hits += ehit;
        if (ehit != res.hit) {
            if (failures++ < 10) fprintf(stderr, "FAIL oracle hit: exact %d unit %d (case %ld)\n", ehit, res.hit, k);
            continue;
        }
        if (ehit && (!rd_ok(res.t, sol[0]) || !rd_ok(res.b1, sol[1]) || !rd_ok(res.b2, sol[2])))
            if (failures++ < 10) fprintf(stderr, "FAIL oracle rounding (case %ld)\n", k);
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) mpq_clear(M[i][j]);
    for (int i = 0; i < 3; i++) mpq_clears(col[i], sol[i], NULL);
    mpq_clears(det, dt, d1, d2, NULL);
    printf("oracle: %d cases, %ld exact hits, all decisions and RD roundings agree = %s\n", ORACLE_CASES, hits,
           failures ? "no" : "yes");
    if (hits < ORACLE_CASES / 20) failures++;
}

static void expect(const char *name, const cbvh_ray *r, const float t[3][3], int want_hit, cbvh_f32 want_t,
                   uint32_t want_st) {
    cbvh_f32 v[3][3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) v[k][a] = fb(t[k][a]);
    cbvh_tri_result res;
    uint32_t st = cbvh_ray_triangle(r, v[0], v[1], v[2], &res);
    if (st != want_st || res.hit != want_hit || (want_hit && want_t && res.t != want_t) ||
        (st && (res.t || res.b1 || res.b2))) {
        fprintf(stderr, "FAIL %s: status %02X hit %d t %08X\n", name, st, res.hit, res.t);
        failures++;
    }
}

static void named(void) {
    const float tri[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}; /* in z = 0 */
    cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(2.0f)}, {0, CBVH_F32_SIGN, fb(-1.0f)}, 0, CBVH_F32_POS_INF};
    expect("axis-parallel (-z, +0/-0)", &r, tri, 1, fb(2.0f), 0);
    r.o[0] = fb(0.5f);
    r.o[1] = fb(0.5f); /* through the hypotenuse edge */
    expect("through an edge", &r, tri, 1, fb(2.0f), 0);
    r.o[0] = 0;
    r.o[1] = CBVH_F32_SIGN; /* through vertex 0 (o = -0) */
    expect("through a vertex", &r, tri, 1, fb(2.0f), 0);
    r.o[0] = fb(0.5f);
    r.o[1] = 0x3F000001u; /* just outside the hypotenuse */
    expect("just outside an edge", &r, tri, 0, 0, 0);
    cbvh_ray g = {{fb(-1.0f), fb(0.25f), 0}, {fb(1.0f), 0, 0}, 0, CBVH_F32_POS_INF};
    expect("grazing in the plane", &g, tri, 0, 0, 0);
    g.o[2] = 1; /* smallest subnormal above the plane: still parallel, misses */
    expect("grazing above the plane", &g, tri, 0, 0, 0);
    cbvh_ray b = {{fb(0.25f), fb(0.25f), fb(2.0f)}, {0, 0, fb(1.0f)}, 0, CBVH_F32_POS_INF};
    expect("triangle behind the origin", &b, tri, 0, 0, 0);
    b.o[2] = 0;
    expect("origin on the triangle (t = 0)", &b, tri, 0, 0, 0);
    cbvh_ray n = {{fb(0.25f), fb(0.25f), fb(2.0f)}, {0, 0, fb(-1.0f)}, 0, CBVH_F32_POS_INF};
    n.o[0] = 0x7FC00000u;
    expect("NaN origin", &n, tri, 0, 0, CBVH_ST_NAN_INF);
    n.o[0] = fb(0.25f);
    n.d[1] = CBVH_F32_NEG_INF;
    expect("-Inf direction", &n, tri, 0, 0, CBVH_ST_NAN_INF);
    n.d[1] = 0;
    n.d[2] = CBVH_F32_SIGN;
    expect("zero direction", &n, tri, 0, 0, CBVH_ST_ZERO_DIR);
    const float inf_tri[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    cbvh_ray ok = {{fb(0.25f), fb(0.25f), fb(2.0f)}, {0, 0, fb(-1.0f)}, 0, CBVH_F32_POS_INF};
    /* a NaN or an infinity in any of the nine coordinates is rejected (the
     * unit's binary64 filter must not decide such a triangle), for rays that
     * hit the finite triangle, along an axis and oblique, each axis the
     * largest |d| (the filter's sheared axis) */
    const cbvh_f32 bad[3] = {0x7FC00000u, CBVH_F32_POS_INF, CBVH_F32_NEG_INF};
    for (int ri = 0; ri < 3 * 64; ri++) {
        int axis = ri % 3; /* toward (0.2, 0.3) on the triangle: along the axis, then oblique */
        float ox = ri < 3 ? 0.2f : (float)(ri % 7) - 3.0f, oy = ri < 3 ? 0.3f : (float)(ri % 5) * 0.75f - 1.5f;
        const float o3[3] = {ox, oy, 2.0f}, d3[3] = {0.2f - ox, 0.3f - oy, -2.0f};
        cbvh_ray ar = ok;
        for (int a = 0; a < 3; a++) {
            ar.o[a] = fb(o3[(a + 2 - axis) % 3]);
            ar.d[a] = fb(d3[(a + 2 - axis) % 3]);
        }
        for (int pos = 0; pos < 9; pos++)
            for (int b = 0; b < 3; b++) {
                cbvh_f32 w[3][3];
                cbvh_tri_result res;
                for (int k = 0; k < 3; k++)
                    for (int a = 0; a < 3; a++) w[k][a] = fb(inf_tri[k][(a + 2 - axis) % 3]);
                w[pos / 3][pos % 3] = bad[b];
                uint32_t st = cbvh_ray_triangle(&ar, w[0], w[1], w[2], &res);
                if (st != CBVH_ST_NAN_INF || res.hit) {
                    fprintf(stderr, "FAIL vertex %d coordinate %d = %08X, ray along %d: status %X, want NAN_INF\n",
                            pos / 3, pos % 3, bad[b], axis, st);
                    failures++;
                }
            }
    }
    /* far from the origin: t = 2^20 exactly */
    cbvh_ray far = {{fb(1e6f), fb(-2e6f), fb(1048576.0f)}, {0, 0, fb(-1.0f)}, 0, CBVH_F32_POS_INF};
    const float ft[3][3] = {{999999.0f, -2000001.0f, 0}, {1000002.0f, -2000001.0f, 0}, {1000000.0f, -1999998.0f, 0}};
    expect("far from the origin", &far, ft, 1, fb(1048576.0f), 0);
}

int main(void) {
    named();
    oracle_test();
    leak_test();
    return failures ? 1 : 0;
}
