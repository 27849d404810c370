/* cbvh trace SCENE: trace only the rays a scene's effects call for, on the
 * float BVH and, with any other format of the table (cbvh/format.h), on that
 * format too, and report the cost per effect with the timing model
 * (docs/scenes.md, docs/timing_model.md). */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "cli/commands.h"
#include "trace/effects.h"
#include "trace/metrics.h"
#include "util/parse_int.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"

static void usage(FILE *f) {
    size_t n;
    const cbvh_format *const *fmts = cbvh_formats(&n);
    fprintf(f, "usage: cbvh trace SCENE [--bits N] [--mant M] [--min-scale E] [--format ");
    for (size_t i = 0; i < n; i++)
        fprintf(f, "%s%s%s", i ? "|" : "", fmts[i]->name, fmts[i]->flags & CBVH_FORMAT_OPTIONS ? "..." : "");
    fprintf(f,
            "]\n"
            "                        [--spp K] [--one-sided] [--json]\n"
            "  SCENE is a scene file (.scene, .json) or a mesh file / proc:NAME (its default scene,\n"
            "  docs/scenes.md).\n"
            "  Traces the rays the scene file's effects call for (docs/scenes.md) and prints, per effect:\n"
            "  rays, box/triangle tests, nodes and bytes per ray, deepest stack, modelled time per ray\n"
            "  (docs/timing_model.md) and the model's CPU time per ray; with any format but float\n"
            "  also each relative to the float BVH on the same rays, and a units-active line.\n"
            "  --bits N       CBVH coordinate bits, %d..%d (default 6)\n"
            "  --mant M       mantissa bits of the ray-box unit, %d..%d (default 24)\n"
            "  --min-scale E  minimum grid scale, %d..%d (default %d)\n",
            CBVH_N_MIN, CBVH_N_MAX, CBVH_MANT_MIN, CBVH_MANT_MAX, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL,
            CBVH_MIN_SCALE_DEFAULT);
    /* One line (or more) per format: its help, continued lines indented. */
    for (size_t i = 0; i < n; i++) {
        fprintf(f, "%s", i ? "                 " : "  --format F     ");
        for (const char *h = fmts[i]->help; *h; h++) {
            fputc(*h, f);
            if (*h == '\n') fputs("                 ", f);
        }
        fputc('\n', f);
    }
    fprintf(f, "  --one-sided    triangles count only from their front side (counter-clockwise), on every\n"
               "                 format; needed by tlist:...:cull\n"
               "  --spp K        camera samples per pixel, 1..1024 (default: the scene's camera.spp)\n"
               "  --json         machine-readable output\n");
}

typedef struct {
    const char *label;
    int last_row;
} progress_ctx;

static void progress(void *ctx, int frame, int frames, int row, int rows) {
    progress_ctx *p = ctx;
    if (row % 4 && row != rows - 1) return;
    fprintf(stderr, "\rtrace %s: frame %d/%d, row %d/%d   ", p->label, frame + 1, frames, row + 1, rows);
    p->last_row = 1;
}

static cbvh_ray_metrics metrics(const cbvh_fx_stats *s, const cbvh_timing_params *tp) {
    cbvh_ray_metrics m;
    cbvh_ray_metrics_of(s, tp, &m); /* tp is validated with the scene file */
    return m;
}

static void print_row(const char *name, const char *kind, const cbvh_ray_metrics *p, const cbvh_ray_metrics *f) {
    printf("%-18s %-7s %9.0f %8.2f %7.2f %8.1f %8.0f %5u %9.1f %8.2f", name, kind, (double)p->rays, p->box, p->tri,
           p->nodes, p->bytes, p->max_stack, p->model_ns, p->cpu_us);
    if (f) {
        double a[5] = {p->box, p->tri, p->bytes, p->model_ns, p->cpu_us}, b[5] = {f->box, f->tri, f->bytes,
                                                                                    f->model_ns, f->cpu_us};
        printf("  ");
        for (int i = 0; i < 5; i++) cbvh_print_x(cbvh_ratio(a[i], b[i]), 3);
    }
    printf("\n");
}

/* A figure to six significant digits, as printf's %g writes it (what the
 * JSON has always held). */
static void json_g6(cJSON *o, const char *key, double v) {
    char buf[32];
    snprintf(buf, sizeof buf, "%.6g", v);
    cJSON_AddNumberToObject(o, key, strtod(buf, NULL));
}

