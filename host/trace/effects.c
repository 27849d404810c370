/* Effects -> rays, traced with the units of the chosen format
 * (docs/scenes.md; the formats are behind cbvh/format.h).  Ray generation is
 * host-side float math (it is not a hardware unit); the traversal and every
 * count come from the bit-exact model. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include "trace/effects.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbvh/oom.h"

#define PI_F 3.14159265358979f

/* ---- deterministic sampling: one splitmix64 stream per pixel sample ----- */
typedef struct {
    uint64_t s;
} rng;

static uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    return z ^ (z >> 31);
}
static float rnd(rng *r) {
    r->s += 0x9E3779B97F4A7C15u;
    return (float)(mix64(r->s) >> 40) * (1.0f / 16777216.0f); /* [0, 1) */
}

/* ---- small vector helpers ---- */
static void sub3(float o[3], const float a[3], const float b[3]) {
    for (int i = 0; i < 3; i++) o[i] = a[i] - b[i];
}
static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(float o[3], const float a[3], const float b[3]) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static void norm3(float v[3]) {
    float l = sqrtf(dot3(v, v));
    if (l > 0)
        for (int i = 0; i < 3; i++) v[i] /= l;
}
/* Orthonormal basis (t, b) around unit n. */
static void onb(const float n[3], float t[3], float b[3]) {
    float a[3] = {fabsf(n[0]) > 0.9f ? 0.0f : 1.0f, fabsf(n[0]) > 0.9f ? 1.0f : 0.0f, 0.0f};
    cross3(t, a, n);
    norm3(t);
    cross3(b, n, t);
}
static void cosine_dir(rng *r, const float n[3], float out[3]) {
    float t[3], b[3];
    onb(n, t, b);
    float u1 = rnd(r), u2 = rnd(r);
    float rad = sqrtf(u1), phi = 2 * PI_F * u2;
    float x = rad * cosf(phi), y = rad * sinf(phi), z = sqrtf(fmaxf(0.0f, 1 - u1));
    for (int i = 0; i < 3; i++) out[i] = x * t[i] + y * b[i] + z * n[i];
}

/* ---- the tracer: the chosen format's state and the frame being traced ---- */
typedef struct {
    const cbvh_scene_desc *d;
    const cbvh_fx_opts *o;
    cbvh_fx_result *res;
    const cbvh_format *F;
    void *state;    /* the format's */
    cbvh_tri *tris; /* current frame */
    float eps;      /* secondary-ray origin offset along the normal */
    int frame;
    int px, py;     /* pixel being traced (for observers) */
    uint8_t *had_ray; /* fisheye: per pixel, 1 once a sample made a camera ray (any frame) */
    cbvh_memsim *mem; /* the timing model's caches, or NULL */
} tracer;

static double cpu_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Per-ray traversal time.  The process CPU clock is a system call (~250 ns
 * here, as long as a fifth of a traversal), so each ray is timed with the
 * monotonic clock (vDSO, ~30 ns) and the clock's own cost, the fastest of
 * 64 back-to-back readings, is taken off every interval. */
static double ray_clock(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double ray_clock_overhead(void) {
    static double overhead = -1;
    if (overhead < 0) {
        double best = 1.0;
        for (int i = 0; i < 64; i++) {
            double a = ray_clock(), b = ray_clock();
            if (b - a < best) best = b - a;
        }
        overhead = best;
    }
    return overhead;
}

static int trace(tracer *T, cbvh_effect fx, cbvh_trav_mode mode, const float o[3], const float dir[3], float tmax,
                 uint32_t src, int light, cbvh_trav_hit *hit) {
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        r.o[a] = cbvh_f32_of(o[a]);
        r.d[a] = cbvh_f32_of(dir[a]);
    }
    r.tmin = 0;
    r.tmax = isinf(tmax) ? CBVH_F32_POS_INF : cbvh_f32_of(tmax);
    cbvh_trav_stats st = {0};
    /* One-sided scenes: the same rule on every format (the reference included). */
    cbvh_trav_mode tm = T->o->one_sided ? (cbvh_trav_mode)(mode | CBVH_TRAV_FRONT_ONLY) : mode;
    cbvh_format_from from = {src, T->px, T->py};
    if (T->mem) cbvh_memsim_ray_begin(T->mem, T->res->fx[fx].mem);
    double clk = ray_clock_overhead(), t0 = ray_clock();
    int rc = T->F->trace(T->state, T->tris, &r, tm, &from, hit, &st);
    double dt = ray_clock() - t0 - clk;
    if (T->mem) cbvh_memsim_ray_end(T->mem, &st);
    if (rc) memset(hit, 0, sizeof *hit);
    cbvh_fx_stats_add_ray(&T->res->fx[fx], mode, rc, hit->hit, &st, dt > 0 ? dt : 0);
    /* Closest hit: triangle and t are defined (same on every format); any hit: only whether. */
    uint64_t h = T->res->hit_digest ^
                 (!hit->hit ? 0xFFFFFFFFFFFFFFFFu : (mode & CBVH_TRAV_ANY) ? 1 : ((uint64_t)hit->prim << 32 | hit->t));
    T->res->hit_digest = mix64(h + (uint64_t)fx);
    if (T->o->on_ray) {
        cbvh_fx_ray fr = {fx, mode, r, src, light, T->frame, hit, &st, T->px, T->py};
        T->o->on_ray(T->o->ctx, &fr);
    }
    return hit->hit;
}

