/* The table of formats (cbvh/format.h), tested through the table only, so a
 * format added to it is tested without editing this file:
 *   - every entry is complete: its words and functions set, options iff a
 *     parser, a unique name that cbvh_format_find returns it for, its
 *     canonical spec a fixed point of its parser, the reference first;
 *   - every format (and some option variants) returns the float BVH's hits
 *     ray by ray: pinhole camera rays (which screen-cell heads may start
 *     further along) and secondary rays leaving the triangles those hit (which
 *     per-polygon heads may start further along), closest hit (triangle, t,
 *     b1, b2 bits) and any hit, two-sided and one-sided; again after a refit to
 *     moved triangles; its unit counts are its counters' (the QBVH stack unit
 *     exactly where the flag says). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/format.h"
#include "scene/scene_load.h"
#include "test_trav_util.h"

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

/* Option variants traced besides each format's bare name (skipped when no
 * format of the table takes them). */
static const char *const variants[] = {"tlist:1:latest", "tlist:2:cull:heads", "tlist:6:heads", "tlist:8:cull:heads"};

static void table_complete(void) {
    size_t n;
    const cbvh_format *const *fmts = cbvh_formats(&n);
    CHECK(n >= 2, "%zu formats", n);
    int refs = 0;
    char names[512], err[256], canon[CBVH_FORMAT_NAME_MAX], again[CBVH_FORMAT_NAME_MAX];
    cbvh_format_names(names, sizeof names);
    for (size_t i = 0; i < n; i++) {
        const cbvh_format *f = fmts[i];
        const char *nm = f->name ? f->name : "(null)";
        CHECK(f->name && f->name[0] && !strchr(f->name, ':'), "format %zu: no name", i);
        CHECK(f->title && f->title[0] && f->help && f->help[0] && f->memory && f->memory[0] && f->build_note &&
                  f->build_note[0] && f->refit_note,
              "%s: a word missing", nm);
        CHECK(f->describe && f->build && f->refit && f->trace && f->bytes && f->units && f->free,
              "%s: a function missing", nm);
        CHECK(!f->parse == !(f->flags & CBVH_FORMAT_OPTIONS), "%s: options without a parser or a parser without", nm);
        CHECK(cbvh_format_find(nm) == f, "%s: not found by its name", nm);
        for (size_t j = 0; j < i; j++) CHECK(strcmp(fmts[j]->name, nm) != 0, "%s: two entries", nm);
        CHECK(strstr(names, nm) != NULL, "%s: not in the names '%s'", nm, names);
        const cbvh_format *g = NULL;
        CHECK(cbvh_format_parse(nm, &g, canon, sizeof canon, err, sizeof err) == 0 && g == f, "%s: %s", nm, err);
        CHECK(strncmp(canon, nm, strlen(nm)) == 0, "%s: canonical spec '%s'", nm, canon);
        CHECK(cbvh_format_parse(canon, &g, again, sizeof again, err, sizeof err) == 0 && strcmp(canon, again) == 0,
              "%s: canonical '%s' parses to '%s'", nm, canon, again);
        if (!(f->flags & CBVH_FORMAT_OPTIONS)) {
            char spec[64];
            snprintf(spec, sizeof spec, "%s:x", nm);
            CHECK(cbvh_format_find(spec) == NULL, "%s takes no options, yet '%s' is found", nm, spec);
        }
        refs += (f->flags & CBVH_FORMAT_REFERENCE) != 0;
    }
    CHECK(refs == 1 && (fmts[0]->flags & CBVH_FORMAT_REFERENCE), "the reference is not the one first entry");
    CHECK(strcmp(fmts[0]->name, "float") == 0, "the reference is not the float BVH");
    const cbvh_format *g;
    CHECK(cbvh_format_find("nosuch") == NULL && cbvh_format_find("") == NULL, "an unknown name found");
    CHECK(cbvh_format_parse("nosuch", &g, canon, sizeof canon, err, sizeof err) == -1 &&
              strstr(err, "format 'nosuch': expected ") && strstr(err, names) && !strchr(err, '\n'),
          "unknown format: '%s'", err);
}

/* ---- the rays: a pinhole camera's and secondary rays from their hits ---- */
#define W 32
#define H 24

typedef struct {
    float pos[3], w[3], u[3], v[3], th;
} camera;

