/* Traversal core (docs/traversal.md §5) on real scenes:
 *   - the plain floating-point traversal (§11) == float-BVH closest hit bit
 *     for bit, same any-hit flag, same triangle-test rule, every box it
 *     culls culled by the unit too (its box tests <= the unit's + 1 %);
 *   - CBVH closest hit == float-BVH closest hit (triangle id and t bit pattern)
 *     for every ray, at N = 3, 6, 10 (modulo) and N = 6 (relative), box unit
 *     M = 24 and M = 8;
 *   - both == brute force over all triangles (a subset of rays);
 *   - any-hit finds a hit iff closest-hit does, and the hit it reports is a
 *     real hit of the unit in [tmin, tmax]; its counters are a prefix of
 *     closest-hit's (it stops at its first accepted hit);
 *   - CBVH box tests >= float-BVH box tests (sums), counters plausible;
 *   - the CBVH decoded once (cbvh_cbvh_decode, docs/traversal.md §12): every
 *     record equals the node-pair unit's decode under the unit's contexts, and
 *     its traversal gives the per-visit traversal's return value, hit and
 *     counters on every ray; malformed trees (a cycle, a pointer out of range,
 *     a pair the unit rejects, pairs of another width) are left to the
 *     per-visit traversal (usable = 0) and keep its results;
 * scenes: scenes/bunny-small.obj, proc:far (far from the origin), proc:cloth
 * (a plane hit edge-on and at grazing angles). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/qbvh.h"
#include "cbvh/traverse.h"
#include "cbvh/unit_table.h"
#include "scene/scene_load.h"
#include "test_trav_util.h"
#include "test_wide.h"

#ifdef CBVH_SANITIZE
#define RAYS 300
#define BRUTE 40
#else
#define RAYS 2500
#define BRUTE 250
#endif

static long failures;
static uint64_t rs = 0xD1B54A32D192ED03u;

static void add_stats(cbvh_trav_stats *sum, const cbvh_trav_stats *s) {
    sum->nodes += s->nodes;
    sum->box_tests += s->box_tests;
    sum->tri_tests += s->tri_tests;
    sum->lines += s->lines;
    sum->bytes += s->bytes;
    if (s->max_stack > sum->max_stack) sum->max_stack = s->max_stack;
}

/* Any hit walks as closest hit does until the first accepted hit (nothing
 * is culled before a hit) and stops there: its work is a prefix of the
 * closest-hit traversal's (and, over many rays, strictly less). */
static int any_is_prefix(const cbvh_trav_stats *any, const cbvh_trav_stats *closest) {
    return any->nodes <= closest->nodes && any->box_tests <= closest->box_tests &&
           any->tri_tests <= closest->tri_tests && any->lines <= closest->lines;
}

/* The decoded traversal equals the per-visit one: return value, hit and
 * every counter. */
static int decoded_same(const cbvh_cbvh_decoded *d, const cbvh_tri *tris, const cbvh_ray *r, int M,
                        cbvh_trav_mode mode) {
    cbvh_trav_hit h1, h2;
    cbvh_trav_stats s1 = {0}, s2 = {0};
    int rc1 = cbvh_trace_cbvh(d->tree, tris, r, M, mode, &h1, &s1);
    int rc2 = cbvh_trace_cbvh_decoded(d, tris, r, M, mode, &h2, &s2);
    return rc1 == rc2 && !memcmp(&h1, &h2, sizeof h1) && !memcmp(&s1, &s2, sizeof s1);
}

/* a + b is exact in binary64 (Knuth's 2Sum: the rounding error is zero). */
static int sum_exact(double a, double b) {
    double x = a + b, bv = x - a;
    double av = x - bv;
    return isfinite(x) && (a - av) + (b - bv) == 0;
}

/* Every reachable record against the node-pair unit (cbvh_nodepair_decode)
 * under contexts derived by the unit (cbvh_axis_child_ctx), independently of
 * the fast decode the records come from.  Returns the number of differences;
 * *exact counts the pairs whose planes are exact in binary64, *f32 those
 * whose planes are also exact in binary32. */
static long decoded_vs_unit(const cbvh_cbvh_decoded *d, long *exact, long *f32) {
    const cbvh_tree *t = d->tree;
    const cbvh_params *p = &t->params;
    uint32_t *sp_pair = malloc(((size_t)t->npairs + 2) * sizeof *sp_pair);
    cbvh_node_ctx *sp_ctx = malloc(((size_t)t->npairs + 2) * sizeof *sp_ctx);
    long bad = 0;
    int sp = 0;
    sp_pair[sp] = t->root_pair;
    sp_ctx[sp++] = t->root_ctx;
    while (sp > 0) {
        uint32_t i = sp_pair[--sp];
        cbvh_node_ctx ctx = sp_ctx[sp];
        cbvh_child_out ch[2];
        if (cbvh_nodepair_decode(p, t->enc, &ctx, t->pairs + (size_t)i * t->pair_bytes, ch)) {
            bad++;
            continue;
        }
        const cbvh_cbvh_dnode *rec = &d->nodes[i];
        uint32_t rc[2][3], sc[2][3]; /* the unit's codes; an empty child: the dummy box 0, 1 */
        for (int a = 0; a < 3; a++)
            bad += d->rel[i].clb[a] != ctx.axis[a].clb || d->rel[i].scale[a] != ctx.axis[a].scale;
        for (int c = 0; c < 2; c++) {
            bad += ((rec->flags >> c) & 1) != (uint32_t)ch[c].leaf ||
                   ((rec->flags >> (2 + c)) & 1) != (uint32_t)ch[c].empty;
            for (int a = 0; a < 3; a++) {
                rc[c][a] = 0;
                sc[c][a] = 1;
                if (ch[c].empty) continue;
                cbvh_axis_store_codes(p, CBVH_ENC_RELATIVE, &ctx.axis[a], &ch[c].axis[a], &rc[c][a], &sc[c][a]);
                if (sc[c][a] == 0) sc[c][a] = 1u << p->quant_bits;
                bad += d->rel[i].r[c][a] != rc[c][a] || d->rel[i].s[c][a] != sc[c][a];
            }
            if (ch[c].empty) continue;
            bad += rec->child[c] != ch[c].ptr;
            if (ch[c].leaf) continue;
            sp_pair[sp] = ch[c].ptr;
            for (int a = 0; a < 3; a++) sp_ctx[sp].axis[a] = cbvh_axis_child_ctx(&ctx.axis[a], &ch[c].axis[a]);
            sp++;
        }
        /* The planes, when the filter is to use them: binary32 in the record
         * (F32, exactly when every one of the pair's twelve is a binary32) or
         * binary64 in wide[]. */
        uint32_t fl = rec->flags & (CBVH_DEC_EXACT | CBVH_DEC_F32);
        *exact += (fl & CBVH_DEC_EXACT) != 0;
        *f32 += (fl & CBVH_DEC_F32) != 0;
        if (!(fl & CBVH_DEC_EXACT)) {
            bad += fl != 0;
            continue;
        }
        bad += fl == CBVH_DEC_EXACT && rec->wide >= d->nwide;
        const cbvh_cbvh_dwide *w = fl == CBVH_DEC_EXACT && rec->wide < d->nwide ? &d->wide[rec->wide] : NULL;
        int all32 = 1;
        for (int c = 0; c < 2; c++)
            for (int a = 0; a < 3; a++) { /* the filter's premise: u + r 2^e, u + s 2^e exact */
                double u = cbvh_float_of(ctx.axis[a].clb), lo = ldexp((double)rc[c][a], ctx.axis[a].scale),
                       hi = ldexp((double)sc[c][a], ctx.axis[a].scale);
                double plo = w ? w->pl[0][a][c] : rec->pl[0][a][c], phi = w ? w->pl[1][a][c] : rec->pl[1][a][c];
                bad += !sum_exact(u, lo) || !sum_exact(u, hi) || plo != u + lo || phi != u + hi;
                all32 &= fabs(u + hi) <= FLT_MAX && (double)(float)(u + lo) == u + lo &&
                         (double)(float)(u + hi) == u + hi; /* u >= -FLT_MAX, u + lo < u + hi: no overflow */
            }
        bad += all32 != (fl == (CBVH_DEC_EXACT | CBVH_DEC_F32));
    }
    free(sp_pair);
    free(sp_ctx);
    return bad;
}

