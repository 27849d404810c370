/* Scenes call for effects (docs/scenes.md) and the timing model
 * (docs/timing_model.md):
 *   - an effect not named produces no rays and no unit activity; a static
 *     scene never runs the refit unit, an animated one does; the float format
 *     never runs the compressor or decoder;
 *   - every effect's rays are of the right kind (any-hit shadow rays aimed at
 *     the lights, mirror rays only from mirror surfaces, ...);
 *   - CBVH and float BVH see the same rays and the same hits;
 *   - so does the QBVH (format qbvh), ray by ray, also after refits; only
 *     it runs the qbvh_stack unit;
 *   - scene-file errors give the right one-line message;
 *   (the timing model's worked examples: tests/trace/test_timing.c) */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cbvh/qbvh.h"
#include "trace/effects.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"

#define MESH CBVH_SCENES_DIR "/bunny-small.obj"
#define CAMERA                                                                                                  \
    "\"camera\": {\"width\": 24, \"height\": 18, \"position\": [0, 6, 22], \"target\": [0, 4.2, 0], \"fov\": 35}"

static void load(const char *json, cbvh_scene_desc *d) {
    char err[512];
    int rc = cbvh_scene_file_parse(json, "t.scene", d, err, sizeof err);
    if (rc) fprintf(stderr, "parse failed: %s\n", err);
    assert_int_equal(rc, 0);
}

static cbvh_fx_opts opts(const char *f) {
    cbvh_fx_opts o = {.format = f, .params = {6, CBVH_MIN_SCALE_DEFAULT}, .mant = 24};
    return o;
}

static void run(const cbvh_scene_desc *d, cbvh_fx_opts *o, cbvh_fx_result *r) {
    char err[512];
    int rc = cbvh_fx_run(d, o, r, err, sizeof err);
    if (rc) fprintf(stderr, "run failed: %s\n", err);
    assert_int_equal(rc, 0);
}

/* ---- observer: checks every ray against what its effect calls for ---- */
typedef struct {
    const cbvh_scene_desc *d;
    uint64_t rays[CBVH_FX_COUNT];
    long bad;
} watch;

static void on_ray(void *ctx, const cbvh_fx_ray *r) {
    watch *w = ctx;
    const cbvh_scene_desc *d = w->d;
    w->rays[r->effect]++;
    int any = r->effect == CBVH_FX_HARD_SHADOWS || r->effect == CBVH_FX_SOFT_SHADOWS ||
              r->effect == CBVH_FX_AMBIENT_OCCLUSION;
    if ((r->mode == CBVH_TRAV_ANY) != any) w->bad++;
    if (r->effect == CBVH_FX_PRIMARY) {
        if (r->source_prim != UINT32_MAX) w->bad++;
        return;
    }
    if (r->source_prim >= d->mesh.ntris) {
        w->bad++;
        return;
    }
    int mirror = d->materials[d->tri_material[r->source_prim]].type == CBVH_MAT_MIRROR;
    if (mirror != (r->effect == CBVH_FX_MIRROR)) w->bad++; /* mirror rays from mirrors only, the rest from diffuse */
    float o[3], dir[3];
    for (int a = 0; a < 3; a++) o[a] = cbvh_float_of(r->ray.o[a]), dir[a] = cbvh_float_of(r->ray.d[a]);
    if (r->effect == CBVH_FX_HARD_SHADOWS || r->effect == CBVH_FX_SOFT_SHADOWS) {
        /* Aimed at the light: o + d is on it, tmax just short of it. */
        if (r->light < 0 || r->light >= d->nlights || !(cbvh_float_of(r->ray.tmax) < 1.0f && cbvh_float_of(r->ray.tmax) > 0.99f)) {
            w->bad++;
            return;
        }
        const cbvh_light *L = &d->lights[r->light];
        float rel[3];
        for (int a = 0; a < 3; a++) rel[a] = o[a] + dir[a] - L->position[a];
        if (r->effect == CBVH_FX_HARD_SHADOWS) {
            for (int a = 0; a < 3; a++)
                if (fabsf(rel[a]) > 1e-3f) w->bad++;
        } else {
            if (L->type != CBVH_LIGHT_AREA) w->bad++;
            /* rel = a u + b v with |a|, |b| <= 1/2 (u, v orthogonal in the test scenes) */
            float uu = L->u[0] * L->u[0] + L->u[1] * L->u[1] + L->u[2] * L->u[2];
            float vv = L->v[0] * L->v[0] + L->v[1] * L->v[1] + L->v[2] * L->v[2];
            float a = (rel[0] * L->u[0] + rel[1] * L->u[1] + rel[2] * L->u[2]) / uu;
            float b = (rel[0] * L->v[0] + rel[1] * L->v[1] + rel[2] * L->v[2]) / vv;
            if (fabsf(a) > 0.5001f || fabsf(b) > 0.5001f) w->bad++;
        }
    } else if (r->effect == CBVH_FX_AMBIENT_OCCLUSION) {
        if (fabsf(cbvh_float_of(r->ray.tmax) - d->effect[CBVH_FX_AMBIENT_OCCLUSION].distance) > 0) w->bad++;
        float l = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        if (fabsf(l - 1.0f) > 1e-3f) w->bad++;
    } else if (r->ray.tmax != CBVH_F32_POS_INF)
        w->bad++; /* mirror and bounce rays are unbounded */
}

