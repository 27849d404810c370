/* cbvh study: the backtracking and memory-traffic study of Viitanen et al.
 * (Table 1 and Fig. 10) on real and procedural scenes.  docs/study.md. */
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "cbvh/oom.h"
#include "cli/commands.h"
#include "cli/data_dir.h"
#include "util/parse_int.h"
#include "scene/scene_load.h"
#include "trace/timing_model.h"

/* Sec. 5.2 memory-traffic model (bytes). */
enum {
    TR_INPUT = 40,      /* triangle (3 x 12 B) + primitive ID */
    TR_SORT = 64,       /* LBVH sort traffic per primitive (read + write of an AABB record) */
    TR_FLOAT_PAIR = 64, /* float BVH node pair: two 24-byte boxes + two 4-byte links, padded */
    TR_ID = 4,          /* primitive-ID array entry */
    TR_BACKTRACK = 128  /* one 64-byte DRAM read + one write */
};

#define NCFG 8 /* R0 R2 R3 R4 M0 M2 M3 M4 (R/M = relative/modulo, digit = treelet depth, 0 = none) */
static const char *cfg_name[NCFG] = {"R-", "R2", "R3", "R4", "M-", "M2", "M3", "M4"};

typedef struct {
    char name[64];        /* the table's row: row_name() */
    char scene_name[64];  /* the loader's name ("proc:cloth" for proc:cloth:4): JSON "name", as before */
    const char *spec;     /* the argument as given: JSON "spec" */
    uint32_t tris, leaves, pairs;
    double prims_per_leaf, sah_ratio, sah_ratio_sah_builder;
    size_t cbvh_bytes, bvh_bytes;
    uint64_t bt_lbvh[NCFG], bt_refit[NCFG];
    double norm_bt[NCFG];              /* LBVH backtracks / R0 (NaN if R0 = 0) */
    double mem_lbvh[NCFG + 1];         /* [0] = top-down = 1 */
    double mem_refit[NCFG + 1];
    uint64_t hist_rel[8], hist_mod[8]; /* re-encodes by depth 1..7+ (LBVH) */
    const char *deform;
    double pair_bytes;
    /* Build and refit time under the timing model's DRAM (ms): LBVH {float,
     * float + top-down, bottom-up relative, bottom-up modulo + 4-level
     * treelets}; refit {float, float + top-down, bottom-up M4}. */
    double t_lbvh[4], t_refit[3];
} scene_result;

enum { BT_RNONE = 0, BT_M4 = 7 }; /* cfg_name indices: R-, M4 */

/* Seed 003 Sec. 5.2's traffic as time (docs/timing_model.md §7): every pass
 * streams its bytes at the DRAM bandwidth; the backtracking unit's steps
 * run one after another, each a DRAM round trip. */
static void build_times(scene_result *r, const cbvh_timing_params *tp) {
    double n = r->tris, P = r->pairs, pb = r->pair_bytes, ms = 1e-3 / tp->clock_mhz; /* cycles -> ms */
    double common = (TR_INPUT + TR_SORT + TR_ID) * n;
    double flt = common + TR_FLOAT_PAIR * P; /* the float LBVH writes its hierarchy */
    r->t_lbvh[0] = cbvh_build_cycles(tp, flt, 0) * ms;
    r->t_lbvh[1] = cbvh_build_cycles(tp, flt + TR_FLOAT_PAIR * P + pb * P, 0) * ms; /* read it back, write the CBVH */
    for (int k = 0; k < 2; k++) {
        double bt = (double)r->bt_lbvh[k ? BT_M4 : BT_RNONE];
        r->t_lbvh[2 + k] = cbvh_build_cycles(tp, common + pb * P + TR_BACKTRACK * bt, bt) * ms;
    }
    double rcommon = (TR_ID + TR_INPUT) * n, bt = (double)r->bt_refit[BT_M4];
    r->t_refit[0] = cbvh_build_cycles(tp, rcommon + 2.0 * TR_FLOAT_PAIR * P, 0) * ms;
    r->t_refit[1] = cbvh_build_cycles(tp, rcommon + 3.0 * TR_FLOAT_PAIR * P + pb * P, 0) * ms;
    r->t_refit[2] = cbvh_build_cycles(tp, rcommon + 2.0 * pb * P + TR_BACKTRACK * bt, bt) * ms;
}