static void json_count(cJSON *o, const char *key, uint64_t v) { cJSON_AddNumberToObject(o, key, (double)v); }

static cJSON *json_stats(const cbvh_fx_stats *s, const cbvh_timing_params *tp) {
    cbvh_ray_metrics p = metrics(s, tp);
    cJSON *o = cJSON_CreateObject();
    json_count(o, "rays", s->rays);
    json_count(o, "closest_hit", s->closest);
    json_count(o, "any_hit", s->any);
    json_count(o, "hits", s->hits);
    json_count(o, "rejected", s->rejected);
    json_count(o, "nodes", s->st.nodes);
    json_count(o, "box_tests", s->st.box_tests);
    json_count(o, "tri_tests", s->st.tri_tests);
    json_count(o, "bytes", s->st.bytes);
    json_count(o, "max_stack", s->st.max_stack);
    json_g6(o, "box_per_ray", p.box);
    json_g6(o, "tri_per_ray", p.tri);
    json_g6(o, "bytes_per_ray", p.bytes);
    json_g6(o, "model_ns_per_ray", p.model_ns);
    json_g6(o, "cpu_us_per_ray", p.cpu_us);
    return o;
}

static const char *const unit_names[] = {"compressor", "decoder", "ray_box", "ray_triangle", "refit", "qbvh_stack",
                                         "ray_sphere"};
#define NUNITS (sizeof unit_names / sizeof unit_names[0])

static void unit_counts(const cbvh_unit_activity *u, uint64_t v[NUNITS]) {
    const uint64_t c[NUNITS] = {u->compressor, u->decoder, u->ray_box, u->ray_triangle, u->refit, u->qbvh_stack,
                                u->ray_sphere};
    memcpy(v, c, sizeof c);
}

static void json_result(cJSON *root, const char *key, const cbvh_scene_desc *d, const cbvh_fx_result *r,
                        const cbvh_timing_params *tp) {
    cJSON *o = cJSON_AddObjectToObject(root, key);
    json_count(o, "node_bytes", r->node_bytes);
    json_g6(o, "build_cpu_s", r->build_cpu_seconds);
    json_count(o, "refits", r->refits);
    cJSON *fx = cJSON_AddObjectToObject(o, "effects");
    for (int e = 0; e < CBVH_FX_COUNT; e++)
        if (d->effect[e].enabled) cJSON_AddItemToObject(fx, cbvh_effect_name((cbvh_effect)e), json_stats(&r->fx[e], tp));
    cbvh_fx_stats t = cbvh_fx_total(r);
    cJSON_AddItemToObject(o, "total", json_stats(&t, tp));
    cJSON *u = cJSON_AddObjectToObject(o, "units");
    uint64_t v[NUNITS];
    unit_counts(&r->units, v);
    for (size_t i = 0; i < NUNITS; i++) json_count(u, unit_names[i], v[i]);
    json_count(o, "qbvh_stack_pushes", t.st.qstack_pushes);
    json_count(o, "qbvh_stack_pops", t.st.qstack_pops);
    char digest[17];
    snprintf(digest, sizeof digest, "%016llx", (unsigned long long)r->hit_digest);
    cJSON_AddStringToObject(o, "hit_digest", digest);
}

static void print_units(const cbvh_unit_activity *u, int animated) {
    uint64_t v[NUNITS];
    unit_counts(u, v);
    printf("units active:");
    int any = 0;
    for (size_t i = 0; i < NUNITS; i++)
        if (v[i]) printf("%s %s %llu", any++ ? "," : "", unit_names[i], (unsigned long long)v[i]);
    printf("  | idle:");
    any = 0;
    for (size_t i = 0; i < NUNITS; i++)
        if (!v[i]) printf("%s %s", any++ ? "," : "", unit_names[i]);
    if (!any) printf(" none");
    printf("%s\n", animated ? "" : "  (static scene: no refit)");
}

typedef struct {
    const char *scene;
    int bits, mant, min_scale, spp, json, one_sided;
    const cbvh_format *fmt;
    char spec[CBVH_FORMAT_NAME_MAX]; /* the format's canonical spelling */
} trace_opts;

