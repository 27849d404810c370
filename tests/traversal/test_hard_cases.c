/* Traversal hard cases (docs/traversal.md §8: the named cases every traversal
 * must get right), one ctest each: traversal.hard.<case>.  Every case builds a small scene in memory, builds
 * float BVHs (SAH and LBVH) and CBVHs (top-down and bottom-up, both
 * encodings, several N / M) and traces rays through all of them:
 *   - CBVH closest hit == float-BVH closest hit (prim, t, b1, b2 bits)
 *     == the plain float traversals' (binary and 4-wide)
 *     == brute force over all triangles with the ray-triangle unit;
 *   - any-hit reports a hit iff there is one, and that hit is real;
 *   - unit-level expectations where the answer is known exactly (origin on a
 *     decoded box face / inside a box: hit with t_near = tmin, axis-parallel
 *     rays: hit iff exact comparisons say so, rejects: status + zero outputs).
 * The FPU (double) is used only as an oracle for exact comparisons.
 * usage: test_hard_cases CASE */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/qbvh.h"
#include "cbvh/traverse.h"
#include "cbvh/unit_table.h"
#include "test_trav_util.h"
#include "test_wide.h"

#ifdef CBVH_SANITIZE
#define SCALE_DOWN 10
#else
#define SCALE_DOWN 1
#endif

static long failures;
#define FAIL(...)                                                                                                     \
    do {                                                                                                              \
        if (failures++ < 12) {                                                                                        \
            fprintf(stderr, "FAIL: ");                                                                                \
            fprintf(stderr, __VA_ARGS__);                                                                             \
            fprintf(stderr, "\n");                                                                                    \
        }                                                                                                             \
    } while (0)

/* ---- small helpers ------------------------------------------------------ */
static uint64_t rs = 0x9E3779B97F4A7C15u;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static double unit(void) { return tu_unit_d(&rs); }
static cbvh_f32 zero_bits(void) { return (rnd() & 1) ? 0u : CBVH_F32_SIGN; } /* +0 or -0 */

static cbvh_ray make_ray(const float o[3], const float d[3]) {
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        r.o[a] = fb(o[a]);
        r.d[a] = fb(d[a]);
    }
    r.tmin = 0;
    r.tmax = CBVH_F32_POS_INF;
    return r;
}
static int zero_dir(const cbvh_ray *r) {
    return cbvh_f32_is_zero(r->d[0]) && cbvh_f32_is_zero(r->d[1]) && cbvh_f32_is_zero(r->d[2]);
}
static void print_ray(const char *what, const cbvh_ray *r) {
    fprintf(stderr, "  %s ray o=(%08X %08X %08X) d=(%08X %08X %08X) tmin=%08X tmax=%08X\n", what, r->o[0], r->o[1],
            r->o[2], r->d[0], r->d[1], r->d[2], r->tmin, r->tmax);
}

/* ---- meshes (indexed, so shared vertices are bit-identical) -------------- */
typedef struct {
    double (*v)[3];
    int nv;
    int (*f)[3];
    int nf;
} mesh;

static void mesh_free(mesh *m) {
    free(m->v);
    free(m->f);
    memset(m, 0, sizeof *m);
}