static double traffic_lbvh(double n, double pairs, double pair_bytes, double bt, int topdown) {
    double common = TR_INPUT * n + TR_SORT * n + TR_ID * n;
    if (topdown) return common + 2.0 * TR_FLOAT_PAIR * pairs + pair_bytes * pairs;
    return common + pair_bytes * pairs + TR_BACKTRACK * bt;
}

static double traffic_refit(double n, double pairs, double pair_bytes, double bt, int topdown) {
    double common = TR_ID * n + TR_INPUT * n;
    if (topdown) return common + 3.0 * TR_FLOAT_PAIR * pairs + pair_bytes * pairs;
    return common + 2.0 * pair_bytes * pairs + TR_BACKTRACK * bt;
}

static cbvh_bvh bvh_copy(const cbvh_bvh *b) {
    cbvh_bvh c = *b;
    c.nodes = malloc((size_t)b->nnodes * sizeof *b->nodes);
    c.prims = malloc((size_t)b->nprims * sizeof *b->prims);
    if (!c.nodes || !c.prims) cbvh_out_of_memory("BVH copy");
    memcpy(c.nodes, b->nodes, (size_t)b->nnodes * sizeof *b->nodes);
    memcpy(c.prims, b->prims, (size_t)b->nprims * sizeof *b->prims);
    return c;
}

/* Bottom-up stats for both encodings; counts for every treelet depth come
 * from the depth histogram (the output is identical for every depth). */
static int run_bu(cbvh_bvh *b, const cbvh_tri *refit, cbvh_params p, uint64_t bt[NCFG], uint64_t hr[8],
                  uint64_t hm[8], char *err, size_t errlen) {
    for (int e = 0; e < 2; e++) {
        cbvh_compress_opts o = {p, e ? CBVH_ENC_MODULO : CBVH_ENC_RELATIVE, 1, 0};
        cbvh_tree t;
        cbvh_bu_stats st;
        cbvh_bvh work = refit ? bvh_copy(b) : *b;
        int rc = cbvh_compress_bottomup(&work, refit, &o, &t, &st, err, errlen);
        if (refit) cbvh_bvh_free(&work);
        if (rc) return -1;
        cbvh_tree_free(&t);
        for (int m = 1; m <= 4; m++) {
            if (m == 2 - 1 + 0 && 0) continue;
            uint64_t deep = 0;
            for (int d = m; d < CBVH_BT_HIST; d++) deep += st.hist[d];
            int idx = e * 4 + (m == 1 ? 0 : m - 1);
            bt[idx] = deep;
        }
        uint64_t *h = e ? hm : hr;
        if (h)
            for (int d = 1; d < CBVH_BT_HIST; d++) h[d < 7 ? d : 7] += st.hist[d];
    }
    return 0;
}

/* The row's name: a procedural spec as given (proc:cloth:4, not the
 * loader's proc:cloth), a file by its name. */
static void row_name(char *out, size_t n, const char *spec, const cbvh_scene *s) {
    snprintf(out, n, "%s", strncmp(spec, "proc:", 5) == 0 ? spec : s->name);
}