/* One scene; scale_exp != 0: every vertex times 2^scale_exp (exact), and
 * the scene named huge (its planes beyond the binary32 lanes' 2^62). */
static void run_scene(const char *spec, int scale_exp) {
    cbvh_scene s;
    char err[256];
    if (cbvh_scene_open(spec, &s, err, sizeof err)) {
        fprintf(stderr, "FAIL %s: %s\n", spec, err);
        failures++;
        return;
    }
    if (scale_exp) {
        for (uint32_t t = 0; t < s.ntris; t++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) s.tris[t].v[v][a] = ldexpf(s.tris[t].v[v][a], scale_exp);
        spec = "bunny-small.obj x 2^64 (huge)";
    }
    cbvh_bvh b;
    if (cbvh_build_sah(&s, 0, 0, &b, err, sizeof err)) {
        fprintf(stderr, "FAIL build %s: %s\n", spec, err);
        failures++;
        cbvh_scene_free(&s);
        return;
    }
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    int edge_on = strstr(spec, "cloth") != NULL;
    cbvh_ray *rays = malloc(RAYS * sizeof *rays);
    cbvh_trav_hit *ref = malloc(RAYS * sizeof *ref);
    cbvh_trav_stats fs = {0}, fa = {0}, ps = {0}, pas = {0};
    cbvh_fbvh fb;
    if (cbvh_fbvh_build(&b, &fb, err, sizeof err)) {
        fprintf(stderr, "FAIL layout %s: %s\n", spec, err);
        failures++;
        fb.nodes = NULL;
    }
    /* the 4- and 8-wide plain float traversals (W = 0, 1), with and without the leaf copy */
    any_wide aw[2][2];
    int have_w[2];
    for (int W = 0; W < 2; W++) {
        have_w[W] = !aw_build(&aw[W][0], W, &b, s.tris, s.ntris, err, sizeof err);
        if (have_w[W] && aw_build(&aw[W][1], W, &b, NULL, 0, err, sizeof err)) {
            aw_free(&aw[W][0]);
            have_w[W] = 0;
        }
        if (!have_w[W] || !aw_leaf_tris(&aw[W][0]) || aw_leaf_tris(&aw[W][1]) || aw_leaf_src(&aw[W][0]) != s.tris) {
            fprintf(stderr, "FAIL %s layout %s: %s\n", wide_name[W], spec, have_w[W] ? "leaf copy" : err);
            failures++;
        }
    }
    cbvh_trav_stats ws[2] = {{0}, {0}};
    long hits = 0, plain_mismatch = 0, wide_mismatch[2] = {0, 0}, isa_mismatch[2] = {0, 0}, isa_rays[2] = {0, 0};
    long lane_mismatch[2] = {0, 0}, lane_box_diff[2] = {0, 0};
    const cbvh_wide_isa isa = cbvh_wide_float_isa();
#ifdef CBVH_WIDE_AVX /* the library has the AVX loop: a CPU with AVX runs it */
    if (__builtin_cpu_supports("avx") && __builtin_cpu_supports("popcnt") && isa != CBVH_WIDE_ISA_AVX) {
        fprintf(stderr, "FAIL: this CPU has AVX and POPCNT, but the wide float traversals run the %s loop\n",
                cbvh_wide_isa_name(isa));
        failures++;
    }
#endif
    for (int i = 0; i < RAYS; i++) {
        rays[i] = box_ray(&rs, lo, hi, i, edge_on);
        cbvh_trav_hit any;
        cbvh_trav_stats c1 = {0}, a1 = {0};
        if (cbvh_trace_bvh(&b, s.tris, &rays[i], 24, CBVH_TRAV_CLOSEST, &ref[i], &c1) ||
            cbvh_trace_bvh(&b, s.tris, &rays[i], 24, CBVH_TRAV_ANY, &any, &a1)) {
            failures++;
            continue;
        }
        add_stats(&fs, &c1);
        add_stats(&fa, &a1);
        hits += ref[i].hit;
        if (any.hit != ref[i].hit || !any_is_prefix(&a1, &c1)) failures++;
        cbvh_trav_hit ph, pa;
        if (!fb.nodes || cbvh_trace_bvh_float(&fb, s.tris, &rays[i], CBVH_TRAV_CLOSEST, &ph, &ps) ||
            cbvh_trace_bvh_float(&fb, s.tris, &rays[i], CBVH_TRAV_ANY, &pa, &pas) || !same_hit(&ph, &ref[i]) ||
            pa.hit != ref[i].hit) {
            if (plain_mismatch++ < 3) fprintf(stderr, "FAIL %s ray %d: plain float BVH != float BVH\n", spec, i);
        }
        for (int W = 0; W < 2; W++)
            for (int k = 0; k < 2 && have_w[W]; k++) {
                cbvh_trav_hit qh, qa;
                cbvh_trav_stats qc1 = {0}, qa1 = {0};
                if (aw_trace(&aw[W][k], s.tris, &rays[i], CBVH_TRAV_CLOSEST, &qh, &qc1) ||
                    aw_trace(&aw[W][k], s.tris, &rays[i], CBVH_TRAV_ANY, &qa, &qa1) || !same_hit(&qh, &ref[i]) ||
                    qa.hit != ref[i].hit) {
                    if (wide_mismatch[W]++ < 3)
                        fprintf(stderr, "FAIL %s ray %d: %s plain float (%s) != float BVH\n", spec, i, wide_name[W],
                                k ? "no leaf copy" : "leaf copy");
                }
                if (!k) add_stats(&ws[W], &qc1);
                /* the AVX build of the loop (where it runs) against the baseline's: the same
                 * hit and counters, so the same visits */
                if (isa != CBVH_WIDE_ISA_BASE) {
                    cbvh_trav_hit bh, ba;
                    cbvh_trav_stats bc1 = {0}, ba1 = {0};
                    cbvh_wide_float_limit_isa(CBVH_WIDE_ISA_BASE);
                    int rc = aw_trace(&aw[W][k], s.tris, &rays[i], CBVH_TRAV_CLOSEST, &bh, &bc1) ||
                             aw_trace(&aw[W][k], s.tris, &rays[i], CBVH_TRAV_ANY, &ba, &ba1);
                    cbvh_wide_float_limit_isa(isa);
                    if (rc || memcmp(&bh, &qh, sizeof bh) || memcmp(&ba, &qa, sizeof ba) ||
                        memcmp(&bc1, &qc1, sizeof bc1) || memcmp(&ba1, &qa1, sizeof ba1)) {
                        if (isa_mismatch[W]++ < 3)
                            fprintf(stderr, "FAIL %s ray %d: %s plain float, %s loop != baseline loop\n", spec, i,
                                    wide_name[W], cbvh_wide_isa_name(isa));
                    }
                    isa_rays[W]++;
                }
                /* the binary64 lanes (§16's fallback) on every box: the same hits */
                if (!k) {
                    cbvh_trav_hit dh, da;
                    cbvh_trav_stats dc1 = {0}, da1 = {0};
                    cbvh_wide_float_box32(0);
                    int rc = aw_trace(&aw[W][k], s.tris, &rays[i], CBVH_TRAV_CLOSEST, &dh, &dc1) ||
                             aw_trace(&aw[W][k], s.tris, &rays[i], CBVH_TRAV_ANY, &da, &da1);
                    cbvh_wide_float_box32(1);
                    if (rc || memcmp(&dh, &qh, sizeof dh) || memcmp(&da, &qa, sizeof da)) {
                        if (lane_mismatch[W]++ < 3)
                            fprintf(stderr, "FAIL %s ray %d: %s plain float, binary64 lanes != binary32 lanes\n",
                                    spec, i, wide_name[W]);
                    }
                    lane_box_diff[W] += (long)(qc1.box_tests - dc1.box_tests);
                }
            }
        if (i < BRUTE) {
            cbvh_trav_hit bf = brute(&s, &rays[i]);
            if (!same_hit(&bf, &ref[i])) {
                if (failures++ < 10) fprintf(stderr, "FAIL %s ray %d: float BVH != brute force\n", spec, i);
            }
        }
    }
    printf("%-22s %6u tris: %d rays, %ld hits | float BVH   closest: %.1f nodes %.1f box %.1f tri %.0f B/ray, "
           "stack %u; any-hit %.1f box\n",
           spec, s.ntris, RAYS, hits, (double)fs.nodes / RAYS, (double)fs.box_tests / RAYS,
           (double)fs.tri_tests / RAYS, (double)fs.bytes / RAYS, fs.max_stack, (double)fa.box_tests / RAYS);
    printf("%-22s %6u tris: plain float traversal closest: %.1f nodes %.1f box %.1f tri %.0f B/ray; "
           "mismatches %ld\n",
           spec, s.ntris, (double)ps.nodes / RAYS, (double)ps.box_tests / RAYS, (double)ps.tri_tests / RAYS,
           (double)ps.bytes / RAYS, plain_mismatch);
    failures += plain_mismatch;
    /* fewer records than the binary (4-wide) or the 4-wide (8-wide) tree, as many triangles
     * within binary64 error */
    for (int W = 0; W < 2; W++) {
        const cbvh_trav_stats *q = &ws[W], *fewer = W ? &ws[0] : &ps;
        printf("%-22s %6u tris: %s plain float   closest: %.1f nodes %.1f box %.1f tri %.0f B/ray; "
               "mismatches %ld; %s loop vs baseline: %ld rays x 2 layouts, %ld differ\n",
               spec, s.ntris, wide_name[W], (double)q->nodes / RAYS, (double)q->box_tests / RAYS,
               (double)q->tri_tests / RAYS, (double)q->bytes / RAYS, wide_mismatch[W], cbvh_wide_isa_name(isa),
               isa_rays[W] / 2, isa_mismatch[W]);
        printf("%-22s %6u tris: %s plain float: binary32 lanes %s, hits as the binary64 lanes' on every ray "
               "(%ld differ), box tests %+ld over them\n",
               spec, s.ntris, wide_name[W], have_w[W] && aw_small(&aw[W][0]) ? "used" : "not used (planes too large)",
               lane_mismatch[W], lane_box_diff[W]);
        failures += wide_mismatch[W] + isa_mismatch[W] + lane_mismatch[W];
        if (have_w[W] && !aw_small(&aw[W][0]) == !strstr(spec, "huge")) {
            fprintf(stderr, "FAIL %s: %s small_planes = %d\n", spec, wide_name[W], aw_small(&aw[W][0]));
            failures++;
        }
        if (have_w[W] && (q->nodes >= fewer->nodes || q->nodes < ps.nodes / (W ? 8 : 4) ||
                          q->bytes != q->lines * CBVH_LINE_BYTES || q->tri_tests > ps.tri_tests + ps.tri_tests / 100 + 10)) {
            fprintf(stderr, "FAIL %s: %s counters: %llu nodes (%s %llu), %llu tri tests (binary %llu)\n", spec,
                    wide_name[W], (unsigned long long)q->nodes, W ? "4-wide" : "binary",
                    (unsigned long long)fewer->nodes, (unsigned long long)q->tri_tests,
                    (unsigned long long)ps.tri_tests);
            failures++;
        }
    }
    for (int W = 0; W < 2; W++)
        if (have_w[W]) {
            aw_free(&aw[W][0]);
            aw_free(&aw[W][1]);
        }
    /* conservative within binary64 error: at most a few more boxes than the exact M = 24 unit */
    if (ps.box_tests > fs.box_tests + fs.box_tests / 100 || ps.box_tests < fs.box_tests / 2 ||
        ps.bytes != ps.lines * CBVH_LINE_BYTES) {
        fprintf(stderr, "FAIL %s: plain float box tests %llu vs unit %llu\n", spec, (unsigned long long)ps.box_tests,
                (unsigned long long)fs.box_tests);
        failures++;
    }
    if (fb.nodes) cbvh_fbvh_free(&fb);
    if (hits < RAYS / 10 || fs.box_tests < (uint64_t)RAYS || !(fa.tri_tests < fs.tri_tests)) failures++;
    struct {
        int N, M;
        cbvh_encoding enc;
    } cfg[] = {{3, 24, CBVH_ENC_MODULO}, {6, 24, CBVH_ENC_MODULO}, {10, 24, CBVH_ENC_MODULO},
               {6, 24, CBVH_ENC_RELATIVE}, {6, 8, CBVH_ENC_MODULO}, {3, 3, CBVH_ENC_MODULO}};
    for (size_t c = 0; c < sizeof cfg / sizeof cfg[0]; c++) {
        cbvh_compress_opts o = {{cfg[c].N, CBVH_MIN_SCALE_DEFAULT}, cfg[c].enc, 1, 0};
        cbvh_tree t;
        if (cbvh_compress_topdown(&b, &o, &t, err, sizeof err)) {
            fprintf(stderr, "FAIL compress %s N=%d: %s\n", spec, cfg[c].N, err);
            failures++;
            continue;
        }
        cbvh_trav_stats cs = {0}, ca = {0};
        long mismatches = 0, exact = 0, f32 = 0, dec_bad = 0;
        cbvh_cbvh_decoded dt;
        if (cbvh_cbvh_decode(&t, &dt, err, sizeof err) || !dt.usable) {
            fprintf(stderr, "FAIL decode %s N=%d: not usable (%s)\n", spec, cfg[c].N, err);
            failures++;
        } else {
            dec_bad = decoded_vs_unit(&dt, &exact, &f32);
            for (int i = 0; i < RAYS; i++)
                for (int mode = 0; mode < 2; mode++)
                    dec_bad += !decoded_same(&dt, s.tris, &rays[i], cfg[c].M, (cbvh_trav_mode)mode);
            /* with the leaves copied too: the copy holds each ID's triangle,
             * and tracing with it is again the per-visit traversal */
            if (cbvh_cbvh_decode_leaves(&dt, s.tris, s.ntris, err, sizeof err) || !dt.leaf_tris ||
                dt.leaf_src != s.tris) {
                fprintf(stderr, "FAIL decode leaves %s: %s\n", spec, err);
                failures++;
            } else {
                for (uint32_t i = 0; i < t.nids; i++)
                    dec_bad += dt.leaf_tris[i].id != t.ids[i] ||
                               memcmp(dt.leaf_tris[i].v, s.tris[t.ids[i] & ~CBVH_ID_LAST].v, sizeof s.tris[0].v);
                for (int i = 0; i < RAYS; i++)
                    for (int mode = 0; mode < 2; mode++)
                        dec_bad += !decoded_same(&dt, s.tris, &rays[i], cfg[c].M, (cbvh_trav_mode)mode);
            }
        }
        /* nearly every pair of these scenes has binary64-exact planes (the filter's case) */
        if (dec_bad || exact * 10 < (long)t.npairs * 9) {
            fprintf(stderr, "FAIL decoded CBVH %s N=%d M=%d: %ld differences, %ld of %u pairs exact (%ld in binary32)\n",
                    spec, cfg[c].N, cfg[c].M, dec_bad, exact, t.npairs, f32);
            failures++;
        }
        cbvh_cbvh_decoded_free(&dt);
        for (int i = 0; i < RAYS; i++) {
            cbvh_trav_hit h, any;
            cbvh_trav_stats c1 = {0}, a1 = {0};
            if (cbvh_trace_cbvh(&t, s.tris, &rays[i], cfg[c].M, CBVH_TRAV_CLOSEST, &h, &c1) ||
                cbvh_trace_cbvh(&t, s.tris, &rays[i], cfg[c].M, CBVH_TRAV_ANY, &any, &a1)) {
                failures++;
                continue;
            }
            add_stats(&cs, &c1);
            add_stats(&ca, &a1);
            if (!any_is_prefix(&a1, &c1)) mismatches++;
            if (!same_hit(&h, &ref[i])) {
                if (mismatches++ < 3)
                    fprintf(stderr, "FAIL %s N=%d M=%d ray %d: CBVH hit %d prim %u t %08X, float %d prim %u t %08X\n",
                            spec, cfg[c].N, cfg[c].M, i, h.hit, h.prim, h.t, ref[i].hit, ref[i].prim, ref[i].t);
            }
            if (any.hit != ref[i].hit) mismatches++;
        }
        failures += mismatches;
        printf("%-22s N=%-2d M=%-2d %-8s CBVH closest: %.1f nodes %.1f box (x%.3f) %.1f tri (x%.3f) %.0f B/ray "
               "(x%.3f), stack %u; any-hit %.1f box; mismatches %ld\n",
               spec, cfg[c].N, cfg[c].M, cbvh_encoding_name(cfg[c].enc), (double)cs.nodes / RAYS,
               (double)cs.box_tests / RAYS, (double)cs.box_tests / (double)fs.box_tests, (double)cs.tri_tests / RAYS,
               (double)cs.tri_tests / (double)fs.tri_tests, (double)cs.bytes / RAYS,
               (double)cs.bytes / (double)fs.bytes, cs.max_stack, (double)ca.box_tests / RAYS, mismatches);
        printf("%-22s N=%-2d M=%-2d %-8s decoded once: %u pairs, %ld exact in binary64 (%ld in binary32), "
               "%d x 2 rays identical\n",
               spec, cfg[c].N, cfg[c].M, cbvh_encoding_name(cfg[c].enc), t.npairs, exact, f32, RAYS);
        if (cs.box_tests < fs.box_tests) {
            fprintf(stderr, "FAIL %s N=%d: CBVH box tests %llu < float %llu\n", spec, cfg[c].N,
                    (unsigned long long)cs.box_tests, (unsigned long long)fs.box_tests);
            failures++;
        }
        if (cs.bytes != cs.lines * CBVH_LINE_BYTES || cs.nodes == 0 || !(ca.tri_tests < cs.tri_tests)) failures++;
        cbvh_tree_free(&t);
    }
    free(rays);
    free(ref);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* NaN/Inf and zero-direction rays are rejected (-1), with no hit reported. */
static void bad_rays(void) {
    cbvh_scene s;
    char err[256];
    if (cbvh_scene_open("proc:far:8", &s, err, sizeof err)) {
        failures++;
        return;
    }
    cbvh_bvh b;
    if (cbvh_build_sah(&s, 0, 0, &b, err, sizeof err)) {
        failures++;
        cbvh_scene_free(&s);
        return;
    }
    cbvh_compress_opts o = {{6, CBVH_MIN_SCALE_DEFAULT}, CBVH_ENC_MODULO, 1, 0};
    cbvh_tree t;
    if (cbvh_compress_topdown(&b, &o, &t, err, sizeof err) == 0) {
        cbvh_ray bad[3] = {{{0x7FC00000u, 0, 0}, {fb(1), 0, 0}, 0, CBVH_F32_POS_INF},
                           {{0, 0, 0}, {CBVH_F32_POS_INF, 0, 0}, 0, CBVH_F32_POS_INF},
                           {{0, 0, 0}, {0, CBVH_F32_SIGN, 0}, 0, CBVH_F32_POS_INF}};
        for (int i = 0; i < 3; i++) {
            cbvh_trav_hit h;
            cbvh_trav_stats st = {0};
            if (cbvh_trace_bvh(&b, s.tris, &bad[i], 24, CBVH_TRAV_CLOSEST, &h, &st) != -1 || h.hit) failures++;
            cbvh_fbvh fb;
            if (cbvh_fbvh_build(&b, &fb, err, sizeof err) ||
                cbvh_trace_bvh_float(&fb, s.tris, &bad[i], CBVH_TRAV_CLOSEST, &h, &st) != -1 || h.hit)
                failures++;
            cbvh_fbvh_free(&fb);
            if (cbvh_trace_cbvh(&t, s.tris, &bad[i], 24, CBVH_TRAV_CLOSEST, &h, &st) != -1 || h.hit) failures++;
            cbvh_cbvh_decoded dt;
            if (cbvh_cbvh_decode(&t, &dt, err, sizeof err) || !dt.usable ||
                cbvh_trace_cbvh_decoded(&dt, s.tris, &bad[i], 24, CBVH_TRAV_CLOSEST, &h, &st) != -1 || h.hit)
                failures++;
            cbvh_cbvh_decoded_free(&dt);
            if (st.box_tests || st.tri_tests) failures++;
        }
        cbvh_tree_free(&t);
    } else
        failures++;
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* The plain traversal's layout: a one-leaf BVH (no records) traces like the
 * unit traversal; what is not a tree is refused with a reason. */
static void layout_cases(void) {
    {
        cbvh_tri tri = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}; /* floats, not bit patterns */
        cbvh_bvh_node leaf = {{0, 0, 0}, {1, 1, 0}, {0, 0}, 0, 1};
        uint32_t prim = 0;
        cbvh_bvh b1 = {&leaf, 1, 0, &prim, 1};
        cbvh_fbvh f1;
        char e1[256] = "";
        cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(1)}, {0, CBVH_F32_SIGN, fb(-1)}, 0, CBVH_F32_POS_INF};
        cbvh_trav_hit hp, hu;
        cbvh_trav_stats sp = {0}, su = {0};
        if (cbvh_fbvh_build(&b1, &f1, e1, sizeof e1) || f1.nnodes != 0 ||
            cbvh_trace_bvh_float(&f1, &tri, &r, CBVH_TRAV_CLOSEST, &hp, &sp) ||
            cbvh_trace_bvh(&b1, &tri, &r, 24, CBVH_TRAV_CLOSEST, &hu, &su) || !hp.hit || !same_hit(&hp, &hu) ||
            hp.t != fb(1) || sp.box_tests != 1 || sp.tri_tests != 1 || sp.nodes != 0 || sp.lines != su.lines) {
            fprintf(stderr, "FAIL one-leaf BVH: plain hit %d t %08X, unit hit %d (%s)\n", hp.hit, hp.t, hu.hit, e1);
            failures++;
        }
        cbvh_fbvh_free(&f1);
    }
    cbvh_bvh_node nodes[3] = {{{0, 0, 0}, {1, 1, 1}, {1, 2}, 0, 0},
                              {{0, 0, 0}, {1, 1, 1}, {0, 0}, 0, 1},
                              {{0, 0, 0}, {1, 1, 1}, {0, 0}, 1, 1}};
    uint32_t prims[2] = {0, 1};
    cbvh_bvh b = {nodes, 3, 0, prims, 2};
    cbvh_fbvh f;
    char err[256] = "";
    if (cbvh_fbvh_build(&b, &f, err, sizeof err) || f.nnodes != 1 || f.root != 0 ||
        f.nodes[0].child[1] != (CBVH_FBVH_LEAF | 1u) || f.nodes[0].count[1] != 1) {
        fprintf(stderr, "FAIL layout of a 3-node tree: %s\n", err);
        failures++;
    }
    cbvh_fbvh_free(&f);
    nodes[0].child[1] = 0; /* a cycle */
    if (cbvh_fbvh_build(&b, &f, err, sizeof err) != -1 || !strstr(err, "not a tree") || f.nodes) {
        fprintf(stderr, "FAIL cyclic BVH accepted by the layout (%s)\n", err);
        failures++;
    }
    nodes[0].child[1] = 7; /* out of range */
    if (cbvh_fbvh_build(&b, &f, err, sizeof err) != -1 || !strstr(err, "not a tree")) {
        fprintf(stderr, "FAIL out-of-range child accepted by the layout (%s)\n", err);
        failures++;
    }
}