/* Icosphere of radius 1: icosahedron, `sub` midpoint subdivisions. */
static mesh icosphere(int sub) {
    mesh m;
    int maxv = 12, maxf = 20;
    for (int i = 0; i < sub; i++) {
        maxv = maxv + maxf * 3 / 2;
        maxf *= 4;
    }
    m.v = malloc(sizeof *m.v * (size_t)maxv);
    m.f = malloc(sizeof *m.f * (size_t)maxf);
    const double p = (1.0 + sqrt(5.0)) / 2.0;
    const double iv[12][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                              {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    const int ifc[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    m.nv = 12;
    m.nf = 20;
    for (int i = 0; i < 12; i++) {
        double l = sqrt(iv[i][0] * iv[i][0] + iv[i][1] * iv[i][1] + iv[i][2] * iv[i][2]);
        for (int a = 0; a < 3; a++) m.v[i][a] = iv[i][a] / l;
    }
    memcpy(m.f, ifc, sizeof ifc);
    int *mid = malloc(sizeof *mid * (size_t)maxv * (size_t)maxv);
    for (int s = 0; s < sub; s++) {
        for (long i = 0; i < (long)maxv * maxv; i++) mid[i] = -1;
        int (*nf)[3] = malloc(sizeof *nf * (size_t)m.nf * 4);
        int k = 0;
        for (int t = 0; t < m.nf; t++) {
            int c[3];
            for (int e = 0; e < 3; e++) {
                int a = m.f[t][e], b = m.f[t][(e + 1) % 3];
                int lo = a < b ? a : b, hi = a < b ? b : a;
                int *slot = &mid[(long)lo * maxv + hi];
                if (*slot < 0) {
                    double q[3], l = 0;
                    for (int x = 0; x < 3; x++) {
                        q[x] = 0.5 * (m.v[a][x] + m.v[b][x]);
                        l += q[x] * q[x];
                    }
                    for (int x = 0; x < 3; x++) m.v[m.nv][x] = q[x] / sqrt(l);
                    *slot = m.nv++;
                }
                c[e] = *slot;
            }
            int a = m.f[t][0], b = m.f[t][1], d = m.f[t][2];
            int tri[4][3] = {{a, c[0], c[2]}, {b, c[1], c[0]}, {d, c[2], c[1]}, {c[0], c[1], c[2]}};
            memcpy(nf[k], tri, sizeof tri);
            k += 4;
        }
        free(m.f);
        m.f = nf;
        m.nf = k;
    }
    free(mid);
    return m;
}

/* Cube [-1, 1]^3, n x n quads per face (two triangles each, alternating
 * diagonals); grid vertices shared between faces. */
static mesh tess_cube(int n) {
    mesh m;
    int g = n + 1;
    m.v = malloc(sizeof *m.v * (size_t)(g * g * g));
    m.f = malloc(sizeof *m.f * (size_t)(12 * n * n));
    m.nv = g * g * g;
    m.nf = 0;
    for (int i = 0; i < g; i++)
        for (int j = 0; j < g; j++)
            for (int k = 0; k < g; k++) {
                int id = (i * g + j) * g + k;
                m.v[id][0] = -1.0 + 2.0 * i / n;
                m.v[id][1] = -1.0 + 2.0 * j / n;
                m.v[id][2] = -1.0 + 2.0 * k / n;
            }
    for (int ax = 0; ax < 3; ax++)
        for (int side = 0; side <= n; side += n)
            for (int u = 0; u < n; u++)
                for (int w = 0; w < n; w++) {
                    int q[4];
                    int cu[4] = {u, u + 1, u + 1, u}, cw[4] = {w, w, w + 1, w + 1};
                    for (int c = 0; c < 4; c++) {
                        int ijk[3];
                        ijk[ax] = side;
                        ijk[(ax + 1) % 3] = cu[c];
                        ijk[(ax + 2) % 3] = cw[c];
                        q[c] = (ijk[0] * g + ijk[1]) * g + ijk[2];
                    }
                    if ((u + w) & 1) {
                        int t0[3] = {q[0], q[1], q[2]}, t1[3] = {q[0], q[2], q[3]};
                        memcpy(m.f[m.nf++], t0, sizeof t0);
                        memcpy(m.f[m.nf++], t1, sizeof t1);
                    } else {
                        int t0[3] = {q[0], q[1], q[3]}, t1[3] = {q[1], q[2], q[3]};
                        memcpy(m.f[m.nf++], t0, sizeof t0);
                        memcpy(m.f[m.nf++], t1, sizeof t1);
                    }
                }
    return m;
}

/* Plane z = 0, [-1, 1]^2, n x n quads. */
static mesh plane_grid(int n) {
    mesh m;
    int g = n + 1;
    m.v = malloc(sizeof *m.v * (size_t)(g * g));
    m.f = malloc(sizeof *m.f * (size_t)(2 * n * n));
    m.nv = g * g;
    m.nf = 0;
    for (int i = 0; i < g; i++)
        for (int j = 0; j < g; j++) {
            m.v[i * g + j][0] = -1.0 + 2.0 * i / n;
            m.v[i * g + j][1] = -1.0 + 2.0 * j / n;
            m.v[i * g + j][2] = 0;
        }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            int a = i * g + j, b = a + g, c = b + 1, d = a + 1;
            int t0[3] = {a, b, c}, t1[3] = {a, c, d};
            memcpy(m.f[m.nf++], t0, sizeof t0);
            memcpy(m.f[m.nf++], t1, sizeof t1);
        }
    return m;
}

/* Appends the mesh, scaled and translated (rounded to binary32 once per
 * vertex, so shared vertices stay shared), to a triangle list. */
static void add_mesh(cbvh_scene *s, const mesh *m, double scale, const double off[3]) {
    s->tris = realloc(s->tris, sizeof *s->tris * (s->ntris + (size_t)m->nf));
    for (int t = 0; t < m->nf; t++)
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) s->tris[s->ntris + t].v[k][a] = (float)(m->v[m->f[t][k]][a] * scale + off[a]);
    s->ntris += (uint32_t)m->nf;
}
static float vtx(const mesh *m, int i, int a, double scale, const double off[3]) {
    return (float)(m->v[i][a] * scale + off[a]);
}

/* ---- the world: one scene, its BVHs and CBVHs ---------------------------- */
#define MAX_TREES 12
typedef struct {
    char name[48];
    int bvh; /* index of the float BVH it was compressed from */
    int M;
    cbvh_tree t;
} tree_cfg;

typedef struct {
    cbvh_scene s;
    cbvh_bvh b[2];
    cbvh_fbvh fb[2]; /* b[i] laid out for the plain float traversal */
    any_wide aw[2][2]; /* b[i] collapsed 4- and 8-wide (aw[W][i]) for the plain float traversals
                        * (leaf copy for b[0]) */
    const char *bname[2];
    int nb;
    tree_cfg tr[MAX_TREES];
    int nt;
    /* counters */
    long rays, hits, checks;
} world;

typedef struct {
    int N, min_scale;
    cbvh_encoding enc;
    int bottomup;
    int M;
} tcfg;

static const tcfg default_cfgs[] = {{6, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_MODULO, 0, 24},
                                    {6, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_RELATIVE, 1, 24},
                                    {6, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_MODULO, 1, 8},
                                    {3, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_MODULO, 0, 24},
                                    {10, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_RELATIVE, 0, 24}};
#define NDEFAULT (int)(sizeof default_cfgs / sizeof default_cfgs[0])

static int world_build(world *w, const tcfg *cfg, int ncfg, int both_builders) {
    char err[256];
    if (cbvh_scene_validate(&w->s, err, sizeof err)) {
        FAIL("scene: %s", err);
        return -1;
    }
    w->nb = 0;
    if (cbvh_build_sah(&w->s, 0, 0, &w->b[w->nb], err, sizeof err)) {
        FAIL("SAH build: %s", err);
        return -1;
    }
    w->bname[w->nb++] = "sah";
    if (both_builders) {
        if (cbvh_build_lbvh(&w->s, &w->b[w->nb], err, sizeof err)) {
            FAIL("LBVH build: %s", err);
            return -1;
        }
        w->bname[w->nb++] = "lbvh";
    }
    for (int bi = 0; bi < w->nb; bi++)
        if (cbvh_fbvh_build(&w->b[bi], &w->fb[bi], err, sizeof err) ||
            aw_build(&w->aw[0][bi], 0, &w->b[bi], bi ? NULL : w->s.tris, w->s.ntris, err, sizeof err) ||
            aw_build(&w->aw[1][bi], 1, &w->b[bi], bi ? NULL : w->s.tris, w->s.ntris, err, sizeof err)) {
            FAIL("float BVH layouts: %s", err);
            return -1;
        }
    w->nt = 0;
    for (int bi = 0; bi < w->nb; bi++)
        for (int c = 0; c < ncfg && w->nt < MAX_TREES; c++) {
            tree_cfg *tc = &w->tr[w->nt];
            cbvh_compress_opts o = {{cfg[c].N, cfg[c].min_scale}, cfg[c].enc, 1, 0};
            cbvh_bu_stats bu;
            int rc = cfg[c].bottomup ? cbvh_compress_bottomup(&w->b[bi], NULL, &o, &tc->t, &bu, err, sizeof err)
                                     : cbvh_compress_topdown(&w->b[bi], &o, &tc->t, err, sizeof err);
            snprintf(tc->name, sizeof tc->name, "%s/%s N=%d ms=%d %s M=%d", w->bname[bi],
                     cfg[c].bottomup ? "bu" : "td", cfg[c].N, cfg[c].min_scale, cbvh_encoding_name(cfg[c].enc),
                     cfg[c].M);
            if (rc) {
                FAIL("compress %s: %s", tc->name, err);
                return -1;
            }
            if (cbvh_tree_check(&tc->t, &w->b[bi], err, sizeof err)) {
                FAIL("tree check %s: %s", tc->name, err);
                cbvh_tree_free(&tc->t);
                return -1;
            }
            tc->bvh = bi;
            tc->M = cfg[c].M;
            w->nt++;
        }
    return 0;
}

static void world_free(world *w) {
    for (int i = 0; i < w->nt; i++) cbvh_tree_free(&w->tr[i].t);
    for (int i = 0; i < w->nb; i++) {
        cbvh_fbvh_free(&w->fb[i]);
        aw_free(&w->aw[0][i]);
        aw_free(&w->aw[1][i]);
        cbvh_bvh_free(&w->b[i]);
    }
    cbvh_scene_free(&w->s);
}

/* An any-hit result must be a real hit of the unit in [tmin, tmax]. */
static int any_ok(const world *w, const cbvh_ray *r, const cbvh_trav_hit *any, int ref_hit) {
    if (any->hit != ref_hit) return 0;
    if (!any->hit) return 1;
    if (any->prim >= w->s.ntris) return 0;
    cbvh_f32 v[3][3];
    memcpy(v, w->s.tris[any->prim].v, sizeof v);
    cbvh_tri_result res;
    if (cbvh_ray_triangle(r, v[0], v[1], v[2], &res) || !res.hit || res.t != any->t) return 0;
    return cbvh_f32_key(res.t) >= cbvh_f32_key(r->tmin) && cbvh_f32_key(res.t) <= cbvh_f32_key(r->tmax);
}

/* Traces one valid ray through every structure and compares.  With
 * use_brute the reference is brute force, else the first float BVH.
 * Returns the reference hit. */
static cbvh_trav_hit check_ray(world *w, const cbvh_ray *r, int use_brute) {
    cbvh_trav_hit ref = {0}, h, any;
    cbvh_trav_stats st = {0};
    w->rays++;
    if (use_brute) ref = brute(&w->s, r);
    for (int bi = 0; bi < w->nb; bi++) {
        if (cbvh_trace_bvh(&w->b[bi], w->s.tris, r, 24, CBVH_TRAV_CLOSEST, &h, &st) ||
            cbvh_trace_bvh(&w->b[bi], w->s.tris, r, 24, CBVH_TRAV_ANY, &any, &st)) {
            FAIL("float BVH %s rejected a valid ray", w->bname[bi]);
            print_ray("", r);
            continue;
        }
        if (!use_brute && bi == 0) ref = h;
        w->checks++;
        if (!same_hit(&h, &ref)) {
            FAIL("float BVH %s closest hit %d prim %u t %08X != %s hit %d prim %u t %08X", w->bname[bi], h.hit, h.prim,
                 h.t, use_brute ? "brute force" : "float BVH", ref.hit, ref.prim, ref.t);
            print_ray("", r);
        }
        if (!any_ok(w, r, &any, ref.hit)) {
            FAIL("float BVH %s any-hit %d prim %u, reference hit %d", w->bname[bi], any.hit, any.prim, ref.hit);
            print_ray("", r);
        }
        /* the plain floating-point traversal of the same BVH */
        if (cbvh_trace_bvh_float(&w->fb[bi], w->s.tris, r, CBVH_TRAV_CLOSEST, &h, &st) ||
            cbvh_trace_bvh_float(&w->fb[bi], w->s.tris, r, CBVH_TRAV_ANY, &any, &st)) {
            FAIL("plain float BVH %s rejected a valid ray", w->bname[bi]);
            print_ray("", r);
            continue;
        }
        w->checks++;
        if (!same_hit(&h, &ref)) {
            FAIL("plain float BVH %s closest hit %d prim %u t %08X != reference hit %d prim %u t %08X", w->bname[bi],
                 h.hit, h.prim, h.t, ref.hit, ref.prim, ref.t);
            print_ray("", r);
        }
        if (!any_ok(w, r, &any, ref.hit)) {
            FAIL("plain float BVH %s any-hit %d prim %u, reference hit %d", w->bname[bi], any.hit, any.prim, ref.hit);
            print_ray("", r);
        }
        /* ... and of its 4- and 8-wide collapses */
        for (int W = 0; W < 2; W++) {
            if (aw_trace(&w->aw[W][bi], w->s.tris, r, CBVH_TRAV_CLOSEST, &h, &st) ||
                aw_trace(&w->aw[W][bi], w->s.tris, r, CBVH_TRAV_ANY, &any, &st)) {
                FAIL("%s plain float %s rejected a valid ray", wide_name[W], w->bname[bi]);
                print_ray("", r);
                continue;
            }
            w->checks++;
            if (!same_hit(&h, &ref) || !any_ok(w, r, &any, ref.hit)) {
                FAIL("%s plain float %s closest hit %d prim %u t %08X any %d != reference hit %d prim %u t %08X",
                     wide_name[W], w->bname[bi], h.hit, h.prim, h.t, any.hit, ref.hit, ref.prim, ref.t);
                print_ray("", r);
            }
        }
    }
    for (int i = 0; i < w->nt; i++) {
        tree_cfg *tc = &w->tr[i];
        if (cbvh_trace_cbvh(&tc->t, w->s.tris, r, tc->M, CBVH_TRAV_CLOSEST, &h, &st) ||
            cbvh_trace_cbvh(&tc->t, w->s.tris, r, tc->M, CBVH_TRAV_ANY, &any, &st)) {
            FAIL("CBVH %s rejected a valid ray", tc->name);
            print_ray("", r);
            continue;
        }
        w->checks++;
        if (!same_hit(&h, &ref)) {
            FAIL("CBVH %s closest hit %d prim %u t %08X != reference hit %d prim %u t %08X", tc->name, h.hit, h.prim,
                 h.t, ref.hit, ref.prim, ref.t);
            print_ray("", r);
        }
        if (!any_ok(w, r, &any, ref.hit)) {
            FAIL("CBVH %s any-hit %d prim %u, reference hit %d", tc->name, any.hit, any.prim, ref.hit);
            print_ray("", r);
        }
    }
    w->hits += ref.hit;
    return ref;
}

/* ---- boxes: float BVH nodes and decoded CBVH children ------------------ */
typedef struct {
    int grid;           /* 1: decoded CBVH child (test with cbvh_ray_box), 0: float box */
    int leaf;
    cbvh_grid_axis g[3];
    float lo[3], hi[3]; /* float box, or decoded clb/cub */
    double L[3], H[3];  /* the planes the unit tests (exact) */
    int exact;          /* L, H exactly representable as double, and equal lo/hi as floats */
} box;

typedef struct {
    box *b;
    int n, cap;
} boxes;

static void push_box(boxes *bs, const box *b) {
    if (bs->n == bs->cap) {
        bs->cap = bs->cap ? 2 * bs->cap : 256;
        bs->b = realloc(bs->b, sizeof *bs->b * (size_t)bs->cap);
    }
    bs->b[bs->n++] = *b;
}

/* u + r 2^e as a double, if that sum is exact (Fast2Sum error term zero). */
static int plane_exact(cbvh_f32 u, int e, uint32_t r, double *out) {
    if ((u & 0x7FFFFFFFu) >= CBVH_F32_POS_INF) return 0;
    double a = bf(u), b = ldexp((double)r, e);
    double big = fabs(a) >= fabs(b) ? a : b, small = fabs(a) >= fabs(b) ? b : a;
    double s = big + small;
    if (s - big != small) return 0;
    *out = s;
    return 1;
}

static void collect_float(const cbvh_bvh *b, boxes *bs) {
    for (uint32_t i = 0; i < b->nnodes; i++) {
        box x;
        memset(&x, 0, sizeof x);
        x.leaf = cbvh_bvh_is_leaf(&b->nodes[i]);
        x.exact = 1;
        for (int a = 0; a < 3; a++) {
            x.lo[a] = b->nodes[i].lo[a];
            x.hi[a] = b->nodes[i].hi[a];
            x.L[a] = x.lo[a];
            x.H[a] = x.hi[a];
        }
        push_box(bs, &x);
    }
}

static void collect_cbvh_rec(const cbvh_tree *t, uint32_t pair, const cbvh_node_ctx *ctx, boxes *bs, int depth) {
    if (pair >= t->npairs || depth > 200) {
        FAIL("CBVH walk: bad pair %u", pair);
        return;
    }
    cbvh_child_out ch[2];
    if (cbvh_nodepair_decode(&t->params, t->enc, ctx, t->pairs + (size_t)pair * t->pair_bytes, ch) &
        CBVH_ST_REJECT) {
        FAIL("CBVH walk: decode rejected pair %u", pair);
        return;
    }
    for (int c = 0; c < 2; c++) {
        if (ch[c].empty) continue;
        box x;
        memset(&x, 0, sizeof x);
        x.grid = 1;
        x.leaf = ch[c].leaf;
        x.exact = 1;
        cbvh_node_ctx cc;
        for (int a = 0; a < 3; a++) {
            x.g[a].u = ctx->axis[a].clb;
            x.g[a].e = ctx->axis[a].scale;
            cbvh_axis_store_codes(&t->params, CBVH_ENC_RELATIVE, &ctx->axis[a], &ch[c].axis[a], &x.g[a].r, &x.g[a].s);
            if (x.g[a].s == 0) x.g[a].s = 1u << t->params.quant_bits;
            x.lo[a] = bf(ch[c].axis[a].clb);
            x.hi[a] = bf(ch[c].axis[a].cub);
            if (!plane_exact(x.g[a].u, x.g[a].e, x.g[a].r, &x.L[a]) ||
                !plane_exact(x.g[a].u, x.g[a].e, x.g[a].s, &x.H[a]) || x.L[a] != (double)x.lo[a] ||
                x.H[a] != (double)x.hi[a])
                x.exact = 0;
            cc.axis[a] = cbvh_axis_child_ctx(&ctx->axis[a], &ch[c].axis[a]);
        }
        push_box(bs, &x);
        if (!ch[c].leaf) collect_cbvh_rec(t, ch[c].ptr, &cc, bs, depth + 1);
    }
}
static void collect_cbvh(const cbvh_tree *t, boxes *bs) { collect_cbvh_rec(t, t->root_pair, &t->root_ctx, bs, 0); }

static uint32_t unit_box(const box *x, const cbvh_ray *r, int M, cbvh_box_result *out) {
    if (x->grid) return cbvh_ray_box(r, M, x->g, out);
    cbvh_f32 lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = fb(x->lo[a]);
        hi[a] = fb(x->hi[a]);
    }
    return cbvh_ray_box_float(r, M, lo, hi, out);
}

