/* Build benchmark (the builders' throughput targets): float LBVH throughput,
 * streaming bottom-up CBVH build vs the float LBVH build in the same run,
 * top-down compression, and CBVH bytes vs float BVH bytes.
 *
 * usage: bench_build [--reps R] [--warm] [--json FILE] [SCENE...]
 *   SCENE as for `cbvh study` (file or proc:NAME[:SIZE]); default: the bundled
 *   bunny and proc:instanced (10.24 M triangles).
 *   --warm: glibc keeps freed memory (no mmap for large blocks, no trimming)
 *   and one untimed repetition runs first, so the timed builds reuse pages
 *   already touched.  Without it every large buffer is fresh memory, and on
 *   a VM whose host backs a page at first touch that cost (measured up to
 *   ~12 us per 4 KiB page) lands in both sides of every ratio
 *   (docs/results.md, "Build throughput").
 *   --json FILE: the same figures for machines, written to FILE (temporary
 *   file, then renamed, so a failed run leaves no half-written FILE).
 * Times are the best of R repetitions (default 3), one core.  Both sides of
 * the ratio build the LBVH the same way (Morton codes, sort and all): the
 * float build alone, and the float build followed by the streaming
 * compression (bu_ms: that compression alone, timed inside the same run).
 * bu/lbvh compares the best of each; run_ratio is the best over repetitions
 * of (LBVH + BU) / LBVH with both from the same repetition, steadier when
 * other jobs share the machine.  fused_ms: the fused build
 * (cbvh_build_lbvh_streaming: the same LBVH with the compression inside its
 * bottom-up pass, same output bits, timed right after the LBVH alone),
 * fused/lbvh the ratio of the bests and fused_med the median over
 * repetitions of fused / LBVH with both from the same repetition.
 * arith_ms: the bare arithmetic of Algorithm 1's per-pair step alone, on
 * the LBVH's own nodes packed beforehand (untimed): each inner node's three
 * scale estimates and context codes and its leaf children's six floors,
 * through the units' inline fast paths (rtl-model/src/fast/unit_fast.h) -- no
 * stack, no records, no packing, no backtracking, no inner children.  Any
 * scalar step built on these fast paths does at least that, so
 * min_fused = 1 + arith_ms / lbvh_ms (bests) is a floor under fused/lbvh
 * (docs/results.md, "Build throughput": the floor). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cjson/cJSON.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "bench_json.h"
#include "scene/scene_load.h"
#include "fast/unit_fast.h"

#ifndef CBVH_SCENES_DIR
#define CBVH_SCENES_DIR "scenes"
#endif

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void die(const char *what, const char *err) {
    fprintf(stderr, "bench_build: %s: %s\n", what, err);
    exit(1);
}

/* One inner node's inputs to the step, as binary32 bit patterns. */
typedef struct {
    cbvh_f32 box[6];     /* lo[3], hi[3] */
    cbvh_f32 leaf[2][6]; /* its leaf children's boxes, nleaf of them */
    uint32_t nleaf;
} arith_rec;

static size_t arith_pack(const cbvh_bvh *b, arith_rec *r) {
    size_t n = 0;
    for (uint32_t x = 0; x < b->nnodes; x++) {
        const cbvh_bvh_node *nd = &b->nodes[x];
        if (cbvh_bvh_is_leaf(nd)) continue;
        arith_rec *q = &r[n++];
        q->nleaf = 0;
        for (int a = 0; a < 3; a++) q->box[a] = cbvh_f32_of(nd->lo[a]), q->box[3 + a] = cbvh_f32_of(nd->hi[a]);
        for (int c = 0; c < 2; c++) {
            const cbvh_bvh_node *cn = &b->nodes[nd->child[c]];
            if (!cbvh_bvh_is_leaf(cn)) continue;
            for (int a = 0; a < 3; a++)
                q->leaf[q->nleaf][a] = cbvh_f32_of(cn->lo[a]), q->leaf[q->nleaf][3 + a] = cbvh_f32_of(cn->hi[a]);
            q->nleaf++;
        }
    }
    return n;
}

static volatile uint64_t arith_sink;

/* The arithmetic every step does (see the header).  Returns how many
 * inputs left the fast paths (they would take the units' general paths). */
static uint64_t arith_step(const arith_rec *r, size_t n, int nq, int ms) {
    uint64_t sum = 0, slow = 0;
    for (size_t i = 0; i < n; i++) {
        int cs[3];
        for (int a = 0; a < 3; a++) {
            int e = 0;
            int64_t k = 0, ku = 0;
            uint32_t lm = 0, um = 0;
            slow += cbvh_scale_estimate_fast_nm(nq, ms, r[i].box[a], r[i].box[3 + a], &e, &k, &ku) != 2;
            slow += !cbvh_fast_code(nq, ms, e, k, ku, &lm, &um, &cs[a]);
            sum += lm ^ um;
        }
        for (uint32_t c = 0; c < r[i].nleaf; c++)
            for (int a = 0; a < 3; a++) {
                int64_t k, ku;
                slow += !(cbvh_fast_floor(r[i].leaf[c][a], cs[a], &k) & cbvh_fast_floor(r[i].leaf[c][3 + a], cs[a], &ku));
                sum += (uint64_t)(ku - k);
            }
    }
    arith_sink = sum;
    return slow;
}

