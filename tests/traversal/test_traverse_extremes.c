/* Every traversal against brute force on random soups at the extremes of
 * binary32 (docs/traversal.md §5: the closest hit is the smallest (t, id)
 * over all triangles the unit hits, whatever the tree; any hit iff one exists):
 *   soups  coordinates to +-FLT_MAX; subnormal to tiny normal; mixed 1e+-30;
 *          flat and far (z = 1e5, x, y within 1e5 +- 5); a degenerate axis
 *          (the cloth's plane); coarse coordinates with shared vertices;
 *   trees  LBVH and binned SAH; top-down and bottom-up CBVHs at N = 3, 6, 10,
 *          both encodings, random min scale (-126, -30, -10, 0) and treelet
 *          depth, bottom-up half of the time with naive re-encoding; the QBVH
 *          with each stack kind;
 *   rays   toward a point on a triangle, random directions, one or two
 *          direction components +0/-0, bounded and unbounded tmax; closest
 *          and any hit; box unit M = 24, 8 and 3.
 * The traversals compared: float BVH through the units, the plain float
 * traversal and its 4-wide variant over the QBVH (half with the leaf copy),
 * the CBVH (each tree), the QBVH (each stack kind), the
 * stackless traversal lists (1, 2, 6 and 8 lists; seed 004); and the CBVH
 * decoded once (docs/traversal.md §12) against the CBVH's per-visit
 * traversal: return value, hit and every counter.  Here planes are often not
 * exact in binary64 (the box unit then decides every box of the pair). */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "cbvh/cbvh_tree.h"
#include "cbvh/qbvh.h"
#include "cbvh/tlist.h"
#include "test_trav_util.h"

#ifdef CBVH_SANITIZE
#define SOUPS 24
#define RAYS 60
#else
#define SOUPS 150
#define RAYS 200
#endif

static long fails, decoded_trees, decoded_traces, decoded_pairs, decoded_inexact, decoded_wide;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

static uint32_t rng = 0x9E3779B9u;
static uint32_t rnd(void) { return tu_xorshift32(&rng); }
static float rndf(void) { return (float)(rnd() & 0xFFFFFF) / 16777216.0f; }

enum { HUGE_, TINY, MIXED, FLAT_FAR, DEGENERATE_AXIS, COARSE, KINDS };
static const char *const kind_name[KINDS] = {"+-FLT_MAX", "subnormal", "mixed 1e+-30", "flat and far",
                                             "degenerate axis", "coarse, shared vertices"};

static void soup(cbvh_scene *s, int k) {
    uint32_t n = 1 + rnd() % 120;
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", kind_name[k]);
    s->tris = calloc(n, sizeof *s->tris);
    s->ntris = n;
    for (uint32_t i = 0; i < n; i++) {
        float c[3];
        for (int a = 0; a < 3; a++) c[a] = rndf() - 0.5f;
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) {
                float x = c[a] + 0.1f * (rndf() - 0.5f);
                switch (k) {
                case HUGE_: x = 2.0f * x * 3.0e38f; break;
                case TINY: x *= 1e-38f * (float)(1u << (rnd() % 8)); break;
                case MIXED: x *= (i & 1) ? 1e30f : 1e-30f; break;
                case FLAT_FAR: x = a == 2 ? 1e5f : 1e5f + 10.0f * x; break;
                case DEGENERATE_AXIS: x = a == 1 ? 0.25f : x; break;
                default: x = (float)(rnd() % 3) + (v ? 0.5f * (float)(rnd() % 2) : 0.0f); break;
                }
                s->tris[i].v[v][a] = x;
            }
    }
    if (k == HUGE_) {
        s->tris[0].v[0][0] = -FLT_MAX;
        s->tris[0].v[1][1] = FLT_MAX;
    }
}

/* Origins in the scene box grown by half its largest extent (so flat scenes
 * get rays from off their plane), clamped to the finite range. */
static void ray_box(const cbvh_scene *s, float lo[3], float hi[3]) {
    cbvh_scene_bounds(s, lo, hi);
    float ext = 0;
    for (int a = 0; a < 3; a++)
        if (hi[a] - lo[a] > ext) ext = hi[a] - lo[a];
    for (int a = 0; a < 3; a++) {
        float g = 0.5f * ext + 1e-3f * fabsf(0.5f * lo[a] + 0.5f * hi[a]);
        if (!isfinite(g)) g = 1e37f;
        lo[a] -= g;
        hi[a] += g;
        if (!isfinite(lo[a])) lo[a] = -FLT_MAX;
        if (!isfinite(hi[a])) hi[a] = FLT_MAX;
    }
}