static int study_scene(const char *spec, cbvh_params p, scene_result *r, char *err, size_t errlen) {
    memset(r, 0, sizeof *r);
    cbvh_scene s;
    if (cbvh_scene_open(spec, &s, err, errlen)) return -1;
    row_name(r->name, sizeof r->name, spec, &s);
    snprintf(r->scene_name, sizeof r->scene_name, "%s", s.name);
    r->spec = spec;
    /* Every vertex at one point: both SAH costs are 0 and their ratio 0/0;
     * rejected as trace and sweep reject it. */
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    if (!(hi[0] > lo[0] || hi[1] > lo[1] || hi[2] > lo[2])) {
        snprintf(err, errlen, "%s: the mesh has no extent (every vertex at one point), so no SAH cost to compare",
                 spec);
        cbvh_scene_free(&s);
        return -1;
    }
    r->tris = s.ntris;
    cbvh_bvh b, sah;
    int rc = -1;
    cbvh_tri *moved = NULL;
    if (cbvh_build_lbvh(&s, &b, err, errlen)) goto out_scene;
    uint32_t inner;
    cbvh_bvh_counts(&b, &r->leaves, &inner);
    r->prims_per_leaf = (double)s.ntris / r->leaves;
    cbvh_compress_opts o = {p, CBVH_ENC_MODULO, 1, 0};
    cbvh_tree td;
    if (cbvh_compress_topdown(&b, &o, &td, err, errlen)) goto out_bvh;
    if (cbvh_tree_check(&td, &b, err, errlen)) {
        cbvh_tree_free(&td);
        goto out_bvh;
    }
    r->pairs = td.npairs;
    r->sah_ratio = cbvh_tree_sah(&td) / cbvh_bvh_sah(&b);
    r->cbvh_bytes = cbvh_tree_bytes(&td);
    r->bvh_bytes = cbvh_bvh_bytes(&b);
    double pb = (double)td.pair_bytes;
    r->pair_bytes = pb;
    cbvh_tree_free(&td);
    if (cbvh_build_sah(&s, 0, 0, &sah, err, errlen) == 0) {
        if (cbvh_compress_topdown(&sah, &o, &td, err, errlen) == 0) {
            r->sah_ratio_sah_builder = cbvh_tree_sah(&td) / cbvh_bvh_sah(&sah);
            cbvh_tree_free(&td);
        }
        cbvh_bvh_free(&sah);
    }
    if (run_bu(&b, NULL, p, r->bt_lbvh, r->hist_rel, r->hist_mod, err, errlen)) goto out_bvh;
    /* Refit to a deformed frame: the glTF morph animation at half time if the
     * scene has one, else a procedural twist + wave. */
    moved = malloc((size_t)s.ntris * sizeof *moved);
    if (!moved) cbvh_out_of_memory("refit frame");
    if (s.nmorph && s.nkeys) {
        cbvh_scene_frame(&s, s.key_time[0] + 0.5f * cbvh_scene_duration(&s), moved);
        r->deform = "morph";
    } else {
        cbvh_scene_deform(&s, 0.5f, 0.02f, 0.7f, moved);
        r->deform = "twist";
    }
    if (run_bu(&b, moved, p, r->bt_refit, NULL, NULL, err, errlen)) goto out_bvh;
    double n = s.ntris, np = r->pairs;
    r->mem_lbvh[0] = r->mem_refit[0] = 1.0;
    double bl = traffic_lbvh(n, np, pb, 0, 1), br = traffic_refit(n, np, pb, 0, 1);
    for (int c = 0; c < NCFG; c++) {
        r->norm_bt[c] = r->bt_lbvh[0] ? (double)r->bt_lbvh[c] / (double)r->bt_lbvh[0] : NAN;
        r->mem_lbvh[c + 1] = traffic_lbvh(n, np, pb, (double)r->bt_lbvh[c], 0) / bl;
        r->mem_refit[c + 1] = traffic_refit(n, np, pb, (double)r->bt_refit[c], 0) / br;
    }
    rc = 0;
out_bvh:
    cbvh_bvh_free(&b);
out_scene:
    free(moved);
    cbvh_scene_free(&s);
    return rc;
}

/* Fig. 10: backtracks per primitive (modulo, no treelets) and CBVH SAH cost
 * for each minimum scale. */
#define NSWEEP 10
static const int sweep_scales[NSWEEP] = {-126, -100, -80, -60, -50, -40, -30, -20, -15, -10};

typedef struct {
    char name[64];
    double bt_per_prim[NSWEEP], sah[NSWEEP];
} sweep_result;