/* Hit point and the geometric normal facing the incoming ray. */
static void surface(const tracer *T, const float o[3], const float dir[3], const cbvh_trav_hit *h, float p[3],
                    float n[3]) {
    float t = cbvh_float_of(h->t);
    for (int a = 0; a < 3; a++) p[a] = o[a] + t * dir[a];
    const cbvh_tri *tr = &T->tris[h->prim];
    float e1[3], e2[3];
    sub3(e1, tr->v[1], tr->v[0]);
    sub3(e2, tr->v[2], tr->v[0]);
    cross3(n, e1, e2);
    norm3(n);
    if (dot3(n, dir) > 0)
        for (int a = 0; a < 3; a++) n[a] = -n[a];
}

static void shade(tracer *T, rng *R, const float o[3], const float dir[3], const cbvh_trav_hit *h, int depth) {
    const cbvh_scene_desc *d = T->d;
    float p[3], n[3], q[3];
    surface(T, o, dir, h, p, n);
    for (int a = 0; a < 3; a++) q[a] = p[a] + T->eps * n[a]; /* origin off the surface, on the ray's side */
    uint32_t prim = h->prim;
    const cbvh_effect_cfg *E = d->effect;
    if (d->materials[d->tri_material[prim]].type == CBVH_MAT_MIRROR) {
        /* A mirror reflects; it receives no shadows, AO or bounce. */
        if (!E[CBVH_FX_MIRROR].enabled || depth >= E[CBVH_FX_MIRROR].max_depth) return;
        float r[3], k = 2 * dot3(dir, n);
        for (int a = 0; a < 3; a++) r[a] = dir[a] - k * n[a];
        cbvh_trav_hit mh;
        if (trace(T, CBVH_FX_MIRROR, CBVH_TRAV_CLOSEST, q, r, INFINITY, prim, -1, &mh)) shade(T, R, q, r, &mh, depth + 1);
        return;
    }
    cbvh_trav_hit sh;
    if (E[CBVH_FX_HARD_SHADOWS].enabled)
        for (int l = 0; l < d->nlights; l++) {
            float to[3];
            sub3(to, d->lights[l].position, q);
            if (dot3(to, n) <= 0) continue; /* light behind the surface: nothing to test */
            trace(T, CBVH_FX_HARD_SHADOWS, CBVH_TRAV_ANY, q, to, 0.9999f, prim, l, &sh);
        }
    if (E[CBVH_FX_SOFT_SHADOWS].enabled)
        for (int l = 0; l < d->nlights; l++) {
            const cbvh_light *L = &d->lights[l];
            if (L->type != CBVH_LIGHT_AREA) continue;
            for (int s = 0; s < E[CBVH_FX_SOFT_SHADOWS].samples; s++) {
                float a = rnd(R) - 0.5f, b = rnd(R) - 0.5f, to[3];
                for (int i = 0; i < 3; i++) to[i] = L->position[i] + a * L->u[i] + b * L->v[i] - q[i];
                if (dot3(to, n) <= 0) continue;
                trace(T, CBVH_FX_SOFT_SHADOWS, CBVH_TRAV_ANY, q, to, 0.9999f, prim, l, &sh);
            }
        }
    if (E[CBVH_FX_AMBIENT_OCCLUSION].enabled)
        for (int s = 0; s < E[CBVH_FX_AMBIENT_OCCLUSION].samples; s++) {
            float w[3];
            cosine_dir(R, n, w);
            trace(T, CBVH_FX_AMBIENT_OCCLUSION, CBVH_TRAV_ANY, q, w, E[CBVH_FX_AMBIENT_OCCLUSION].distance, prim, -1,
                  &sh);
        }
    if (E[CBVH_FX_DIFFUSE_BOUNCE].enabled)
        for (int s = 0; s < E[CBVH_FX_DIFFUSE_BOUNCE].samples; s++) {
            float w[3];
            cosine_dir(R, n, w);
            trace(T, CBVH_FX_DIFFUSE_BOUNCE, CBVH_TRAV_CLOSEST, q, w, INFINITY, prim, -1, &sh);
        }
}

