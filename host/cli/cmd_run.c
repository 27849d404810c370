/* `cbvh run`: the kit's main job.
 *   1. check the golden vectors on the board, or on the model without one;
 *   2. on the bundled scene file, what each coordinate width N costs: trace the
 *      rays the scene's effects call for through the float BVH and through the
 *      bit-exact CBVH at N = 3..10, and report memory, traversal work, the timing
 *      model's time and CPU time relative to the float BVH, with a proof that
 *      every CBVH gives exactly the float BVH's hits. */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "link/backend.h"
#include "cbvh/oom.h"
#include "cli/commands.h"
#include "trace/effects.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"
#include "vectors/vectors_check.h"

/* The defaults are the source tree's committed vectors and bundled scene
 * wherever cbvh runs: a ./vectors or ./scenes of the working directory is
 * not what the help promises.  Explicit paths stay relative to the cwd. */
#define DEFAULT_VECTORS CBVH_SOURCE_DIR "/vectors"
#define DEFAULT_SCENE CBVH_SOURCE_DIR "/scenes/bunny.scene"

static void usage(FILE *f) {
    fprintf(f,
            "usage: cbvh run [--backend SPEC] [--vectors DIR] [--scene SCENE] [--json]\n"
            "\n"
            "The main job: checks the golden vectors (on a board if one is attached, else on\n"
            "the bit-exact model), then traces the effects of a scene file through the float\n"
            "BVH and the bit-exact CBVH at N = 3..10 and prints what each width costs: node\n"
            "memory, box and triangle tests, bytes, modelled and CPU time per ray, relative to\n"
            "the float BVH, and whether the hits are identical.\n"
            "\n"
            "  --backend SPEC  auto (default), model, usb, hid, sim:ADDR\n"
            "  --vectors DIR   vector directory (default: the committed vectors/ of the source tree,\n"
            "                  from any working directory)\n"
            "  --scene SCENE   scene file, or a mesh file / proc:NAME with its default scene\n"
            "                  (default: the source tree's scenes/bunny.scene; docs/scenes.md)\n"
            "  --json          one JSON object instead of tables\n");
}

typedef struct {
    int bits; /* 0 = float BVH */
    uint64_t node_bytes, rays, hit_digest;
    double box, tri, bytes, model_ns, cpu_us; /* per ray, all effects */
} width_row;

/* Traces the scene in one format and sums the per-effect counters. */
static int measure(const cbvh_scene_desc *d, const cbvh_timing_params *tp, int bits, width_row *row, char *err,
                   size_t errlen) {
    cbvh_fx_opts o;
    memset(&o, 0, sizeof o);
    o.format = bits ? CBVH_FORMAT_CBVH : CBVH_FORMAT_FLOAT;
    o.params.quant_bits = bits ? bits : CBVH_N_DEFAULT;
    o.params.min_scale = CBVH_MIN_SCALE_DEFAULT;
    o.mant = 24;
    cbvh_fx_result r;
    if (cbvh_fx_run(d, &o, &r, err, errlen) != 0) return -1;
    cbvh_fx_stats t = cbvh_fx_total(&r);
    cbvh_timing_work w = {t.st.box_tests, t.st.tri_tests, t.st.nodes, t.st.bytes};
    memset(row, 0, sizeof *row);
    row->bits = bits;
    row->rays = t.rays;
    cbvh_timing_result tr;
    if (cbvh_timing_eval(tp, &w, &tr) != 0 || row->rays == 0) {
        snprintf(err, errlen, "scene traces no rays or has an invalid timing model");
        return -1;
    }
    double n = (double)row->rays;
    row->node_bytes = r.node_bytes;
    row->hit_digest = r.hit_digest;
    row->box = (double)w.box_tests / n;
    row->tri = (double)w.tri_tests / n;
    row->bytes = (double)w.bytes / n;
    row->model_ns = tr.seconds * 1e9 / n;
    row->cpu_us = t.cpu_seconds * 1e6 / n;
    return 0;
}

