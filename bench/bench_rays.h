/* What the traversal benchmarks share (same definitions, so figures compare):
 *   - the rays: camera rays over a square image looking at the scene centre
 *     from outside its box (first half) and random rays with origins in the box
 *     and directions uniform on the sphere (second half); xorshift64, seeded by
 *     the caller through rs;
 *   - option parsing (--rays, --reps), scene loading + SAH float BVH, wall-clock
 *     timing and the fatal-error exit.
 * Define BENCH_NAME (the program name, for error messages) before including. */
#ifndef CBVH_BENCH_RAYS_H
#define CBVH_BENCH_RAYS_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbvh/traverse.h"
#include "scene/scene_load.h"
#include "test_util.h" /* fb, bf, xorshift64 (tests/common) */

#ifndef BENCH_NAME
#error "define BENCH_NAME before including bench_rays.h"
#endif

static uint64_t rs = 1; /* generator state: set it before make_rays */

static inline uint64_t rnd(void) { return tu_xorshift64(&rs); }
static inline float unit(void) { return tu_unit_f(&rs); }

static inline double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static inline void die(const char *what, const char *err) {
    fprintf(stderr, BENCH_NAME ": %s: %s\n", what, err);
    exit(1);
}

/* argv[*i] == name with a value in [lo, hi]: store it, step past it, return 1. */
static inline int int_option(int argc, char **argv, int *i, const char *name, int lo, int hi, int *val) {
    if (strcmp(argv[*i], name) || *i + 1 >= argc) return 0;
    *val = atoi(argv[++*i]);
    if (*val < lo || *val > hi) {
        char msg[64];
        snprintf(msg, sizeof msg, "must be %d..%d", lo, hi);
        die(name, msg);
    }
    return 1;
}

/* The command line of the traversal-vs-Embree benches:
 *   [--rays R] [--seed S] [--reps K] [--embree-isa ISA] [--embree-robust] [SCENE...]
 * (isa: Embree's isa= setting; NULL = Embree's own choice; robust: Embree's
 * scene flag RTC_SCENE_FLAG_ROBUST, its watertight mode).  Exits 2 with the
 * usage on an unknown option, 1 on a bad value; no scene = the bundled bunny. */
typedef struct {
    int nrays, reps;
    uint64_t seed;
    const char *isa;
    int robust;
    const char *specs[64];
    int ns;
} bench_args;

static inline void bench_parse(int argc, char **argv, bench_args *a, const char *default_scene) {
    for (int i = 1; i < argc; i++) {
        if (int_option(argc, argv, &i, "--rays", 2, 10000000, &a->nrays) ||
            int_option(argc, argv, &i, "--reps", 1, 100, &a->reps))
            continue;
        if (!strcmp(argv[i], "--seed") && i + 1 < argc) {
            a->seed = strtoull(argv[++i], NULL, 0);
        } else if (!strcmp(argv[i], "--embree-isa") && i + 1 < argc) {
            a->isa = argv[++i];
            static const char *const known[] = {"sse2", "sse4.2", "avx", "avx2", "avx512"};
            int ok = 0;
            for (size_t k = 0; k < sizeof known / sizeof known[0]; k++) ok |= !strcmp(a->isa, known[k]);
            if (!ok) die("--embree-isa", "must be sse2, sse4.2, avx, avx2 or avx512");
        } else if (!strcmp(argv[i], "--embree-robust")) {
            a->robust = 1;
        } else if (!strcmp(argv[i], "--wide-isa") && i + 1 < argc) { /* cap the wide float traversals' ISA */
            const char *w = argv[++i];
            if (strcmp(w, "base") && strcmp(w, "avx")) die("--wide-isa", "must be base or avx");
            cbvh_wide_float_limit_isa(strcmp(w, "avx") ? CBVH_WIDE_ISA_BASE : CBVH_WIDE_ISA_AVX);
        } else if (!strcmp(argv[i], "--wide-box") && i + 1 < argc) { /* the wide float box lanes' precision */
            const char *w = argv[++i];
            if (strcmp(w, "f32") && strcmp(w, "f64")) die("--wide-box", "must be f32 or f64");
            cbvh_wide_float_box32(!strcmp(w, "f32"));
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: " BENCH_NAME " [--rays R] [--seed S] [--reps K] [--embree-isa ISA] "
                            "[--embree-robust] [--wide-isa base|avx] [--wide-box f32|f64] [SCENE...]\n");
            exit(2);
        } else if (a->ns < 64) {
            a->specs[a->ns++] = argv[i];
        }
    }
    if (!a->ns) a->specs[a->ns++] = default_scene;
    rs = a->seed * 0x9E3779B97F4A7C15u + 0x2545F4914F6CDD1Du; /* the rays' generator */
    if (!rs) rs = 1;
}