static int sweep_scene(const char *spec, int quant_bits, sweep_result *r, char *err, size_t errlen) {
    cbvh_scene s;
    if (cbvh_scene_open(spec, &s, err, errlen)) return -1;
    row_name(r->name, sizeof r->name, spec, &s);
    cbvh_bvh b;
    int rc = -1;
    if (cbvh_build_lbvh(&s, &b, err, errlen)) goto out;
    double fsah = cbvh_bvh_sah(&b);
    for (int i = 0; i < NSWEEP; i++) {
        cbvh_compress_opts o = {{quant_bits, sweep_scales[i]}, CBVH_ENC_MODULO, 1, 0};
        cbvh_tree t;
        cbvh_bu_stats st;
        if (cbvh_compress_bottomup(&b, NULL, &o, &t, &st, err, errlen)) goto out_b;
        r->bt_per_prim[i] = (double)st.backtracks / s.ntris;
        r->sah[i] = cbvh_tree_sah(&t) / fsah;
        cbvh_tree_free(&t);
    }
    rc = 0;
out_b:
    cbvh_bvh_free(&b);
out:
    cbvh_scene_free(&s);
    return rc;
}

/* --json numbers as the table's precision (%.6g), NaN (no ratio) as null. */
static cJSON *json_num(double x) {
    if (isnan(x)) return cJSON_CreateNull();
    char buf[32];
    snprintf(buf, sizeof buf, "%.6g", x);
    return cJSON_CreateNumber(strtod(buf, NULL));
}

static cJSON *json_arr(const double *v, int n) {
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; i < n; i++) cJSON_AddItemToArray(a, json_num(v[i]));
    return a;
}

static cJSON *json_counts(const uint64_t *v, int n) {
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; i < n; i++) cJSON_AddItemToArray(a, cJSON_CreateNumber((double)v[i]));
    return a;
}