static const char *all_fx_scene =
    "{\"mesh\": \"" MESH "\", " CAMERA ","
    "\"lights\": [{\"type\": \"point\", \"position\": [8, 16, 10]},"
    "             {\"type\": \"area\", \"position\": [-6, 14, 8], \"u\": [3, 0, 0], \"v\": [0, 0, 3]}],"
    "\"materials\": [{\"name\": \"clay\", \"type\": \"diffuse\"}, {\"name\": \"chrome\", \"type\": \"mirror\"}],"
    "\"mesh_material\": \"clay\", \"floor\": {\"material\": \"chrome\", \"size\": 3},"
    "\"effects\": [\"primary\", \"hard_shadows\", {\"effect\": \"soft_shadows\", \"samples\": 3},"
    "  {\"effect\": \"ambient_occlusion\", \"samples\": 2, \"distance\": 1.5}, {\"effect\": \"mirror\", \"max_depth\": 2},"
    "  {\"effect\": \"diffuse_bounce\", \"samples\": 2}]}";

/* Only primary: zero rays of every other effect, zero any-hit traversals, no
 * refit; float format: no compressor, no decoder. */
static void primary_only(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", " CAMERA
         ", \"lights\": [{\"type\": \"point\", \"position\": [8, 16, 10]}], \"effects\": [\"primary\"]}",
         &d);
    for (int f = 0; f < 2; f++) {
        cbvh_fx_opts o = opts(f ? "cbvh" : "float");
        watch w = {&d, {0}, 0};
        o.on_ray = on_ray;
        o.ctx = &w;
        cbvh_fx_result r;
        run(&d, &o, &r);
        assert_int_equal(w.bad, 0);
        assert_int_equal(r.fx[CBVH_FX_PRIMARY].rays, 24 * 18);
        assert_int_equal(w.rays[CBVH_FX_PRIMARY], 24 * 18);
        assert_true(r.fx[CBVH_FX_PRIMARY].hits > 0);
        assert_int_equal(r.fx[CBVH_FX_PRIMARY].any, 0);
        for (int e = 1; e < CBVH_FX_COUNT; e++) {
            assert_int_equal(r.fx[e].rays, 0);
            assert_int_equal(w.rays[e], 0);
            assert_int_equal(r.fx[e].st.box_tests + r.fx[e].st.tri_tests + r.fx[e].st.bytes, 0);
        }
        assert_int_equal(r.units.refit, 0);
        assert_int_equal(r.refits, 0);
        assert_int_equal(r.units.ray_box, r.fx[CBVH_FX_PRIMARY].st.box_tests);
        assert_int_equal(r.units.ray_triangle, r.fx[CBVH_FX_PRIMARY].st.tri_tests);
        if (f) {
            assert_true(r.units.compressor > 0);
            assert_int_equal(r.units.decoder, 6 * r.fx[CBVH_FX_PRIMARY].st.nodes);
        } else {
            assert_int_equal(r.units.compressor, 0);
            assert_int_equal(r.units.decoder, 0);
        }
    }
    cbvh_scene_desc_free(&d);
}

/* Every effect named: each produces rays of its kind; CBVH = float BVH on the
 * same rays (same counts per effect, same hits). */