/* The world's boxes: float boxes of every BVH, decoded boxes of every tree. */
static void collect_all(const world *w, boxes *bs) {
    for (int i = 0; i < w->nb; i++) collect_float(&w->b[i], bs);
    for (int i = 0; i < w->nt; i++) collect_cbvh(&w->tr[i].t, bs);
}

/* Box unit: origin in the closed box -> hit with t_near = tmin (+0). */
static long unit_inside_checks;
static void expect_inside_hit(const box *x, const cbvh_ray *r, const char *what) {
    for (int M = 3; M <= 24; M += 21) {
        cbvh_box_result br;
        uint32_t st = unit_box(x, r, M, &br);
        unit_inside_checks++;
        if (st || !br.hit || br.t_near != r->tmin) {
            FAIL("%s: box unit (M=%d, %s box) status %02X hit %d t_near %08X for an origin in the box", what, M,
                 x->grid ? "decoded" : "float", st, br.hit, br.t_near);
            print_ray("", r);
        }
    }
}

static void scene_sphere_cube(world *w, int sphere_sub, int cube_n) {
    mesh s = icosphere(sphere_sub), c = tess_cube(cube_n);
    double o1[3] = {0, 0, 0}, o2[3] = {2.75, 0.25, -0.5};
    add_mesh(&w->s, &c, 1.0, o1);
    add_mesh(&w->s, &s, 0.625, o2);
    snprintf(w->s.name, sizeof w->s.name, "cube%d+sphere%d", cube_n, sphere_sub);
    mesh_free(&s);
    mesh_free(&c);
}

