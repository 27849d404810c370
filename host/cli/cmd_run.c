/* `cbvh run`: the kit's main job.
 *   1. check the golden vectors on the board, or on the model without one;
 *   2. on the bundled scene file, what each coordinate width N costs: trace the
 *      rays the scene's effects call for through the float BVH and through the
 *      bit-exact CBVH at N = 3..10, and report memory, traversal work, the timing
 *      model's time and CPU time relative to the float BVH, with a proof that
 *      every CBVH gives exactly the float BVH's hits. */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "link/backend.h"
#include "cli/commands.h"
#include "cli/data_dir.h"
#include "trace/effects.h"
#include "trace/metrics.h"
#include "trace/model_eval.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"
#include "util/parse_int.h"
#include "vectors/vectors_check.h"

/* The defaults are the committed vectors and the bundled scene, installed
 * (PREFIX/share/cbvh) or in the source tree (cli/data_dir.c), wherever cbvh
 * runs: a ./vectors or ./scenes of the working directory is not what the help
 * promises.  Explicit paths stay relative to the cwd. */
#define DEFAULT_VECTORS "vectors"
#define DEFAULT_SCENE "scenes/bunny.scene"

static void usage(FILE *f) {
    fprintf(f,
            "usage: cbvh run [--backend SPEC] [--vectors DIR] [--scene SCENE] [--cache KB] [--reps K]\n"
            "                [--cost-table DIR] [--timing K=V,...] [--json]\n"
            "\n"
            "The main job: checks the golden vectors (on a board if one is attached, else on\n"
            "the bit-exact model), then traces the effects of a scene file through the float\n"
            "BVH and the bit-exact CBVH at N = 3..10 and prints what each width costs: node\n"
            "memory, box and triangle tests, bytes, modelled time and energy per ray (timing\n"
            "model with a node and triangle cache, docs/timing_model.md) and CPU time per ray,\n"
            "relative to the float BVH, and whether the hits are identical; it ends with the\n"
            "best setting for the scene and what it costs or saves against the float BVH.\n"
            "\n"
            "  --backend SPEC  auto (default), model, usb, hid, sim:ADDR\n"
            "  --vectors DIR   vector directory (default: the committed vectors/, installed in\n"
            "                  PREFIX/share/cbvh or of the source tree, from any working directory)\n"
            "  --scene SCENE   scene file, or a mesh file / proc:NAME with its default scene\n"
            "                  (default: scenes/bunny.scene beside those vectors; docs/scenes.md)\n"
            "  --cache KB      the timing model's cache in KB, 0..%d (0 = none) or inf (default 64)\n"
            "  --reps K        timed repetitions for the CPU column, 1..%d (default 5; the median)\n"
            "  --cost-table DIR  the RTL cost table (default: gateware/cost beside those vectors)\n"
            "  --timing K=V,...  timing-model parameters over the scene file's (docs/scenes.md)\n"
            "  --json          one JSON object instead of tables\n",
            CBVH_CACHE_KB_MAX, CBVH_REPS_MAX);
}

typedef struct {
    int bits; /* 0 = float BVH */
    uint64_t node_bytes, hit_digest;
    cbvh_ray_metrics m; /* per ray, all effects */
    cbvh_fx_stats tot;  /* the counters summed over effects (the CPU repetitions) */
} width_row;

/* The timing model's machine: parameters, the cost table, the cache. */
typedef struct {
    cbvh_timing_params tp;
    cbvh_cost_table table;
    double cache_kb;
    int reps;
} run_machine;

/* Traces the scene in one format (once with the cache model, then `reps`
 * timed passes) and sums the per-effect counters. */
static int measure(const cbvh_scene_desc *d, const run_machine *rm, int bits, width_row *row, char *err,
                   size_t errlen) {
    cbvh_fx_opts o;
    memset(&o, 0, sizeof o);
    o.format = bits ? "cbvh" : "float";
    o.params.quant_bits = bits ? bits : 6;
    o.params.min_scale = CBVH_MIN_SCALE_DEFAULT;
    o.mant = 24;
    o.cache_kb = &rm->cache_kb;
    o.ncaches = 1;
    o.cache_ways = (int)rm->tp.cache_ways;
    static cbvh_fx_result r, rep;
    if (cbvh_fx_run(d, &o, &r, err, errlen) != 0) return -1;
    o.ncaches = 0;
    for (int k = 0; k < rm->reps; k++)
        if (cbvh_fx_run(d, &o, &rep, err, errlen) != 0 || cbvh_fx_add_rep(&r, &rep)) {
            snprintf(err, errlen, "a timed repetition failed or traced other rays");
            return -1;
        }
    cbvh_config_model cm;
    if (cbvh_config_model_init(&cm, &r, &rm->table, &rm->tp, "ray_box", bits ? bits : CBVH_N_DEFAULT, 24, err, errlen)) return -1;
    memset(row, 0, sizeof *row);
    row->bits = bits;
    row->tot = cbvh_fx_total(&r);
    if (cbvh_ray_metrics_of(&row->tot, &cm.mc[0], &row->m) != 0 || row->m.rays == 0) {
        snprintf(err, errlen, "scene traces no rays or has an invalid timing model");
        return -1;
    }
    row->node_bytes = r.node_bytes;
    row->hit_digest = r.hit_digest;
    return 0;
}