static void all_effects(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load(all_fx_scene, &d);
    cbvh_fx_result r[2];
    for (int f = 0; f < 2; f++) {
        cbvh_fx_opts o = opts(f ? "cbvh" : "float");
        watch w = {&d, {0}, 0};
        o.on_ray = on_ray;
        o.ctx = &w;
        run(&d, &o, &r[f]);
        assert_int_equal(w.bad, 0);
        for (int e = 0; e < CBVH_FX_COUNT; e++) {
            assert_true(r[f].fx[e].rays > 0);
            assert_int_equal(w.rays[e], r[f].fx[e].rays);
            int any = e == CBVH_FX_HARD_SHADOWS || e == CBVH_FX_SOFT_SHADOWS || e == CBVH_FX_AMBIENT_OCCLUSION;
            assert_int_equal(any ? r[f].fx[e].closest : r[f].fx[e].any, 0);
        }
        assert_int_equal(r[f].units.refit, 0);
    }
    assert_int_equal(r[0].hit_digest, r[1].hit_digest);
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        assert_int_equal(r[0].fx[e].rays, r[1].fx[e].rays);
        assert_int_equal(r[0].fx[e].hits, r[1].fx[e].hits);
        assert_true(r[1].fx[e].st.box_tests >= r[0].fx[e].st.box_tests); /* CBVH boxes enclose the float ones */
    }
    /* Soft shadows: 3 samples per area light per lit point, so a multiple of 3. */
    assert_int_equal(r[1].fx[CBVH_FX_SOFT_SHADOWS].rays % 3, 0);
    /* Deterministic: the same run gives the same digest. */
    cbvh_fx_opts o = opts("cbvh");
    cbvh_fx_result again;
    run(&d, &o, &again);
    assert_int_equal(again.hit_digest, r[1].hit_digest);
    cbvh_scene_desc_free(&d);
}

/* Removing mirrors from the scene removes every mirror ray. */
static void no_mirror_material(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", " CAMERA ", \"floor\": {}, \"effects\": [\"primary\", \"mirror\"]}", &d);
    cbvh_fx_opts o = opts("cbvh");
    cbvh_fx_result r;
    run(&d, &o, &r);
    assert_true(r.fx[CBVH_FX_PRIMARY].hits > 0);
    assert_int_equal(r.fx[CBVH_FX_MIRROR].rays, 0);
    cbvh_scene_desc_free(&d);
}

/* Animation forces refits (frames - 1 of them, on both formats); the static
 * scene above never refits. */
static void animated_refits(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"],"
         "\"animation\": {\"type\": \"twist\", \"frames\": 3, \"amount\": 0.8}}",
         &d);
    for (int f = 0; f < 2; f++) {
        cbvh_fx_opts o = opts(f ? "cbvh" : "float");
        cbvh_fx_result r;
        run(&d, &o, &r);
        assert_int_equal(r.frames, 3);
        assert_int_equal(r.refits, 2);
        assert_true(r.units.refit > 0);
        assert_int_equal(r.units.refit % 2, 0);
        assert_int_equal(r.fx[CBVH_FX_PRIMARY].rays, 3 * 24 * 18);
        for (int e = 1; e < CBVH_FX_COUNT; e++) assert_int_equal(r.fx[e].rays, 0);
    }
    /* The frames really move: frame 2 differs from frame 0. */
    cbvh_tri *a = malloc(d.mesh.ntris * sizeof *a), *b = malloc(d.mesh.ntris * sizeof *b);
    cbvh_scene_desc_frame(&d, 0, a);
    cbvh_scene_desc_frame(&d, 2, b);
    assert_true(memcmp(a, b, d.mesh.ntris * sizeof *a) != 0);
    free(a);
    free(b);
    cbvh_scene_desc_free(&d);
}

/* ---- QBVH (docs/qbvh.md): the same rays and hits as the float BVH ---- */
typedef struct {
    watch w;
    uint64_t n, cap;
    uint32_t *rec; /* per ray: effect, hit, prim, t bits (closest) */
} recorder;

static void record(void *ctx, const cbvh_fx_ray *r) {
    recorder *c = ctx;
    on_ray(&c->w, r);
    if (c->n + 4 > c->cap) {
        c->cap = c->cap ? 2 * c->cap : 4096;
        c->rec = realloc(c->rec, c->cap * sizeof *c->rec);
        assert_non_null(c->rec);
    }
    int closest = r->mode == CBVH_TRAV_CLOSEST;
    c->rec[c->n++] = (uint32_t)r->effect;
    c->rec[c->n++] = r->hit->hit != 0;
    c->rec[c->n++] = closest && r->hit->hit ? r->hit->prim : 0;
    c->rec[c->n++] = closest && r->hit->hit ? r->hit->t : 0;
}

static void run_recorded(const cbvh_scene_desc *d, const char *f, recorder *c, cbvh_fx_result *r) {
    memset(c, 0, sizeof *c);
    c->w.d = d;
    cbvh_fx_opts o = opts(f);
    o.on_ray = record;
    o.ctx = c;
    run(d, &o, r);
    assert_int_equal(c->w.bad, 0);
}

/* Every effect: the QBVH traces the float BVH's rays and returns its hits ray
 * by ray (triangle and t bits for closest hit, hit/miss for any hit); the
 * qbvh_stack unit runs only in format qbvh, once per inner node visited plus
 * once per pop; the compressed stack is never deeper than the binary one. */