/* Open a scene and build its binned-SAH float BVH; `build` names the step in
 * the error message. */
static inline void load_scene(const char *spec, cbvh_scene *s, cbvh_bvh *b, const char *build) {
    char err[512];
    if (cbvh_scene_open(spec, s, err, sizeof err)) die(spec, err);
    if (cbvh_build_sah(s, 0, 0, b, err, sizeof err)) die(build, err);
}

/* File name of a scene spec, for the tables. */
static inline const char *scene_base(const char *spec) {
    const char *slash = strrchr(spec, '/');
    return slash ? slash + 1 : spec;
}

/* The pinhole camera of make_rays for n rays: eye, forward w, right u, up v,
 * ncam = n / 2 camera rays over a side x side image. */
typedef struct {
    float eye[3], w[3], u[3], v[3];
    int side, ncam;
} camera;

static inline void camera_of(const float lo[3], const float hi[3], int n, camera *C) {
    float c[3], ext = 0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        if (hi[a] - lo[a] > ext) ext = hi[a] - lo[a];
    }
    if (ext <= 0) ext = 1;
    C->ncam = n / 2;
    C->side = (int)ceil(sqrt((double)C->ncam));
    float eye[3] = {c[0] + 0.3f * ext, c[1] + 0.4f * ext, c[2] + 1.6f * ext}, len = 0;
    memcpy(C->eye, eye, sizeof eye);
    for (int a = 0; a < 3; a++) C->w[a] = c[a] - eye[a], len += C->w[a] * C->w[a];
    len = sqrtf(len);
    for (int a = 0; a < 3; a++) C->w[a] /= len;
    float u[3] = {C->w[2], 0, -C->w[0]}, ul = sqrtf(u[0] * u[0] + u[2] * u[2]);
    for (int a = 0; a < 3; a++) C->u[a] = u[a] / ul;
    C->v[0] = C->u[1] * C->w[2] - C->u[2] * C->w[1];
    C->v[1] = C->u[2] * C->w[0] - C->u[0] * C->w[2];
    C->v[2] = C->u[0] * C->w[1] - C->u[1] * C->w[0];
}

/* Direction through image point (X, Y) in pixels (pixel centres at k + 0.5). */
static inline void cam_dir(const camera *C, float X, float Y, float d[3]) {
    float px = X / (float)C->side * 2 - 1, py = Y / (float)C->side * 2 - 1;
    for (int a = 0; a < 3; a++) d[a] = C->w[a] + 0.45f * (px * C->u[a] + py * C->v[a]);
}

static inline void make_rays(const float lo[3], const float hi[3], int n, cbvh_ray *rays) {
    camera C;
    camera_of(lo, hi, n, &C);
    for (int i = 0; i < n; i++) {
        cbvh_ray *r = &rays[i];
        float d[3], o[3];
        if (i < C.ncam) {
            memcpy(o, C.eye, sizeof o);
            cam_dir(&C, (float)(i % C.side) + 0.5f, (float)(i / C.side) + 0.5f, d);
        } else {
            float z = unit() * 2 - 1, phi = 6.2831853f * unit(), s = sqrtf(fmaxf(0, 1 - z * z));
            d[0] = s * cosf(phi);
            d[1] = s * sinf(phi);
            d[2] = z;
            for (int a = 0; a < 3; a++) o[a] = lo[a] + unit() * (hi[a] - lo[a]);
            if (d[0] == 0 && d[1] == 0 && d[2] == 0) d[0] = 1;
        }
        for (int a = 0; a < 3; a++) {
            r->o[a] = fb(o[a]);
            r->d[a] = fb(d[a]);
        }
        r->tmin = 0;
        r->tmax = CBVH_F32_POS_INF;
    }
}

#endif