static cbvh_ray make_ray(const cbvh_scene *s, const float lo[3], const float hi[3]) {
    float o[3], d[3];
    int kind = (int)(rnd() % 4);
    for (int a = 0; a < 3; a++) {
        o[a] = lo[a] + (hi[a] - lo[a]) * rndf();
        if (!isfinite(o[a])) o[a] = lo[a];
        d[a] = rndf() - 0.5f;
    }
    if (kind == 0) { /* toward a point on a triangle */
        const cbvh_tri *t = &s->tris[rnd() % s->ntris];
        float w0 = rndf(), w1 = rndf() * (1 - w0), w2 = 1 - w0 - w1;
        for (int a = 0; a < 3; a++) {
            float p = w0 * t->v[0][a] + w1 * t->v[1][a] + w2 * t->v[2][a];
            d[a] = p - o[a];
            if (!isfinite(d[a])) d[a] = 0.5f * p - 0.5f * o[a];
        }
    } else if (kind == 2) {
        d[rnd() % 3] = (rnd() & 1) ? 0.0f : -0.0f;
    } else if (kind == 3) {
        int z = (int)(rnd() % 3);
        d[z] = 0.0f;
        d[(z + 1) % 3] = (rnd() & 1) ? -0.0f : 0.0f;
    }
    if (d[0] == 0 && d[1] == 0 && d[2] == 0) d[0] = 1;
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        r.o[a] = fb(isfinite(o[a]) ? o[a] : 0.0f);
        r.d[a] = fb(isfinite(d[a]) ? d[a] : 1.0f);
    }
    r.tmin = 0;
    r.tmax = rnd() % 4 == 0 ? fb(2.0f * rndf()) : CBVH_F32_POS_INF;
    return r;
}

/* Closest hit: the brute-force hit bit for bit; any hit: a hit iff there is one. */
static void expect(const char *kind, const char *what, int mode, const cbvh_trav_hit *want, int rc,
                   const cbvh_trav_hit *got) {
    CHECK(rc == 0, "%s: %s mode %d: traversal failed", kind, what, mode);
    if (mode == CBVH_TRAV_ANY)
        CHECK(got->hit == want->hit, "%s: %s any hit %d, brute force %d", kind, what, got->hit, want->hit);
    else
        CHECK(same_hit(got, want), "%s: %s closest hit %d prim %u t %08x, brute force %d prim %u t %08x", kind, what,
              got->hit, got->prim, got->t, want->hit, want->prim, want->t);
}

#define TREES 6
static const int tree_n[3] = {3, 6, 10};
static const int mant[3] = {24, 8, 3};