static void qbvh_all_effects(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load(all_fx_scene, &d);
    static cbvh_fx_result r[3];
    recorder c[3];
    const char *const fm[3] = {"float", "cbvh", "qbvh"};
    for (int f = 0; f < 3; f++) run_recorded(&d, fm[f], &c[f], &r[f]);
    assert_int_equal(c[2].n, c[0].n);
    assert_memory_equal(c[2].rec, c[0].rec, c[0].n * sizeof *c[0].rec);
    assert_int_equal(r[2].hit_digest, r[0].hit_digest);
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        assert_true(r[2].fx[e].rays > 0);
        assert_int_equal(r[2].fx[e].rays, r[0].fx[e].rays);
        assert_int_equal(r[2].fx[e].hits, r[0].fx[e].hits);
        assert_int_equal(r[2].fx[e].st.qstack_pushes, r[2].fx[e].st.nodes);
        assert_true(r[2].fx[e].st.qstack_pops > 0);
        assert_true(r[2].fx[e].st.max_stack <= r[0].fx[e].st.max_stack);
    }
    cbvh_fx_stats t = cbvh_fx_total(&r[2]);
    assert_true(r[2].units.qbvh_stack > 0);
    assert_int_equal(r[2].units.qbvh_stack, t.st.qstack_pushes + t.st.qstack_pops);
    assert_int_equal(r[2].units.ray_box, t.st.box_tests);
    assert_int_equal(r[2].units.ray_triangle, t.st.tri_tests);
    assert_int_equal(r[2].units.compressor + r[2].units.decoder + r[2].units.refit, 0);
    assert_int_equal(r[0].units.qbvh_stack, 0);
    assert_int_equal(r[1].units.qbvh_stack, 0);
    /* The 4-ary tree: fewer nodes than the binary one, so less memory. */
    assert_true(r[2].node_bytes > 0 && r[2].node_bytes < r[0].node_bytes);
    for (int f = 0; f < 3; f++) free(c[f].rec);
    cbvh_scene_desc_free(&d);
}

/* Effects not named make no QBVH rays (and no stack activity for them). */
static void qbvh_effects_obeyed(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", " CAMERA ", \"lights\": [{\"type\": \"point\", \"position\": [8, 16, 10]}],"
         " \"effects\": [\"primary\", \"hard_shadows\"]}",
         &d);
    cbvh_fx_result r;
    recorder c;
    run_recorded(&d, "qbvh", &c, &r);
    assert_int_equal(r.fx[CBVH_FX_PRIMARY].rays, 24 * 18);
    assert_true(r.fx[CBVH_FX_HARD_SHADOWS].rays > 0);
    assert_int_equal(r.fx[CBVH_FX_HARD_SHADOWS].closest, 0);
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        if (e == CBVH_FX_PRIMARY || e == CBVH_FX_HARD_SHADOWS) continue;
        assert_int_equal(r.fx[e].rays, 0);
        assert_int_equal(c.w.rays[e], 0);
        assert_int_equal(r.fx[e].st.box_tests + r.fx[e].st.qstack_pushes + r.fx[e].st.qstack_pops, 0);
    }
    assert_true(r.units.qbvh_stack > 0);
    assert_int_equal(r.refits + r.units.refit, 0);
    free(c.rec);
    cbvh_scene_desc_free(&d);
}

/* Animated: the QBVH's boxes are refitted every frame (its node count per
 * refit) and the hits stay the float BVH's on every frame; without the refit
 * the moved triangles would fall outside the frame-0 boxes. */
static void qbvh_animated(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", " CAMERA ", \"lights\": [{\"type\": \"point\", \"position\": [8, 16, 10]}],"
         " \"effects\": [\"primary\", \"hard_shadows\"],"
         "\"animation\": {\"type\": \"twist\", \"frames\": 3, \"amount\": 0.8}}",
         &d);
    static cbvh_fx_result r[2];
    recorder c[2];
    run_recorded(&d, "float", &c[0], &r[0]);
    run_recorded(&d, "qbvh", &c[1], &r[1]);
    assert_int_equal(r[1].refits, 2);
    uint64_t nnodes = (r[1].node_bytes - (uint64_t)d.mesh.ntris * 4u) / CBVH_QBVH_NODE_BYTES;
    assert_int_equal(r[1].units.refit, 2 * nnodes);
    assert_int_equal(c[1].n, c[0].n);
    assert_memory_equal(c[1].rec, c[0].rec, c[0].n * sizeof *c[0].rec);
    assert_int_equal(r[1].hit_digest, r[0].hit_digest);
    assert_int_equal(r[1].fx[CBVH_FX_PRIMARY].rays, 3 * 24 * 18);
    free(c[0].rec);
    free(c[1].rec);
    cbvh_scene_desc_free(&d);
}