/* A coordinate for an origin: a plane of some box, a vertex coordinate, or a
 * random value in [lo - 1, hi + 1]. */
static float pick_coord(const boxes *bs, const cbvh_scene *s, int a, float lo, float hi) {
    switch (rnd() % 4) {
    case 0: {
        const box *x = &bs->b[rnd() % (uint64_t)bs->n];
        return (rnd() & 1) ? x->lo[a] : x->hi[a];
    }
    case 1: return s->tris[rnd() % s->ntris].v[rnd() % 3][a];
    default: return (float)(lo - 1 + unit() * (hi - lo + 2));
    }
}

/* ---- cases ---------------------------------------------------------------- */

/* Direction components +0 / -0 on one and two axes; origins outside, inside
 * and on slab planes.  Unit level (one nonzero axis): the exact answer is a
 * comparison, so the box unit must agree with it in both directions. */
static int case_axis_parallel(void) {
    world w = {0};
    scene_sphere_cube(&w, 2, 4);
    if (world_build(&w, default_cfgs, NDEFAULT, 1)) return 1;
    boxes bs = {0};
    collect_all(&w, &bs);
    float lo[3], hi[3];
    cbvh_scene_bounds(&w.s, lo, hi);
    const int nrays = 6000 / SCALE_DOWN;
    long unit_checks = 0, one_axis = 0;
    for (int i = 0; i < nrays; i++) {
        float o[3], d[3];
        for (int a = 0; a < 3; a++) o[a] = pick_coord(&bs, &w.s, a, lo[a], hi[a]);
        int nz = 1 + (i & 1); /* zero components: 1 or 2 */
        int skip = (int)(rnd() % 3);
        for (int a = 0; a < 3; a++) d[a] = (float)(unit() * 2 - 1);
        if (nz == 2) {
            for (int a = 0; a < 3; a++)
                if (a != skip) d[a] = bf(zero_bits());
            if (d[skip] == 0) d[skip] = 1;
            if (i % 8 < 4) d[skip] = (rnd() & 1) ? 1.0f : -1.0f;
        } else
            d[skip] = bf(zero_bits());
        cbvh_ray r = make_ray(o, d);
        if (nz == 2) { /* keep the exact signed zeros */
            for (int a = 0; a < 3; a++)
                if (a != skip) r.d[a] = zero_bits();
        } else
            r.d[skip] = zero_bits();
        check_ray(&w, &r, 1);
        if (nz == 2) {
            one_axis++;
            /* exact oracle: zero axes L <= o <= H; moving axis: the box is ahead (or contains o) */
            for (int k = 0; k < bs.n; k += 3) {
                const box *x = &bs.b[k];
                if (!x->exact) continue;
                int ex = 1;
                for (int a = 0; a < 3; a++) {
                    double oa = bf(r.o[a]);
                    if (a != skip)
                        ex &= x->L[a] <= oa && oa <= x->H[a];
                    else
                        ex &= bf(r.d[a]) > 0 ? x->H[a] >= oa : x->L[a] <= oa;
                }
                cbvh_box_result br;
                int M = (k & 1) ? 24 : 5;
                uint32_t st = unit_box(x, &r, M, &br);
                unit_checks++;
                if (st || br.hit != ex) {
                    FAIL("axis_parallel: box unit (%s box, M=%d) status %02X hit %d, exact %d", x->grid ? "decoded" : "float",
                         M, st, br.hit, ex);
                    print_ray("", &r);
                }
            }
        }
    }
    printf("axis_parallel: %ld rays (%ld with two zero components), %ld hits, %ld traversal comparisons "
           "(%d CBVHs, %d float BVHs), %ld exact box-unit checks on %d boxes, %ld failures\n",
           w.rays, one_axis, w.hits, w.checks, w.nt, w.nb, unit_checks, bs.n, failures);
    if (w.hits < w.rays / 20) FAIL("axis_parallel: too few hits (%ld of %ld): rays not exercising the scene", w.hits, w.rays);
    free(bs.b);
    world_free(&w);
    return failures != 0;
}

/* Origins exactly on a decoded (or float) box face, pointing in, out, along. */
static int case_ray_on_box_face(void) {
    world w = {0};
    scene_sphere_cube(&w, 2, 4);
    if (world_build(&w, default_cfgs, NDEFAULT, 1)) return 1;
    boxes bs = {0};
    collect_all(&w, &bs);
    const int nrays = 6000 / SCALE_DOWN;
    long inexact = 0, kinds[3] = {0, 0, 0};
    for (int k = 0; k < bs.n; k++)
        if (!bs.b[k].exact) inexact++;
    for (int i = 0; i < nrays; i++) {
        const box *x = &bs.b[rnd() % (uint64_t)bs.n];
        if (!x->exact) continue;
        int fa = (int)(rnd() % 3), upper = (int)(rnd() & 1);
        float o[3], d[3];
        for (int a = 0; a < 3; a++) {
            int pos = (int)(rnd() % 4); /* 0: lower, 1: upper face/edge/corner, else inside */
            o[a] = pos == 0 ? x->lo[a] : pos == 1 ? x->hi[a] : (float)(x->lo[a] + unit() * ((double)x->hi[a] - x->lo[a]));
            if (o[a] < x->lo[a] || o[a] > x->hi[a]) o[a] = x->lo[a];
            d[a] = (float)(unit() * 2 - 1);
        }
        o[fa] = upper ? x->hi[fa] : x->lo[fa];
        int kind = i % 3; /* 0 in, 1 out, 2 along */
        float mag = (float)(0.05 + unit());
        if (kind == 0) d[fa] = upper ? -mag : mag;
        if (kind == 1) d[fa] = upper ? mag : -mag;
        cbvh_ray r = make_ray(o, d);
        if (kind == 2) r.d[fa] = zero_bits();
        if (zero_dir(&r)) r.d[(fa + 1) % 3] = fb(1.0f);
        kinds[kind]++;
        expect_inside_hit(x, &r, "ray_on_box_face");
        check_ray(&w, &r, 1);
    }
    printf("ray_on_box_face: %ld rays (in %ld, out %ld, along %ld) on faces of %d boxes (%ld skipped: planes not "
           "exact in double), %ld hits, %ld traversal comparisons, %ld box-unit checks, %ld failures\n",
           w.rays, kinds[0], kinds[1], kinds[2], bs.n, inexact, w.hits, w.checks, unit_inside_checks, failures);
    if (w.hits < w.rays / 20) FAIL("ray_on_box_face: too few hits (%ld of %ld)", w.hits, w.rays);
    free(bs.b);
    world_free(&w);
    return failures != 0;
}