/* --cache, --reps, --cost-table; 0 or 2 (one line printed). */
static int machine_option(int c, const char *v, run_machine *rm, const char **cost_dir, const char **timing) {
    long n;
    if (c == 'c' && cbvh_cache_kb_parse(v, &rm->cache_kb)) {
        fprintf(stderr, "cbvh run: --cache expects a size in KB, 0..%d, or inf, got '%s'\n", CBVH_CACHE_KB_MAX, v);
        return 2;
    }
    if (c == 'r') {
        if (cbvh_parse_long(v, 1, CBVH_REPS_MAX, &n)) {
            fprintf(stderr, "cbvh run: --reps expects an integer in 1..%d, got '%s'\n", CBVH_REPS_MAX, v);
            return 2;
        }
        rm->reps = (int)n;
    }
    if (c == 't') *cost_dir = v;
    if (c == 'm') *timing = v;
    return 0;
}

int cmd_run(int argc, char **argv) {
    static const struct option longopts[] = {{"backend", required_argument, 0, 'b'},
                                             {"vectors", required_argument, 0, 'v'},
                                             {"scene", required_argument, 0, 's'},
                                             {"json", no_argument, 0, 'j'},
                                             {"cache", required_argument, 0, 'c'},
                                             {"reps", required_argument, 0, 'r'},
                                             {"cost-table", required_argument, 0, 't'},
                                             {"timing", required_argument, 0, 'm'},
                                             {"help", no_argument, 0, 'h'},
                                             {0, 0, 0, 0}};
    const char *backend = "auto", *vec_dir = NULL, *scene_path = NULL, *cost_dir = cbvh_cost_dir(), *timing = NULL;
    static run_machine rm;
    rm.cache_kb = 64;
    rm.reps = 5;
    int json = 0, c;
    char err[512];
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'b': backend = optarg; break;
        case 'v': vec_dir = optarg; break;
        case 's': scene_path = optarg; break;
        case 'j': json = 1; break;
        case 'c':
        case 'r':
        case 't':
        case 'm':
            if (machine_option(c, optarg, &rm, &cost_dir, &timing)) return 2;
            break;
        case 'h': usage(stdout); return 0;
        default: return cbvh_bad_option("cbvh run", argv, optind);
        }
    }
    if (optind != argc) {
        fprintf(stderr, "cbvh run: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    char def_vectors[PATH_MAX], def_scene[PATH_MAX];
    if (!vec_dir) {
        snprintf(def_vectors, sizeof def_vectors, "%s/" DEFAULT_VECTORS, cbvh_data_dir());
        vec_dir = def_vectors;
    }
    if (!scene_path) {
        snprintf(def_scene, sizeof def_scene, "%s/" DEFAULT_SCENE, cbvh_data_dir());
        scene_path = def_scene;
    }
    /* Options first, then the scene (a typo in --scene is reported at once,
     * not after a whole vector check on a board): nothing is printed before. */
    struct stat vst;
    char why[400];
    if (cbvh_backend_spec_check(backend, why, sizeof why)) { /* worded as the vector check would */
        fprintf(stderr, "cbvh run: backend '%.100s': %s\n", backend, why);
        return 2;
    }
    if (stat(vec_dir, &vst) != 0) {
        fprintf(stderr, "cbvh run: %s: %s\n", vec_dir, strerror(errno));
        return 2;
    }

    cbvh_scene_desc d;
    if (cbvh_scene_file_open(scene_path, &d, err, sizeof err) != 0) {
        fprintf(stderr, "cbvh run: %s\n", err);
        return 2;
    }
    cbvh_fx_timing(&d, &rm.tp);
    if (cbvh_timing_check(&rm.tp, err, sizeof err) || (timing && cbvh_timing_set(&rm.tp, timing, err, sizeof err)) ||
        cbvh_cost_table_load(cost_dir, &rm.table, err, sizeof err)) {
        fprintf(stderr, "cbvh run: %s: %s\n", scene_path, err);
        cbvh_scene_desc_free(&d);
        return 2;
    }

    /* 1. Golden vectors. */
    cbvh_check_summary sum;
    memset(&sum, 0, sizeof sum);
    cbvh_check_opts co;
    memset(&co, 0, sizeof co);
    co.backend = backend;
    co.max_errors = 20;
    co.quiet = 1;
    co.out = json ? stderr : stdout;
    co.summary = &sum;
    co.who = "cbvh run";
    if (!json) printf("== Golden vectors: %s ==\n", vec_dir);
    const char *paths[1] = {vec_dir};
    int check = cbvh_vectors_check(paths, 1, &co);
    if (check == CBVH_CHECK_BAD_INPUT) {
        cbvh_cost_table_free(&rm.table);
        cbvh_scene_desc_free(&d);
        return 2;
    }

    /* 2. Accuracy vs time on the scene. */
    static width_row rows[1 + CBVH_N_MAX - CBVH_N_MIN + 1];
    int nrows = 0, rc = check, same_hits = 1;
    for (int n = 0; n <= CBVH_N_MAX; n = n ? n + 1 : CBVH_N_MIN, nrows++) {
        if (measure(&d, &rm, n, &rows[nrows], err, sizeof err) != 0) {
            fprintf(stderr, "cbvh run: %s: %s\n", scene_path, err);
            cbvh_cost_table_free(&rm.table);
            cbvh_scene_desc_free(&d);
            return 2;
        }
        if (rows[nrows].hit_digest != rows[0].hit_digest) same_hits = 0;
    }
    cbvh_cost_table_free(&rm.table);
    if (!same_hits) rc = 1;
    const width_row *f = &rows[0];
    /* The sentence: the fastest in modelled time, and the fastest CBVH. */
    int best = 0, best_cbvh = 1;
    for (int i = 1; i < nrows; i++) {
        if (rows[i].m.model_ns < rows[best].m.model_ns) best = i;
        if (rows[i].m.model_ns < rows[best_cbvh].m.model_ns) best_cbvh = i;
    }
    char sentence[700], bname[64], rname[64];
    snprintf(bname, sizeof bname, "the CBVH at N=%d (M=24, min scale %d)", rows[best].bits, CBVH_MIN_SCALE_DEFAULT);
    snprintf(rname, sizeof rname, "the CBVH at N=%d", rows[best_cbvh].bits);
    cbvh_best_sentence(sentence, sizeof sentence, scene_path, bname, rm.cache_kb, &rows[best].m, &f->m, best == 0,
                       rname, &rows[best_cbvh].m);

    if (json) {
        cJSON *root = cJSON_CreateObject();
        cJSON *v = cJSON_AddObjectToObject(root, "vectors");
        cJSON_AddStringToObject(v, "backend", sum.backend);
        cJSON_AddNumberToObject(v, "files", (double)sum.files);
        cJSON_AddNumberToObject(v, "passed", (double)sum.passed);
        cJSON_AddNumberToObject(v, "failed", (double)sum.failed);
        cJSON *s = cJSON_AddObjectToObject(root, "scene");
        cJSON_AddStringToObject(s, "path", scene_path);
        cJSON_AddNumberToObject(s, "triangles", d.mesh.ntris);
        cJSON_AddNumberToObject(s, "rays", (double)f->m.rays);
        cJSON_AddBoolToObject(s, "hits_identical_to_float", same_hits);
        cJSON *arr = cJSON_AddArrayToObject(root, "formats");
        for (int i = 0; i < nrows; i++) {
            const width_row *w = &rows[i];
            cJSON *r = cJSON_CreateObject();
            cJSON_AddStringToObject(r, "format", w->bits ? "cbvh" : "float");
            if (w->bits) cJSON_AddNumberToObject(r, "bits", w->bits);
            cJSON_AddNumberToObject(r, "node_bytes", (double)w->node_bytes);
            cJSON_AddNumberToObject(r, "box_tests_per_ray", w->m.box);
            cJSON_AddNumberToObject(r, "tri_tests_per_ray", w->m.tri);
            cJSON_AddNumberToObject(r, "bytes_per_ray", w->m.bytes);
            cJSON_AddNumberToObject(r, "model_ns_per_ray", w->m.model_ns);
            cJSON_AddNumberToObject(r, "energy_nj_per_ray", w->m.energy_nj);
            cJSON_AddNumberToObject(r, "area_lut4", w->m.area_lut4);
            cJSON_AddNumberToObject(r, "dram_bytes_per_ray", w->m.dram_bytes);
            cJSON_AddNumberToObject(r, "hit_rate", w->m.hit_rate);
            cJSON_AddStringToObject(r, "bound", cbvh_timing_bound_name(w->m.bound));
            cJSON_AddNumberToObject(r, "cpu_us_per_ray", w->m.cpu_us);
            cJSON_AddNumberToObject(r, "cpu_us_per_ray_min", w->m.cpu_lo);
            cJSON_AddNumberToObject(r, "cpu_us_per_ray_max", w->m.cpu_hi);
            cJSON_AddItemToArray(arr, r);
        }
        cJSON *mj = cJSON_AddObjectToObject(root, "timing");
        if (isfinite(rm.cache_kb))
            cJSON_AddNumberToObject(mj, "cache_kb", rm.cache_kb);
        else
            cJSON_AddNullToObject(mj, "cache_kb");
        cJSON_AddNumberToObject(mj, "rays_in_flight", rm.tp.rays_in_flight);
        cJSON_AddNumberToObject(mj, "cpu_reps", rm.reps);
        cJSON_AddStringToObject(root, "best", best ? "cbvh" : "float");
        if (best) cJSON_AddNumberToObject(root, "best_bits", rows[best].bits);
        cJSON_AddStringToObject(root, "advice", sentence);
        cbvh_json_print_pretty(root, stdout); /* a write error is main's one line */
        cJSON_Delete(root);
    } else {
        printf("\n== Accuracy vs time: %s (%u triangles, %llu rays over its effects) ==\n", scene_path,
               d.mesh.ntris, (unsigned long long)f->m.rays);
        char line[400], cn[32];
        cbvh_machine_line(&rm.tp, line, sizeof line);
        printf("  timing model (docs/timing_model.md): cache %s; %s\n", cbvh_cache_name(rm.cache_kb, cn, sizeof cn),
               line);
        printf("  format  memory  box/ray  tri/ray  bytes/ray  model ns/ray  nJ/ray  hit %%  CPU us/ray [min-max]   "
               "(x float: memory, box, tri, bytes, model, energy, CPU)\n");
        for (int i = 0; i < nrows; i++) {
            const width_row *w = &rows[i];
            char name[16];
            snprintf(name, sizeof name, w->bits ? "N=%d" : "float", w->bits);
            char cpu[40];
            snprintf(cpu, sizeof cpu, "%.2f [%.2f-%.2f]", w->m.cpu_us, w->m.cpu_lo, w->m.cpu_hi);
            printf("  %-6s %7llu  %7.2f  %7.2f  %9.0f  %12.1f  %6.3f  %5.1f  %-20s", name,
                   (unsigned long long)w->node_bytes, w->m.box, w->m.tri, w->m.bytes, w->m.model_ns, w->m.energy_nj,
                   100.0 * w->m.hit_rate, cpu);
            if (w->bits) {
                printf("  ");
                cbvh_print_x(cbvh_ratio((double)w->node_bytes, (double)f->node_bytes), 3);
                cbvh_print_x(cbvh_ratio(w->m.box, f->m.box), 3);
                cbvh_print_x(cbvh_ratio(w->m.tri, f->m.tri), 3);
                cbvh_print_x(cbvh_ratio(w->m.bytes, f->m.bytes), 3);
                cbvh_print_x(cbvh_ratio(w->m.model_ns, f->m.model_ns), 3);
                cbvh_print_x(cbvh_ratio(w->m.energy_nj, f->m.energy_nj), 3);
                cbvh_print_x(cbvh_fx_cpu_ratio(&w->tot, &f->tot), 2);
            }
            printf("\n");
        }
        printf("\nHits %s the float BVH's for every width (closest hits: triangle and t bits;\n"
               "any hits: hit or not). Model time: docs/timing_model.md; CPU time is the bit-exact\n"
               "model's own speed on this machine (median of %d timed passes). Per effect: cbvh trace %s --bits N;\n"
               "every N, M, min scale and cache size: cbvh sweep %s --cache 16 256.\n\n%s\n",
               same_hits ? "are identical to" : "DIFFER from", rm.reps, scene_path, scene_path, sentence);
    }
    cbvh_scene_desc_free(&d);
    return rc;
}