/* ---- traversal lists (docs/tlist.md) ----------------------------------------
 * Every effect, every list option (1/2/6/8 lists, both orders, culling,
 * heads), two-sided and one-sided: the lists trace the float BVH's rays and
 * return its hits ray by ray; only the sphere and triangle units run. */
static void run_recorded_o(const cbvh_scene_desc *d, cbvh_fx_opts *o, recorder *c, cbvh_fx_result *r) {
    memset(c, 0, sizeof *c);
    c->w.d = d;
    o->on_ray = record;
    o->ctx = c;
    run(d, o, r);
    assert_int_equal(c->w.bad, 0);
}

static void tlist_all_effects(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load(all_fx_scene, &d);
    static const char *specs[] = {"tlist:1",        "tlist:2:latest",     "tlist:6",           "tlist:8:latest",
                                  "tlist:6:heads",  "tlist:6:cull",       "tlist:8:cull:heads", "tlist:1:latest:heads",
                                  "tlist:2:cull:heads"};
    for (int one_sided = 0; one_sided < 2; one_sided++) {
        static cbvh_fx_result rf, rl;
        recorder cf, cl;
        cbvh_fx_opts o = opts("float");
        o.one_sided = one_sided;
        run_recorded_o(&d, &o, &cf, &rf);
        for (size_t k = 0; k < sizeof specs / sizeof specs[0]; k++) {
            char err[256];
            o = opts(specs[k]);
            o.one_sided = one_sided;
            if (strstr(specs[k], ":cull") && !one_sided) {
                cbvh_fx_result bad;
                assert_int_equal(cbvh_fx_run(&d, &o, &bad, err, sizeof err), -1);
                assert_non_null(strstr(err, "--one-sided"));
                continue;
            }
            run_recorded_o(&d, &o, &cl, &rl);
            if (cl.n != cf.n || memcmp(cl.rec, cf.rec, cf.n * sizeof *cf.rec))
                fprintf(stderr, "%s (one-sided %d) differs from the float BVH\n", specs[k], one_sided);
            assert_int_equal(cl.n, cf.n);
            assert_memory_equal(cl.rec, cf.rec, cf.n * sizeof *cf.rec);
            assert_int_equal(rl.hit_digest, rf.hit_digest);
            cbvh_fx_stats t = cbvh_fx_total(&rl);
            assert_true(rl.units.ray_sphere > 0);
            assert_int_equal(rl.units.ray_sphere, t.st.box_tests);
            assert_int_equal(rl.units.ray_triangle, t.st.tri_tests);
            assert_int_equal(rl.units.ray_box + rl.units.compressor + rl.units.decoder + rl.units.refit +
                                 rl.units.qbvh_stack,
                             0);
            assert_int_equal(t.st.max_stack, 0); /* stackless */
            assert_true(rl.node_bytes > 0);
            free(cl.rec);
        }
        assert_int_equal(rf.units.ray_sphere, 0);
        free(cf.rec);
    }
    cbvh_scene_desc_free(&d);
}

/* Heads only skip work: the same hits with fewer sphere tests in total. */
static void tlist_heads_save_work(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load(all_fx_scene, &d);
    cbvh_fx_result r[2];
    for (int h = 0; h < 2; h++) {
        cbvh_fx_opts o = opts(h ? "tlist:6:heads" : "tlist:6");
        run(&d, &o, &r[h]);
    }
    assert_int_equal(r[1].hit_digest, r[0].hit_digest);
    cbvh_fx_stats a = cbvh_fx_total(&r[0]), b = cbvh_fx_total(&r[1]);
    assert_true(b.st.box_tests < a.st.box_tests);
    assert_true(r[1].fx[CBVH_FX_PRIMARY].st.box_tests < r[0].fx[CBVH_FX_PRIMARY].st.box_tests); /* cell heads */
    assert_true(r[1].fx[CBVH_FX_DIFFUSE_BOUNCE].st.box_tests < r[0].fx[CBVH_FX_DIFFUSE_BOUNCE].st.box_tests); /* polygon */
    assert_true(r[1].node_bytes > r[0].node_bytes); /* the per-polygon heads are stored */
    cbvh_scene_desc_free(&d);
}

/* Animated: the lists are rebuilt every frame (lists are not updatable:
 * culling and heads depend on the moved triangles); hits stay the float BVH's. */