/* Origins inside leaf and inner boxes (random points, centres, corners). */
static int case_ray_inside_box(void) {
    world w = {0};
    scene_sphere_cube(&w, 2, 4);
    if (world_build(&w, default_cfgs, NDEFAULT, 1)) return 1;
    boxes bs = {0};
    collect_all(&w, &bs);
    const int nrays = 6000 / SCALE_DOWN;
    long leaf = 0, inner = 0;
    for (int i = 0; i < nrays; i++) {
        /* alternate leaf / inner boxes */
        const box *x = NULL;
        for (int tries = 0; tries < 64; tries++) {
            const box *y = &bs.b[rnd() % (uint64_t)bs.n];
            if (y->exact && y->leaf == (i & 1)) {
                x = y;
                break;
            }
        }
        if (!x) continue;
        float o[3], d[3];
        int mode = (i >> 1) % 3; /* 0 random, 1 centre, 2 corner */
        for (int a = 0; a < 3; a++) {
            double lo = x->lo[a], hi = x->hi[a];
            o[a] = mode == 0 ? (float)(lo + unit() * (hi - lo)) : mode == 1 ? (float)(0.5 * (lo + hi)) : ((rnd() & 1) ? x->lo[a] : x->hi[a]);
            if (o[a] < x->lo[a] || o[a] > x->hi[a]) o[a] = x->lo[a];
            d[a] = (float)(unit() * 2 - 1);
        }
        cbvh_ray r = make_ray(o, d);
        if (i % 5 == 0) r.d[rnd() % 3] = zero_bits();
        if (i % 7 == 0) r.tmax = fb((float)(0.01 + unit()));
        if (zero_dir(&r)) r.d[0] = fb(1.0f);
        if (x->leaf) leaf++;
        else inner++;
        expect_inside_hit(x, &r, "ray_inside_box");
        check_ray(&w, &r, 1);
    }
    printf("ray_inside_box: %ld rays (%ld from leaf boxes, %ld from inner boxes; random/centre/corner), %ld hits, "
           "%ld traversal comparisons, %ld box-unit checks, %ld failures\n",
           w.rays, leaf, inner, w.hits, w.checks, unit_inside_checks, failures);
    if (w.hits < w.rays / 20) FAIL("ray_inside_box: too few hits (%ld of %ld)", w.hits, w.rays);
    free(bs.b);
    world_free(&w);
    return failures != 0;
}

/* Rays in the plane of an axis-aligned face of a tessellated cube, along
 * tessellation edges, and one ulp off the plane. */
static int case_grazing_face(void) {
    world w = {0};
    mesh c = tess_cube(4);
    double off[3] = {0, 0, 0};
    add_mesh(&w.s, &c, 1.0, off);
    snprintf(w.s.name, sizeof w.s.name, "cube4");
    if (world_build(&w, default_cfgs, NDEFAULT, 1)) return 1;
    const int nrays = 8000 / SCALE_DOWN;
    long in_plane = 0, along_edge = 0, off_plane = 0, root_checks = 0;
    cbvh_f32 rlo[3] = {fb(-1), fb(-1), fb(-1)}, rhi[3] = {fb(1), fb(1), fb(1)};
    for (int i = 0; i < nrays; i++) {
        int fa = (int)(rnd() % 3);
        float side = (rnd() & 1) ? 1.0f : -1.0f;
        float o[3], d[3], tgt[3];
        int kind = i % 4;
        for (int a = 0; a < 3; a++) {
            o[a] = (float)(unit() * 6 - 3);
            tgt[a] = (float)(unit() * 1.6 - 0.8); /* inside the face's square */
        }
        o[fa] = side;
        tgt[fa] = side;
        if (kind == 1) { /* along a tessellation line of the face: one more coordinate on the grid */
            int b = (fa + 1 + (int)(rnd() % 2)) % 3;
            o[b] = tgt[b] = (float)(-1.0 + 0.5 * (double)(rnd() % 5));
        }
        if (kind == 2) { /* along a diagonal of a quad: through two grid points */
            int b = (fa + 1) % 3, e = (fa + 2) % 3;
            float p0[3], p1[3];
            int u = (int)(rnd() % 4), v = (int)(rnd() % 4);
            p0[fa] = p1[fa] = side;
            /* the quad (u, v)'s diagonal (see tess_cube): (u, v)-(u+1, v+1) or (u, v+1)-(u+1, v) */
            int odd = (u + v) & 1;
            p0[b] = (float)(-1.0 + 0.5 * u);
            p0[e] = (float)(-1.0 + 0.5 * (odd ? v : v + 1));
            p1[b] = p0[b] + 0.5f;
            p1[e] = odd ? p0[e] + 0.5f : p0[e] - 0.5f;
            float s = (float)(unit() * 6 - 3);
            for (int a = 0; a < 3; a++) {
                o[a] = p0[a] + s * (p1[a] - p0[a]);
                tgt[a] = p1[a];
            }
            o[fa] = tgt[fa] = side;
        }
        for (int a = 0; a < 3; a++) d[a] = tgt[a] - o[a];
        cbvh_ray r = make_ray(o, d);
        r.d[fa] = zero_bits();
        if (kind == 3) { /* one ulp off the plane, outside or inside */
            r.o[fa] = fb(nextafterf(side, (rnd() & 1) ? 2.0f * side : 0.0f));
            off_plane++;
        } else if (kind == 0)
            in_plane++;
        else
            along_edge++;
        if (zero_dir(&r)) r.d[(fa + 1) % 3] = fb(1.0f);
        check_ray(&w, &r, 1);
        /* unit level: a ray in the plane of the root box's face, aimed at the face's interior, hits the box */
        if (kind != 3 && (o[0] != tgt[0] || o[1] != tgt[1] || o[2] != tgt[2])) {
            cbvh_box_result br;
            for (int M = 3; M <= 24; M += 7) {
                uint32_t st = cbvh_ray_box_float(&r, M, rlo, rhi, &br);
                root_checks++;
                if (st || !br.hit) {
                    FAIL("grazing_face: box unit M=%d misses the cube box for a ray in its face plane", M);
                    print_ray("", &r);
                }
            }
        }
    }
    printf("grazing_face: %ld rays (in face plane %ld, along edges/diagonals %ld, one ulp off %ld), %ld hits, %ld "
           "traversal comparisons, %ld box-unit face checks, %ld failures\n",
           w.rays, in_plane, along_edge, off_plane, w.hits, w.checks, root_checks, failures);
    if (w.hits < w.rays / 10) FAIL("grazing_face: too few hits (%ld of %ld)", w.hits, w.rays);
    mesh_free(&c);
    world_free(&w);
    return failures != 0;
}

/* >= 1 M rays from inside closed meshes, through the CBVH (N = 6) and the plain
 * floating-point traversal of its float BVH: no leaks. */