/* The 4-wide plain float layout: a one-leaf tree, a root with two leaves,
 * QBVHs it must refuse with a reason, and the leaf copy read only for the
 * triangle array it was made from. */
static void wide_layout_cases(void) {
    /* floats, not bit patterns: triangle 1 one unit below triangle 0 */
    cbvh_tri tri[2] = {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, {{{0, 0, -1}, {1, 0, -1}, {0, 1, -1}}}};
    cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(1)}, {0, CBVH_F32_SIGN, fb(-1)}, 0, CBVH_F32_POS_INF};
    cbvh_bvh_node leaf = {{0, 0, -1}, {1, 1, 0}, {0, 0}, 0, 2};
    uint32_t prims[2] = {1, 0};
    cbvh_bvh b1 = {&leaf, 1, 0, prims, 2};
    cbvh_bvh_node nodes[3] = {{{0, 0, -1}, {1, 1, 0}, {1, 2}, 0, 0},
                              {{0, 0, -1}, {1, 1, -1}, {0, 0}, 0, 1},
                              {{0, 0, 0}, {1, 1, 0}, {0, 0}, 1, 1}};
    cbvh_bvh b3 = {nodes, 3, 0, prims, 2};
    char err[256] = "";
    for (int W = 0; W < 2; W++) /* both layouts: 4- and 8-wide */
        for (int k = 0; k < 2; k++) {
            any_wide f;
            cbvh_trav_hit hw = {0}, hu;
            cbvh_trav_stats sw = {0}, su = {0};
            const cbvh_bvh *b = k ? &b3 : &b1;
            int ok = !aw_build(&f, W, b, tri, 2, err, sizeof err);
            /* with two leaves the farther one (triangle 1) is culled after the nearer hit */
            ok = ok && aw_nrecs(&f) == (uint32_t)k && aw_leaf_tris(&f) && aw_leaf_tris(&f)[0].id == 1 &&
                 !aw_trace(&f, tri, &r, CBVH_TRAV_CLOSEST, &hw, &sw) &&
                 !cbvh_trace_bvh(b, tri, &r, 24, CBVH_TRAV_CLOSEST, &hu, &su) && hw.hit && same_hit(&hw, &hu) &&
                 hw.prim == 0 && hw.t == fb(1) && sw.tri_tests == (k ? 1u : 2u) && sw.nodes == (uint64_t)k &&
                 sw.box_tests == 1 + 2 * (uint64_t)k && sw.lines == su.lines - (uint64_t)k + (uint64_t)k * (W ? 4 : 2);
            if (ok && k) /* the root's record: two leaf children, the other slots empty */
                ok = aw_valid(&f, 0) == 3 && aw_child(&f, 0, 1) == (CBVH_FQBVH_LEAF | 1u) && aw_count(&f, 0, 1) == 1;
            if (ok) { /* another triangle array (triangle 0 moved): read, not the copy */
                cbvh_tri moved[2] = {tri[0], tri[1]};
                for (int v = 0; v < 3; v++) moved[0].v[v][2] = -0.5f;
                ok = !aw_trace(&f, moved, &r, CBVH_TRAV_CLOSEST, &hw, &sw) && hw.hit && hw.prim == 0 &&
                     hw.t == fb(1.5f);
            }
            if (!ok) {
                fprintf(stderr, "FAIL %s layout of a %d-node tree: hit %d prim %u t %08X (%s)\n", wide_name[W],
                        k ? 3 : 1, hw.hit, hw.prim, hw.t, err);
                failures++;
            }
            aw_free(&f);
        }
    /* A chain of 4-child nodes, all boxes [0, 1]^2 x [-1, 0]: each level defers its three leaves
     * (ties: slot 0, the next level, first), so the stack grows by 3 a level: depth 20 fits
     * (max_stack 3 * 20 + 1, 20 nodes), depth 100 overflows (-1); a ray missing the root
     * leaves max_stack 0. */
    for (int depth = 20; depth <= 100; depth += 80) {
        uint32_t nn = 1 + 4 * (uint32_t)depth, cf[401], cc[401], pz = 0;
        float cmin[401][4], cmax[401][4];
        for (uint32_t i = 0; i < nn; i++) {
            float lo4[4] = {0, 0, -1, 0}, hi4[4] = {1, 1, 0, 0};
            memcpy(cmin[i], lo4, sizeof lo4);
            memcpy(cmax[i], hi4, sizeof hi4);
            cf[i] = 0;
            cc[i] = CBVH_QBVH_LEAF | 1;
        }
        for (int j = 0; j < depth; j++) { /* level j's inner node, its children at 1 + 4j .. */
            uint32_t in = j ? 1 + 4 * (uint32_t)(j - 1) : 0;
            cf[in] = 1 + 4 * (uint32_t)j;
            cc[in] = 4;
        }
        cbvh_qbvh cq = {nn, cmin, cmax, cf, cc, &pz, 1, 0, 0};
        cbvh_fqbvh cfq;
        cbvh_trav_hit ch;
        cbvh_trav_stats cs = {0}, cm = {0};
        cbvh_ray miss = r;
        miss.o[0] = fb(5.0f); /* beside the root box */
        int built = !cbvh_fqbvh_build(&cq, NULL, 0, &cfq, err, sizeof err);
        int rc = built ? cbvh_trace_qbvh_float(&cfq, tri, &r, CBVH_TRAV_CLOSEST, &ch, &cs) : -9;
        int rm = built ? cbvh_trace_qbvh_float(&cfq, tri, &miss, CBVH_TRAV_CLOSEST, &ch, &cm) : -9;
        int ok = depth == 20 ? rc == 0 && cs.max_stack == 61 && cs.nodes == 20 : rc == -1;
        if (!ok || rm != 0 || ch.hit || cm.max_stack != 0 || cm.box_tests != 1) {
            fprintf(stderr, "FAIL 4-wide chain depth %d: rc %d max_stack %u nodes %llu; miss rc %d max_stack %u (%s)\n",
                    depth, rc, cs.max_stack, (unsigned long long)cs.nodes, rm, cm.max_stack, err);
            failures++;
        }
        if (built) cbvh_fqbvh_free(&cfq);
    }
    /* hand-made QBVHs: a child before its parent, a leaf past the IDs, a leaf too large */
    float bmin[3][4] = {{0}}, bmax[3][4] = {{1, 1, 1, 0}, {1, 1, 1, 0}, {1, 1, 1, 0}};
    uint32_t first[3] = {1, 0, 1}, count[3] = {2, CBVH_QBVH_LEAF | 1, CBVH_QBVH_LEAF | 1};
    static uint32_t many[70000];
    cbvh_qbvh q = {3, bmin, bmax, first, count, many, 2, 1, 1};
    struct {
        uint32_t node, first, count;
        const char *why;
    } bad[] = {{0, 0, 2, "bad children"},
               {0, 2, 2, "bad children"},
               {0, 1, 1, "bad children"},
               {2, 2, CBVH_QBVH_LEAF | 1, "out of bounds"},
               {2, 0, CBVH_QBVH_LEAF, "out of bounds"},
               {2, 0, CBVH_QBVH_LEAF | 65536, "above 65535"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint32_t f0 = first[bad[i].node], c0 = count[bad[i].node];
        first[bad[i].node] = bad[i].first;
        count[bad[i].node] = bad[i].count;
        q.nprims = bad[i].count == (CBVH_QBVH_LEAF | 65536) ? 70000 : 2;
        cbvh_fqbvh f;
        err[0] = 0;
        if (cbvh_fqbvh_build(&q, NULL, 0, &f, err, sizeof err) != -1 || !strstr(err, bad[i].why) || f.nodes) {
            fprintf(stderr, "FAIL 4-wide layout accepted bad QBVH %zu (%s)\n", i, err);
            failures++;
        }
        first[bad[i].node] = f0;
        count[bad[i].node] = c0;
    }
    q.nprims = 2;
    cbvh_fqbvh f;
    if (cbvh_fqbvh_build(&q, NULL, 0, &f, err, sizeof err) || f.nnodes != 1 || f.leaf_tris) {
        fprintf(stderr, "FAIL 4-wide layout refused a good QBVH (%s)\n", err);
        failures++;
    }
    cbvh_fqbvh_free(&f);
}

