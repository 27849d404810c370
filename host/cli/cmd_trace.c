/* cbvh trace SCENE: trace only the rays a scene's effects call for, on the
 * float BVH and/or the CBVH or QBVH, and report the cost per effect with the timing
 * model (docs/scenes.md, docs/timing_model.md). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "trace/effects.h"
#include "util/parse_int.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"

static void usage(FILE *f) {
    fprintf(f,
            "usage: cbvh trace SCENE [--bits N] [--mant M] [--min-scale E] [--format float|cbvh|qbvh|tlist...]\n"
            "                        [--spp K] [--one-sided] [--json]\n"
            "  SCENE is a scene file (.scene, .json) or a mesh file / proc:NAME (its default scene,\n"
            "  docs/scenes.md).\n"
            "  Traces the rays the scene file's effects call for (docs/scenes.md) and prints, per effect:\n"
            "  rays, box/triangle tests, nodes and bytes per ray, deepest stack, modelled time per ray\n"
            "  (docs/timing_model.md) and the model's CPU time per ray; with --format cbvh (default), qbvh\n"
            "  or tlist also each relative to the float BVH on the same rays, and a units-active line.\n"
            "  --bits N       CBVH coordinate bits, %d..%d (default %d)\n"
            "  --mant M       mantissa bits of the ray-box unit, %d..%d (default 24)\n"
            "  --min-scale E  minimum grid scale, %d..%d (default %d)\n"
            "  --format F     float: the float BVH only; cbvh: the CBVH against the float BVH (default);\n"
            "                 qbvh: the QBVH (4-ary, compressed 32-bit stack, docs/qbvh.md) against it;\n"
            "                 tlist[:1|2|6|8][:earliest|:latest][:cull][:heads]: traversal lists over a\n"
            "                 bounding-sphere hierarchy (docs/tlist.md; default 6 lists, earliest first)\n"
            "  --one-sided    triangles count only from their front side (counter-clockwise), on every\n"
            "                 format; needed by tlist:...:cull\n"
            "  --spp K        camera samples per pixel, 1..1024 (default: the scene's camera.spp)\n"
            "  --json         machine-readable output\n",
            CBVH_N_MIN, CBVH_N_MAX, CBVH_N_DEFAULT, CBVH_MANT_MIN, CBVH_MANT_MAX, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL,
            CBVH_MIN_SCALE_DEFAULT);
}

static int parse_int(const char *opt, const char *s, long lo, long hi, int *out) {
    long v;
    if (cbvh_parse_long(s, lo, hi, &v)) {
        fprintf(stderr, "cbvh trace: %s expects an integer in %ld..%ld, got '%s'\n", opt, lo, hi, s ? s : "");
        return -1;
    }
    *out = (int)v;
    return 0;
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

typedef struct {
    double rays, box, tri, nodes, bytes, model_ns, cpu_us;
    uint32_t stack;
} per_ray;

static per_ray summarize(const cbvh_fx_stats *s, const cbvh_timing_params *tp) {
    per_ray p = {0};
    p.rays = (double)s->rays;
    p.stack = s->st.max_stack;
    if (!s->rays) return p;
    double n = (double)s->rays;
    p.box = (double)s->st.box_tests / n;
    p.tri = (double)s->st.tri_tests / n;
    p.nodes = (double)s->st.nodes / n;
    p.bytes = (double)s->st.bytes / n;
    cbvh_timing_work w = {s->st.box_tests, s->st.tri_tests, s->st.nodes, s->st.bytes};
    cbvh_timing_result tr;
    if (cbvh_timing_eval(tp, &w, &tr) == 0) p.model_ns = tr.seconds * 1e9 / n;
    p.cpu_us = s->cpu_seconds * 1e6 / n;
    return p;
}

/* A JSON string literal (paths may hold quotes, backslashes, control bytes
 * and bytes that are not UTF-8). */
static void json_str(const char *s) { cbvh_json_str(s, stdout); }