static void tlist_animated(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", " CAMERA ", \"lights\": [{\"type\": \"point\", \"position\": [8, 16, 10]}],"
         " \"effects\": [\"primary\", \"hard_shadows\"],"
         "\"animation\": {\"type\": \"twist\", \"frames\": 3, \"amount\": 0.8}}",
         &d);
    static cbvh_fx_result r[2];
    recorder c[2];
    cbvh_fx_opts o = opts("float");
    o.one_sided = 1;
    run_recorded_o(&d, &o, &c[0], &r[0]);
    o = opts("tlist:6:cull:heads");
    o.one_sided = 1;
    run_recorded_o(&d, &o, &c[1], &r[1]);
    assert_int_equal(r[1].refits, 2);
    assert_true(r[1].units.refit > 0);
    assert_int_equal(c[1].n, c[0].n);
    assert_memory_equal(c[1].rec, c[0].rec, c[0].n * sizeof *c[0].rec);
    free(c[0].rec);
    free(c[1].rec);
    cbvh_scene_desc_free(&d);
}

/* The option parser (through the format table): defaults, canonical names,
 * one-line errors; a bad spec fails the run with the same line. */
static void tlist_options(void **state) {
    (void)state;
    const cbvh_format *f;
    char err[256], name[CBVH_FORMAT_NAME_MAX];
    assert_int_equal(cbvh_format_parse("tlist", &f, name, sizeof name, err, sizeof err), 0);
    assert_string_equal(f->name, "tlist");
    assert_string_equal(name, "tlist:6:earliest");
    assert_int_equal(cbvh_format_parse("tlist:heads:8:cull:latest", &f, name, sizeof name, err, sizeof err), 0);
    assert_string_equal(name, "tlist:8:latest:cull:heads");
    assert_int_equal(cbvh_format_parse("tlist:4", &f, name, sizeof name, err, sizeof err), -1);
    assert_non_null(strstr(err, "unknown tlist option '4'"));
    assert_int_equal(cbvh_format_parse("tlistx", &f, name, sizeof name, err, sizeof err), -1);
    assert_non_null(strstr(err, "format 'tlistx': expected tlist[:1|2|6|8]"));
    assert_int_equal(cbvh_format_parse("tlist:", &f, name, sizeof name, err, sizeof err), -1);
    /* each option group once: the last one would otherwise win silently */
    static const char *const twice[][2] = {{"tlist:6:2", "a list count given twice"},
                                           {"tlist:earliest:latest", "an order given twice"},
                                           {"tlist:cull:8:cull", "cull given twice"},
                                           {"tlist:heads:heads", "heads given twice"}};
    for (int i = 0; i < 4; i++) {
        assert_int_equal(cbvh_format_parse(twice[i][0], &f, name, sizeof name, err, sizeof err), -1);
        if (!strstr(err, twice[i][1]) || strchr(err, '\n')) fail_msg("%s: '%s'", twice[i][0], err);
    }
    /* the run refuses the same spec with the same line */
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"]}", &d);
    cbvh_fx_opts o = opts("tlist:earliest:latest");
    cbvh_fx_result r;
    assert_int_equal(cbvh_fx_run(&d, &o, &r, err, sizeof err), -1);
    assert_string_equal(err, "format 'tlist:earliest:latest': an order given twice");
    o = opts("obvh");
    assert_int_equal(cbvh_fx_run(&d, &o, &r, err, sizeof err), -1);
    assert_string_equal(err, "format 'obvh': expected float, cbvh, qbvh or tlist[:options]");
    cbvh_scene_desc_free(&d);
}

/* Cameras: fisheye leaves the corners without rays; thin lens shoots spp
 * rays per pixel from different lens points. */
static void cameras(void **state) {
    (void)state;
    cbvh_scene_desc d;
    load("{\"mesh\": \"" MESH "\", \"camera\": {\"type\": \"fisheye\", \"width\": 20, \"height\": 20,"
         "\"position\": [0, 5, 9], \"target\": [0, 4.2, 0]}, \"effects\": [\"primary\"]}",
         &d);
    cbvh_fx_opts o = opts("float");
    cbvh_fx_result r;
    run(&d, &o, &r);
    assert_true(r.samples_without_ray > 0);
    assert_int_equal(r.fx[CBVH_FX_PRIMARY].rays + r.samples_without_ray, 400);
    assert_int_equal(r.pixels_without_ray, r.samples_without_ray); /* 1 spp: a sample is a pixel */
    /* 8 spp: samples are counted as samples, pixels as pixels (at most 400); a
     * pixel counts only when none of its 8 samples made a ray. */
    o.spp = 8;
    run(&d, &o, &r);
    assert_int_equal(r.fx[CBVH_FX_PRIMARY].rays + r.samples_without_ray, 8 * 400);
    assert_true(r.pixels_without_ray > 0 && r.pixels_without_ray < 400);
    assert_true(8 * r.pixels_without_ray < r.samples_without_ray); /* border pixels: some samples in, some out */
    o.spp = 0;
    cbvh_scene_desc_free(&d);
    load("{\"mesh\": \"" MESH "\", \"camera\": {\"type\": \"thin_lens\", \"width\": 8, \"height\": 6, \"spp\": 3,"
         "\"position\": [0, 6, 22], \"target\": [0, 4.2, 0], \"aperture\": 0.5}, \"effects\": [\"primary\"]}",
         &d);
    assert_float_equal(d.camera.focus_distance, sqrtf(6 * 6 * 0.09f + 22 * 22), 1e-3);
    o.spp = 2; /* --spp overrides camera.spp */
    run(&d, &o, &r);
    assert_int_equal(r.fx[CBVH_FX_PRIMARY].rays, 8 * 6 * 2);
    cbvh_scene_desc_free(&d);
}