/* The 8-wide layout (docs/traversal.md §14; the one-leaf and two-leaf trees
 * are wide_layout_cases'): a complete binary tree of depth 3 collapsed into
 * one record of eight leaves, a depth-4 tree of ties, and malformed binary
 * BVHs refused with their reason. */
static void wide8_layout_cases(void) {
    cbvh_tri tri[8] = {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}};
    for (int i = 1; i < 8; i++) /* triangles 1..7 below triangle 0 */
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) tri[i].v[v][a] = a < 2 ? tri[0].v[v][a] : -(float)i;
    cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(1)}, {0, CBVH_F32_SIGN, fb(-1)}, 0, CBVH_F32_POS_INF};
    uint32_t prims[8] = {1, 0, 2, 3, 4, 5, 6, 7};
    char err[256] = "";
    /* complete binary tree of depth 3: inner nodes 0..6 (children 2i + 1, 2i + 2), leaves 7..14
     * with one triangle each; leaf j's box encloses triangle prims[j - 7] */
    cbvh_bvh_node full[15];
    for (uint32_t i = 0; i < 15; i++) {
        cbvh_bvh_node n = {{0, 0, -7}, {1, 1, 0}, {0, 0}, 0, 0};
        if (i < 7) {
            n.child[0] = 2 * i + 1;
            n.child[1] = 2 * i + 2;
        } else {
            n.first = i - 7;
            n.count = 1;
            float z = tri[prims[i - 7]].v[0][2];
            n.lo[2] = n.hi[2] = z;
        }
        full[i] = n;
    }
    cbvh_bvh b15 = {full, 15, 0, prims, 8};
    cbvh_f8bvh f;
    cbvh_trav_hit hw = {0}, hu = {0};
    cbvh_trav_stats sw = {0}, su = {0};
    int ok = !cbvh_f8bvh_build(&b15, NULL, 0, &f, err, sizeof err) && f.nnodes == 1 && f.nodes[0].valid == 255 &&
             !cbvh_trace_f8bvh_float(&f, tri, &r, CBVH_TRAV_CLOSEST, &hw, &sw) &&
             !cbvh_trace_bvh(&b15, tri, &r, 24, CBVH_TRAV_CLOSEST, &hu, &su) && same_hit(&hw, &hu) && hw.prim == 0 &&
             sw.nodes == 1 && sw.box_tests == 9 && sw.tri_tests == 1;
    for (int c = 0; ok && c < 8; c++) /* slots in the binary tree's left-to-right order */
        ok = f.nodes[0].child[c] == (CBVH_F8BVH_LEAF | (uint32_t)c) && f.nodes[0].count[c] == 1 &&
             f.nodes[0].pl[(0 * 3 + 2) * 8 + c] == tri[prims[c]].v[0][2];
    if (!ok) {
        fprintf(stderr, "FAIL 8-wide collapse of a depth-3 tree: hit %d prim %u, %llu box tests (%s)\n", hw.hit,
                hw.prim, (unsigned long long)sw.box_tests, err);
        failures++;
    }
    cbvh_f8bvh_free(&f);
    /* malformed: a child outside the BVH, a child back to the root, a leaf past the IDs, a leaf too large */
    static uint32_t many[70000];
    struct {
        uint32_t node, child0, first, count;
        const char *why;
    } bad[] = {{0, 99, 0, 0, "outside the BVH"},
               {1, 0, 0, 0, "reached twice"},
               {9, 0, 8, 1, "out of bounds"},
               {9, 0, 0, 65536, "above 65535"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cbvh_bvh_node keep = full[bad[i].node];
        if (bad[i].count) {
            full[bad[i].node].first = bad[i].first;
            full[bad[i].node].count = bad[i].count;
        } else {
            full[bad[i].node].child[0] = bad[i].child0;
        }
        cbvh_bvh bb = {full, 15, 0, bad[i].count == 65536 ? many : prims, bad[i].count == 65536 ? 70000 : 8};
        err[0] = 0;
        if (cbvh_f8bvh_build(&bb, NULL, 0, &f, err, sizeof err) != -1 || !strstr(err, bad[i].why) || f.nodes) {
            fprintf(stderr, "FAIL 8-wide layout accepted bad BVH %zu (%s)\n", i, err);
            failures++;
        }
        full[bad[i].node] = keep;
    }
    /* Complete binary tree of depth 4, all boxes equal (every choice a tie): the leftmost
     * inner child is opened first, so the root's record holds leaves 15..20, then inner
     * node 10 and inner node 2 (records 1 and 2: depth-first, 10's before 2's); a direct
     * child of a later record (node 10's) that is already in the root's record is refused. */
    cbvh_bvh_node deep[31];
    static uint32_t prims16[16];
    for (uint32_t i = 0; i < 31; i++) {
        cbvh_bvh_node n = {{0, 0, -7}, {1, 1, 0}, {0, 0}, 0, 0};
        if (i < 15) {
            n.child[0] = 2 * i + 1;
            n.child[1] = 2 * i + 2;
        } else {
            n.first = prims16[i - 15] = i - 15;
            n.count = 1;
        }
        deep[i] = n;
    }
    cbvh_bvh b31 = {deep, 31, 0, prims16, 16};
    ok = !cbvh_f8bvh_build(&b31, NULL, 0, &f, err, sizeof err) && f.nnodes == 3 && f.nodes[0].valid == 255 &&
         f.nodes[0].child[6] == 1 && f.nodes[0].child[7] == 2 && f.nodes[1].valid == 3 && f.nodes[2].valid == 255;
    for (int c = 0; ok && c < 6; c++) ok = f.nodes[0].child[c] == (CBVH_F8BVH_LEAF | (uint32_t)c);
    for (int c = 0; ok && c < 8; c++) ok = f.nodes[2].child[c] == (CBVH_F8BVH_LEAF | (uint32_t)(8 + c));
    if (!ok) {
        fprintf(stderr, "FAIL 8-wide collapse of a depth-4 tree of ties: %u records (%s)\n", f.nnodes, err);
        failures++;
    }
    cbvh_f8bvh_free(&f);
    deep[10].child[0] = 15;
    if (cbvh_f8bvh_build(&b31, NULL, 0, &f, err, sizeof err) != -1 || !strstr(err, "reached twice")) {
        fprintf(stderr, "FAIL 8-wide layout accepted a leaf reached twice (%s)\n", err);
        failures++;
    }
    cbvh_bvh broot = {full, 15, 15, prims, 8};
    if (cbvh_f8bvh_build(&broot, NULL, 0, &f, err, sizeof err) != -1 || !strstr(err, "supported")) {
        fprintf(stderr, "FAIL 8-wide layout accepted a root outside the BVH (%s)\n", err);
        failures++;
    }
}