/* The camera's orthonormal frame: w forward, u right, v up. */
static void camera_frame(const cbvh_camera *c, float w[3], float u[3], float v[3]) {
    sub3(w, c->target, c->position);
    norm3(w);
    cross3(u, w, c->up);
    norm3(u);
    cross3(v, u, w);
}

/* The pinhole direction through image point (px, py) in [0, 1]^2 (the
 * formula of camera_ray) of camera cam (a cbvh_camera; the signature of
 * cbvh_format_pinhole.dir). */
static void pinhole_dir(const void *cam, float px, float py, float dir[3]) {
    const cbvh_camera *c = cam;
    float w[3], u[3], v[3];
    camera_frame(c, w, u, v);
    float th = tanf(0.5f * c->fov * PI_F / 180.0f), aspect = (float)c->width / (float)c->height;
    float sx = (2 * px - 1) * th * aspect, sy = (1 - 2 * py) * th;
    for (int i = 0; i < 3; i++) dir[i] = w[i] + sx * u[i] + sy * v[i];
}

/* Camera ray through pixel (x, y), sample s.  0 if the pixel has no ray
 * (fisheye outside its image circle). */
static int camera_ray(const cbvh_camera *c, int x, int y, int spp, rng *R, float o[3], float dir[3]) {
    float w[3], u[3], v[3];
    camera_frame(c, w, u, v);
    float jx = spp > 1 ? rnd(R) : 0.5f, jy = spp > 1 ? rnd(R) : 0.5f;
    float px = ((float)x + jx) / (float)c->width, py = ((float)y + jy) / (float)c->height; /* [0,1) */
    memcpy(o, c->position, 3 * sizeof(float));
    if (c->type == CBVH_CAM_FISHEYE) {
        /* Equidistant fisheye: image circle inscribed in the frame, angle from
         * the axis proportional to the radius, fov = full angle of the circle. */
        float m = (float)(c->width < c->height ? c->width : c->height);
        float cx = ((float)x + jx - 0.5f * (float)c->width) / (0.5f * m);
        float cy = (0.5f * (float)c->height - ((float)y + jy)) / (0.5f * m);
        float r = sqrtf(cx * cx + cy * cy);
        if (r > 1.0f) return 0;
        float th = r * 0.5f * c->fov * PI_F / 180.0f, ph = atan2f(cy, cx);
        for (int i = 0; i < 3; i++)
            dir[i] = cosf(th) * w[i] + sinf(th) * (cosf(ph) * u[i] + sinf(ph) * v[i]);
        return 1;
    }
    pinhole_dir(c, px, py, dir);
    if (c->type == CBVH_CAM_THIN_LENS) {
        /* Point in focus at distance focus_distance along the axis; origin on
         * the lens disk of radius `aperture`. */
        float f[3], rr = c->aperture * sqrtf(rnd(R)), ph = 2 * PI_F * rnd(R);
        for (int i = 0; i < 3; i++) f[i] = c->position[i] + c->focus_distance * dir[i];
        for (int i = 0; i < 3; i++) o[i] = c->position[i] + rr * cosf(ph) * u[i] + rr * sinf(ph) * v[i];
        sub3(dir, f, o);
    }
    return 1;
}