/* One option with its value (NULL: missing); 0, or 2 after a one-line message. */
static int set_option(trace_opts *t, int opt, const char *v) {
    static const struct {
        int opt;
        const char *name;
        long lo, hi;
    } ints[] = {{'b', "--bits", CBVH_N_MIN, CBVH_N_MAX},
                {'m', "--mant", CBVH_MANT_MIN, CBVH_MANT_MAX},
                {'e', "--min-scale", CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL},
                {'s', "--spp", 1, 1024}};
    int *dst[] = {&t->bits, &t->mant, &t->min_scale, &t->spp};
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++) {
        if (ints[i].opt != opt) continue;
        long x;
        if (cbvh_parse_long(v, ints[i].lo, ints[i].hi, &x)) {
            fprintf(stderr, "cbvh trace: %s expects an integer in %ld..%ld, got '%s'\n", ints[i].name, ints[i].lo,
                    ints[i].hi, v ? v : "");
            return 2;
        }
        *dst[i] = (int)x;
        return 0;
    }
    /* --format */
    char err[200];
    if (!v) v = "";
    t->fmt = cbvh_format_find(v);
    if (!t->fmt) {
        cbvh_format_names(err, sizeof err);
        fprintf(stderr, "cbvh trace: --format expects %s, got '%s'\n", err, v);
        return 2;
    }
    if (cbvh_format_parse(v, &t->fmt, t->spec, sizeof t->spec, err, sizeof err)) {
        fprintf(stderr, "cbvh trace: --format: %s\n", err);
        return 2;
    }
    return 0;
}

/* 0 (options in *t), 1 (--help printed), or 2 after a one-line message. */
static int parse_options(int argc, char **argv, trace_opts *t) {
    static const struct option longopts[] = {{"bits", required_argument, 0, 'b'},
                                             {"mant", required_argument, 0, 'm'},
                                             {"min-scale", required_argument, 0, 'e'},
                                             {"spp", required_argument, 0, 's'},
                                             {"format", required_argument, 0, 'f'},
                                             {"one-sided", no_argument, 0, 'o'},
                                             {"json", no_argument, 0, 'j'},
                                             {"help", no_argument, 0, 'h'},
                                             {0, 0, 0, 0}};
    *t = (trace_opts){.bits = 6, .mant = 24, .min_scale = CBVH_MIN_SCALE_DEFAULT};
    int c, rc = set_option(t, 'f', "cbvh");
    optind = 1;
    opterr = 0;
    /* ':' first: a missing value is told apart from an unknown option. */
    while (!rc && (c = getopt_long(argc, argv, ":h", longopts, NULL)) != -1) {
        switch (c) {
        case 'h': usage(stdout); return 1;
        case 'j': t->json = 1; break;
        case 'o': t->one_sided = 1; break;
        case ':': rc = set_option(t, optopt, NULL); break;
        case '?':
            fprintf(stderr, "cbvh trace: unknown option '%s' (see cbvh trace --help)\n", argv[optind - 1]);
            return 2;
        default: rc = set_option(t, c, optarg); break;
        }
    }
    if (rc) return rc;
    if (optind < argc) t->scene = argv[optind];
    if (optind + 1 < argc) {
        fprintf(stderr, "cbvh trace: more than one scene ('%s', '%s')\n", argv[optind], argv[optind + 1]);
        return 2;
    }
    if (!t->scene) {
        fprintf(stderr, "cbvh trace: no scene file given (see cbvh trace --help)\n");
        return 2;
    }
    return 0;
}

/* Traces the scene in one format; 0, or 2 after a one-line message. */
static int run(const cbvh_scene_desc *d, cbvh_fx_opts *fo, const char *spec, progress_ctx *pc, const char *scene,
               cbvh_fx_result *r) {
    char err[1024];
    fo->format = spec;
    pc->label = spec;
    if (cbvh_fx_run(d, fo, r, err, sizeof err) == 0) return 0;
    if (pc->last_row) fprintf(stderr, "\n");
    fprintf(stderr, "cbvh trace: %s: %s\n", scene, err);
    return 2; /* the run could not be done: not a finding about hits */
}