/* A one-pair CBVH over [0, 1]^3 (N = 6, relative codes): child 0 with the
 * pair's own box, an inner node at pair `ptr` or a leaf whose IDs start at
 * `ptr`; child 1 empty.  pair_bytes 16, or padded to 32 (the fast decode takes
 * only pairs of the codec's width: the unit then decodes).  0 on success. */
static int one_pair_cbvh(cbvh_tree *t, uint8_t pair[32], int leaf, uint32_t ptr, int padded) {
    memset(t, 0, sizeof *t);
    memset(pair, 0, 32);
    t->params.quant_bits = 6;
    t->params.min_scale = -30;
    t->enc = CBVH_ENC_RELATIVE;
    cbvh_child_in in[2];
    cbvh_child_out out[2];
    memset(in, 0, sizeof in);
    for (int a = 0; a < 3; a++) {
        t->root_lo[a] = in[0].lo[a] = fb(0);
        t->root_hi[a] = in[0].hi[a] = fb(1);
        if (cbvh_axis_root_ctx(&t->params, t->root_lo[a], t->root_hi[a], &t->root_ctx.axis[a])) return -1;
    }
    in[0].leaf = leaf;
    in[0].ptr = ptr;
    in[1].empty = 1;
    in[1].leaf = 1;
    if (cbvh_nodepair_encode(&t->params, t->enc, &t->root_ctx, in, pair, out)) return -1;
    t->pair_bytes = padded ? 32 : cbvh_nodepair_bytes(6);
    t->npairs = 1;
    t->pairs = pair;
    return 0;
}