static void json_write(const scene_result *res, const sweep_result *sw, int ns, int sweep, cbvh_params p,
                       const cbvh_timing_params *tp) {
    cJSON *root = cJSON_CreateObject();
    cJSON_AddNumberToObject(root, "quant_bits", p.quant_bits);
    cJSON_AddNumberToObject(root, "min_scale", p.min_scale);
    cJSON_AddItemToObject(root, "configs", cJSON_CreateStringArray(cfg_name, NCFG));
    cJSON *tm = cJSON_AddObjectToObject(root, "traffic_model");
    cJSON_AddNumberToObject(tm, "input", TR_INPUT);
    cJSON_AddNumberToObject(tm, "sort", TR_SORT);
    cJSON_AddNumberToObject(tm, "float_pair", TR_FLOAT_PAIR);
    cJSON_AddNumberToObject(tm, "id", TR_ID);
    cJSON_AddNumberToObject(tm, "backtrack", TR_BACKTRACK);
    cJSON *bm = cJSON_AddObjectToObject(root, "build_time_model");
    cJSON_AddItemToObject(bm, "lbvh", cJSON_CreateStringArray((const char *const[]){"float", "float+topdown",
                                                                                     "bottomup_relative",
                                                                                     "bottomup_modulo_treelets4"},
                                                               4));
    cJSON_AddItemToObject(bm, "refit",
                          cJSON_CreateStringArray((const char *const[]){"float", "float+topdown",
                                                                        "bottomup_modulo_treelets4"},
                                                  3));
    cJSON_AddNumberToObject(bm, "dram_bytes_per_cycle", tp->dram_bytes_per_cycle);
    cJSON_AddNumberToObject(bm, "fetch_latency", tp->fetch_latency);
    cJSON_AddNumberToObject(bm, "clock_mhz", tp->clock_mhz);
    cJSON *scenes = cJSON_AddArrayToObject(root, "scenes");
    for (int i = 0; i < ns; i++) {
        const scene_result *r = &res[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(scenes, o);
        cJSON_AddStringToObject(o, "name", r->scene_name);
        cJSON_AddStringToObject(o, "spec", r->spec);
        cJSON_AddNumberToObject(o, "triangles", r->tris);
        cJSON_AddNumberToObject(o, "leaves", r->leaves);
        cJSON_AddNumberToObject(o, "node_pairs", r->pairs);
        cJSON_AddItemToObject(o, "prims_per_leaf", json_num(r->prims_per_leaf));
        cJSON_AddItemToObject(o, "sah_cbvh_over_float", json_num(r->sah_ratio));
        cJSON_AddItemToObject(o, "sah_cbvh_over_float_sah_builder", json_num(r->sah_ratio_sah_builder));
        cJSON_AddNumberToObject(o, "cbvh_bytes", (double)r->cbvh_bytes);
        cJSON_AddNumberToObject(o, "float_bvh_bytes", (double)r->bvh_bytes);
        cJSON_AddStringToObject(o, "refit_deformation", r->deform);
        cJSON_AddItemToObject(o, "backtracks_lbvh", json_counts(r->bt_lbvh, NCFG));
        cJSON_AddItemToObject(o, "backtracks_refit", json_counts(r->bt_refit, NCFG));
        cJSON_AddItemToObject(o, "backtracks_norm", json_arr(r->norm_bt, NCFG));
        cJSON_AddItemToObject(o, "traffic_lbvh_norm", json_arr(r->mem_lbvh, NCFG + 1));
        cJSON_AddItemToObject(o, "traffic_refit_norm", json_arr(r->mem_refit, NCFG + 1));
        cJSON *bt = cJSON_AddObjectToObject(o, "build_time_ms");
        cJSON_AddItemToObject(bt, "lbvh", json_arr(r->t_lbvh, 4));
        cJSON_AddItemToObject(bt, "refit", json_arr(r->t_refit, 3));
        if (sweep) {
            cJSON *j = cJSON_AddObjectToObject(o, "sweep");
            cJSON_AddItemToObject(j, "min_scale", cJSON_CreateIntArray(sweep_scales, NSWEEP));
            cJSON_AddItemToObject(j, "backtracks_per_prim", json_arr(sw[i].bt_per_prim, NSWEEP));
            cJSON_AddItemToObject(j, "sah_over_float", json_arr(sw[i].sah, NSWEEP));
        }
    }
    cbvh_json_print(root, stdout);
    cJSON_Delete(root);
}

/* min / max / avg over scenes of one column (NaNs skipped). */
static void stats3(const scene_result *r, int nr, size_t off, int col, double out[3]) {
    out[0] = INFINITY, out[1] = -INFINITY, out[2] = 0;
    int k = 0;
    for (int i = 0; i < nr; i++) {
        /* cppcheck-suppress invalidPointerCast ; off = offsetof(scene_result, a double array) */
        double v = ((const double *)((const char *)&r[i] + off))[col];
        if (isnan(v)) continue;
        if (v < out[0]) out[0] = v;
        if (v > out[1]) out[1] = v;
        out[2] += v;
        k++;
    }
    if (k)
        out[2] /= k;
    else
        out[0] = out[1] = out[2] = NAN;
}

static void print_block(const char *title, const scene_result *r, int nr, size_t off, int ncol, int first_td) {
    printf("\n%s\n%-26s", title, "scene");
    if (first_td) printf(" %6s", "TD");
    for (int c = 0; c < NCFG; c++) printf(" %6s", cfg_name[c]);
    printf("\n");
    for (int i = 0; i < nr; i++) {
        printf("%-26.26s", r[i].name);
        /* cppcheck-suppress invalidPointerCast ; off = offsetof(scene_result, a double array) */
        const double *v = (const double *)((const char *)&r[i] + off);
        for (int c = 0; c < ncol; c++) isnan(v[c]) ? printf(" %6s", "-") : printf(" %6.3f", v[c]);
        printf("\n");
    }
    const char *lab[3] = {"min", "max", "avg"};
    for (int k = 0; k < 3; k++) {
        printf("%-26s", lab[k]);
        for (int c = 0; c < ncol; c++) {
            double s[3];
            stats3(r, nr, off, c, s);
            isnan(s[k]) ? printf(" %6s", "-") : printf(" %6.3f", s[k]);
        }
        printf("\n");
    }
}

static void usage(FILE *f) {
    fprintf(f, "usage: cbvh study [SCENE...] [--json] [--quant-bits N] [--min-scale E] [--no-sweep]\n"
               "                  [--timing K=V,...]\n"
               "  SCENE: a mesh file (OBJ, PLY, OFF, STL, glTF/GLB) or proc:cloth, proc:far, proc:wave,\n"
               "         proc:instanced[:K] (K x K spheres, 40 -> 10.2M triangles); default: the bundled\n"
               "         bunny plus proc:cloth, proc:far, proc:wave.\n"
               "  Prints the Table-1-style study (backtracking, memory traffic of LBVH and refit,\n"
               "  SAH cost, primitives per leaf) and the minimum-scale sweep of Fig. 10 (docs/study.md).\n"
               "  --quant-bits N  coordinate bits, %d..%d (default %d); --min-scale E  %d..%d (default %d)\n"
               "  --timing K=V,...  the DRAM of the build and refit times (docs/timing_model.md §7):\n"
               "                  dram_bytes_per_cycle, fetch_latency, clock_mhz (default 12.8, 100, 1000)\n"
               "  Exit status: 0 done, 2 bad input (an option, or a scene that cannot be loaded or built).\n",
            CBVH_N_MIN, CBVH_N_MAX, CBVH_N_DEFAULT, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, CBVH_MIN_SCALE_DEFAULT);
}

typedef struct {
    const char **specs; /* argc + 4 entries */
    int ns, json, sweep;
    cbvh_params p;
    cbvh_timing_params tp; /* the DRAM of the build times */
} study_opts;

/* The build and refit times beside seed 003's Table 2 / Fig. 11. */
static void print_build_times(const scene_result *r, int nr, const cbvh_timing_params *tp) {
    printf("\nBuild and refit time under the timing model's DRAM (%g B/cycle, %g-cycle latency, %g MHz; "
           "docs/timing_model.md §7), ms, and x the float LBVH (x the float refit):\n",
           tp->dram_bytes_per_cycle, tp->fetch_latency, tp->clock_mhz);
    printf("%-26s %9s %15s %15s %15s | %9s %15s %15s\n", "scene", "float", "float + TD", "BU relative",
           "BU mod+treelet4", "refit", "float + TD", "BU mod+treelet4");
    double sum[6] = {0}, sum_vs_td = 0;
    for (int i = 0; i < nr; i++) {
        const double *l = r[i].t_lbvh, *f = r[i].t_refit;
        printf("%-26.26s %9.4f %8.4f x%5.3f %8.4f x%5.3f %8.4f x%5.3f | %9.4f %8.4f x%5.3f %8.4f x%5.3f\n",
               r[i].name, l[0], l[1], l[1] / l[0], l[2], l[2] / l[0], l[3], l[3] / l[0], f[0], f[1], f[1] / f[0],
               f[2], f[2] / f[0]);
        for (int k = 0; k < 3; k++) sum[k] += l[k + 1] / l[0];
        for (int k = 0; k < 2; k++) sum[3 + k] += f[k + 1] / f[0];
        sum_vs_td += l[3] / l[1];
    }
    if (!nr) return;
    printf("%-26s %9s %15s %15s %15s | %9s %15s %15s\n", "avg x float", "", "", "", "", "", "", "");
    printf("%-26s %9s %+14.0f%% %+14.0f%% %+14.0f%% | %9s %+14.0f%% %+14.0f%%\n", "  ours", "",
           100 * (sum[0] / nr - 1), 100 * (sum[1] / nr - 1), 100 * (sum[2] / nr - 1), "", 100 * (sum[3] / nr - 1),
           100 * (sum[4] / nr - 1));
    printf("%-26s %9s %15s %15s %15s | %9s\n", "  paper (Table 2, Fig. 11)", "", "+36%", "+52%", "-20%",
           "(no refit runtime in the paper)");
    printf("BU modulo + treelets 4 against float + top-down: ours %+.0f %%, paper -41 %%\n",
           100 * (sum_vs_td / nr - 1));
}

/* --quant-bits / --min-scale: one line naming the option and the value (not
 * the usage).  0 or -1. */
static int parse_param(const char *opt, const char *val, long lo, long hi, int *out) {
    long v;
    if (!val) {
        fprintf(stderr, "cbvh study: %s needs a value (%ld..%ld)\n", opt, lo, hi);
        return -1;
    }
    if (cbvh_parse_long(val, LONG_MIN, LONG_MAX, &v)) {
        fprintf(stderr, "cbvh study: %s needs an integer in %ld..%ld, got '%s'\n", opt, lo, hi, val);
        return -1;
    }
    if (v < lo || v > hi) {
        fprintf(stderr, "cbvh study: %s %s out of range %ld..%ld\n", opt, val, lo, hi);
        return -1;
    }
    *out = (int)v;
    return 0;
}

enum { OPT_JSON = 256, OPT_NO_SWEEP, OPT_QUANT_BITS, OPT_MIN_SCALE, OPT_TIMING };

/* --quant-bits or --min-scale (opt) with its value (NULL: missing). */
static int set_param(int opt, const char *val, cbvh_params *p) {
    return opt == OPT_QUANT_BITS ? parse_param("--quant-bits", val, CBVH_N_MIN, CBVH_N_MAX, &p->quant_bits)
                                 : parse_param("--min-scale", val, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, &p->min_scale);
}

/* 0: run; 1: --help printed; 2: bad input (one line printed). */
static int parse_options(int argc, char **argv, study_opts *o) {
    static const struct option lo[] = {{"help", no_argument, 0, 'h'},
                                       {"json", no_argument, 0, OPT_JSON},
                                       {"no-sweep", no_argument, 0, OPT_NO_SWEEP},
                                       {"quant-bits", required_argument, 0, OPT_QUANT_BITS},
                                       {"min-scale", required_argument, 0, OPT_MIN_SCALE},
                                       {"timing", required_argument, 0, OPT_TIMING},
                                       {0, 0, 0, 0}};
    int c;
    optind = 0;
    opterr = 0;
    /* "-": scenes come back in order (as 1); ":": a missing value is ':' */
    while ((c = getopt_long(argc, argv, "-:h", lo, NULL)) != -1) {
        switch (c) {
        case 1: o->specs[o->ns++] = optarg; break;
        case 'h': usage(stdout); return 1;
        case OPT_JSON: o->json = 1; break;
        case OPT_NO_SWEEP: o->sweep = 0; break;
        case OPT_TIMING: {
            char err[200];
            if (cbvh_timing_set(&o->tp, optarg, err, sizeof err)) {
                fprintf(stderr, "cbvh study: %s\n", err);
                return 2;
            }
            break;
        }
        case OPT_QUANT_BITS:
        case OPT_MIN_SCALE:
            if (set_param(c, optarg, &o->p)) return 2;
            break;
        case ':': /* only the three options above take a value */
            if (optopt == OPT_TIMING) {
                fprintf(stderr, "cbvh study: --timing needs key=value[,key=value...]\n");
                return 2;
            }
            if (set_param(optopt, NULL, &o->p)) return 2;
            break;
        default: return cbvh_unknown_option("cbvh study", argv, optind);
        }
    }
    while (optind < argc) o->specs[o->ns++] = argv[optind++]; /* after "--" */
    return 0;
}

int cmd_study(int argc, char **argv) {
    char bunny[PATH_MAX];
    snprintf(bunny, sizeof bunny, "%s/scenes/bunny-small.obj", cbvh_data_dir());
    const char *defaults[] = {bunny, "proc:cloth", "proc:far", "proc:wave"};
    study_opts o = {.specs = malloc((size_t)(argc + 4) * sizeof *o.specs), .sweep = 1,
                    .p = {CBVH_N_DEFAULT, CBVH_MIN_SCALE_DEFAULT}};
    cbvh_timing_defaults(&o.tp);
    if (!o.specs) cbvh_out_of_memory("scene list");
    int rc = parse_options(argc, argv, &o);
    if (rc) {
        free(o.specs);
        return rc == 1 ? 0 : 2;
    }
    const char **specs = o.specs;
    int ns = o.ns, json = o.json, sweep = o.sweep;
    cbvh_params p = o.p;
    if (ns == 0)
        for (int i = 0; i < 4; i++) specs[ns++] = defaults[i];
    scene_result *res = calloc((size_t)ns, sizeof *res);
    sweep_result *sw = calloc((size_t)ns, sizeof *sw);
    if (!res || !sw) cbvh_out_of_memory("study results");
    char err[512];
    int status = 0;
    for (int i = 0; i < ns; i++) {
        if (study_scene(specs[i], p, &res[i], err, sizeof err) ||
            (sweep && sweep_scene(specs[i], p.quant_bits, &sw[i], err, sizeof err))) {
            fprintf(stderr, "cbvh study: %s\n", err);
            status = 2; /* bad input, as for the other commands */
            goto done;
        }
        build_times(&res[i], &o.tp);
    }
    if (json) {
        json_write(res, sw, ns, sweep, p, &o.tp);
        goto done;
    }
    printf("cbvh study: N = %d, min scale 2^%d, LBVH (30-bit Morton, equal codes share a leaf)\n", p.quant_bits,
           p.min_scale);
    printf("\n%-26s %10s %8s %9s %10s %10s %11s %12s %7s\n", "scene", "triangles", "leaves", "prim/leaf",
           "SAH(LBVH)", "SAH(SAH)", "CBVH bytes", "float bytes", "refit");
    for (int i = 0; i < ns; i++)
        printf("%-26.26s %10u %8u %9.2f %10.4f %10.4f %11zu %12zu %7s\n", res[i].name, res[i].tris, res[i].leaves,
               res[i].prims_per_leaf, res[i].sah_ratio, res[i].sah_ratio_sah_builder, res[i].cbvh_bytes,
               res[i].bvh_bytes, res[i].deform);
    printf("(SAH: CBVH cost / float BVH cost, same tree; every compressor gives the same CBVH bits)\n");
    print_block("Backtrack iterations (LBVH), normalized to R- (relative, no treelets)", res, ns,
                offsetof(scene_result, norm_bt), NCFG, 0);
    print_block("Memory traffic (LBVH), normalized to top-down (TD)", res, ns, offsetof(scene_result, mem_lbvh),
                NCFG + 1, 1);
    print_block("Memory traffic (refit), normalized to top-down (TD)", res, ns, offsetof(scene_result, mem_refit),
                NCFG + 1, 1);
    print_build_times(res, ns, &o.tp);
    printf("\nRaw backtrack iterations (LBVH | refit):\n");
    for (int i = 0; i < ns; i++) {
        printf("%-26.26s", res[i].name);
        for (int c = 0; c < NCFG; c++) printf(" %s=%llu", cfg_name[c], (unsigned long long)res[i].bt_lbvh[c]);
        printf(" |");
        for (int c = 0; c < NCFG; c++) printf(" %llu", (unsigned long long)res[i].bt_refit[c]);
        printf("\n");
    }
    printf("\nBacktrack depth histogram (LBVH re-encodes at depth 1..6, 7+), relative | modulo:\n");
    for (int i = 0; i < ns; i++) {
        printf("%-26.26s", res[i].name);
        for (int d = 1; d < 8; d++) printf(" %llu", (unsigned long long)res[i].hist_rel[d]);
        printf(" |");
        for (int d = 1; d < 8; d++) printf(" %llu", (unsigned long long)res[i].hist_mod[d]);
        printf("\n");
    }
    if (sweep) {
        printf("\nMinimum-scale sweep (Fig. 10): backtracks per primitive (modulo, no treelets) / SAH(CBVH)/SAH(float)\n");
        printf("%-26s", "scene");
        for (int k = 0; k < NSWEEP; k++) printf(" %13d", sweep_scales[k]);
        printf("\n");
        double avg_bt[NSWEEP] = {0}, avg_sah[NSWEEP] = {0};
        int others = 0;
        for (int i = 0; i < ns; i++) {
            printf("%-26.26s", sw[i].name);
            for (int k = 0; k < NSWEEP; k++) printf(" %6.3f/%6.4f", sw[i].bt_per_prim[k], sw[i].sah[k]);
            printf("\n");
            if (strstr(sw[i].name, "cloth")) continue;
            others++;
            for (int k = 0; k < NSWEEP; k++) avg_bt[k] += sw[i].bt_per_prim[k], avg_sah[k] += sw[i].sah[k];
        }
        if (others) {
            printf("%-26s", "avg (all but cloth)");
            for (int k = 0; k < NSWEEP; k++) printf(" %6.3f/%6.4f", avg_bt[k] / others, avg_sah[k] / others);
            printf("\n");
        }
    }
done:
    free(specs);
    free(res);
    free(sw);
    return status;
}