int cmd_run(int argc, char **argv) {
    static const struct option longopts[] = {{"backend", required_argument, 0, 'b'},
                                             {"vectors", required_argument, 0, 'v'},
                                             {"scene", required_argument, 0, 's'},
                                             {"json", no_argument, 0, 'j'},
                                             {"help", no_argument, 0, 'h'},
                                             {0, 0, 0, 0}};
    const char *backend = "auto", *vec_dir = NULL, *scene_path = NULL;
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
        case 'h': usage(stdout); return 0;
        default: return cbvh_bad_option("cbvh run", argv, optind);
        }
    }
    if (optind != argc) {
        fprintf(stderr, "cbvh run: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    if (!vec_dir) vec_dir = DEFAULT_VECTORS;
    if (!scene_path) scene_path = DEFAULT_SCENE;
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
        cbvh_scene_desc_free(&d);
        return 2;
    }

    /* 2. Accuracy vs time on the scene. */
    cbvh_timing_params tp;
    cbvh_fx_timing(&d, &tp);
    width_row rows[1 + CBVH_N_MAX - CBVH_N_MIN + 1];
    int nrows = 0, rc = check, same_hits = 1;
    for (int n = 0; n <= CBVH_N_MAX; n = n ? n + 1 : CBVH_N_MIN, nrows++) {
        if (measure(&d, &tp, n, &rows[nrows], err, sizeof err) != 0) {
            fprintf(stderr, "cbvh run: %s: %s\n", scene_path, err);
            cbvh_scene_desc_free(&d);
            return 2;
        }
        if (rows[nrows].hit_digest != rows[0].hit_digest) same_hits = 0;
    }
    if (!same_hits) rc = 1;
    const width_row *f = &rows[0];

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
        cJSON_AddNumberToObject(s, "rays", (double)f->rays);
        cJSON_AddBoolToObject(s, "hits_identical_to_float", same_hits);
        cJSON *arr = cJSON_AddArrayToObject(root, "formats");
        for (int i = 0; i < nrows; i++) {
            const width_row *w = &rows[i];
            cJSON *r = cJSON_CreateObject();
            cJSON_AddStringToObject(r, "format", w->bits ? "cbvh" : "float");
            if (w->bits) cJSON_AddNumberToObject(r, "bits", w->bits);
            cJSON_AddNumberToObject(r, "node_bytes", (double)w->node_bytes);
            cJSON_AddNumberToObject(r, "box_tests_per_ray", w->box);
            cJSON_AddNumberToObject(r, "tri_tests_per_ray", w->tri);
            cJSON_AddNumberToObject(r, "bytes_per_ray", w->bytes);
            cJSON_AddNumberToObject(r, "model_ns_per_ray", w->model_ns);
            cJSON_AddNumberToObject(r, "cpu_us_per_ray", w->cpu_us);
            cJSON_AddItemToArray(arr, r);
        }
        char *text = cJSON_Print(root);
        if (!text) cbvh_out_of_memory("run JSON");
        cbvh_json_fputs_utf8(text, stdout); /* paths may hold bytes that are not UTF-8 */
        putchar('\n');
        free(text);
        cJSON_Delete(root);
    } else {
        printf("\n== Accuracy vs time: %s (%u triangles, %llu rays over its effects) ==\n", scene_path,
               d.mesh.ntris, (unsigned long long)f->rays);
        printf("  format  memory  box/ray  tri/ray  bytes/ray  model ns/ray  CPU us/ray   (x float: memory, box, tri, "
               "bytes, model, CPU)\n");
        for (int i = 0; i < nrows; i++) {
            const width_row *w = &rows[i];
            char name[16];
            snprintf(name, sizeof name, w->bits ? "N=%d" : "float", w->bits);
            printf("  %-6s %7llu  %7.2f  %7.2f  %9.0f  %12.1f  %10.2f", name, (unsigned long long)w->node_bytes,
                   w->box, w->tri, w->bytes, w->model_ns, w->cpu_us);
            if (w->bits) {
                printf("  ");
                cbvh_print_x(cbvh_ratio((double)w->node_bytes, (double)f->node_bytes), 3);
                cbvh_print_x(cbvh_ratio(w->box, f->box), 3);
                cbvh_print_x(cbvh_ratio(w->tri, f->tri), 3);
                cbvh_print_x(cbvh_ratio(w->bytes, f->bytes), 3);
                cbvh_print_x(cbvh_ratio(w->model_ns, f->model_ns), 3);
                cbvh_print_x(cbvh_ratio(w->cpu_us, f->cpu_us), 2);
            }
            printf("\n");
        }
        printf("\nHits %s the float BVH's for every width (closest hits: triangle and t bits;\n"
               "any hits: hit or not). Model time: docs/timing_model.md; CPU time is the bit-exact\n"
               "model's own speed on this machine. Per effect: cbvh trace %s --bits N.\n",
               same_hits ? "are identical to" : "DIFFER from", scene_path);
    }
    cbvh_scene_desc_free(&d);
    return rc;
}
