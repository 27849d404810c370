/* The traversals' fast paths are invisible (docs/traversal.md §9): this
 * program is built twice from the model's sources, once as the kit runs and
 * once with -DCBVH_NO_FAST_PATHS (the ray-box unit's integer fast path and
 * its binary64 filter, the triangle unit's filter, the ray-sphere unit's
 * fast decision and the CBVH's fast pair decode all off: the units' exact
 * paths decide everything).  Each run prints a digest of every traversal's
 * every output, counters included (rc, hit, prim, t, b1, b2, nodes, box and
 * triangle tests, lines, bytes, stack depth), and the ctest
 * traversal_fast_invisible fails unless the two digests are equal.
 *
 * The fast paths decide unless a binary64 estimate lies within a few ulps of
 * a rounding boundary; random rays almost never get there.  So besides random
 * rays, half the rays pass exactly through a triangle vertex at t = k (k = 1,
 * 2, 3) with direction components such as 49 2^j, for which the binary64
 * estimate (P - o) RN(1/d) is one ulp below k: every box plane through that
 * vertex gives an undecided estimate on the wrong side of the M-bit grid
 * point, and the triangle's edge functions are exactly 0 there.
 *   scenes  a closed lattice (a cube's surface, coordinates in 1/8), a random
 *           soup, a cloth plane (degenerate z), the soup far from the origin;
 *   trees   LBVH and SAH float BVHs (box unit M = 24, 8, 3); top-down CBVHs
 *           at N = 3, 6, 10 modulo and N = 6 relative, a bottom-up N = 6;
 *           the QBVH (compressed stack); traversal lists (2 lists); each
 *           CBVH also decoded once (docs/traversal.md §12: with the fast
 *           paths off the decoded copy is not usable and its traversal is the
 *           per-visit one, so the digest compares it with the exact paths);
 *   modes   closest and any hit.
 * usage: test_fast_invisible [--digest-out FILE] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/cbvh_tree.h"
#include "cbvh/qbvh.h"
#include "cbvh/tlist.h"
#include "cbvh/traverse.h"
#include "fast/fast_paths.h"
#include "test_util.h"

#ifdef CBVH_SANITIZE
#define RAYS 150
#else
#define RAYS 4000
#endif

static uint64_t rs = 0x2545F4914F6CDD1Du;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static float rndf(void) { return (float)(rnd() & 0xFFFFFF) / 16777216.0f; }

static digest dgst;
static uint64_t traversals, hits, vertex_rays;
static void dg(uint64_t v) { digest_u64(&dgst, v); }

static void record(int rc, const cbvh_trav_hit *h, const cbvh_trav_stats *st) {
    traversals++;
    hits += rc == 0 && h->hit;
    dg((uint64_t)(int64_t)rc);
    dg(h->hit);
    dg(h->prim);
    dg(h->t);
    dg(h->b1);
    dg(h->b2);
    dg(st->nodes);
    dg(st->box_tests);
    dg(st->tri_tests);
    dg(st->lines);
    dg(st->bytes);
    dg(st->max_stack);
}

enum { LATTICE, SOUP, CLOTH, FAR, SCENES };
static const char *const scene_name[SCENES] = {"lattice", "soup", "cloth", "far soup"};

static void add_tri(cbvh_scene *s, const float a[3], const float b[3], const float c[3]) {
    cbvh_tri *t = &s->tris[s->ntris++];
    memcpy(t->v[0], a, sizeof t->v[0]);
    memcpy(t->v[1], b, sizeof t->v[1]);
    memcpy(t->v[2], c, sizeof t->v[2]);
}

static void make_scene(cbvh_scene *s, int k) {
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", scene_name[k]);
    s->tris = calloc(1024, sizeof *s->tris);
    if (k == LATTICE) { /* the surface of [-1, 1]^3, 6 faces x 8 x 8 quads */
        for (int f = 0; f < 6; f++)
            for (int i = 0; i < 8; i++)
                for (int j = 0; j < 8; j++) {
                    float q[4][3];
                    for (int c = 0; c < 4; c++) {
                        float u = (float)(i + (c & 1)) / 4.0f - 1.0f, v = (float)(j + (c >> 1)) / 4.0f - 1.0f;
                        int ax = f % 3;
                        q[c][ax] = f < 3 ? -1.0f : 1.0f;
                        q[c][(ax + 1) % 3] = u;
                        q[c][(ax + 2) % 3] = v;
                    }
                    add_tri(s, q[0], q[1], q[2]);
                    add_tri(s, q[1], q[3], q[2]);
                }
    } else if (k == CLOTH) { /* z = -0.4 on a 16 x 16 grid of [-1, 1]^2 */
        for (int i = 0; i < 16; i++)
            for (int j = 0; j < 16; j++) {
                float q[4][3];
                for (int c = 0; c < 4; c++) {
                    q[c][0] = (float)(i + (c & 1)) / 8.0f - 1.0f;
                    q[c][1] = (float)(j + (c >> 1)) / 8.0f - 1.0f;
                    q[c][2] = -0.4f;
                }
                add_tri(s, q[0], q[1], q[2]);
                add_tri(s, q[1], q[3], q[2]);
            }
    } else { /* 300 small random triangles in [-1, 1]^3, or at 1e5 */
        float off = k == FAR ? 1e5f : 0.0f;
        for (int i = 0; i < 300; i++) {
            float c[3], v[3][3];
            for (int a = 0; a < 3; a++) c[a] = 2.0f * rndf() - 1.0f;
            for (int w = 0; w < 3; w++)
                for (int a = 0; a < 3; a++) v[w][a] = off + c[a] + 0.2f * (rndf() - 0.5f);
            add_tri(s, v[0], v[1], v[2]);
        }
    }
}

