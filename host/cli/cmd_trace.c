/* cbvh trace SCENE: trace only the rays a scene's effects call for, on the
 * float BVH and, with any other format of the table (cbvh/format.h), on that
 * format too, and report the cost per effect with the timing model
 * (docs/scenes.md, docs/timing_model.md). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "cli/commands.h"
#include "cli/data_dir.h"
#include "trace/event_sim.h"
#include "trace/effects.h"
#include "trace/metrics.h"
#include "trace/model_eval.h"
#include "util/parse_int.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"

static void usage(FILE *f) {
    size_t n;
    const cbvh_format *const *fmts = cbvh_formats(&n);
    fprintf(f, "usage: cbvh trace SCENE [--bits N] [--mant M] [--min-scale E] [--box-unit U] [--format ");
    for (size_t i = 0; i < n; i++)
        fprintf(f, "%s%s%s", i ? "|" : "", fmts[i]->name, fmts[i]->flags & CBVH_FORMAT_OPTIONS ? "..." : "");
    fprintf(f,
            "]\n"
            "                        [--spp K] [--one-sided] [--cache KB] [--reps K] [--cost-table DIR]\n"
            "                        [--timing K=V,...] [--timing-check] [--json]\n"
            "  SCENE is a scene file (.scene, .json) or a mesh file / proc:NAME (its default scene,\n"
            "  docs/scenes.md).\n"
            "  Traces the rays the scene file's effects call for (docs/scenes.md) and prints, per effect:\n"
            "  rays, box/triangle tests, nodes and bytes per ray, deepest stack, modelled time and energy\n"
            "  per ray and the cache's hit rate (docs/timing_model.md) and the model's CPU time per ray;\n"
            "  with any format but float\n"
            "  also each relative to the float BVH on the same rays, and a units-active line.\n"
            "  --bits N       CBVH coordinate bits, %d..%d (default %d)\n"
            "  --mant M       mantissa bits of the ray-box unit, %d..%d (default 24)\n"
            "  --min-scale E  minimum grid scale, %d..%d (default %d)\n"
            "  --box-unit U   exact (unit 6: each plane distance exact, rounded once; default) or\n"
            "                 incremental[:X] (unit 10: Eq. 5 from the parent's distances, M-bit\n"
            "                 reciprocal and distances with X exponent bits, %d..%d, default %d; counts\n"
            "                 its false-positive box hits and the triangle tests under them); cbvh only\n",
            CBVH_N_MIN, CBVH_N_MAX, CBVH_N_DEFAULT, CBVH_MANT_MIN, CBVH_MANT_MAX, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL,
            CBVH_MIN_SCALE_DEFAULT, CBVH_RBI_TEXP_MIN, CBVH_RBI_TEXP_MAX, CBVH_RBI_TEXP_DEFAULT);
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
               "  --cache KB     the timing model's node and triangle cache in KB, 0..%d (0 = none) or inf\n"
               "                 (default 64)\n"
               "  --reps K       timed repetitions for the CPU column, 1..%d (default 5; the median is shown)\n"
               "  --cost-table DIR  the RTL cost table (default: gateware/cost beside the committed vectors)\n"
               "  --timing K=V,... timing-model parameters over the scene file's (its timing keys,\n"
               "                 docs/scenes.md), e.g. rays_in_flight=256,box_cycles=1\n"
               "  --timing-check the analytic timing model against an event-driven simulation of the same\n"
               "                 rays, for several machines (rays in flight, cache, units): error per machine\n"
               "  --json         machine-readable output\n",
            CBVH_CACHE_KB_MAX, CBVH_REPS_MAX);
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

static cbvh_ray_metrics metrics(const cbvh_fx_stats *s, const cbvh_machine *mc) {
    cbvh_ray_metrics m;
    cbvh_ray_metrics_of(s, mc, &m); /* the parameters are checked before tracing */
    return m;
}