static long leak_rays(world *w, const mesh *m, long n, double inner_r, int cube) {
    const cbvh_tree *t = &w->tr[0].t;
    double off[3] = {0, 0, 0};
    long leaks = 0, kinds[4] = {0, 0, 0, 0};
    cbvh_trav_stats st = {0};
    for (long i = 0; i < n; i++) {
        float o[3], tgt[3];
        if (i % 64 == 0)
            o[0] = o[1] = o[2] = 0;
        else
            for (int a = 0; a < 3; a++) o[a] = (float)((unit() * 2 - 1) * inner_r);
        int kind = (int)(i % 4);
        if (kind == 0) { /* a vertex */
            int v = (int)(rnd() % (uint64_t)m->nv);
            for (int a = 0; a < 3; a++) tgt[a] = vtx(m, v, a, 1.0, off);
        } else if (kind <= 2) { /* an edge midpoint (float; exact on the cube grid) */
            int f = (int)(rnd() % (uint64_t)m->nf), e = (int)(rnd() % 3);
            for (int a = 0; a < 3; a++)
                tgt[a] = 0.5f * (vtx(m, m->f[f][e], a, 1.0, off) + vtx(m, m->f[f][(e + 1) % 3], a, 1.0, off));
        } else { /* a random point of a triangle */
            int f = (int)(rnd() % (uint64_t)m->nf);
            double b1 = unit(), b2 = unit();
            if (b1 + b2 > 1) {
                b1 = 1 - b1;
                b2 = 1 - b2;
            }
            for (int a = 0; a < 3; a++)
                tgt[a] = (float)((1 - b1 - b2) * m->v[m->f[f][0]][a] + b1 * m->v[m->f[f][1]][a] + b2 * m->v[m->f[f][2]][a]);
        }
        kinds[kind]++;
        float d[3];
        for (int a = 0; a < 3; a++) d[a] = tgt[a] - o[a];
        cbvh_ray r = make_ray(o, d);
        if (i % 10 == 5) { /* axis-parallel from the same origin */
            int keep = (int)(rnd() % 3);
            for (int a = 0; a < 3; a++)
                if (a != keep) r.d[a] = zero_bits();
        }
        if (zero_dir(&r)) r.d[0] = fb(1.0f);
        cbvh_trav_hit h;
        /* a quarter closest hit (exhaustive), the rest any-hit (hit iff closest hit finds one, §5) */
        if (cbvh_trace_cbvh(t, w->s.tris, &r, 24, (i & 3) ? CBVH_TRAV_ANY : CBVH_TRAV_CLOSEST, &h, &st)) {
            FAIL("closed_mesh_no_leaks: CBVH rejected a valid ray");
            print_ray("", &r);
            leaks++;
            continue;
        }
        w->rays++;
        w->hits += h.hit;
        if (!h.hit) {
            leaks++;
            FAIL("closed_mesh_no_leaks: %s ray %ld leaked (target kind %d)", cube ? "cube" : "sphere", i, kind);
            print_ray("", &r);
        }
        /* the plain floating-point traversal has its own box test: no leak either */
        cbvh_trav_hit hp;
        cbvh_trav_stats sp = {0};
        if (cbvh_trace_bvh_float(&w->fb[0], w->s.tris, &r, (i & 3) ? CBVH_TRAV_ANY : CBVH_TRAV_CLOSEST, &hp, &sp) ||
            !hp.hit) {
            leaks++;
            FAIL("closed_mesh_no_leaks: %s ray %ld leaked through the plain float traversal", cube ? "cube" : "sphere",
                 i);
            print_ray("", &r);
        }
        for (int W = 0; W < 2; W++)
            if (aw_trace(&w->aw[W][0], w->s.tris, &r, (i & 3) ? CBVH_TRAV_ANY : CBVH_TRAV_CLOSEST, &hp, &sp) ||
                !hp.hit) {
                leaks++;
                FAIL("closed_mesh_no_leaks: %s ray %ld leaked through the %s plain float traversal",
                     cube ? "cube" : "sphere", i, wide_name[W]);
                print_ray("", &r);
            }
        if (i % 997 == 0) check_ray(w, &r, i % (997 * 8) == 0); /* all structures; brute force on a subset */
    }
    return leaks;
}

static int case_closed_mesh_no_leaks(void) {
    const long total = 1000000 / SCALE_DOWN;
    static const tcfg cfg[] = {{6, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_MODULO, 0, 24},
                               {6, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_RELATIVE, 1, 24}};
    long leaks = 0, rays = 0, hits = 0, checks = 0;
    for (int which = 0; which < 2; which++) {
        world w = {0};
        mesh m = which ? tess_cube(4) : icosphere(2);
        double off[3] = {0, 0, 0};
        add_mesh(&w.s, &m, 1.0, off);
        if (world_build(&w, cfg, 2, 1)) return 1;
        /* icosphere(2): inradius > 0.93, so |o| <= 0.5 * sqrt(3) is inside; cube: [-0.9, 0.9]^3 */
        leaks += leak_rays(&w, &m, total / 2, which ? 0.9 : 0.5, which);
        rays += w.rays;
        hits += w.hits;
        checks += w.checks;
        printf("closed_mesh_no_leaks: %s (%u triangles): %ld rays, %ld hits\n", which ? "cube 4x4/face" : "icosphere 2",
               w.s.ntris, w.rays, w.hits);
        mesh_free(&m);
        world_free(&w);
    }
    printf("closed_mesh_no_leaks: %ld rays from inside (25%% at vertices, 50%% at edge midpoints, 10%% axis-parallel) "
           "through the CBVH N=6 and the plain float traversal, %ld leaks, %ld cross-checks against the float "
           "BVHs/brute force, %ld failures\n",
           rays, leaks, checks, failures);
    if (rays < total) FAIL("closed_mesh_no_leaks: only %ld rays traced", rays);
    (void)hits;
    return failures != 0;
}

/* The same small mesh translated far from the origin. */
static int case_far_from_origin(void) {
    struct {
        double off[3], scale;
    } pl[] = {{{1e6, -2e6, 3e6}, 1.0},
              {{1e6, -2e6, 3e6}, 100.0},
              {{1099511627776.0, 1099511627776.0, 1099511627776.0}, 1.0},
              {{1099511627776.0, -1099511627776.0, 1099511627776.0}, 1073741824.0}};
    mesh s = icosphere(1), c = tess_cube(2);
    const int nrays = 1500 / SCALE_DOWN;
    long rays = 0, hits = 0;
    for (size_t p = 0; p < sizeof pl / sizeof pl[0]; p++) {
        world w = {0};
        double o2[3] = {pl[p].off[0] + 2.5 * pl[p].scale, pl[p].off[1], pl[p].off[2]};
        add_mesh(&w.s, &c, pl[p].scale, pl[p].off);
        add_mesh(&w.s, &s, 0.75 * pl[p].scale, o2);
        if (world_build(&w, default_cfgs, NDEFAULT, 1)) return 1;
        float lo[3], hi[3];
        cbvh_scene_bounds(&w.s, lo, hi);
        for (int i = 0; i < nrays; i++) {
            float o[3], d[3];
            for (int a = 0; a < 3; a++) {
                double ext = (double)hi[a] - lo[a];
                if (ext <= 0) ext = 1;
                double t = lo[a] + unit() * ext;
                double oo = (i % 3 == 0) ? lo[a] + unit() * ext : 0.5 * ((double)lo[a] + hi[a]) + (unit() * 4 - 2) * ext;
                o[a] = (float)oo;
                d[a] = (float)(t - o[a]);
            }
            if (i % 4 == 1) { /* aim at a vertex */
                const float *v = w.s.tris[rnd() % w.s.ntris].v[rnd() % 3];
                for (int a = 0; a < 3; a++) d[a] = (float)((double)v[a] - o[a]);
            }
            cbvh_ray r = make_ray(o, d);
            if (i % 7 == 0)
                for (int a = 0; a < 3; a++)
                    if (a != i % 3) r.d[a] = zero_bits();
            if (zero_dir(&r)) r.d[0] = fb(1.0f);
            check_ray(&w, &r, 1);
        }
        printf("far_from_origin: offset (%.6g, %.6g, %.6g) mesh scale %g: %u triangles, %ld rays, %ld hits, %ld "
               "traversal comparisons\n",
               pl[p].off[0], pl[p].off[1], pl[p].off[2], pl[p].scale, w.s.ntris, w.rays, w.hits, w.checks);
        /* at 2^40 the unscaled mesh collapses (ulp 2^17 >> 1): only brute-force equality is expected */
        if (!(p == 2) && w.hits < w.rays / 20) FAIL("far_from_origin: too few hits (%ld of %ld)", w.hits, w.rays);
        rays += w.rays;
        hits += w.hits;
        world_free(&w);
    }
    printf("far_from_origin: %ld rays, %ld hits, all equal to brute force; %ld failures\n", rays, hits, failures);
    mesh_free(&s);
    mesh_free(&c);
    return failures != 0;
}