/* A random ray from outside toward a random point of a random triangle. */
static cbvh_ray random_ray(const cbvh_scene *s, const float lo[3], const float hi[3]) {
    const cbvh_tri *t = &s->tris[rnd() % s->ntris];
    float w0 = rndf(), w1 = rndf() * (1 - w0), w2 = 1 - w0 - w1;
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        float ext = hi[a] - lo[a] + 1.0f;
        float o = lo[a] - ext + 3.0f * ext * rndf();
        float p = w0 * t->v[0][a] + w1 * t->v[1][a] + w2 * t->v[2][a];
        r.o[a] = fb(o);
        r.d[a] = fb(p - o == 0 ? 1.0f : p - o);
    }
    r.tmin = 0;
    r.tmax = rnd() % 4 ? CBVH_F32_POS_INF : fb(1.5f);
    return r;
}

/* A ray through vertex P at t = k exactly: o = P - k d with d_a = D 2^j,
 * D among integers with D RN(1/D) != 1 in binary64, 2^j a multiple of P_a's
 * ulp so that o is exact in binary32.  0 if no such o was found. */
static int vertex_ray(const cbvh_scene *s, cbvh_ray *r) {
    static const int D[6] = {49, 98, 103, 107, 161, 187};
    const cbvh_tri *t = &s->tris[rnd() % s->ntris];
    const float *P = t->v[rnd() % 3];
    int k = 1 + (int)(rnd() % 3);
    for (int a = 0; a < 3; a++) {
        int dd = D[rnd() % 6];
        int e;
        frexpf(P[a], &e);
        int j = P[a] == 0 ? -8 : e - 24 + (int)(rnd() % 8); /* 2^j >= ulp(P_a) */
        double d = ldexp((double)dd, j) * (rnd() & 1 ? -1.0 : 1.0), o = (double)P[a] - k * d;
        if ((double)(float)o != o || (float)d != d) return 0;
        r->o[a] = fb((float)o);
        r->d[a] = fb((float)d);
    }
    r->tmin = 0;
    r->tmax = rnd() % 4 ? CBVH_F32_POS_INF : fb((float)k);
    return 1;
}