static void print_row(const char *name, const char *kind, const per_ray *p, const per_ray *f) {
    printf("%-18s %-7s %9.0f %8.2f %7.2f %8.1f %8.0f %5u %9.1f %8.2f", name, kind, p->rays, p->box, p->tri, p->nodes,
           p->bytes, p->stack, p->model_ns, p->cpu_us);
    if (f) {
        double a[5] = {p->box, p->tri, p->bytes, p->model_ns, p->cpu_us}, b[5] = {f->box, f->tri, f->bytes,
                                                                                    f->model_ns, f->cpu_us};
        printf("  ");
        for (int i = 0; i < 5; i++) cbvh_print_x(cbvh_ratio(a[i], b[i]), 3);
    }
    printf("\n");
}

static void json_stats(const char *key, const cbvh_fx_stats *s, const cbvh_timing_params *tp, int comma) {
    per_ray p = summarize(s, tp);
    printf("%s\"%s\":{\"rays\":%llu,\"closest_hit\":%llu,\"any_hit\":%llu,\"hits\":%llu,\"rejected\":%llu,"
           "\"nodes\":%llu,\"box_tests\":%llu,\"tri_tests\":%llu,\"bytes\":%llu,\"max_stack\":%u,"
           "\"box_per_ray\":%.6g,\"tri_per_ray\":%.6g,\"bytes_per_ray\":%.6g,\"model_ns_per_ray\":%.6g,"
           "\"cpu_us_per_ray\":%.6g}",
           comma ? "," : "", key, (unsigned long long)s->rays, (unsigned long long)s->closest,
           (unsigned long long)s->any, (unsigned long long)s->hits, (unsigned long long)s->rejected,
           (unsigned long long)s->st.nodes, (unsigned long long)s->st.box_tests, (unsigned long long)s->st.tri_tests,
           (unsigned long long)s->st.bytes, s->st.max_stack, p.box, p.tri, p.bytes, p.model_ns, p.cpu_us);
}

static void json_result(const char *key, const cbvh_scene_desc *d, const cbvh_fx_result *r,
                        const cbvh_timing_params *tp) {
    printf(",\"%s\":{\"node_bytes\":%llu,\"build_cpu_s\":%.6g,\"refits\":%llu,\"effects\":{", key,
           (unsigned long long)r->node_bytes, r->build_cpu_seconds, (unsigned long long)r->refits);
    int first = 1;
    for (int e = 0; e < CBVH_FX_COUNT; e++)
        if (d->effect[e].enabled) {
            json_stats(cbvh_effect_name((cbvh_effect)e), &r->fx[e], tp, !first);
            first = 0;
        }
    cbvh_fx_stats t = cbvh_fx_total(r);
    printf("},");
    json_stats("total", &t, tp, 0);
    printf(",\"units\":{\"compressor\":%llu,\"decoder\":%llu,\"ray_box\":%llu,\"ray_triangle\":%llu,\"refit\":%llu,"
           "\"qbvh_stack\":%llu,\"ray_sphere\":%llu},\"qbvh_stack_pushes\":%llu,\"qbvh_stack_pops\":%llu,\"hit_digest\":\"%016llx\"}",
           (unsigned long long)r->units.compressor, (unsigned long long)r->units.decoder,
           (unsigned long long)r->units.ray_box, (unsigned long long)r->units.ray_triangle,
           (unsigned long long)r->units.refit, (unsigned long long)r->units.qbvh_stack,
           (unsigned long long)r->units.ray_sphere, (unsigned long long)t.st.qstack_pushes, (unsigned long long)t.st.qstack_pops,
           (unsigned long long)r->hit_digest);
}

static void print_units(const cbvh_unit_activity *u, int animated) {
    const char *names[] = {"compressor", "decoder", "ray_box", "ray_triangle", "refit", "qbvh_stack", "ray_sphere"};
    uint64_t v[] = {u->compressor, u->decoder, u->ray_box, u->ray_triangle, u->refit, u->qbvh_stack, u->ray_sphere};
    printf("units active:");
    int any = 0;
    for (int i = 0; i < 7; i++)
        if (v[i]) printf("%s %s %llu", any++ ? "," : "", names[i], (unsigned long long)v[i]);
    printf("  | idle:");
    any = 0;
    for (int i = 0; i < 7; i++)
        if (!v[i]) printf("%s %s", any++ ? "," : "", names[i]);
    if (!any) printf(" none");
    printf("%s\n", animated ? "" : "  (static scene: no refit)");
}