/* A finely tessellated plane at z = -0.4 hit edge-on (d_z = 0, o_z = -0.4
 * exactly: no triangle may report a hit, the unit's det is 0) and nearly
 * edge-on (tiny d_z, origins a few ulps off the plane). */
static int case_cloth_edge_on(void) {
    world w = {0};
    mesh m = plane_grid(24);
    const float zc = -0.4f;
    double off[3] = {0, 0, zc};
    add_mesh(&w.s, &m, 1.0, off);
    snprintf(w.s.name, sizeof w.s.name, "cloth24");
    if (world_build(&w, default_cfgs, NDEFAULT, 0)) return 1;
    boxes bs = {0};
    collect_all(&w, &bs);
    const int nrays = 6000 / SCALE_DOWN;
    long edge_on = 0, edge_on_hits = 0, near = 0, near_hits = 0, box_checks = 0;
    static const float tiny[] = {1e-7f, 1e-20f, 1e-38f, 1e-45f, 3e-4f};
    for (int i = 0; i < nrays; i++) {
        float o[3], d[3], tgt[3];
        for (int a = 0; a < 2; a++) {
            o[a] = (float)(unit() * 6 - 3);
            tgt[a] = (i % 5 == 0) ? (float)(-1.0 + (double)(rnd() % 33) / 16) : (float)(unit() * 2.2 - 1.1);
            d[a] = tgt[a] - o[a];
        }
        o[2] = zc;
        d[2] = 0;
        cbvh_ray r = make_ray(o, d);
        int kind = i % 3;
        if (kind == 0) { /* edge-on */
            r.d[2] = zero_bits();
            if (zero_dir(&r)) r.d[0] = fb(1.0f);
            cbvh_trav_hit h = check_ray(&w, &r, 1);
            edge_on++;
            edge_on_hits += h.hit;
            /* unit level: every box containing the plane is hit when the ray crosses its x-y extent
               (checked on the float root box, whose z extent is exactly [zc, zc]) */
            for (int k = 0; k < bs.n; k++) {
                const box *x = &bs.b[k];
                if (x->grid || x->lo[2] != zc || x->hi[2] != zc) continue;
                if (!(o[0] >= x->lo[0] && o[0] <= x->hi[0] && o[1] >= x->lo[1] && o[1] <= x->hi[1])) continue;
                cbvh_box_result br;
                box_checks++;
                if (unit_box(x, &r, 24, &br) || !br.hit || br.t_near != 0) {
                    FAIL("cloth_edge_on: box unit misses a zero-thickness box for an edge-on origin inside it");
                    print_ray("", &r);
                }
            }
        } else { /* nearly edge-on: tiny d_z and/or origin a few ulps off the plane */
            float dz = tiny[rnd() % 5];
            float oz = zc;
            int ulps = (int)(rnd() % 4);
            for (int u = 0; u < ulps; u++) oz = nextafterf(oz, (rnd() & 1) ? 1.0f : -1.0f);
            r.o[2] = fb(oz);
            r.d[2] = fb(kind == 1 ? (oz > zc ? -dz : dz) : ((rnd() & 1) ? dz : -dz));
            if (kind == 2 && (rnd() & 1)) r.d[2] = zero_bits(); /* parallel, off the plane */
            if (zero_dir(&r)) r.d[0] = fb(1.0f);
            cbvh_trav_hit h = check_ray(&w, &r, 1);
            near++;
            near_hits += h.hit;
        }
    }
    if (edge_on_hits) FAIL("cloth_edge_on: %ld edge-on rays hit a triangle of the plane they lie in", edge_on_hits);
    if (near_hits == 0) FAIL("cloth_edge_on: no nearly-edge-on ray hit the cloth");
    printf("cloth_edge_on: %u triangles at z = -0.4; %ld edge-on rays (0 hits expected: %ld), %ld nearly edge-on "
           "rays (%ld hits), %ld traversal comparisons, %ld box-unit checks, %ld failures\n",
           w.s.ntris, edge_on, edge_on_hits, near, near_hits, w.checks, box_checks, failures);
    free(bs.b);
    mesh_free(&m);
    world_free(&w);
    return failures != 0;
}

/* N = 3 and N = 10, min_scale -30 and -126, both encodings and compressors:
 * the same hits as the float BVH. */
static int case_extremes_n3_n10(void) {
    world w = {0};
    mesh m = icosphere(3);
    double off[3] = {0.3, -0.2, 0.1};
    add_mesh(&w.s, &m, 1.0, off);
    /* a second, small and far-off sphere stretches the scales */
    double off2[3] = {40.0, 3.0, -7.0};
    add_mesh(&w.s, &m, 0.01, off2);
    snprintf(w.s.name, sizeof w.s.name, "spheres");
    static const tcfg cfg[] = {{3, -30, CBVH_ENC_MODULO, 0, 24},   {3, -126, CBVH_ENC_RELATIVE, 1, 24},
                               {3, -126, CBVH_ENC_MODULO, 1, 3},   {10, -30, CBVH_ENC_RELATIVE, 0, 24},
                               {10, -126, CBVH_ENC_MODULO, 1, 24}, {10, -126, CBVH_ENC_MODULO, 0, 3}};
    if (world_build(&w, cfg, 6, 1)) return 1;
    float lo[3], hi[3];
    cbvh_scene_bounds(&w.s, lo, hi);
    const int nrays = 3000 / SCALE_DOWN;
    for (int i = 0; i < nrays; i++) {
        float o[3], d[3];
        int small = i % 4 == 3;
        for (int a = 0; a < 3; a++) {
            double c = small ? off2[a] : off[a], ext = small ? 0.02 : 2.0;
            double t = c + (unit() - 0.5) * ext;
            o[a] = (float)((i % 3 == 0) ? c + (unit() - 0.5) * ext * 0.4 : c + (unit() * 4 - 2) * ext);
            d[a] = (float)(t - o[a]);
        }
        cbvh_ray r = make_ray(o, d);
        if (i % 11 == 0) r.d[i % 3] = zero_bits();
        if (zero_dir(&r)) r.d[0] = fb(1.0f);
        check_ray(&w, &r, i % 4 == 0);
    }
    printf("extremes_n3_n10: %u triangles, %ld rays, %ld hits, %ld traversal comparisons over %d CBVHs "
           "(N=3/10, min_scale -30/-126, M=24/3) and %d float BVHs; %ld failures\n",
           w.s.ntris, w.rays, w.hits, w.checks, w.nt, w.nb, failures);
    if (w.hits < w.rays / 10) FAIL("extremes_n3_n10: too few hits (%ld of %ld)", w.hits, w.rays);
    mesh_free(&m);
    world_free(&w);
    return failures != 0;
}

/* NaN / Inf rays and the zero direction: rejected with status bits, zero
 * outputs, trace returns -1 with no hit and no unit activity. */