static void run_scene(int k) {
    char err[256];
    cbvh_scene s;
    make_scene(&s, k);
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    cbvh_bvh b[2];
    for (int i = 0; i < 2; i++)
        if (i ? cbvh_build_sah(&s, 16, 4, &b[i], err, sizeof err) : cbvh_build_lbvh(&s, &b[i], err, sizeof err)) {
            fprintf(stderr, "FAIL %s: build: %s\n", scene_name[k], err);
            exit(1);
        }
    enum { NT = 5 };
    static const int tn[NT] = {3, 6, 10, 6, 6};
    cbvh_tree t[NT];
    cbvh_cbvh_decoded dt[NT];
    for (int j = 0; j < NT; j++) {
        cbvh_compress_opts o = {{tn[j], -30}, j == 3 ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO, 2, 0};
        int rc;
        if (j < 4) {
            rc = cbvh_compress_topdown(&b[1], &o, &t[j], err, sizeof err);
        } else {
            cbvh_bvh c = b[0];
            c.nodes = malloc(b[0].nnodes * sizeof *b[0].nodes);
            memcpy(c.nodes, b[0].nodes, b[0].nnodes * sizeof *b[0].nodes);
            cbvh_bu_stats bs;
            rc = cbvh_compress_bottomup(&c, NULL, &o, &t[j], &bs, err, sizeof err);
            free(c.nodes);
        }
        if (rc) {
            fprintf(stderr, "FAIL %s: CBVH %d: %s\n", scene_name[k], j, err);
            exit(1);
        }
        for (size_t i = 0; i < (size_t)t[j].npairs * t[j].pair_bytes; i++) dg(t[j].pairs[i]); /* the trees too */
        if (cbvh_cbvh_decode(&t[j], &dt[j], err, sizeof err) || dt[j].usable != CBVH_FAST_PATHS ||
            cbvh_cbvh_decode_leaves(&dt[j], s.tris, s.ntris, err, sizeof err) ||
            (dt[j].leaf_tris != NULL) != CBVH_FAST_PATHS) {
            fprintf(stderr, "FAIL %s: decoded CBVH %d: usable %d (%s)\n", scene_name[k], j, dt[j].usable, err);
            exit(1);
        }
    }
    cbvh_qbvh q;
    cbvh_bsh_params bp;
    cbvh_bsh_default_params(&bp);
    cbvh_bsh h;
    cbvh_tlists L;
    cbvh_tlist_params lp = {2, CBVH_TLIST_EARLIEST_FIRST, 0};
    if (cbvh_qbvh_from_bvh(&b[1], &q, err, sizeof err) || cbvh_bsh_build(&s, &bp, &h, err, sizeof err) ||
        cbvh_tlists_build(&h, &s, &lp, &L, err, sizeof err)) {
        fprintf(stderr, "FAIL %s: QBVH or lists: %s\n", scene_name[k], err);
        exit(1);
    }
    static const int mant[3] = {24, 8, 3};
    for (int i = 0; i < RAYS; i++) {
        cbvh_ray r;
        if (!(i & 1) || !vertex_ray(&s, &r)) r = random_ray(&s, lo, hi);
        else vertex_rays++;
        for (int mode = 0; mode < 2; mode++) {
            cbvh_trav_mode md = (cbvh_trav_mode)mode;
            cbvh_trav_hit hit;
            for (int m = 0; m < 3; m++)
                for (int bi = 0; bi < 2; bi++) {
                    cbvh_trav_stats st = {0};
                    record(cbvh_trace_bvh(&b[bi], s.tris, &r, mant[m], md, &hit, &st), &hit, &st);
                }
            for (int j = 0; j < NT; j++) {
                cbvh_trav_stats st = {0};
                record(cbvh_trace_cbvh(&t[j], s.tris, &r, mant[(i + j) % 3], md, &hit, &st), &hit, &st);
                memset(&st, 0, sizeof st);
                record(cbvh_trace_cbvh_decoded(&dt[j], s.tris, &r, mant[(i + j + 1) % 3], md, &hit, &st), &hit, &st);
            }
            cbvh_trav_stats st = {0};
            record(cbvh_trace_qbvh(&q, s.tris, &r, mant[i % 3], md, CBVH_QSTACK_COMPRESSED, &hit, &st), &hit, &st);
            memset(&st, 0, sizeof st);
            record(cbvh_trace_tlist(&L, cbvh_tlist_pick(&L, &r), 0, s.tris, &r, md, &hit, &st), &hit, &st);
        }
    }
    cbvh_tlists_free(&L);
    cbvh_bsh_free(&h);
    cbvh_qbvh_free(&q);
    for (int j = 0; j < NT; j++) {
        cbvh_cbvh_decoded_free(&dt[j]);
        cbvh_tree_free(&t[j]);
    }
    cbvh_bvh_free(&b[0]);
    cbvh_bvh_free(&b[1]);
    cbvh_scene_free(&s);
}

int main(int argc, char **argv) {
    const char *out = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--digest-out") && i + 1 < argc) out = argv[++i];
        else {
            fprintf(stderr, "usage: %s [--digest-out FILE]\n", argv[0]);
            return 2;
        }
    }
    digest_init(&dgst);
    for (int k = 0; k < SCENES; k++) run_scene(k);
#ifdef CBVH_NO_FAST_PATHS
    const char *build = "exact paths only";
#else
    const char *build = "fast paths on";
#endif
    printf("%s: %llu traversals (%llu with a hit), %llu rays through a vertex at t = k; digest %016llx\n", build,
           (unsigned long long)traversals, (unsigned long long)hits, (unsigned long long)vertex_rays,
           (unsigned long long)dgst.h);
    if (vertex_rays < RAYS || hits < traversals / 4) {
        fprintf(stderr, "FAIL too few vertex rays (%llu) or hits (%llu): the comparison would be vacuous\n",
                (unsigned long long)vertex_rays, (unsigned long long)hits);
        return 1;
    }
    if (out) {
        FILE *f = fopen(out, "w");
        if (!f || fprintf(f, "%016llx\n", (unsigned long long)dgst.h) < 0 || fclose(f)) {
            fprintf(stderr, "cannot write %s\n", out);
            return 1;
        }
    }
    return 0;
}