int main(int argc, char **argv) {
    int reps = 3, warm = 0;
    const char *specs[64], *json = NULL;
    int ns = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            char *end;
            errno = 0;
            long v = strtol(argv[++i], &end, 10);
            if (errno || end == argv[i] || *end || v < 1 || v > 100) die("--reps", "must be an integer 1..100");
            reps = (int)v;
        } else if (!strcmp(argv[i], "--warm")) {
#if defined(__GLIBC__)
            warm = 1;
#else
            die("--warm", "needs glibc's mallopt");
#endif
        } else if (!strcmp(argv[i], "--json") && i + 1 < argc) {
            json = argv[++i];
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: bench_build [--reps R] [--warm] [--json FILE] [SCENE...]\n");
            return 2;
        } else if (ns < 64) {
            specs[ns++] = argv[i];
        } else {
            die(argv[i], "at most 64 scenes");
        }
    }
#if defined(__GLIBC__)
    if (warm && (!mallopt(M_MMAP_MAX, 0) || !mallopt(M_TRIM_THRESHOLD, INT_MAX)))
        die("--warm", "mallopt refused the settings");
#endif
    if (!ns) {
        specs[ns++] = CBVH_SCENES_DIR "/bunny-small.obj";
        specs[ns++] = "proc:instanced";
    }
    char err[512];
    cJSON *jroot = cJSON_CreateObject(), *jscenes = cJSON_AddArrayToObject(jroot, "scenes");
    if (!jroot || !jscenes) die("--json", "out of memory");
    cJSON_AddNumberToObject(jroot, "reps", reps);
    cJSON_AddBoolToObject(jroot, "warm", warm);
    cJSON_AddNumberToObject(jroot, "quant_bits", 6);
    cJSON_AddStringToObject(jroot, "encoding", "modulo");
    cJSON_AddNumberToObject(jroot, "treelet_depth", 4);
    if (warm) printf("# --warm: freed memory kept for reuse, one untimed repetition first\n");
    printf("%-24s %10s %10s %9s %9s %9s %9s %7s %9s %7s %9s %11s %9s %11s %11s %6s %9s %9s\n", "scene", "triangles", "lbvh_ms",
           "Mtri/s", "lbvh+bu", "bu_ms", "lbvh+td", "bu/lbvh", "run_ratio", "td/lbvh", "fused_ms", "fused/lbvh",
           "fused_med", "cbvh_bytes", "float_bytes", "ratio", "arith_ms", "min_fused");
    for (int i = 0; i < ns; i++) {
        cbvh_scene s;
        if (cbvh_scene_open(specs[i], &s, err, sizeof err)) die(specs[i], err);
        cbvh_compress_opts o = {{CBVH_N_DEFAULT, CBVH_MIN_SCALE_DEFAULT}, CBVH_ENC_MODULO, 4, 0};
        double best_l = 1e30, best_bu = 1e30, best_td = 1e30, best_c = 1e30, best_run = 1e30, best_f = 1e30,
               fr[100] = {0}, best_a = 1e30;
        uint64_t slow = 0;
        size_t cb = 0, fb = 0, nar = 0;
        arith_rec *ar = NULL; /* the LBVH's inner nodes, packed once per scene */
        for (int r = -warm; r < reps; r++) { /* r < 0: the untimed warm-up */
            cbvh_bvh b;
            cbvh_tree t;
            cbvh_bu_stats st;
            /* float LBVH alone */
            double t0 = now();
            if (cbvh_build_lbvh(&s, &b, err, sizeof err)) die(specs[i], err);
            double t1 = now();
            cbvh_bvh_free(&b);
            /* fused LBVH + streaming compression, right after the LBVH alone
             * so that the pair sees the same machine load */
            double t6 = now();
            if (cbvh_build_lbvh_streaming(&s, &o, &b, &t, &st, err, sizeof err)) die(specs[i], err);
            double t7 = now();
            size_t fused_bytes = cbvh_tree_bytes(&t);
            cbvh_tree_free(&t);
            cbvh_bvh_free(&b);
            if (r >= 0 && t7 - t6 < best_f) best_f = t7 - t6;
            if (r >= 0) fr[r] = (t7 - t6) / (t1 - t0);
            /* LBVH + streaming bottom-up compression (the CBVH build) */
            double t2 = now();
            if (cbvh_build_lbvh(&s, &b, err, sizeof err)) die(specs[i], err);
            double t2c = now();
            if (cbvh_compress_bottomup(&b, NULL, &o, &t, &st, err, sizeof err)) die(specs[i], err);
            double t3 = now();
            if (r >= 0 && t3 - t2c < best_c) best_c = t3 - t2c;
            if (r >= 0 && (t3 - t2) / (t2c - t2) < best_run) best_run = (t3 - t2) / (t2c - t2);
            cb = cbvh_tree_bytes(&t);
            if (fused_bytes != cb) die(specs[i], "fused build: CBVH size differs");
            fb = cbvh_bvh_bytes(&b);
            cbvh_tree_free(&t);
            /* LBVH + top-down compression (build-then-compress baseline) */
            double t4 = now();
            cbvh_bvh_free(&b);
            if (cbvh_build_lbvh(&s, &b, err, sizeof err)) die(specs[i], err);
            if (cbvh_compress_topdown(&b, &o, &t, err, sizeof err)) die(specs[i], err);
            double t5 = now();
            cbvh_tree_free(&t);
            if (!ar) { /* untimed; the LBVH is the same every repetition */
                ar = malloc((size_t)(b.nnodes + 1) / 2 * sizeof *ar); /* > inner nodes of a binary tree */
                if (!ar) die(specs[i], "out of memory for the arithmetic floor");
                nar = arith_pack(&b, ar);
            }
            cbvh_bvh_free(&b);
            /* the step's bare arithmetic, last: not between the LBVH and a build compared with it */
            double ta0 = now();
            slow = arith_step(ar, nar, o.params.quant_bits, o.params.min_scale);
            double ta1 = now();
            if (r < 0) continue;
            if (ta1 - ta0 < best_a) best_a = ta1 - ta0;
            if (t1 - t0 < best_l) best_l = t1 - t0;
            if (t3 - t2 < best_bu) best_bu = t3 - t2;
            if (t5 - t4 < best_td) best_td = t5 - t4;
        }
        free(ar);
        qsort(fr, (size_t)reps, sizeof fr[0], cmp_double);
        double fused_med = reps % 2 ? fr[reps / 2] : 0.5 * (fr[reps / 2 - 1] + fr[reps / 2]);
        printf("%-24.24s %10u %10.2f %9.2f %9.2f %9.2f %9.2f %7.2f %9.2f %7.2f %9.2f %11.2f %9.2f %11zu %11zu %6.3f %9.2f %9.2f\n",
               s.name, s.ntris, 1e3 * best_l, s.ntris / best_l / 1e6, 1e3 * best_bu, 1e3 * best_c, 1e3 * best_td,
               best_bu / best_l, best_run, best_td / best_l, 1e3 * best_f, best_f / best_l, fused_med, cb, fb,
               (double)cb / (double)fb, 1e3 * best_a, 1.0 + best_a / best_l);
        cJSON *js = cJSON_CreateObject();
        cJSON_AddItemToArray(jscenes, js);
        cJSON_AddStringToObject(js, "scene", s.name);
        cJSON_AddNumberToObject(js, "triangles", s.ntris);
        cJSON_AddNumberToObject(js, "lbvh_ms", 1e3 * best_l);
        cJSON_AddNumberToObject(js, "lbvh_mtri_per_s", s.ntris / best_l / 1e6);
        cJSON_AddNumberToObject(js, "lbvh_bu_ms", 1e3 * best_bu);
        cJSON_AddNumberToObject(js, "bu_ms", 1e3 * best_c);
        cJSON_AddNumberToObject(js, "lbvh_td_ms", 1e3 * best_td);
        cJSON_AddNumberToObject(js, "bu_over_lbvh", best_bu / best_l);
        cJSON_AddNumberToObject(js, "run_ratio", best_run);
        cJSON_AddNumberToObject(js, "td_over_lbvh", best_td / best_l);
        cJSON_AddNumberToObject(js, "fused_ms", 1e3 * best_f);
        cJSON_AddNumberToObject(js, "fused_over_lbvh", best_f / best_l);
        cJSON_AddNumberToObject(js, "fused_median", fused_med);
        cJSON_AddNumberToObject(js, "cbvh_bytes", (double)cb);
        cJSON_AddNumberToObject(js, "float_bytes", (double)fb);
        cJSON_AddNumberToObject(js, "bytes_ratio", (double)cb / (double)fb);
        cJSON_AddNumberToObject(js, "arith_ms", 1e3 * best_a);
        cJSON_AddNumberToObject(js, "min_fused", 1.0 + best_a / best_l);
        cJSON_AddNumberToObject(js, "arith_slow_inputs", (double)slow);
        if (slow)
            printf("# %s: %llu inputs left the fast paths (the general paths, slower, are not timed)\n", s.name,
                   (unsigned long long)slow);
        fflush(stdout);
        cbvh_scene_free(&s);
    }
    if (json && bench_json_write(jroot, json)) die(json, "cannot write the JSON file");
    cJSON_Delete(jroot);
    return 0;
}