/* A CBVH whose pair 0 has an inner child pointing back to pair 0 with the
 * pair's own box (relative codes 0 and 2^N: the child's context is the
 * pair's), so every visit hits it again: -1 after npairs visits, not a hang
 * (docs/traversal.md §5, a malformed tree).  Both decoders: the fast path and
 * the unit. */
static void cyclic_cbvh(void) {
    for (int unit = 0; unit < 2; unit++) {
        cbvh_tree t;
        uint8_t pair[32];
        if (one_pair_cbvh(&t, pair, 0, 0, unit)) {
            fprintf(stderr, "FAIL cyclic CBVH: cannot encode\n");
            failures++;
            return;
        }
        cbvh_tri tri = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}; /* floats, not bit patterns */
        cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(2)}, {0, 0, fb(-1)}, 0, CBVH_F32_POS_INF};
        cbvh_trav_hit h;
        cbvh_trav_stats st = {0};
        int rc = cbvh_trace_cbvh(&t, &tri, &r, 24, CBVH_TRAV_CLOSEST, &h, &st);
        if (rc != -1 || h.hit) {
            fprintf(stderr, "FAIL cyclic CBVH (%s decode): rc %d hit %d, want -1 and no hit\n",
                    unit ? "unit" : "fast", rc, h.hit);
            failures++;
        }
        /* not a tree: the decoded copy is not usable and tracing keeps the -1 */
        cbvh_cbvh_decoded dt;
        char err[256] = "";
        if (cbvh_cbvh_decode(&t, &dt, err, sizeof err) || dt.usable || dt.nodes ||
            !decoded_same(&dt, &tri, &r, 24, CBVH_TRAV_CLOSEST)) {
            fprintf(stderr, "FAIL cyclic CBVH (%s decode): decoded copy usable %d (%s)\n", unit ? "unit" : "fast",
                    dt.usable, err);
            failures++;
        }
        cbvh_cbvh_decoded_free(&dt);
    }
}

