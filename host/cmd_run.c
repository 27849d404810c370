/* `cbvh run`: the kit's main job.
 *   1. check the golden vectors on the board, or on the model without one;
 *   2. on the bundled scene, what each coordinate width N costs and buys:
 *      CBVH memory and tree quality (SAH cost of the decoded boxes) against the
 *      float BVH, and the time of the top-down compression that produces it. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "commands.h"
#include "scene_load.h"
#include "vectors_check.h"

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A bundled resource: relative to the working directory, else to the source tree. */
static const char *bundled(const char *rel, char *buf, size_t len) {
    if (access(rel, R_OK) == 0) return rel;
    snprintf(buf, len, "%s/%s", CBVH_SOURCE_DIR, rel);
    return buf;
}

static void usage(FILE *f) {
    fprintf(f,
            "usage: cbvh run [--backend SPEC] [--vectors DIR] [--scene PATH] [--json]\n"
            "\n"
            "The main job: checks the golden vectors (on a board if one is attached, else on\n"
            "the bit-exact model), then prints an accuracy-vs-time table for a scene: per\n"
            "coordinate width N, the CBVH's memory and SAH cost against the float BVH and the\n"
            "time to compress it.\n"
            "\n"
            "  --backend SPEC  auto (default), model, usb, hid, sim:ADDR\n"
            "  --vectors DIR   vector directory (default: the committed vectors/)\n"
            "  --scene PATH    mesh file or proc:NAME (default: scenes/bunny-small.obj)\n"
            "  --json          one JSON object instead of tables\n");
}

typedef struct {
    int bits;
    size_t bytes;
    double sah, seconds;
} width_row;