static void run_soup(int k, long hits[KINDS], long rays[KINDS]) {
    char err[512], what[96];
    cbvh_scene s;
    soup(&s, k);
    float lo[3], hi[3];
    ray_box(&s, lo, hi);
    /* the traversal lists over the bounding-sphere hierarchy, 1/2/6/8 lists */
    cbvh_bsh_params bp;
    cbvh_bsh_default_params(&bp);
    cbvh_bsh h;
    cbvh_tlists L[4];
    int have_l[4] = {0, 0, 0, 0}, nl[4] = {1, 2, 6, 8};
    int have_h = !cbvh_bsh_build(&s, &bp, &h, err, sizeof err);
    /* a sphere around coordinates near +-FLT_MAX has no binary32 radius: the
     * builder refuses such a scene (one line), any other must build */
    CHECK(have_h || (k == HUGE_ && strstr(err, "exceeds binary32")), "%s: BSH: %s", kind_name[k], err);
    for (int i = 0; i < 4 && have_h; i++) {
        cbvh_tlist_params lp = {nl[i], (cbvh_tlist_order)(rnd() % 2), 0};
        have_l[i] = !cbvh_tlists_build(&h, &s, &lp, &L[i], err, sizeof err);
        CHECK(have_l[i], "%s: %d lists: %s", kind_name[k], nl[i], err);
    }
    for (int i = 0; i < RAYS && have_h; i++) {
        cbvh_ray r = make_ray(&s, lo, hi);
        cbvh_trav_hit want = brute(&s, &r), got;
        cbvh_trav_stats st = {0};
        for (int mode = 0; mode < 2; mode++)
            for (int j = 0; j < 4; j++) {
                if (!have_l[j]) continue;
                snprintf(what, sizeof what, "%d traversal lists", nl[j]);
                int rc = cbvh_trace_tlist(&L[j], cbvh_tlist_pick(&L[j], &r), 0, s.tris, &r, (cbvh_trav_mode)mode, &got,
                                          &st);
                expect(kind_name[k], what, mode, &want, rc, &got);
            }
    }
    for (int i = 0; i < 4; i++)
        if (have_l[i]) cbvh_tlists_free(&L[i]);
    if (have_h) cbvh_bsh_free(&h);
    for (int builder = 0; builder < 2; builder++) {
        cbvh_bvh b;
        int rc = builder ? cbvh_build_sah(&s, 16, 4, &b, err, sizeof err) : cbvh_build_lbvh(&s, &b, err, sizeof err);
        CHECK(rc == 0, "%s: build: %s", kind_name[k], err);
        if (rc) continue;
        cbvh_fbvh fb;
        cbvh_qbvh q;
        int have_fb = !cbvh_fbvh_build(&b, &fb, err, sizeof err);
        CHECK(have_fb, "%s: float layout: %s", kind_name[k], err);
        int have_q = !cbvh_qbvh_from_bvh(&b, &q, err, sizeof err);
        CHECK(have_q, "%s: QBVH: %s", kind_name[k], err);
        cbvh_fqbvh fq; /* the 4-wide plain float layout, with the leaf copy for one builder */
        int have_fq = have_q && !cbvh_fqbvh_build(&q, builder ? s.tris : NULL, s.ntris, &fq, err, sizeof err);
        CHECK(have_fq, "%s: 4-wide float layout: %s", kind_name[k], err);
        cbvh_tree t[2][TREES];
        cbvh_cbvh_decoded dt[2][TREES];
        int have_t[2][TREES];
        for (int j = 0; j < TREES; j++) {
            static const int ms[4] = {-126, -30, -10, 0};
            cbvh_compress_opts o = {{tree_n[j % 3], ms[rnd() % 4]}, (cbvh_encoding)(j / 3), 1 + (int)(rnd() % 4), 0};
            have_t[0][j] = !cbvh_compress_topdown(&b, &o, &t[0][j], err, sizeof err);
            CHECK(have_t[0][j], "%s: top-down N=%d: %s", kind_name[k], o.params.quant_bits, err);
            cbvh_bvh c = b;
            c.nodes = malloc(b.nnodes * sizeof *b.nodes);
            memcpy(c.nodes, b.nodes, b.nnodes * sizeof *b.nodes);
            cbvh_bu_stats bs;
            o.naive_reencode = (int)(rnd() % 2);
            have_t[1][j] = !cbvh_compress_bottomup(&c, NULL, &o, &t[1][j], &bs, err, sizeof err);
            CHECK(have_t[1][j], "%s: bottom-up N=%d naive=%d: %s", kind_name[k], o.params.quant_bits,
                  o.naive_reencode, err);
            free(c.nodes);
            for (int bu = 0; bu < 2; bu++) {
                if (!have_t[bu][j]) continue;
                CHECK(cbvh_cbvh_decode(&t[bu][j], &dt[bu][j], err, sizeof err) == 0 && dt[bu][j].usable,
                      "%s: decoded CBVH not usable: %s", kind_name[k], err);
                if (j % 2) /* half the trees with their leaves copied too */
                    CHECK(cbvh_cbvh_decode_leaves(&dt[bu][j], s.tris, s.ntris, err, sizeof err) == 0 &&
                              dt[bu][j].leaf_tris,
                          "%s: no leaf copy: %s", kind_name[k], err);
                decoded_trees++;
                for (uint32_t q = 0; dt[bu][j].usable && q < t[bu][j].npairs; q++) {
                    uint32_t fl = dt[bu][j].nodes[q].flags & (CBVH_DEC_EXACT | CBVH_DEC_F32);
                    decoded_inexact += !(fl & CBVH_DEC_EXACT);
                    decoded_wide += fl == CBVH_DEC_EXACT;
                }
                decoded_pairs += t[bu][j].npairs;
            }
        }
        for (int i = 0; i < RAYS; i++) {
            cbvh_ray r = make_ray(&s, lo, hi);
            cbvh_trav_hit want = brute(&s, &r), got;
            cbvh_trav_stats st = {0};
            rays[k]++;
            hits[k] += want.hit;
            for (int mode = 0; mode < 2; mode++) {
                cbvh_trav_mode md = (cbvh_trav_mode)mode;
                for (int m = 0; m < 3; m++) {
                    snprintf(what, sizeof what, "float BVH (units) M=%d", mant[m]);
                    rc = cbvh_trace_bvh(&b, s.tris, &r, mant[m], md, &got, &st);
                    expect(kind_name[k], what, mode, &want, rc, &got);
                }
                if (have_fb) {
                    rc = cbvh_trace_bvh_float(&fb, s.tris, &r, md, &got, &st);
                    expect(kind_name[k], "plain float BVH", mode, &want, rc, &got);
                }
                if (have_fq) {
                    rc = cbvh_trace_qbvh_float(&fq, s.tris, &r, md, &got, &st);
                    expect(kind_name[k], "4-wide plain float", mode, &want, rc, &got);
                }
                for (int kind = CBVH_QSTACK_COMPRESSED; have_q && kind <= CBVH_QSTACK_PLAIN; kind++) {
                    snprintf(what, sizeof what, "QBVH stack kind %d", kind);
                    rc = cbvh_trace_qbvh(&q, s.tris, &r, 24, md, (cbvh_qstack_kind)kind, &got, &st);
                    expect(kind_name[k], what, mode, &want, rc, &got);
                }
                for (int bu = 0; bu < 2; bu++)
                    for (int j = 0; j < TREES; j++) {
                        if (!have_t[bu][j]) continue;
                        int M = mant[rnd() % 3];
                        snprintf(what, sizeof what, "%s CBVH N=%d enc=%d M=%d", bu ? "bottom-up" : "top-down",
                                 tree_n[j % 3], j / 3, M);
                        cbvh_trav_stats s1 = {0}, s2 = {0};
                        cbvh_trav_hit g2;
                        rc = cbvh_trace_cbvh(&t[bu][j], s.tris, &r, M, md, &got, &s1);
                        expect(kind_name[k], what, mode, &want, rc, &got);
                        int rc2 = cbvh_trace_cbvh_decoded(&dt[bu][j], s.tris, &r, M, md, &g2, &s2);
                        CHECK(rc2 == rc && !memcmp(&g2, &got, sizeof got) && !memcmp(&s1, &s2, sizeof s1),
                              "%s: %s mode %d: decoded rc %d hit %d prim %u nodes %llu, per-visit rc %d hit %d prim %u "
                              "nodes %llu", kind_name[k], what, mode, rc2, g2.hit, g2.prim,
                              (unsigned long long)s2.nodes, rc, got.hit, got.prim, (unsigned long long)s1.nodes);
                        decoded_traces++;
                    }
            }
        }
        for (int bu = 0; bu < 2; bu++)
            for (int j = 0; j < TREES; j++)
                if (have_t[bu][j]) {
                    cbvh_cbvh_decoded_free(&dt[bu][j]);
                    cbvh_tree_free(&t[bu][j]);
                }
        if (have_fq) cbvh_fqbvh_free(&fq);
        if (have_q) cbvh_qbvh_free(&q);
        if (have_fb) cbvh_fbvh_free(&fb);
        cbvh_bvh_free(&b);
    }
    cbvh_scene_free(&s);
}