static void pinhole_dir(const void *ctx, float u, float v, float out[3]) {
    const camera *c = ctx;
    float sx = (2 * u - 1) * c->th * ((float)W / (float)H), sy = (1 - 2 * v) * c->th;
    for (int a = 0; a < 3; a++) out[a] = c->w[a] + sx * c->u[a] + sy * c->v[a];
}

static void normalize(float v[3]) {
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int a = 0; a < 3; a++) v[a] /= l;
}

typedef struct {
    cbvh_ray r;
    cbvh_format_from from;
} ray_rec;

static cbvh_ray make_ray(const float o[3], const float d[3]) {
    cbvh_ray r = {{fb(o[0]), fb(o[1]), fb(o[2])}, {fb(d[0]), fb(d[1]), fb(d[2])}, 0, CBVH_F32_POS_INF};
    return r;
}

/* Camera rays, then for each closest hit of the float BVH (traced here
 * through the table, two-sided) a ray leaving its triangle on the side it
 * came from: origin hit point + eps n, direction n plus a random tilt.
 * Returns the number of rays in out (at most 2 W H). */
static int make_rays(const camera *cam, const cbvh_format_pinhole *pin, const cbvh_tri *tris, const void *ref,
                     float eps, uint64_t *rs, ray_rec *out) {
    const cbvh_format *F = cbvh_formats(&(size_t){0})[0];
    int n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float d[3];
            pin->dir(pin->ctx, ((float)x + 0.5f) / W, ((float)y + 0.5f) / H, d);
            out[n] = (ray_rec){make_ray(cam->pos, d), {UINT32_MAX, x, y}};
            cbvh_trav_hit h;
            cbvh_trav_stats st = {0};
            F->trace(ref, tris, &out[n].r, CBVH_TRAV_CLOSEST, &out[n].from, &h, &st);
            n++;
            if (!h.hit) continue;
            const cbvh_tri *t = &tris[h.prim];
            float e1[3], e2[3], nn[3], p[3], q[3], s[3];
            for (int a = 0; a < 3; a++) {
                e1[a] = t->v[1][a] - t->v[0][a];
                e2[a] = t->v[2][a] - t->v[0][a];
                p[a] = cam->pos[a] + bf(h.t) * d[a];
            }
            nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
            nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
            nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
            normalize(nn);
            if (nn[0] * d[0] + nn[1] * d[1] + nn[2] * d[2] > 0)
                for (int a = 0; a < 3; a++) nn[a] = -nn[a];
            for (int a = 0; a < 3; a++) {
                q[a] = p[a] + eps * nn[a];
                s[a] = nn[a] + 0.9f * (2 * tu_unit_f(rs) - 1);
            }
            if (s[0] * nn[0] + s[1] * nn[1] + s[2] * nn[2] <= 0) memcpy(s, nn, sizeof s);
            out[n++] = (ray_rec){make_ray(q, s), {h.prim, x, y}};
        }
    return n;
}

/* Traces every ray through format f (state st) and compares with the
 * reference's hits; adds the counters to *sum.  Returns the hits. */
static int compare(const char *spec, const char *phase, int one_sided, const cbvh_format *f, const void *st,
                   const void *ref, const cbvh_tri *tris, const ray_rec *rays, int n, cbvh_trav_stats *sum) {
    const cbvh_format *R = cbvh_formats(&(size_t){0})[0];
    int hits = 0;
    for (int i = 0; i < n; i++)
        for (int any = 0; any < 2; any++) {
            cbvh_trav_mode m = (cbvh_trav_mode)((any ? CBVH_TRAV_ANY : CBVH_TRAV_CLOSEST) |
                                                (one_sided ? CBVH_TRAV_FRONT_ONLY : 0));
            cbvh_trav_hit hr, hf;
            cbvh_trav_stats sr = {0}, sf = {0};
            int rr = R->trace(ref, tris, &rays[i].r, m, &rays[i].from, &hr, &sr);
            int rf = f->trace(st, tris, &rays[i].r, m, &rays[i].from, &hf, &sf);
            CHECK(rr == 0 && rf == 0, "%s %s: ray %d rejected (%d, %d)", spec, phase, i, rr, rf);
            CHECK(any ? hr.hit == hf.hit : same_hit(&hr, &hf),
                  "%s %s one-sided %d ray %d (%s, %s): float hit %d prim %u t %08x, %s hit %d prim %u t %08x", spec,
                  phase, one_sided, i, rays[i].from.src_prim == UINT32_MAX ? "camera" : "secondary",
                  any ? "any" : "closest", hr.hit, hr.prim, hr.t, spec, hf.hit, hf.prim, hf.t);
            hits += hf.hit;
            sum->nodes += sf.nodes;
            sum->box_tests += sf.box_tests;
            sum->tri_tests += sf.tri_tests;
            sum->qstack_pushes += sf.qstack_pushes;
            sum->qstack_pops += sf.qstack_pops;
        }
    return hits;
}