/* Best of `reps` top-down compressions at width n, checked against the float BVH. */
static int measure_width(const cbvh_bvh *bvh, int n, int reps, width_row *row, char *err, size_t errlen) {
    cbvh_compress_opts o;
    memset(&o, 0, sizeof o);
    o.params.quant_bits = n;
    o.params.min_scale = CBVH_MIN_SCALE_DEFAULT;
    o.enc = CBVH_ENC_MODULO;
    o.treelet_depth = 1;
    row->bits = n;
    row->seconds = 1e30;
    for (int r = 0; r < reps; r++) {
        cbvh_tree t;
        double t0 = now_seconds();
        if (cbvh_compress_topdown(bvh, &o, &t, err, errlen) != 0) return -1;
        double dt = now_seconds() - t0;
        if (dt < row->seconds) row->seconds = dt;
        if (r == 0) {
            if (cbvh_tree_check(&t, bvh, err, errlen) != 0) {
                cbvh_tree_free(&t);
                return -1;
            }
            row->bytes = cbvh_tree_bytes(&t);
            row->sah = cbvh_tree_sah(&t);
        }
        cbvh_tree_free(&t);
    }
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
    char vbuf[1024], sbuf[1024], err[512];
    optind = 1;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'b': backend = optarg; break;
        case 'v': vec_dir = optarg; break;
        case 's': scene_path = optarg; break;
        case 'j': json = 1; break;
        case 'h': usage(stdout); return 0;
        default: usage(stderr); return 2;
        }
    }
    if (optind != argc) {
        fprintf(stderr, "cbvh run: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    if (!vec_dir) vec_dir = bundled("vectors", vbuf, sizeof vbuf);
    if (!scene_path) scene_path = bundled("scenes/bunny-small.obj", sbuf, sizeof sbuf);

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
    if (!json) printf("== Golden vectors: %s ==\n", vec_dir);
    const char *paths[1] = {vec_dir};
    int check = cbvh_vectors_check(paths, 1, &co);
    if (check == CBVH_CHECK_BAD_INPUT) return 2;

    /* 2. Accuracy vs time on the scene. */
    cbvh_scene scene;
    memset(&scene, 0, sizeof scene);
    if (cbvh_scene_open(scene_path, &scene, err, sizeof err) != 0) {
        fprintf(stderr, "cbvh run: %s\n", err);
        return 2;
    }
    cbvh_bvh bvh;
    double t0 = now_seconds();
    if (cbvh_build_sah(&scene, 0, 0, &bvh, err, sizeof err) != 0) {
        fprintf(stderr, "cbvh run: %s: %s\n", scene_path, err);
        cbvh_scene_free(&scene);
        return 2;
    }
    double build_s = now_seconds() - t0;
    double float_sah = cbvh_bvh_sah(&bvh);
    size_t float_bytes = cbvh_bvh_bytes(&bvh);
    uint32_t leaves, inner;
    cbvh_bvh_counts(&bvh, &leaves, &inner);

    width_row rows[CBVH_N_MAX - CBVH_N_MIN + 1];
    int nrows = 0, rc = check;
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++, nrows++) {
        if (measure_width(&bvh, n, 5, &rows[nrows], err, sizeof err) != 0) {
            fprintf(stderr, "cbvh run: N=%d: %s\n", n, err);
            rc = 1;
            break;
        }
    }

    if (json) {
        cJSON *root = cJSON_CreateObject();
        cJSON *v = cJSON_AddObjectToObject(root, "vectors");
        cJSON_AddStringToObject(v, "backend", sum.backend);
        cJSON_AddNumberToObject(v, "files", (double)sum.files);
        cJSON_AddNumberToObject(v, "passed", (double)sum.passed);
        cJSON_AddNumberToObject(v, "failed", (double)sum.failed);
        cJSON *s = cJSON_AddObjectToObject(root, "scene");
        cJSON_AddStringToObject(s, "path", scene_path);
        cJSON_AddNumberToObject(s, "triangles", scene.ntris);
        cJSON_AddNumberToObject(s, "float_bvh_bytes", (double)float_bytes);
        cJSON_AddNumberToObject(s, "float_bvh_sah", float_sah);
        cJSON_AddNumberToObject(s, "float_bvh_build_seconds", build_s);
        cJSON *arr = cJSON_AddArrayToObject(root, "widths");
        for (int i = 0; i < nrows; i++) {
            cJSON *r = cJSON_CreateObject();
            cJSON_AddNumberToObject(r, "bits", rows[i].bits);
            cJSON_AddNumberToObject(r, "bytes", (double)rows[i].bytes);
            cJSON_AddNumberToObject(r, "memory_vs_float", (double)rows[i].bytes / (double)float_bytes);
            cJSON_AddNumberToObject(r, "sah", rows[i].sah);
            cJSON_AddNumberToObject(r, "sah_vs_float", rows[i].sah / float_sah);
            cJSON_AddNumberToObject(r, "compress_seconds", rows[i].seconds);
            cJSON_AddNumberToObject(r, "compress_vs_float_build", rows[i].seconds / build_s);
            cJSON_AddItemToArray(arr, r);
        }
        char *text = cJSON_Print(root);
        printf("%s\n", text);
        free(text);
        cJSON_Delete(root);
    } else {
        printf("\n== Accuracy vs time: %s (%u triangles; float SAH BVH: %u inner nodes, %u leaves) ==\n",
               scene_path, scene.ntris, inner, leaves);
        printf("   N  pair B   memory/float   SAH cost/float   compress ns/node   compress/float build\n");
        printf("  float  64      1.000          1.000            %8.1f (build)       1.00\n",
               1e9 * build_s / (double)(inner ? inner : 1));
        for (int i = 0; i < nrows; i++)
            printf("  %3d  %4zu      %6.3f         %6.3f           %8.1f               %5.2f\n", rows[i].bits,
                   cbvh_nodepair_bytes(rows[i].bits), (double)rows[i].bytes / (double)float_bytes,
                   rows[i].sah / float_sah, 1e9 * rows[i].seconds / (double)(inner ? inner : 1),
                   rows[i].seconds / build_s);
        printf("\nEvery decoded CBVH box was checked to enclose its float box. SAH cost is the\n"
               "expected traversal work (box + triangle tests) relative to the float BVH.\n");
    }
    cbvh_bvh_free(&bvh);
    cbvh_scene_free(&scene);
    return rc;
}