static void trace_frame(tracer *T) {
    const cbvh_scene_desc *d = T->d;
    const cbvh_camera *c = &d->camera;
    int spp = T->o->spp > 0 ? T->o->spp : c->spp, frames = cbvh_scene_desc_frames(d);
    for (int y = 0; y < c->height; y++) {
        if (T->o->progress) T->o->progress(T->o->ctx, T->frame, frames, y, c->height);
        for (int x = 0; x < c->width; x++)
            for (int s = 0; s < spp; s++) {
                T->px = x;
                T->py = y;
                uint64_t pix = ((uint64_t)y * (uint64_t)c->width + (uint64_t)x) * (uint64_t)spp + (uint64_t)s;
                rng R = {mix64(d->seed * 0x9E3779B97F4A7C15u ^ mix64(pix + ((uint64_t)T->frame << 40)))};
                float o[3], dir[3];
                if (!camera_ray(c, x, y, spp, &R, o, dir)) {
                    T->res->samples_without_ray++;
                    continue;
                }
                if (T->had_ray) T->had_ray[(size_t)y * (size_t)c->width + (size_t)x] = 1;
                cbvh_trav_hit h;
                if (trace(T, CBVH_FX_PRIMARY, CBVH_TRAV_CLOSEST, o, dir, INFINITY, UINT32_MAX, -1, &h))
                    shade(T, &R, o, dir, &h, 0);
            }
    }
}