/* The units of a run are its counters'; the stack unit runs exactly where
 * the format says. */
static void check_units(const char *spec, const cbvh_format *f, const cbvh_trav_stats *sum) {
    cbvh_unit_activity u = {0};
    f->units(sum, &u);
    CHECK(u.ray_triangle == sum->tri_tests, "%s: ray_triangle %llu, tri tests %llu", spec,
          (unsigned long long)u.ray_triangle, (unsigned long long)sum->tri_tests);
    CHECK(u.ray_box + u.ray_sphere == sum->box_tests && (!u.ray_box || !u.ray_sphere),
          "%s: box %llu + sphere %llu, box tests %llu", spec, (unsigned long long)u.ray_box,
          (unsigned long long)u.ray_sphere, (unsigned long long)sum->box_tests);
    CHECK(u.decoder == 0 || u.decoder == 6 * sum->nodes, "%s: decoder %llu", spec, (unsigned long long)u.decoder);
    int stack = (f->flags & CBVH_FORMAT_STACK_UNIT) != 0;
    CHECK(stack ? u.qbvh_stack == sum->qstack_pushes + sum->qstack_pops && u.qbvh_stack > 0 : u.qbvh_stack == 0,
          "%s: qbvh_stack %llu (flag %d)", spec, (unsigned long long)u.qbvh_stack, stack);
    CHECK(u.compressor == 0 && u.refit == 0, "%s: traversals ran the compressor or refit", spec);
}