static int case_nan_inf_rays(void) {
    world w = {0};
    scene_sphere_cube(&w, 1, 2);
    if (world_build(&w, default_cfgs, 2, 0)) return 1;
    static const cbvh_f32 bad[] = {0x7FC00000u, 0xFFC00000u, 0x7F800001u, 0x7FFFFFFFu, CBVH_F32_POS_INF,
                                   CBVH_F32_NEG_INF};
    const int nbad = (int)(sizeof bad / sizeof bad[0]);
    long rejected = 0, cases = 0, unit_checks = 0;
    cbvh_f32 lo[3] = {fb(-1), fb(-1), fb(-1)}, hi[3] = {fb(1), fb(1), fb(1)};
    cbvh_f32 v[3][3];
    memcpy(v, w.s.tris[0].v, sizeof v);
    for (int field = 0; field < 10; field++) { /* o0..2, d0..2, tmin, tmax, zero dir (2 variants) */
        for (int k = 0; k < (field >= 8 ? 8 : nbad); k++) {
            cbvh_ray r = make_ray((const float[3]){0.125f, 0.25f, -3.0f}, (const float[3]){0.0f, 0.0f, 1.0f});
            uint32_t want = CBVH_ST_NAN_INF;
            if (field < 3)
                r.o[field] = bad[k];
            else if (field < 6)
                r.d[field - 3] = bad[k];
            else if (field == 6)
                r.tmin = bad[k];
            else if (field == 7) {
                if (bad[k] == CBVH_F32_POS_INF) continue; /* +Inf tmax is a valid unbounded ray */
                r.tmax = bad[k];
            } else { /* d = (+-0, +-0, +-0); field 9 also from inside the mesh */
                for (int a = 0; a < 3; a++) r.d[a] = (k >> a & 1) ? CBVH_F32_SIGN : 0;
                if (field == 9) r.o[0] = r.o[1] = r.o[2] = 0;
                want = CBVH_ST_ZERO_DIR;
            }
            cases++;
            /* units */
            cbvh_box_result br;
            memset(&br, 0xAB, sizeof br);
            uint32_t st = cbvh_ray_box_float(&r, 24, lo, hi, &br);
            unit_checks++;
            if (!(st & want) || br.hit || br.t_near || br.t_far) {
                FAIL("nan_inf_rays: box unit status %02X (want bit %02X) hit %d t %08X %08X", st, want, br.hit,
                     br.t_near, br.t_far);
                print_ray("", &r);
            }
            if (field != 6 && field != 7) { /* tmin/tmax are not triangle-unit inputs */
                cbvh_tri_result tr;
                memset(&tr, 0xAB, sizeof tr);
                st = cbvh_ray_triangle(&r, v[0], v[1], v[2], &tr);
                unit_checks++;
                if (!(st & want) || tr.hit || tr.t || tr.b1 || tr.b2) {
                    FAIL("nan_inf_rays: triangle unit status %02X (want bit %02X) hit %d", st, want, tr.hit);
                    print_ray("", &r);
                }
            }
            /* traversals */
            int all_rejected = 1;
            for (int mode = 0; mode < 2; mode++) {
                cbvh_trav_hit h;
                cbvh_trav_stats ts = {0};
                memset(&h, 0xAB, sizeof h);
                int rc = cbvh_trace_bvh(&w.b[0], w.s.tris, &r, 24, (cbvh_trav_mode)mode, &h, &ts);
                if (rc != -1 || h.hit || h.prim || h.t || ts.box_tests || ts.tri_tests || ts.nodes || ts.bytes) {
                    all_rejected = 0;
                    FAIL("nan_inf_rays: float BVH (mode %d) rc %d hit %d box %llu tri %llu", mode, rc, h.hit,
                         (unsigned long long)ts.box_tests, (unsigned long long)ts.tri_tests);
                    print_ray("", &r);
                }
                memset(&h, 0xAB, sizeof h);
                rc = cbvh_trace_bvh_float(&w.fb[0], w.s.tris, &r, (cbvh_trav_mode)mode, &h, &ts);
                if (rc != -1 || h.hit || h.prim || h.t || ts.box_tests || ts.tri_tests || ts.nodes || ts.bytes) {
                    all_rejected = 0;
                    FAIL("nan_inf_rays: plain float BVH (mode %d) rc %d hit %d", mode, rc, h.hit);
                    print_ray("", &r);
                }
                for (int W = 0; W < 2; W++) {
                    memset(&h, 0xAB, sizeof h);
                    rc = aw_trace(&w.aw[W][0], w.s.tris, &r, (cbvh_trav_mode)mode, &h, &ts);
                    if (rc != -1 || h.hit || h.prim || h.t || ts.box_tests || ts.tri_tests || ts.nodes || ts.bytes) {
                        all_rejected = 0;
                        FAIL("nan_inf_rays: %s plain float (mode %d) rc %d hit %d", wide_name[W], mode, rc, h.hit);
                        print_ray("", &r);
                    }
                }
                for (int t = 0; t < w.nt; t++) {
                    memset(&h, 0xAB, sizeof h);
                    memset(&ts, 0, sizeof ts);
                    rc = cbvh_trace_cbvh(&w.tr[t].t, w.s.tris, &r, w.tr[t].M, (cbvh_trav_mode)mode, &h, &ts);
                    if (rc != -1 || h.hit || h.prim || h.t || ts.box_tests || ts.tri_tests || ts.nodes || ts.bytes) {
                        all_rejected = 0;
                        FAIL("nan_inf_rays: CBVH %s (mode %d) rc %d hit %d box %llu tri %llu", w.tr[t].name, mode, rc,
                             h.hit, (unsigned long long)ts.box_tests, (unsigned long long)ts.tri_tests);
                        print_ray("", &r);
                    }
                }
            }
            rejected += all_rejected;
        }
    }
    /* control: the same base ray is valid and hits (so rejects are not a blanket failure) */
    cbvh_ray ok = make_ray((const float[3]){0.125f, 0.25f, -3.0f}, (const float[3]){0.0f, 0.0f, 1.0f});
    cbvh_trav_hit h = check_ray(&w, &ok, 1);
    if (!h.hit) FAIL("nan_inf_rays: control ray missed");
    printf("nan_inf_rays: %ld bad rays (NaN/sNaN/-NaN/+-Inf in each of o, d, tmin, tmax; 16 zero directions) "
           "rejected by both units and by %d traversals x 2 modes: %ld of %ld; %ld unit checks; control ray hits; "
           "%ld failures\n",
           cases, w.nt + 1, rejected, cases, unit_checks, failures);
    if (rejected != cases) FAIL("nan_inf_rays: %ld of %ld bad rays not rejected everywhere", cases - rejected, cases);
    world_free(&w);
    return failures != 0;
}

static const struct {
    const char *name;
    int (*fn)(void);
} cases[] = {
    {"axis_parallel", case_axis_parallel},
    {"ray_on_box_face", case_ray_on_box_face},
    {"ray_inside_box", case_ray_inside_box},
    {"grazing_face", case_grazing_face},
    {"closed_mesh_no_leaks", case_closed_mesh_no_leaks},
    {"far_from_origin", case_far_from_origin},
    {"cloth_edge_on", case_cloth_edge_on},
    {"extremes_n3_n10", case_extremes_n3_n10},
    {"nan_inf_rays", case_nan_inf_rays},
};

int main(int argc, char **argv) {
    const int n = (int)(sizeof cases / sizeof cases[0]);
    if (argc != 2) {
        fprintf(stderr, "usage: %s CASE\ncases:", argv[0]);
        for (int i = 0; i < n; i++) fprintf(stderr, " %s", cases[i].name);
        fprintf(stderr, "\n");
        return 2;
    }
    for (int i = 0; i < n; i++)
        if (strcmp(argv[1], cases[i].name) == 0) {
            int rc = cases[i].fn();
            if (rc || failures) {
                fprintf(stderr, "%s: FAILED (%ld failures)\n", cases[i].name, failures);
                return 1;
            }
            return 0;
        }
    fprintf(stderr, "error: unknown case '%s'\n", argv[1]);
    return 2;
}