static void print_row(const char *name, const char *kind, const cbvh_ray_metrics *p, const cbvh_ray_metrics *f,
                      double cpu_ratio) {
    printf("%-18s %-7s %9.0f %8.2f %7.2f %8.1f %8.0f %5u %9.1f %8.3f %6.1f %8.2f", name, kind, (double)p->rays, p->box,
           p->tri, p->nodes, p->bytes, p->max_stack, p->model_ns, p->energy_nj, 100.0 * p->hit_rate, p->cpu_us);
    if (f) {
        double a[5] = {p->box, p->tri, p->bytes, p->model_ns, p->energy_nj},
               b[5] = {f->box, f->tri, f->bytes, f->model_ns, f->energy_nj};
        printf("  ");
        for (int i = 0; i < 5; i++) cbvh_print_x(cbvh_ratio(a[i], b[i]), 3);
        cbvh_print_x(cpu_ratio, 3);
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

static cJSON *json_stats(const cbvh_fx_stats *s, const cbvh_machine *mc, int incremental) {
    cbvh_ray_metrics p = metrics(s, mc);
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
    cbvh_model_json(o, &p);
    json_g6(o, "cpu_us_per_ray", p.cpu_us);
    json_g6(o, "cpu_us_per_ray_min", p.cpu_lo);
    json_g6(o, "cpu_us_per_ray_max", p.cpu_hi);
    if (incremental) {
        json_count(o, "fp_box_hits", s->st.fp_box_hits);
        json_count(o, "fp_tri_tests", s->st.fp_tri_tests);
    }
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
                        const cbvh_machine *mc, int incremental) {
    cJSON *o = cJSON_AddObjectToObject(root, key);
    json_count(o, "node_bytes", r->node_bytes);
    json_g6(o, "build_cpu_s", r->build_cpu_seconds);
    json_count(o, "refits", r->refits);
    cJSON *fx = cJSON_AddObjectToObject(o, "effects");
    for (int e = 0; e < CBVH_FX_COUNT; e++)
        if (d->effect[e].enabled)
            cJSON_AddItemToObject(fx, cbvh_effect_name((cbvh_effect)e), json_stats(&r->fx[e], mc, incremental));
    cbvh_fx_stats t = cbvh_fx_total(r);
    cJSON_AddItemToObject(o, "total", json_stats(&t, mc, incremental));
    json_g6(o, "area_lut4", metrics(&t, mc).area_lut4);
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
    int bits, mant, min_scale, spp, json, one_sided, reps, check;
    int box_unit, texp; /* --box-unit */
    double cache_kb;
    const char *cost_dir, *timing;
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
                {'s', "--spp", 1, 1024},
                {'r', "--reps", 1, CBVH_REPS_MAX}};
    int *dst[] = {&t->bits, &t->mant, &t->min_scale, &t->spp, &t->reps};
    if (opt == 'c') {
        if (cbvh_cache_kb_parse(v, &t->cache_kb)) {
            fprintf(stderr, "cbvh trace: --cache expects a size in KB, 0..%d, or inf, got '%s'\n", CBVH_CACHE_KB_MAX,
                    v ? v : "");
            return 2;
        }
        return 0;
    }
    if (opt == 'M' || opt == 'T') { /* --timing, --cost-table: a non-empty word */
        if (!v || !v[0]) {
            fprintf(stderr, "cbvh trace: %s\n", opt == 'M' ? "--timing expects key=value[,key=value...]"
                                                            : "--cost-table expects a directory");
            return 2;
        }
        *(opt == 'M' ? &t->timing : &t->cost_dir) = v;
        return 0;
    }
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
    if (opt == 'u') /* --box-unit */
        return cbvh_parse_box_unit("cbvh trace", v, &t->box_unit, &t->texp) ? 2 : 0;
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
                                             {"box-unit", required_argument, 0, 'u'},
                                             {"one-sided", no_argument, 0, 'o'},
                                             {"cache", required_argument, 0, 'c'},
                                             {"reps", required_argument, 0, 'r'},
                                             {"cost-table", required_argument, 0, 'T'},
                                             {"timing-check", no_argument, 0, 'k'},
                                             {"timing", required_argument, 0, 'M'},
                                             {"json", no_argument, 0, 'j'},
                                             {"help", no_argument, 0, 'h'},
                                             {0, 0, 0, 0}};
    *t = (trace_opts){.bits = CBVH_N_DEFAULT,
                      .mant = 24,
                      .min_scale = CBVH_MIN_SCALE_DEFAULT,
                      .reps = 5,
                      .cache_kb = 64,
                      .cost_dir = cbvh_cost_dir(),
                      .texp = CBVH_RBI_TEXP_DEFAULT};
    int c, rc = set_option(t, 'f', "cbvh");
    optind = 1;
    opterr = 0;
    /* ':' first: a missing value is told apart from an unknown option. */
    while (!rc && (c = getopt_long(argc, argv, ":h", longopts, NULL)) != -1) {
        switch (c) {
        case 'h': usage(stdout); return 1;
        case 'j': t->json = 1; break;
        case 'o': t->one_sided = 1; break;
        case 'k': t->check = 1; break;
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
    if (t->box_unit == CBVH_FORMAT_BOX_INCREMENTAL && !(t->fmt->flags & CBVH_FORMAT_BOX_UNIT)) {
        fprintf(stderr, "cbvh trace: --box-unit incremental: format %s has no incremental box unit (cbvh has)\n",
                t->spec);
        return 2;
    }
    return 0;
}

/* Traces the scene in one format; 0, or 2 after a one-line message. */
/* Traces the scene in one format: the pass the timing model observes (its
 * cache), then `reps` timed passes for the CPU column; 0, or 2 after a
 * one-line message. */
static int run(const cbvh_scene_desc *d, cbvh_fx_opts *fo, const char *spec, progress_ctx *pc, const char *scene,
               int reps, cbvh_fx_result *r) {
    char err[1024];
    fo->format = spec;
    pc->label = spec;
    int rc = cbvh_fx_run(d, fo, r, err, sizeof err);
    cbvh_fx_opts plain = *fo;
    plain.ncaches = 0;
    plain.steps = NULL;
    for (int k = 0; k < reps && rc == 0; k++) {
        cbvh_fx_result rep;
        rc = cbvh_fx_run(d, &plain, &rep, err, sizeof err);
        if (rc == 0 && cbvh_fx_add_rep(r, &rep)) {
            snprintf(err, sizeof err, "a timed repetition traced other rays or hits than the first pass");
            rc = -1;
        }
    }
    if (rc == 0) return 0;
    if (pc->last_row) fprintf(stderr, "\n");
    fprintf(stderr, "cbvh trace: %s: %s\n", scene, err);
    return 2; /* the run could not be done: not a finding about hits */
}

/* The float BVH's machine and the traced format's. */
typedef struct {
    cbvh_config_model f, m;
} trace_models;

static void json_machine(cJSON *root, const cbvh_timing_params *tp, const trace_opts *t, const trace_models *tm) {
    cJSON *tj = cJSON_AddObjectToObject(root, "timing");
    cbvh_timing_json(tj, tp, t->cost_dir);
    if (isfinite(t->cache_kb))
        json_g6(tj, "cache_kb", t->cache_kb);
    else
        cJSON_AddNullToObject(tj, "cache_kb");
    cJSON_AddNumberToObject(tj, "cpu_reps", t->reps);
    const cbvh_unit_cost *u[] = {&tm->m.mc[0].units.node, &tm->m.mc[0].units.tri, &tm->m.mc[0].units.dec,
                                 &tm->m.mc[0].units.qstack};
    cJSON *ua = cJSON_AddArrayToObject(tj, "units");
    for (int k = 0; k < 4; k++)
        if (u[k]->present) cJSON_AddItemToArray(ua, cbvh_unit_json(u[k]));
}

static void write_json(const trace_opts *t, const cbvh_scene_desc *d, const cbvh_fx_result *rf,
                       const cbvh_fx_result *rc, const cbvh_timing_params *tp, const trace_models *tm, int spp_used,
                       int same) {
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
    if (t->box_unit == CBVH_FORMAT_BOX_INCREMENTAL) {
        cJSON_AddStringToObject(root, "box_unit", "incremental");
        cJSON_AddNumberToObject(root, "texp", t->texp);
    }
    json_count(root, "camera_samples_without_ray", rf->samples_without_ray);
    json_count(root, "pixels_without_camera_ray", rf->pixels_without_ray);
    json_machine(root, tp, t, tm);
    json_result(root, "float", d, rf, &tm->f.mc[0], 0);
    if (rc) {
        json_result(root, t->fmt->name, d, rc, &tm->m.mc[0], t->box_unit == CBVH_FORMAT_BOX_INCREMENTAL);
        cJSON_AddBoolToObject(root, "same_hits", same);
    }
    cbvh_json_print(root, stdout); /* a write error is main's one line */
    cJSON_Delete(root);
}

static void write_table(const trace_opts *t, const cbvh_scene_desc *d, const cbvh_fx_result *rf,
                        const cbvh_fx_result *rc, const cbvh_timing_params *tp, const trace_models *tm, int spp_used,
                        int same) {
    static const char *cams[] = {"pinhole", "thin_lens", "fisheye"};
    const cbvh_fx_result *main_r = rc ? rc : rf;
    const cbvh_machine *mm = rc ? &tm->m.mc[0] : &tm->f.mc[0], *mf = &tm->f.mc[0];
    printf("scene %s: %s, %u triangles, %d frame%s%s, %s camera %dx%d, %d spp\n", t->scene, d->mesh_spec,
           d->mesh.ntris, rf->frames, rf->frames > 1 ? "s" : "",
           rf->frames > 1 ? " (animated: refit per frame)" : " (static)", cams[d->camera.type], d->camera.width,
           d->camera.height, spp_used);
    char desc[200];
    cbvh_format_params fp = {{t->bits, t->min_scale}, t->mant, t->one_sided, t->box_unit, t->texp};
    t->fmt->describe(&fp, desc, sizeof desc);
    printf("format %s: %s; %s memory %llu B", t->spec, desc, t->fmt->memory, (unsigned long long)main_r->node_bytes);
    if (rc)
        printf(" (float BVH %llu B, x%.3f)", (unsigned long long)rf->node_bytes,
               cbvh_ratio((double)rc->node_bytes, (double)rf->node_bytes));
    printf("\n");
    if (t->one_sided) printf("one-sided: triangles count only from their counter-clockwise front side\n");
    char line[400], cn[32];
    cbvh_machine_line(tp, line, sizeof line);
    printf("timing model (docs/timing_model.md): cache %s; %s\n", cbvh_cache_name(t->cache_kb, cn, sizeof cn), line);
    printf("CPU us: the bit-exact model's own time, the median of %d timed passes\n\n", t->reps);
    printf("%-18s %-7s %9s %8s %7s %8s %8s %5s %9s %8s %6s %8s", "effect", "kind", "rays", "box/ray", "tri/ray",
           "node/ray", "B/ray", "stack", "model ns", "nJ/ray", "hit %", "CPU us");
    if (rc) printf("   vs float: box, tri, bytes, model, energy, CPU");
    printf("\n");
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        if (!d->effect[e].enabled) continue;
        cbvh_ray_metrics pf = metrics(&rf->fx[e], mf), pm = metrics(&main_r->fx[e], mm);
        const char *kind = main_r->fx[e].any ? (main_r->fx[e].closest ? "mixed" : "any") : "closest";
        if (!main_r->fx[e].rays) kind = "-";
        print_row(cbvh_effect_name((cbvh_effect)e), kind, &pm, rc ? &pf : NULL,
                  cbvh_fx_cpu_ratio(&main_r->fx[e], &rf->fx[e]));
    }
    cbvh_fx_stats tf = cbvh_fx_total(rf), tt = cbvh_fx_total(main_r);
    cbvh_ray_metrics pf = metrics(&tf, mf), pm = metrics(&tt, mm);
    print_row("total", "", &pm, rc ? &pf : NULL, cbvh_fx_cpu_ratio(&tt, &tf));
    printf("model: %s-bound; unit area %.0f LUT4 (float BVH %.0f); DRAM %.1f B/ray; CPU us %.2f [%.2f-%.2f]\n",
           cbvh_timing_bound_name(pm.bound), pm.area_lut4, pf.area_lut4, pm.dram_bytes, pm.cpu_us, pm.cpu_lo,
           pm.cpu_hi);
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
    if (tt.rejected) printf("rays rejected by a unit (no hit): %llu\n", (unsigned long long)tt.rejected);
    if (rc && t->box_unit == CBVH_FORMAT_BOX_INCREMENTAL)
        printf("incremental box unit (M=%d, X=%d): false-positive box hits %.2f per ray (%.1f%% of its box tests: "
               "unit 6 at M=%d rejects them), triangle tests under them %.2f per ray (%.1f%%)\n",
               t->mant, t->texp, pm.fp_box, 100.0 * cbvh_ratio(pm.fp_box, pm.box), t->mant, pm.fp_tri,
               100.0 * cbvh_ratio(pm.fp_tri, pm.tri));
    print_units(&main_r->units, main_r->frames > 1);
    printf("build%s: %.3f s CPU (%s%s)\n", main_r->frames > 1 ? " + refits" : "", main_r->build_cpu_seconds,
           t->fmt->build_note, main_r->frames > 1 ? t->fmt->refit_note : "");
    if (t->fmt->flags & CBVH_FORMAT_STACK_UNIT)
        printf("qbvh stack unit: %llu sort+push, %llu pop operations; deepest stack %u entries (float BVH %u)\n",
               (unsigned long long)tt.st.qstack_pushes, (unsigned long long)tt.st.qstack_pops, tt.st.max_stack,
               tf.st.max_stack);
    if (rc)
        printf("hits: %s the float BVH's (digest %016llx)\n", same ? "identical to" : "DIFFERENT FROM",
               (unsigned long long)rc->hit_digest);
}

/* --timing-check: the analytic model against the event-driven simulation
 * (trace/event_sim.h) on the same rays, for caches x rays in flight x units
 * (the cost table's, and v1's one-cycle pipelined units).  0 or 2. */
#define CHECK_RAYS 20000
static int timing_check(const trace_opts *t, const cbvh_scene_desc *d, const cbvh_fx_opts *fo0, const char *spec,
                        const cbvh_timing_params *tp, const cbvh_cost_table *table) {
    static const double caches[] = {0, 16, 64, 256};
    static const double rays[] = {1, 16, 64, 256};
    cJSON *arr = t->json ? cJSON_CreateArray() : NULL;
    double worst = 0;
    char err[1024], cn[32];
    if (!t->json)
        printf("%-6s %-8s %6s %-10s %14s %14s %9s %14s %9s  %s\n", "format", "cache", "rays", "units",
               "analytic ns/ray", "event ns/ray", "error", "steady ns/ray", "error", "bound");
    for (size_t ci = 0; ci < sizeof caches / sizeof caches[0]; ci++) {
        cbvh_step_log log = {.max_rays = CHECK_RAYS, .cache = 0};
        cbvh_fx_opts fo = *fo0;
        fo.format = spec;
        fo.cache_kb = &caches[ci];
        fo.ncaches = 1;
        fo.steps = &log;
        fo.progress = NULL;
        cbvh_fx_result r;
        cbvh_timing_units u;
        if (cbvh_fx_run(d, &fo, &r, err, sizeof err) ||
            cbvh_fx_units(&r, table, tp, cbvh_box_units[t->box_unit].cost_unit, t->bits, t->mant, &u, err, sizeof err)) {
            fprintf(stderr, "cbvh trace: %s: %s\n", t->scene, err);
            cbvh_step_log_free(&log);
            cJSON_Delete(arr);
            return 2;
        }
        for (int uv = 0; uv < 2; uv++)
            for (size_t ri = 0; ri < sizeof rays / sizeof rays[0]; ri++) {
                cbvh_timing_params p = *tp;
                p.rays_in_flight = rays[ri];
                cbvh_timing_units uu = u;
                if (uv) { /* v1's units: one cycle, pipelined */
                    p.box_cycles = p.tri_cycles = 1;
                    cbvh_fx_units(&r, table, &p, cbvh_box_units[t->box_unit].cost_unit, t->bits, t->mant, &uu, err,
                                  sizeof err);
                }
                cbvh_event_result ev;
                /* at least 50 rays per slot, so start-up and drain stay small */
                if ((double)log.nrays < 50 * rays[ri] || cbvh_event_sim(&log, &p, &uu, caches[ci], &ev)) continue;
                double ns = 1e3 / p.clock_mhz / (double)ev.rays;
                if (fabs(ev.rel_error) > worst) worst = fabs(ev.rel_error);
                if (arr) {
                    cJSON *o = cJSON_CreateObject();
                    cJSON_AddItemToArray(arr, o);
                    cJSON_AddStringToObject(o, "format", spec);
                    json_g6(o, "cache_kb", caches[ci]);
                    json_g6(o, "rays_in_flight", rays[ri]);
                    cJSON_AddStringToObject(o, "units", uv ? "one_cycle" : "cost_table");
                    json_count(o, "rays", ev.rays);
                    json_g6(o, "analytic_ns_per_ray", ev.analytic * ns);
                    json_g6(o, "event_ns_per_ray", ev.cycles * ns);
                    json_g6(o, "rel_error", ev.rel_error);
                    json_g6(o, "event_steady_ns_per_ray", ev.steady * ns);
                    json_g6(o, "rel_error_steady", ev.rel_error_steady);
                    cJSON_AddStringToObject(o, "bound", cbvh_timing_bound_name(ev.bound));
                } else
                    printf("%-6s %-8s %6g %-10s %14.2f %14.2f %+8.2f%% %14.2f %+8.2f%%  %s\n", spec,
                           cbvh_cache_name(caches[ci], cn, sizeof cn), rays[ri], uv ? "one-cycle" : "cost table",
                           ev.analytic * ns, ev.cycles * ns, 100 * ev.rel_error, ev.steady * ns,
                           100 * ev.rel_error_steady, cbvh_timing_bound_name(ev.bound));
            }
        cbvh_step_log_free(&log);
    }
    if (arr) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", t->scene);
        cJSON_AddItemToObject(root, "timing_check", arr);
        json_g6(root, "max_abs_rel_error", worst);
        cbvh_json_print(root, stdout);
        cJSON_Delete(root);
    } else
        printf("largest |error| of the analytic model: %.2f %% (the first %d rays of each run; docs/timing_model.md "
               "§6)\n",
               100 * worst, CHECK_RAYS);
    return 0;
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
    cbvh_cost_table table;
    if (cbvh_timing_check(&tp, err, sizeof err) || (t.timing && cbvh_timing_set(&tp, t.timing, err, sizeof err)) ||
        cbvh_cost_table_load(t.cost_dir, &table, err, sizeof err)) {
        fprintf(stderr, "cbvh trace: %s\n", err);
        cbvh_scene_desc_free(&d);
        return 2;
    }
    progress_ctx pc = {NULL, 0};
    int tty = isatty(2) && !t.json;
    int cmp = !(t.fmt->flags & CBVH_FORMAT_REFERENCE); /* a format compared against the float BVH */
    cbvh_fx_opts fo = {.params = {t.bits, t.min_scale},
                       .mant = cmp ? 24 : t.mant,
                       .spp = t.spp,
                       .progress = tty ? progress : NULL,
                       .ctx = &pc,
                       .one_sided = t.one_sided,
                       .box_unit = t.box_unit,
                       .texp = t.texp,
                       .cache_kb = &t.cache_kb,
                       .ncaches = 1,
                       .cache_ways = (int)tp.cache_ways};
    if (t.check) {
        fo.mant = t.mant;
        status = timing_check(&t, &d, &fo, cmp ? t.spec : "float", &tp, &table);
        cbvh_cost_table_free(&table);
        cbvh_scene_desc_free(&d);
        return status;
    }
    static cbvh_fx_result rf, rc;
    trace_models tm;
    status = run(&d, &fo, "float", &pc, t.scene, t.reps, &rf);
    int same = 1;
    if (!status && cmp) {
        fo.mant = t.mant;
        status = run(&d, &fo, t.spec, &pc, t.scene, t.reps, &rc);
        same = rc.hit_digest == rf.hit_digest; /* every format must return the float BVH's hits */
    }
    if (!status && (cbvh_config_model_init(&tm.f, &rf, &table, &tp, "ray_box", 6, 24, err, sizeof err) ||
                    cbvh_config_model_init(&tm.m, cmp ? &rc : &rf, &table, &tp,
                                           cbvh_box_units[cmp ? t.box_unit : 0].cost_unit, t.bits, t.mant, err,
                                           sizeof err))) {
        fprintf(stderr, "cbvh trace: %s\n", err);
        status = 2;
    }
    cbvh_cost_table_free(&table);
    if (status) {
        cbvh_scene_desc_free(&d);
        return status;
    }
    if (pc.last_row) fprintf(stderr, "\r%60s\r", "");
    int spp_used = t.spp ? t.spp : d.camera.spp;
    if (t.json)
        write_json(&t, &d, &rf, cmp ? &rc : NULL, &tp, &tm, spp_used, same);
    else
        write_table(&t, &d, &rf, cmp ? &rc : NULL, &tp, &tm, spp_used, same);
    if (!same) fprintf(stderr, "cbvh trace: %s hits differ from the float BVH (a traversal bug)\n", t.fmt->title);
    cbvh_scene_desc_free(&d);
    return same ? 0 : 1;
}