/* Trees the decoded copy must leave to the per-visit traversal (usable = 0),
 * which then gives its own result (here -1: the ray reaches the bad part):
 * an inner child pointing past the last pair, an inverted child box the
 * node-pair unit rejects, a root context the unit rejects, no pairs at all,
 * pairs padded to another width (the fast decode's case: the unit decodes). */
static void decoded_malformed(void) {
    static const char *const what[5] = {"pointer out of range", "inverted child", "bad root context", "no pairs",
                                        "padded pairs"};
    cbvh_tri tri = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}; /* floats, not bit patterns */
    cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(2)}, {0, 0, fb(-1)}, 0, CBVH_F32_POS_INF};
    for (int k = 0; k < 5; k++) {
        cbvh_tree t;
        uint8_t pair[32];
        uint32_t id = CBVH_ID_LAST;
        if (one_pair_cbvh(&t, pair, k == 4, k == 4 ? 0 : 5, k == 4)) {
            failures++;
            continue;
        }
        t.ids = &id;
        t.nids = 1;
        if (k == 1) { /* child 0, x: codes r = 7, s = 3 (0 and 2^N before) */
            pair[0] = 7u | 3u << 6;
            pair[1] &= (uint8_t)~0x0Fu;
        }
        if (k == 2) t.root_ctx.axis[1].lb_mod = 64;
        if (k == 3) t.npairs = 0;
        cbvh_cbvh_decoded dt;
        char err[256] = "";
        cbvh_trav_hit h;
        cbvh_trav_stats st = {0};
        int rc = cbvh_trace_cbvh(&t, &tri, &r, 24, CBVH_TRAV_CLOSEST, &h, &st);
        if (cbvh_cbvh_decode(&t, &dt, err, sizeof err) || dt.usable ||
            !decoded_same(&dt, &tri, &r, 24, CBVH_TRAV_CLOSEST) || rc != (k == 4 ? 0 : -1)) {
            fprintf(stderr, "FAIL decoded CBVH, %s: usable %d, per-visit rc %d (%s)\n", what[k], dt.usable, rc, err);
            failures++;
        }
        cbvh_cbvh_decoded_free(&dt);
    }
}