static void write_json(const trace_opts *t, const cbvh_scene_desc *d, const cbvh_fx_result *rf,
                       const cbvh_fx_result *rc, const cbvh_timing_params *tp, int spp_used, int same) {
    static const char *cams[] = {"pinhole", "thin_lens", "fisheye"};
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scene", t->scene);
    cJSON_AddStringToObject(root, "mesh", d->mesh_spec);
    json_count(root, "triangles", d->mesh.ntris);
    json_count(root, "frames", (uint64_t)rf->frames);
    cJSON_AddStringToObject(root, "camera", cams[d->camera.type]);
    json_count(root, "width", (uint64_t)d->camera.width);
    json_count(root, "height", (uint64_t)d->camera.height);
    json_count(root, "spp", (uint64_t)spp_used);
    cJSON_AddBoolToObject(root, "one_sided", t->one_sided);
    cJSON_AddStringToObject(root, "format", t->spec);
    cJSON_AddNumberToObject(root, "bits", t->bits);
    cJSON_AddNumberToObject(root, "mant", t->mant);
    cJSON_AddNumberToObject(root, "min_scale", t->min_scale);
    json_count(root, "camera_samples_without_ray", rf->samples_without_ray);
    json_count(root, "pixels_without_camera_ray", rf->pixels_without_ray);
    cJSON *tj = cJSON_AddObjectToObject(root, "timing");
    json_g6(tj, "box_cycles", tp->box_cycles);
    json_g6(tj, "tri_cycles", tp->tri_cycles);
    json_g6(tj, "fetch_latency", tp->fetch_latency);
    json_g6(tj, "dram_bytes_per_cycle", tp->dram_bytes_per_cycle);
    json_g6(tj, "clock_mhz", tp->clock_mhz);
    json_result(root, "float", d, rf, tp);
    if (rc) {
        json_result(root, t->fmt->name, d, rc, tp);
        cJSON_AddBoolToObject(root, "same_hits", same);
    }
    cbvh_json_print(root, stdout); /* a write error is main's one line */
    cJSON_Delete(root);
}

static void write_table(const trace_opts *t, const cbvh_scene_desc *d, const cbvh_fx_result *rf,
                        const cbvh_fx_result *rc, const cbvh_timing_params *tp, int spp_used, int same) {
    static const char *cams[] = {"pinhole", "thin_lens", "fisheye"};
    const cbvh_fx_result *main_r = rc ? rc : rf;
    printf("scene %s: %s, %u triangles, %d frame%s%s, %s camera %dx%d, %d spp\n", t->scene, d->mesh_spec,
           d->mesh.ntris, rf->frames, rf->frames > 1 ? "s" : "",
           rf->frames > 1 ? " (animated: refit per frame)" : " (static)", cams[d->camera.type], d->camera.width,
           d->camera.height, spp_used);
    char desc[200];
    cbvh_format_params fp = {{t->bits, t->min_scale}, t->mant, t->one_sided};
    t->fmt->describe(&fp, desc, sizeof desc);
    printf("format %s: %s; %s memory %llu B", t->spec, desc, t->fmt->memory, (unsigned long long)main_r->node_bytes);
    if (rc)
        printf(" (float BVH %llu B, x%.3f)", (unsigned long long)rf->node_bytes,
               cbvh_ratio((double)rc->node_bytes, (double)rf->node_bytes));
    printf("\n");
    if (t->one_sided) printf("one-sided: triangles count only from their counter-clockwise front side\n");
    printf("timing model: %g cycle/box, %g cycle/tri, %g cycles fetch latency, %g B/cycle DRAM, %g MHz "
           "(docs/timing_model.md)\n\n",
           tp->box_cycles, tp->tri_cycles, tp->fetch_latency, tp->dram_bytes_per_cycle, tp->clock_mhz);
    printf("%-18s %-7s %9s %8s %7s %8s %8s %5s %9s %8s", "effect", "kind", "rays", "box/ray", "tri/ray", "node/ray",
           "B/ray", "stack", "model ns", "CPU us");
    if (rc) printf("   vs float: box, tri, bytes, model, CPU");
    printf("\n");
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        if (!d->effect[e].enabled) continue;
        cbvh_ray_metrics pf = metrics(&rf->fx[e], tp), pm = metrics(&main_r->fx[e], tp);
        const char *kind = main_r->fx[e].any ? (main_r->fx[e].closest ? "mixed" : "any") : "closest";
        if (!main_r->fx[e].rays) kind = "-";
        print_row(cbvh_effect_name((cbvh_effect)e), kind, &pm, rc ? &pf : NULL);
    }
    cbvh_fx_stats tf = cbvh_fx_total(rf), tm = cbvh_fx_total(main_r);
    cbvh_ray_metrics pf = metrics(&tf, tp), pm = metrics(&tm, tp);
    print_row("total", "", &pm, rc ? &pf : NULL);
    int unnamed = 0;
    for (int e = 0; e < CBVH_FX_COUNT; e++)
        if (!d->effect[e].enabled)
            printf("%s %s %llu", unnamed++ ? "," : "not in the scene (rays):", cbvh_effect_name((cbvh_effect)e),
                   (unsigned long long)main_r->fx[e].rays);
    if (unnamed) printf("\n");
    if (main_r->samples_without_ray)
        printf("camera samples without a ray (outside the fisheye circle): %llu of %llu; pixels with no ray in "
               "any sample: %llu of %llu\n",
               (unsigned long long)main_r->samples_without_ray,
               (unsigned long long)d->camera.width * (unsigned long long)d->camera.height *
                   (unsigned long long)spp_used * (unsigned long long)main_r->frames,
               (unsigned long long)main_r->pixels_without_ray,
               (unsigned long long)d->camera.width * (unsigned long long)d->camera.height);
    if (tm.rejected) printf("rays rejected by a unit (no hit): %llu\n", (unsigned long long)tm.rejected);
    print_units(&main_r->units, main_r->frames > 1);
    printf("build%s: %.3f s CPU (%s%s)\n", main_r->frames > 1 ? " + refits" : "", main_r->build_cpu_seconds,
           t->fmt->build_note, main_r->frames > 1 ? t->fmt->refit_note : "");
    if (t->fmt->flags & CBVH_FORMAT_STACK_UNIT)
        printf("qbvh stack unit: %llu sort+push, %llu pop operations; deepest stack %u entries (float BVH %u)\n",
               (unsigned long long)tm.st.qstack_pushes, (unsigned long long)tm.st.qstack_pops, tm.st.max_stack,
               tf.st.max_stack);
    if (rc)
        printf("hits: %s the float BVH's (digest %016llx)\n", same ? "identical to" : "DIFFERENT FROM",
               (unsigned long long)rc->hit_digest);
}