/* ---- scene-file errors: one line, naming the field ---- */
static void errors(void **state) {
    (void)state;
    static const struct {
        const char *json, *msg;
    } cases[] = {
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\", \"caustics\"]}",
         "t.scene: effects[1]: unknown effect 'caustics'"},
        {"{\"mesh\": \"no/such/mesh.obj\", " CAMERA ", \"effects\": [\"primary\"]}", "t.scene: mesh: "},
        {"{" CAMERA ", \"effects\": [\"primary\"]}", "t.scene: mesh: missing"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"width\": \"wide\", \"position\": [0,0,1], \"target\": [0,0,0]},"
         "\"effects\": [\"primary\"]}",
         "t.scene: camera.width: expected an integer in 1..4096"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"width\": 2.5, \"position\": [0,0,1], \"target\": [0,0,0]},"
         "\"effects\": [\"primary\"]}",
         "t.scene: camera.width: expected an integer"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"fov\": -5, \"position\": [0,0,1], \"target\": [0,0,0]},"
         "\"effects\": [\"primary\"]}",
         "t.scene: camera.fov: -5 is out of range (0, 179]"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"position\": [0,0,1], \"target\": [0,0]}, \"effects\": [\"primary\"]}",
         "t.scene: camera.target: expected [x, y, z]"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"position\": [0,0,1], \"target\": [0,0,1]}, \"effects\": [\"primary\"]}",
         "t.scene: camera.target: equals camera.position"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"fovv\": 3, \"position\": [0,0,1], \"target\": [0,0,0]},"
         "\"effects\": [\"primary\"]}",
         "t.scene: camera.fovv: unknown field"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"position\": [0,0,1], \"target\": [0,0,0], \"aperture\": 1},"
         "\"effects\": [\"primary\"]}",
         "t.scene: camera.aperture: only for \"type\": \"thin_lens\""},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"type\": \"thin_lens\", \"position\": [0,0,1], \"target\": [0,0,0]},"
         "\"effects\": [\"primary\"]}",
         "t.scene: camera.aperture: missing"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"type\": \"ortho\", \"position\": [0,0,1], \"target\": [0,0,0]},"
         "\"effects\": [\"primary\"]}",
         "t.scene: camera.type: unknown camera 'ortho'"},
        {"{\"mesh\": \"" MESH "\", \"effects\": [\"primary\"]}", "t.scene: camera: missing"},
        /* a key with a line break: the message stays on one line */
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"\\nmaterials\": [], \"effects\": [\"primary\"]}",
         "t.scene: ?materials: unknown field"},
        {"{\"mesh\": \"" MESH "\",\n " CAMERA ",\n \"effects\": [\"primary\",]}", "t.scene: line 3: not valid JSON"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\", \"hard_shadows\"]}",
         "t.scene: effects: 'hard_shadows' needs at least one light"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"lights\": [{\"type\": \"point\", \"position\": [0,9,0]}],"
         "\"effects\": [\"primary\", \"soft_shadows\"]}",
         "t.scene: effects: 'soft_shadows' needs at least one area light"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"ambient_occlusion\"]}",
         "t.scene: effects: 'ambient_occlusion' needs 'primary'"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\", \"primary\"]}",
         "t.scene: effects[1]: effect 'primary' listed twice"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": []}", "t.scene: effects: empty"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [{\"effect\": \"ambient_occlusion\", \"samples\": 0}]}",
         "t.scene: effects[0](ambient_occlusion).samples: expected an integer in 1..4096"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\", {\"effect\": \"mirror\", \"samples\": 2}]}",
         "t.scene: effects[1](mirror).samples: unknown field"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"lights\": [{\"type\": \"spot\", \"position\": [0,9,0]}],"
         "\"effects\": [\"primary\"]}",
         "t.scene: lights[0].type: unknown light 'spot'"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"lights\": [{\"type\": \"area\", \"position\": [0,9,0]}],"
         "\"effects\": [\"primary\"]}",
         "t.scene: lights[0].u: missing"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"materials\": [{\"name\": \"m\", \"type\": \"glass\"}],"
         "\"effects\": [\"primary\"]}",
         "t.scene: materials[0].type: unknown material 'glass'"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"mesh_material\": \"gold\", \"effects\": [\"primary\"]}",
         "t.scene: mesh_material: no material named 'gold'"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"animation\": {\"type\": \"morph\"}}",
         "t.scene: animation.type: 'morph' but mesh"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"animation\": {\"type\": \"twist\","
         "\"frames\": 1}}",
         "t.scene: animation.frames: expected an integer in 2..1000"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"timing\": {\"clock_mhz\": 0}}",
         "t.scene: timing.clock_mhz: 0 is out of range [0.001, 1e+09]"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"timing\": {\"dram_bytes_per_cycle\": 1e-6}}",
         "t.scene: timing.dram_bytes_per_cycle: 1e-06 is out of range [0.001, 1e+09]"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"timing\": {\"cache_ways\": 0}}",
         "t.scene: timing.cache_ways: 0 is out of range [1, 64]"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"timing\": {\"rays_in_flight\": 0}}",
         "t.scene: timing.rays_in_flight: 0 is out of range [0.001, 1e+09]"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"timing\": {\"issue_width\": 2000}}",
         "t.scene: timing.issue_width: 2000 is out of range [1, 1024]"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"timing\": {\"warp\": 1}}",
         "t.scene: timing.warp: unknown field"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"shadows\": true}",
         "t.scene: shadows: unknown field"},
        {"[1, 2]", "t.scene: expected a JSON object at the top level"},
        {"{\"mesh\": \"" MESH "\", \"mesh\": \"no/such.obj\", " CAMERA ", \"effects\": [\"primary\"]}",
         "t.scene: mesh: given twice"},
        {"{\"mesh\": \"" MESH "\", " CAMERA ", \"effects\": [\"primary\"], \"effects\": [\"mirror\"]}",
         "t.scene: effects: given twice"},
        {"{\"mesh\": \"" MESH "\", \"camera\": {\"position\": [0,0,1], \"target\": [0,0,0], \"fov\": 40, "
         "\"fov\": 50}, \"effects\": [\"primary\"]}",
         "t.scene: camera.fov: given twice"},
        /* a NUL ends a cJSON string: refused, not the name before it loaded */
        {"{\"mesh\": \"" MESH "\\u0000.ply\", " CAMERA ", \"effects\": [\"primary\"]}",
         "t.scene: line 1: a string holds \\u0000 (NUL), which no name or path can hold"},
        {"{\"mesh\": \"" MESH "\",\n" CAMERA ",\n\"materials\": [{\"name\": \"a\\u0000b\", \"type\": \"diffuse\"}],"
         " \"effects\": [\"primary\"]}",
         "t.scene: line 3: a string holds \\u0000 (NUL)"},
        /* an escaped backslash before "u0000" is no NUL: the name is looked for as written */
        {"{\"mesh\": \"no\\\\u0000such.obj\", " CAMERA ", \"effects\": [\"primary\"]}",
         "t.scene: mesh: cannot open 'no\\u0000such.obj'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cbvh_scene_desc d;
        char err[512] = "";
        int rc = cbvh_scene_file_parse(cases[i].json, "t.scene", &d, err, sizeof err);
        if (rc != -1 || strncmp(err, cases[i].msg, strlen(cases[i].msg)) != 0 || strchr(err, '\n'))
            fprintf(stderr, "case %zu: rc %d, got '%s', want '%s...'\n", i, rc, err, cases[i].msg);
        assert_int_equal(rc, -1);
        assert_true(strncmp(err, cases[i].msg, strlen(cases[i].msg)) == 0);
        assert_null(strchr(err, '\n'));
        assert_null(d.mesh.tris); /* nothing half-loaded */
    }
    /* A relative mesh path is looked up next to the scene file. */
    cbvh_scene_desc d;
    char err[512];
    int rc = cbvh_scene_file_parse("{\"mesh\": \"bunny-small.obj\", " CAMERA ", \"effects\": [\"primary\"]}",
                                   CBVH_SCENES_DIR "/x.scene", &d, err, sizeof err);
    assert_int_equal(rc, 0);
    assert_int_equal(d.mesh.ntris, 3674);
    cbvh_scene_desc_free(&d);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(primary_only), cmocka_unit_test(all_effects), cmocka_unit_test(no_mirror_material),
        cmocka_unit_test(animated_refits), cmocka_unit_test(cameras), cmocka_unit_test(errors),
        cmocka_unit_test(qbvh_all_effects), cmocka_unit_test(qbvh_effects_obeyed),
        cmocka_unit_test(qbvh_animated), cmocka_unit_test(tlist_all_effects), cmocka_unit_test(tlist_heads_save_work),
        cmocka_unit_test(tlist_animated), cmocka_unit_test(tlist_options),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