int cmd_trace(int argc, char **argv) {
    const char *scene = NULL;
    int bits = CBVH_N_DEFAULT, mant = 24, min_scale = CBVH_MIN_SCALE_DEFAULT, spp = 0, json = 0;
    cbvh_accel_format fmt = CBVH_FORMAT_CBVH;
    cbvh_tlist_opts tlo;
    char tlname[48] = "tlist", terr[200];
    int one_sided = 0;
    cbvh_tlist_opts_parse("tlist", &tlo, terr, sizeof terr);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--json") == 0)
            json = 1;
        else if (strcmp(a, "--bits") == 0) {
            if (parse_int(a, i + 1 < argc ? argv[++i] : NULL, CBVH_N_MIN, CBVH_N_MAX, &bits)) return 2;
        } else if (strcmp(a, "--mant") == 0) {
            if (parse_int(a, i + 1 < argc ? argv[++i] : NULL, CBVH_MANT_MIN, CBVH_MANT_MAX, &mant)) return 2;
        } else if (strcmp(a, "--min-scale") == 0) {
            if (parse_int(a, i + 1 < argc ? argv[++i] : NULL, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, &min_scale)) return 2;
        } else if (strcmp(a, "--spp") == 0) {
            if (parse_int(a, i + 1 < argc ? argv[++i] : NULL, 1, 1024, &spp)) return 2;
        } else if (strcmp(a, "--format") == 0) {
            const char *f = i + 1 < argc ? argv[++i] : "";
            if (strcmp(f, "float") == 0)
                fmt = CBVH_FORMAT_FLOAT;
            else if (strcmp(f, "cbvh") == 0)
                fmt = CBVH_FORMAT_CBVH;
            else if (strcmp(f, "qbvh") == 0)
                fmt = CBVH_FORMAT_QBVH;
            else if (strncmp(f, "tlist", 5) == 0) {
                if (cbvh_tlist_opts_parse(f, &tlo, terr, sizeof terr)) {
                    fprintf(stderr, "cbvh trace: --format: %s\n", terr);
                    return 2;
                }
                fmt = CBVH_FORMAT_TLIST;
                cbvh_tlist_opts_name(&tlo, tlname, sizeof tlname);
            } else {
                fprintf(stderr, "cbvh trace: --format expects float, cbvh, qbvh or tlist[:options], got '%s'\n", f);
                return 2;
            }
        } else if (strcmp(a, "--one-sided") == 0) {
            one_sided = 1;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "cbvh trace: unknown option '%s' (see cbvh trace --help)\n", a);
            return 2;
        } else if (scene) {
            fprintf(stderr, "cbvh trace: more than one scene ('%s', '%s')\n", scene, a);
            return 2;
        } else
            scene = a;
    }
    if (!scene) {
        fprintf(stderr, "cbvh trace: no scene file given (see cbvh trace --help)\n");
        return 2;
    }
    cbvh_scene_desc d;
    char err[1024];
    if (cbvh_scene_file_open(scene, &d, err, sizeof err)) {
        fprintf(stderr, "cbvh trace: %s\n", err);
        return 2;
    }
    cbvh_timing_params tp;
    cbvh_fx_timing(&d, &tp);
    progress_ctx pc = {"float", 0};
    int tty = isatty(2) && !json;
    cbvh_fx_opts fo = {.format = CBVH_FORMAT_FLOAT,
                       .params = {bits, min_scale},
                       .mant = fmt == CBVH_FORMAT_FLOAT ? mant : 24,
                       .spp = spp,
                       .progress = tty ? progress : NULL,
                       .ctx = &pc};
    fo.tlist = tlo;
    fo.one_sided = one_sided;
    static cbvh_fx_result rf, rc;
    int status = 0;
    if (cbvh_fx_run(&d, &fo, &rf, err, sizeof err)) {
        if (pc.last_row) fprintf(stderr, "\n");
        fprintf(stderr, "cbvh trace: %s: %s\n", scene, err);
        cbvh_scene_desc_free(&d);
        return 2; /* the run could not be done: not a finding about hits */
    }
    const cbvh_fx_result *main_r = &rf;
    int cmp = fmt != CBVH_FORMAT_FLOAT; /* a format compared against the float BVH */
    if (cmp) {
        pc.label = fmt == CBVH_FORMAT_TLIST ? tlname : cbvh_format_name(fmt);
        fo.format = fmt;
        fo.mant = mant;
        if (cbvh_fx_run(&d, &fo, &rc, err, sizeof err)) {
            if (pc.last_row) fprintf(stderr, "\n");
            fprintf(stderr, "cbvh trace: %s: %s\n", scene, err);
            cbvh_scene_desc_free(&d);
            return 2; /* the run could not be done: not a finding about hits */
        }
        main_r = &rc;
        if (rc.hit_digest != rf.hit_digest) status = 1; /* every format must return the float BVH's hits */
    }
    if (pc.last_row) fprintf(stderr, "\r%60s\r", "");
    int spp_used = spp ? spp : d.camera.spp;
    static const char *cams[] = {"pinhole", "thin_lens", "fisheye"};
    if (json) {
        printf("{\"scene\":");
        json_str(scene);
        printf(",\"mesh\":");
        json_str(d.mesh_spec);
        printf(",\"triangles\":%u,\"frames\":%d,\"camera\":\"%s\",\"width\":%d,"
               "\"height\":%d,\"spp\":%d,\"one_sided\":%s,\"format\":\"%s\",\"bits\":%d,\"mant\":%d,\"min_scale\":%d,"
               "\"camera_samples_without_ray\":%llu,\"pixels_without_camera_ray\":%llu,"
               "\"timing\":{\"box_cycles\":%g,\"tri_cycles\":%g,\"fetch_latency\":%g,\"dram_bytes_per_cycle\":%g,"
               "\"clock_mhz\":%g}",
               d.mesh.ntris, rf.frames, cams[d.camera.type], d.camera.width, d.camera.height,
               spp_used, one_sided ? "true" : "false", fmt == CBVH_FORMAT_TLIST ? tlname : cbvh_format_name(fmt), bits, mant, min_scale,
               (unsigned long long)rf.samples_without_ray, (unsigned long long)rf.pixels_without_ray, tp.box_cycles,
               tp.tri_cycles, tp.fetch_latency, tp.dram_bytes_per_cycle, tp.clock_mhz);
        json_result("float", &d, &rf, &tp);
        if (cmp) {
            json_result(fmt == CBVH_FORMAT_TLIST ? "tlist" : cbvh_format_name(fmt), &d, &rc, &tp);
            printf(",\"same_hits\":%s", status ? "false" : "true");
        }
        printf("}\n");
    } else {
        printf("scene %s: %s, %u triangles, %d frame%s%s, %s camera %dx%d, %d spp\n", scene, d.mesh_spec, d.mesh.ntris,
               rf.frames, rf.frames > 1 ? "s" : "", rf.frames > 1 ? " (animated: refit per frame)" : " (static)",
               cams[d.camera.type], d.camera.width, d.camera.height, spp_used);
        if (fmt == CBVH_FORMAT_CBVH)
            printf("format cbvh: N=%d, M=%d, min scale %d, modulo; node memory %llu B (float BVH %llu B, x%.3f)\n", bits,
                   mant, min_scale, (unsigned long long)rc.node_bytes, (unsigned long long)rf.node_bytes,
                   cbvh_ratio((double)rc.node_bytes, (double)rf.node_bytes));
        else if (fmt == CBVH_FORMAT_QBVH)
            printf("format qbvh: 4-ary, compressed 32-bit stack, M=%d; node memory %llu B (float BVH %llu B, x%.3f)\n",
                   mant, (unsigned long long)rc.node_bytes, (unsigned long long)rf.node_bytes,
                   cbvh_ratio((double)rc.node_bytes, (double)rf.node_bytes));
        else if (fmt == CBVH_FORMAT_TLIST)
            printf("format %s: sphere hierarchy + lists; list memory %llu B (float BVH %llu B, x%.3f)\n", tlname,
                   (unsigned long long)rc.node_bytes, (unsigned long long)rf.node_bytes,
                   cbvh_ratio((double)rc.node_bytes, (double)rf.node_bytes));
        else
            printf("format float: M=%d; node memory %llu B\n", mant, (unsigned long long)rf.node_bytes);
        if (one_sided) printf("one-sided: triangles count only from their counter-clockwise front side\n");
        printf("timing model: %g cycle/box, %g cycle/tri, %g cycles fetch latency, %g B/cycle DRAM, %g MHz "
               "(docs/timing_model.md)\n\n",
               tp.box_cycles, tp.tri_cycles, tp.fetch_latency, tp.dram_bytes_per_cycle, tp.clock_mhz);
        printf("%-18s %-7s %9s %8s %7s %8s %8s %5s %9s %8s", "effect", "kind", "rays", "box/ray", "tri/ray",
               "node/ray", "B/ray", "stack", "model ns", "CPU us");
        if (cmp) printf("   vs float: box, tri, bytes, model, CPU");
        printf("\n");
        per_ray pf[CBVH_FX_COUNT + 1], pm;
        for (int e = 0; e < CBVH_FX_COUNT; e++) {
            if (!d.effect[e].enabled) continue;
            pf[e] = summarize(&rf.fx[e], &tp);
            pm = summarize(&main_r->fx[e], &tp);
            const char *kind = main_r->fx[e].any ? (main_r->fx[e].closest ? "mixed" : "any") : "closest";
            if (!main_r->fx[e].rays) kind = "-";
            print_row(cbvh_effect_name((cbvh_effect)e), kind, &pm, cmp ? &pf[e] : NULL);
        }
        cbvh_fx_stats tf = cbvh_fx_total(&rf), tm = cbvh_fx_total(main_r);
        pf[CBVH_FX_COUNT] = summarize(&tf, &tp);
        pm = summarize(&tm, &tp);
        print_row("total", "", &pm, cmp ? &pf[CBVH_FX_COUNT] : NULL);
        int unnamed = 0;
        for (int e = 0; e < CBVH_FX_COUNT; e++)
            if (!d.effect[e].enabled) {
                printf("%s %s %llu", unnamed++ ? "," : "not in the scene (rays):", cbvh_effect_name((cbvh_effect)e),
                       (unsigned long long)main_r->fx[e].rays);
            }
        if (unnamed) printf("\n");
        if (main_r->samples_without_ray)
            printf("camera samples without a ray (outside the fisheye circle): %llu of %llu; pixels with no ray in "
                   "any sample: %llu of %llu\n",
                   (unsigned long long)main_r->samples_without_ray,
                   (unsigned long long)d.camera.width * (unsigned long long)d.camera.height *
                       (unsigned long long)spp_used * (unsigned long long)main_r->frames,
                   (unsigned long long)main_r->pixels_without_ray,
                   (unsigned long long)d.camera.width * (unsigned long long)d.camera.height);
        if (tm.rejected) printf("rays rejected by a unit (no hit): %llu\n", (unsigned long long)tm.rejected);
        print_units(&main_r->units, main_r->frames > 1);
        printf("build%s: %.3f s CPU%s\n", main_r->frames > 1 ? " + refits" : "", main_r->build_cpu_seconds,
               fmt == CBVH_FORMAT_CBVH   ? " (CBVH: SAH build + bottom-up streaming compression)"
               : fmt == CBVH_FORMAT_QBVH ? (main_r->frames > 1 ? " (QBVH: SAH build + 4-ary collapse; refits: the QBVH's "
                                                                   "own boxes bottom-up, topology kept)"
                                                                 : " (QBVH: SAH build + 4-ary collapse)")
                                         : fmt == CBVH_FORMAT_TLIST
                                             ? (main_r->frames > 1 ? " (sphere hierarchy + lists, rebuilt per frame)"
                                                                   : " (sphere hierarchy + lists)")
                                             : " (SAH build)");
        if (fmt == CBVH_FORMAT_QBVH)
            printf("qbvh stack unit: %llu sort+push, %llu pop operations; deepest stack %u entries (float BVH %u)\n",
                   (unsigned long long)tm.st.qstack_pushes, (unsigned long long)tm.st.qstack_pops, tm.st.max_stack,
                   tf.st.max_stack);
        if (cmp)
            printf("hits: %s the float BVH's (digest %016llx)\n", status ? "DIFFERENT FROM" : "identical to",
                   (unsigned long long)rc.hit_digest);
    }
    if (status)
        fprintf(stderr, "cbvh trace: %s hits differ from the float BVH (a traversal bug)\n",
                fmt == CBVH_FORMAT_QBVH ? "QBVH" : fmt == CBVH_FORMAT_TLIST ? "traversal-list" : "CBVH");
    cbvh_scene_desc_free(&d);
    return status;
}