int main(void) {
    long hits[KINDS] = {0}, rays[KINDS] = {0};
    for (int i = 0; i < SOUPS; i++) run_soup(i % KINDS, hits, rays);
    /* the rays must reach triangles in every kind of soup, or nothing was compared */
    for (int k = 0; k < KINDS; k++) {
        printf("%-24s %6ld rays, %5ld hit\n", kind_name[k], rays[k], hits[k]);
        CHECK(hits[k] * 50 >= rays[k], "%s: only %ld of %ld rays hit", kind_name[k], hits[k], rays[k]);
    }
    printf("decoded once: %ld trees, %ld pairs (%ld with planes not exact in binary64, %ld exact in binary64 "
           "only), %ld traversals compared with the per-visit traversal\n",
           decoded_trees, decoded_pairs, decoded_inexact, decoded_wide, decoded_traces);
    /* all three of the decoded traversal's box paths must have been compared */
    CHECK(decoded_traces > 0 && decoded_inexact > 0 && decoded_wide > 0 && decoded_inexact + decoded_wide < decoded_pairs,
          "decoded traversal: %ld traces, %ld of %ld pairs inexact, %ld binary64 only", decoded_traces,
          decoded_inexact, decoded_pairs, decoded_wide);
    printf("%s: %ld failures\n", fails ? "FAIL" : "ok", fails);
    return fails ? 1 : 0;
}