int cbvh_fx_run(const cbvh_scene_desc *d, const cbvh_fx_opts *o, cbvh_fx_result *r, char *err, size_t errlen) {
    memset(r, 0, sizeof *r);
    if (o->mant < CBVH_MANT_MIN || o->mant > CBVH_MANT_MAX) {
        snprintf(err, errlen, "--mant %d out of range %d..%d", o->mant, CBVH_MANT_MIN, CBVH_MANT_MAX);
        return -1;
    }
    tracer T = {.d = d, .o = o, .res = r};
    char spec[CBVH_FORMAT_NAME_MAX];
    if (cbvh_format_parse(o->format ? o->format : "float", &T.F, spec, sizeof spec, err, errlen)) return -1;
    r->frames = cbvh_scene_desc_frames(d);
    r->ntris = d->mesh.ntris;
    r->format_flags = T.F->flags;
    snprintf(r->format, sizeof r->format, "%s", spec);
    T.tris = malloc((size_t)d->mesh.ntris * sizeof *T.tris);
    if (!T.tris) cbvh_out_of_memory("frame triangles");
    cbvh_scene_desc_frame(d, 0, T.tris);
    cbvh_scene frame0 = d->mesh;
    frame0.tris = T.tris;
    float lo[3], hi[3];
    cbvh_scene_bounds(&frame0, lo, hi);
    float dg[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    T.eps = 1e-4f * sqrtf(dot3(dg, dg));
    if (!(T.eps > 0)) T.eps = 1e-6f;
    /* What the rays will be: camera rays from within the lens around the
     * position; a pinhole camera's through the formula of camera_ray. */
    const cbvh_camera *c = &d->camera;
    cbvh_format_pinhole pin = {c->width, c->height, {c->position[0], c->position[1], c->position[2]}, pinhole_dir, c};
    cbvh_format_input in = {.spec = spec,
                            .p = {o->params, o->mant, o->one_sided, o->box_unit, o->texp},
                            .scene = &frame0,
                            .eps = T.eps,
                            .pinhole = c->type == CBVH_CAM_PINHOLE ? &pin : NULL};
    for (int a = 0; a < 3; a++) in.origin_max = fmaxf(in.origin_max, fabsf(c->position[a]) + fabsf(c->aperture));
    int rc = -1;
    cbvh_memsim mem;
    if (o->ncaches > 0) {
        if (cbvh_memsim_init(&mem, o->cache_kb, o->ncaches, o->cache_ways > 0 ? (uint32_t)o->cache_ways : 8u, o->steps,
                             err, errlen)) {
            free(T.tris);
            return -1;
        }
        T.mem = &mem;
        r->ncaches = o->ncaches;
        memcpy(r->cache_kb, o->cache_kb, (size_t)o->ncaches * sizeof *o->cache_kb);
    }
    double b0 = cpu_now();
    if (T.F->build(&in, &T.state, &r->units, err, errlen)) {
        if (T.mem) cbvh_memsim_free(T.mem);
        free(T.tris);
        return -1;
    }
    r->node_bytes = T.F->bytes(T.state);
    r->build_cpu_seconds = cpu_now() - b0;
    size_t npx = (size_t)c->width * (size_t)c->height;
    if (c->type == CBVH_CAM_FISHEYE) { /* only a fisheye leaves pixels without a ray */
        T.had_ray = calloc(npx, 1);
        if (!T.had_ray) cbvh_out_of_memory("fisheye pixel map");
    }
    if (T.mem) cbvh_trav_set_observer(&T.mem->obs);
    for (T.frame = 0; T.frame < r->frames; T.frame++) {
        if (T.frame > 0) {
            /* Animation: move the vertices and refit (never for a static scene). */
            cbvh_scene_desc_frame(d, T.frame, T.tris);
            double t0 = cpu_now();
            if (T.F->refit(T.state, T.tris, &r->units, err, errlen)) goto out;
            r->build_cpu_seconds += cpu_now() - t0;
            r->refits++;
        }
        trace_frame(&T);
    }
    for (size_t p = 0; T.had_ray && p < npx; p++) r->pixels_without_ray += !T.had_ray[p];
    cbvh_fx_stats total = cbvh_fx_total(r);
    T.F->units(&total.st, &r->units); /* the units the traversals ran */
    for (int e = 0; e < CBVH_FX_COUNT; e++) T.F->units(&r->fx[e].st, &r->fx[e].ops);
    rc = 0;
out:
    if (T.mem) {
        cbvh_trav_set_observer(NULL);
        cbvh_memsim_free(T.mem);
    }
    free(T.had_ray);
    T.F->free(T.state);
    free(T.tris);
    return rc;
}

cbvh_fx_stats cbvh_fx_total(const cbvh_fx_result *r) {
    cbvh_fx_stats t = {0};
    for (int e = 0; e < CBVH_FX_COUNT; e++) cbvh_fx_stats_add(&t, &r->fx[e]);
    return t;
}

void cbvh_fx_timing(const cbvh_scene_desc *d, cbvh_timing_params *tp) {
    cbvh_timing_defaults(tp);
    const cbvh_timing_overrides *o = &d->timing;
    const double *src[] = {&o->box_cycles, &o->tri_cycles, &o->fetch_latency, &o->dram_bytes_per_cycle,
                           &o->clock_mhz, &o->rays_in_flight, &o->cache_hit_latency, &o->cache_ways,
                           &o->unit_cycle_scale, &o->dram_pj_per_byte, &o->sram_pj_per_word, &o->issue_width};
    double *dst[] = {&tp->box_cycles, &tp->tri_cycles, &tp->fetch_latency, &tp->dram_bytes_per_cycle,
                     &tp->clock_mhz, &tp->rays_in_flight, &tp->cache_hit_latency, &tp->cache_ways,
                     &tp->unit_cycle_scale, &tp->dram_pj_per_byte, &tp->sram_pj_per_word, &tp->issue_width};
    for (size_t i = 0; i < sizeof src / sizeof src[0]; i++)
        if (!isnan(*src[i])) *dst[i] = *src[i];
}

int cbvh_fx_add_rep(cbvh_fx_result *main, const cbvh_fx_result *rep) {
    if (rep->hit_digest != main->hit_digest) return -1;
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        cbvh_fx_stats *s = &main->fx[e];
        if (rep->fx[e].rays != s->rays) return -1;
    }
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        cbvh_fx_stats *s = &main->fx[e];
        if (s->nreps < CBVH_REPS_MAX) s->cpu_rep[s->nreps++] = rep->fx[e].cpu_seconds;
    }
    return 0;
}

const cbvh_box_unit cbvh_box_units[CBVH_BOX_UNITS] = {{"exact", "ray_box"}, {"incremental", "ray_box_incr"}};

int cbvh_fx_units(const cbvh_fx_result *r, const cbvh_cost_table *t, const cbvh_timing_params *tp,
                  const char *box_unit, int n, int m, cbvh_timing_units *u, char *err, size_t errlen) {
    cbvh_fx_stats s = cbvh_fx_total(r);
    const char *node = s.ops.ray_sphere || strncmp(r->format, "tlist", 5) == 0 ? "ray_sphere" : box_unit;
    return cbvh_timing_units_for(t, tp, node, (r->format_flags & CBVH_FORMAT_USES_N) != 0,
                                 (r->format_flags & CBVH_FORMAT_STACK_UNIT) != 0, n, m, u, err, errlen);
}