/* The leaf copy (cbvh_cbvh_decode_leaves): tracing reads it only when given
 * the triangle array it was copied from, and reads the array it is given
 * otherwise; an ID not below ntris, or a decoded copy that is not usable:
 * no leaf copy (0, not an error). */
static void decoded_leaves(void) {
    for (int padded = 0; padded < 2; padded++) {
        cbvh_tree t;
        uint8_t pair[32];
        uint32_t id = CBVH_ID_LAST; /* triangle 0, the leaf's last */
        if (one_pair_cbvh(&t, pair, 1, 0, padded)) {
            failures++;
            return;
        }
        t.ids = &id;
        t.nids = 1;
        cbvh_tri tri = {{{0, 0, 0.5f}, {1, 0, 0.5f}, {0, 1, 0.5f}}}, moved = tri; /* floats */
        for (int k = 0; k < 3; k++) moved.v[k][2] = 0.25f;
        cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(2)}, {0, 0, fb(-1)}, 0, CBVH_F32_POS_INF};
        cbvh_cbvh_decoded dt;
        char err[256] = "";
        int ok = cbvh_cbvh_decode(&t, &dt, err, sizeof err) == 0 && dt.usable == !padded &&
                 cbvh_cbvh_decode_leaves(&dt, &tri, 1, err, sizeof err) == 0 && (dt.leaf_tris == NULL) == padded &&
                 decoded_same(&dt, &tri, &r, 24, CBVH_TRAV_CLOSEST) &&
                 decoded_same(&dt, &moved, &r, 24, CBVH_TRAV_CLOSEST);
        cbvh_trav_hit h1 = {0}, h2 = {0};
        cbvh_trav_stats st = {0};
        ok = ok && cbvh_trace_cbvh_decoded(&dt, &tri, &r, 24, CBVH_TRAV_CLOSEST, &h1, &st) == 0 &&
             cbvh_trace_cbvh_decoded(&dt, &moved, &r, 24, CBVH_TRAV_CLOSEST, &h2, &st) == 0 && h1.hit && h2.hit &&
             h1.t == fb(1.5f) && h2.t == fb(1.75f);
        ok = ok && cbvh_cbvh_decode_leaves(&dt, &tri, 0, err, sizeof err) == 0 && !dt.leaf_tris && !dt.leaf_src &&
             decoded_same(&dt, &tri, &r, 24, CBVH_TRAV_CLOSEST);
        /* the record of a pair with an empty slot (its dummy box [u, u + 2^e]) */
        long exact = 0, f32 = 0;
        ok = ok && (padded || (decoded_vs_unit(&dt, &exact, &f32) == 0 && exact == 1 && f32 == 1));
        if (!ok) {
            fprintf(stderr, "FAIL decoded CBVH leaf copy (%s pairs): usable %d, copy %d, hits %d %d at %08x %08x (%s)\n",
                    padded ? "padded" : "plain", dt.usable, dt.leaf_tris != NULL, h1.hit, h2.hit, h1.t, h2.t, err);
            failures++;
        }
        cbvh_cbvh_decoded_free(&dt);
    }
}

/* The byte counters follow the memory image of docs/traversal.md §5 (node
 * pairs from 0, then the 4-byte IDs, then the 36-byte triangles, each region
 * on a 64-byte line; every read counts the lines it covers): a one-pair CBVH
 * whose leaf's single ID sits at every index 0..63 of the ID array and names
 * triangle 0..15, so that every ID offset within a line and both triangle
 * alignments occur.  Expected lines, spelled out from the map: the pair (one
 * line), the ID (4 bytes at a multiple of 4: one line), the triangle. */
static void memory_map(void) {
    cbvh_tri tris[16];
    for (int i = 0; i < 16; i++) {
        const float v[3][3] = {{0, 0, 0.5f}, {1, 0, 0.5f}, {0, 1, 0.5f}};
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) tris[i].v[k][a] = v[k][a];
    }
    uint32_t ids[64];
    long bad = 0;
    for (uint32_t p = 0; p < 64; p++)
        for (uint32_t id = 0; id < 16; id++)
            for (int unit = 0; unit < 2; unit++) {
                cbvh_tree t;
                uint8_t pair[32];
                if (one_pair_cbvh(&t, pair, 1, p, unit)) {
                    bad++;
                    continue;
                }
                for (uint32_t i = 0; i < 64; i++) ids[i] = i == p ? id | CBVH_ID_LAST : CBVH_ID_LAST;
                t.ids = ids;
                t.nids = p + 1;
                uint64_t ids_base = (t.npairs * t.pair_bytes + 63) / 64 * 64;
                uint64_t tris_base = (ids_base + 4u * t.nids + 63) / 64 * 64, ta = tris_base + 36u * id;
                uint64_t want = 1 + 1 + ((ta + 35) / 64 - ta / 64 + 1);
                cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(2)}, {0, 0, fb(-1)}, 0, CBVH_F32_POS_INF};
                cbvh_trav_hit h;
                cbvh_trav_stats st = {0};
                int rc = cbvh_trace_cbvh(&t, tris, &r, 24, CBVH_TRAV_CLOSEST, &h, &st);
                if (rc || !h.hit || h.prim != id || st.nodes != 1 || st.tri_tests != 1 || st.lines != want ||
                    st.bytes != 64 * want) {
                    if (bad++ < 5)
                        fprintf(stderr, "FAIL memory map: ID index %u, triangle %u (%s decode): rc %d hit %d prim %u, "
                                        "%llu lines / %llu bytes, want %llu\n",
                                p, id, unit ? "unit" : "fast", rc, h.hit, h.prim, (unsigned long long)st.lines,
                                (unsigned long long)st.bytes, (unsigned long long)want);
                }
            }
    failures += bad;
}

int main(void) {
    bad_rays();
    layout_cases();
    wide_layout_cases();
    wide8_layout_cases();
    cyclic_cbvh();
    decoded_malformed();
    decoded_leaves();
    memory_map();
    run_scene(CBVH_SCENES_DIR "/bunny-small.obj", 0);
    run_scene("proc:far:8", 0);
    run_scene("proc:cloth:24", 0);
    run_scene(CBVH_SCENES_DIR "/bunny-small.obj", 64);
    if (failures) fprintf(stderr, "%ld failures\n", failures);
    return failures ? 1 : 0;
}