int cmd_trace(int argc, char **argv) {
    trace_opts t;
    int status = parse_options(argc, argv, &t);
    if (status) return status == 1 ? 0 : status;
    cbvh_scene_desc d;
    char err[1024];
    if (cbvh_scene_file_open(t.scene, &d, err, sizeof err)) {
        fprintf(stderr, "cbvh trace: %s\n", err);
        return 2;
    }
    cbvh_timing_params tp;
    cbvh_fx_timing(&d, &tp);
    progress_ctx pc = {NULL, 0};
    int tty = isatty(2) && !t.json;
    int cmp = !(t.fmt->flags & CBVH_FORMAT_REFERENCE); /* a format compared against the float BVH */
    cbvh_fx_opts fo = {.params = {t.bits, t.min_scale},
                       .mant = cmp ? 24 : t.mant,
                       .spp = t.spp,
                       .progress = tty ? progress : NULL,
                       .ctx = &pc,
                       .one_sided = t.one_sided};
    static cbvh_fx_result rf, rc;
    if (run(&d, &fo, "float", &pc, t.scene, &rf)) {
        cbvh_scene_desc_free(&d);
        return 2;
    }
    int same = 1;
    if (cmp) {
        fo.mant = t.mant;
        if (run(&d, &fo, t.spec, &pc, t.scene, &rc)) {
            cbvh_scene_desc_free(&d);
            return 2;
        }
        same = rc.hit_digest == rf.hit_digest; /* every format must return the float BVH's hits */
    }
    if (pc.last_row) fprintf(stderr, "\r%60s\r", "");
    int spp_used = t.spp ? t.spp : d.camera.spp;
    if (t.json)
        write_json(&t, &d, &rf, cmp ? &rc : NULL, &tp, spp_used, same);
    else
        write_table(&t, &d, &rf, cmp ? &rc : NULL, &tp, spp_used, same);
    if (!same) fprintf(stderr, "cbvh trace: %s hits differ from the float BVH (a traversal bug)\n", t.fmt->title);
    cbvh_scene_desc_free(&d);
    return same ? 0 : 1;
}