static void hits_through_table(void) {
    cbvh_scene s = {0};
    char err[256];
    if (cbvh_scene_open(CBVH_SCENES_DIR "/bunny-small.obj", &s, err, sizeof err)) {
        CHECK(0, "%s", err);
        return;
    }
    float lo[3], hi[3], c[3], ext = 0;
    cbvh_scene_bounds(&s, lo, hi);
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        ext = fmaxf(ext, hi[a] - lo[a]);
    }
    camera cam = {{c[0] + 0.3f * ext, c[1] + 0.4f * ext, c[2] + 1.8f * ext}, {0}, {0}, {0}, tanf(0.35f)};
    const float up[3] = {0, 1, 0};
    for (int a = 0; a < 3; a++) cam.w[a] = c[a] - cam.pos[a];
    normalize(cam.w);
    cam.u[0] = cam.w[1] * up[2] - cam.w[2] * up[1];
    cam.u[1] = cam.w[2] * up[0] - cam.w[0] * up[2];
    cam.u[2] = cam.w[0] * up[1] - cam.w[1] * up[0];
    normalize(cam.u);
    cam.v[0] = cam.u[1] * cam.w[2] - cam.u[2] * cam.w[1];
    cam.v[1] = cam.u[2] * cam.w[0] - cam.u[0] * cam.w[2];
    cam.v[2] = cam.u[0] * cam.w[1] - cam.u[1] * cam.w[0];
    cbvh_format_pinhole pin = {W, H, {cam.pos[0], cam.pos[1], cam.pos[2]}, pinhole_dir, &cam};
    float eps = 1e-4f * ext * sqrtf(3.0f);
    cbvh_tri *tris = malloc((size_t)s.ntris * sizeof *tris), *moved = malloc((size_t)s.ntris * sizeof *moved);
    ray_rec *rays = malloc(2 * W * H * sizeof *rays);
    if (!tris || !moved || !rays) {
        CHECK(0, "out of memory");
        goto out;
    }
    memcpy(tris, s.tris, (size_t)s.ntris * sizeof *tris);
    cbvh_scene_deform(&s, 0.8f, 0.1f, 1.0f, moved);
    cbvh_scene frame = s;
    frame.tris = tris;
    size_t nf;
    const cbvh_format *const *fmts = cbvh_formats(&nf);
    /* The specs: every format's name, then the variants of formats with options. */
    const char *specs[64];
    size_t ns = 0;
    for (size_t i = 0; i < nf && ns < 64; i++) specs[ns++] = fmts[i]->name;
    for (size_t i = 0; i < sizeof variants / sizeof variants[0] && ns < 64; i++)
        if (cbvh_format_find(variants[i])) specs[ns++] = variants[i];
    for (int one_sided = 0; one_sided < 2; one_sided++) {
        memcpy(tris, s.tris, (size_t)s.ntris * sizeof *tris);
        cbvh_format_input in = {.p = {{6, CBVH_MIN_SCALE_DEFAULT}, 24, one_sided, CBVH_FORMAT_BOX_EXACT, 0}, .scene = &frame, .eps = eps,
                                .origin_max = fmaxf(fmaxf(fabsf(cam.pos[0]), fabsf(cam.pos[1])), fabsf(cam.pos[2])),
                                .pinhole = &pin};
        void *state[64] = {0}, *ref2 = NULL;
        cbvh_unit_activity u[64] = {{0}}, ur = {0};
        /* The rays come from a two-sided float BVH; the reference traced
         * against is the first entry built like every other. */
        cbvh_format_input in2 = in;
        in2.spec = fmts[0]->name;
        in2.p.one_sided = 0;
        CHECK(fmts[0]->build(&in2, &ref2, &ur, err, sizeof err) == 0, "reference: %s", err);
        for (size_t k = 0; k < ns; k++) {
            const cbvh_format *f;
            char spec[CBVH_FORMAT_NAME_MAX];
            CHECK(cbvh_format_parse(specs[k], &f, spec, sizeof spec, err, sizeof err) == 0, "%s: %s", specs[k], err);
            in.spec = spec;
            int rc = f->build(&in, &state[k], &u[k], err, sizeof err);
            if (rc && !one_sided && strstr(specs[k], ":cull")) { /* culling needs one-sided triangles */
                CHECK(strstr(err, "one-sided") && !strchr(err, '\n'), "%s two-sided: '%s'", specs[k], err);
                state[k] = NULL;
                continue;
            }
            CHECK(rc == 0, "%s: build: %s", specs[k], err);
            if (rc) state[k] = NULL;
        }
        uint64_t rs = 0x243F6A8885A308D3ull;
        for (int phase = 0; phase < 2 && ref2; phase++) {
            if (phase) { /* the twist: every format refits to it */
                memcpy(tris, moved, (size_t)s.ntris * sizeof *tris);
                CHECK(fmts[0]->refit(ref2, tris, &ur, err, sizeof err) == 0, "reference refit: %s", err);
            }
            int n = make_rays(&cam, &pin, tris, ref2, eps, &rs, rays);
            CHECK(n > W * H + W * H / 8, "only %d rays", n);
            for (size_t k = 0; k < ns; k++) {
                if (!state[k]) continue;
                const cbvh_format *f = cbvh_format_find(specs[k]);
                if (phase) {
                    uint64_t before = u[k].refit;
                    CHECK(f->refit(state[k], tris, &u[k], err, sizeof err) == 0, "%s: refit: %s", specs[k], err);
                    CHECK(u[k].refit > before, "%s: the refit counted no node", specs[k]);
                }
                cbvh_trav_stats sum = {0};
                int hits = compare(specs[k], phase ? "refitted" : "built", one_sided, f, state[k], state[0], tris,
                                   rays, n, &sum);
                CHECK(hits > n / 4, "%s: only %d hits of %d rays", specs[k], hits, 2 * n);
                check_units(specs[k], f, &sum);
                CHECK(f->bytes(state[k]) > 0, "%s: no bytes", specs[k]);
                char desc[200] = "";
                f->describe(&in.p, desc, sizeof desc);
                CHECK(desc[0], "%s: no description", specs[k]);
                if (phase == 1 && one_sided)
                    printf("%-20s %5d rays, %6d hits closest+any, %8llu box and %7llu triangle tests, %8llu B\n",
                           specs[k], n, hits, (unsigned long long)sum.box_tests, (unsigned long long)sum.tri_tests,
                           (unsigned long long)f->bytes(state[k]));
            }
        }
        for (size_t k = 0; k < ns; k++)
            if (state[k]) cbvh_format_find(specs[k])->free(state[k]);
        if (ref2) fmts[0]->free(ref2);
    }
out:
    free(tris);
    free(moved);
    free(rays);
    cbvh_scene_free(&s);
}

int main(void) {
    table_complete();
    hits_through_table();
    printf("%s (%d failures)\n", fails ? "FAILED" : "ok", fails);
    return fails ? 1 : 0;
}
