/* Effects -> rays, traced with the units of the chosen format
 * (docs/scenes.md).  Ray generation is host-side float math (it is not a
 * hardware unit); the traversal and every count come from the bit-exact
 * model. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include "trace/effects.h"

#include <ctype.h>
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

/* ---- the accelerator: float BVH, CBVH, QBVH or traversal lists ---- */
typedef struct {
    const cbvh_scene_desc *d;
    const cbvh_fx_opts *o;
    cbvh_fx_result *res;
    cbvh_bvh bvh;
    cbvh_tree tree;
    int have_tree;
    cbvh_qbvh qbvh;
    int have_qbvh;
    cbvh_bsh bsh;
    cbvh_tlists tl;
    int have_tl;
    uint32_t *cell_head; /* pinhole primary rays: per screen cell, per list */
    int cell_w, cell_h;  /* cell size in pixels */
    cbvh_tri *tris; /* current frame */
    float eps;      /* secondary-ray origin offset along the normal */
    int frame;
    int px, py;     /* pixel being traced (for observers) */
    uint8_t *had_ray; /* fisheye: per pixel, 1 once a sample made a camera ray (any frame) */
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

/* Where a ray starts in list l (docs/tlist.md §7): a camera ray of a pinhole
 * camera at its screen cell's head; a secondary ray at its source triangle's
 * head when it leaves on the front side; else the list's start. */
static uint32_t tlist_head(const tracer *T, const cbvh_ray *r, int l, uint32_t src) {
    const cbvh_tlists *L = &T->tl;
    if (src == UINT32_MAX) {
        if (!T->cell_head) return 0;
        int cx = T->px / T->cell_w, cy = T->py / T->cell_h, ncx = (T->d->camera.width + T->cell_w - 1) / T->cell_w;
        return T->cell_head[((size_t)cy * (size_t)ncx + (size_t)cx) * CBVH_TLIST_MAX + (size_t)l];
    }
    return T->o->tlist.poly_heads ? cbvh_tlist_poly_head(L, l, src, T->tris, r) : 0;
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
    double clk = ray_clock_overhead(), t0 = ray_clock();
    int rc;
    if (T->o->format == CBVH_FORMAT_TLIST) {
        int l = cbvh_tlist_pick(&T->tl, &r);
        rc = cbvh_trace_tlist(&T->tl, l, tlist_head(T, &r, l, src), T->tris, &r, tm, hit, &st);
    } else
        rc = T->o->format == CBVH_FORMAT_CBVH ? cbvh_trace_cbvh(&T->tree, T->tris, &r, T->o->mant, tm, hit, &st)
             : T->o->format == CBVH_FORMAT_QBVH
                 ? cbvh_trace_qbvh(&T->qbvh, T->tris, &r, T->o->mant, tm, CBVH_QSTACK_COMPRESSED, hit, &st)
                 : cbvh_trace_bvh(&T->bvh, T->tris, &r, T->o->mant, tm, hit, &st);
    double dt = ray_clock() - t0 - clk;
    cbvh_fx_stats *s = &T->res->fx[fx];
    s->cpu_seconds += dt > 0 ? dt : 0;
    s->rays++;
    if (mode & CBVH_TRAV_ANY)
        s->any++;
    else
        s->closest++;
    if (rc) {
        s->rejected++;
        memset(hit, 0, sizeof *hit);
    }
    s->hits += hit->hit != 0;
    s->st.nodes += st.nodes;
    s->st.box_tests += st.box_tests;
    s->st.tri_tests += st.tri_tests;
    s->st.lines += st.lines;
    s->st.bytes += st.bytes;
    if (st.max_stack > s->st.max_stack) s->st.max_stack = st.max_stack;
    s->st.qstack_pushes += st.qstack_pushes;
    s->st.qstack_pops += st.qstack_pops;
    cbvh_unit_activity *u = &T->res->units;
    if (T->o->format == CBVH_FORMAT_TLIST)
        u->ray_sphere += st.box_tests; /* the lists' "box tests" are sphere tests */
    else
        u->ray_box += st.box_tests;
    u->ray_triangle += st.tri_tests;
    if (T->o->format == CBVH_FORMAT_CBVH) u->decoder += 6 * st.nodes;
    u->qbvh_stack += st.qstack_pushes + st.qstack_pops;
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
 * formula of camera_ray). */
static void pinhole_dir(const cbvh_camera *c, float px, float py, float dir[3]) {
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

static int compress(tracer *T, const cbvh_tri *refit, char *err, size_t errlen) {
    cbvh_compress_opts co = {T->o->params, CBVH_ENC_MODULO, 1, 0};
    cbvh_tree nt;
    cbvh_bu_stats bs;
    if (cbvh_compress_bottomup(&T->bvh, refit, &co, &nt, &bs, err, errlen)) return -1;
    if (T->have_tree) cbvh_tree_free(&T->tree);
    T->tree = nt;
    T->have_tree = 1;
    T->res->units.compressor += 6 * (bs.encodes + bs.reencodes) + 3;
    return 0;
}

/* Refit of the QBVH's own boxes, keeping its topology: nodes are laid out
 * breadth-first (children after their parent), so one pass from the last
 * node to the root sees every child before its parent.  Returns the number
 * of node boxes recomputed. */
static uint64_t qbvh_refit(cbvh_qbvh *q, const cbvh_tri *tris) {
    for (uint32_t i = q->nnodes; i-- > 0;) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        uint32_t c = q->count[i], f = q->first[i];
        if (c & CBVH_QBVH_LEAF) {
            for (uint32_t k = 0; k < (c & ~CBVH_QBVH_LEAF); k++)
                for (int v = 0; v < 3; v++)
                    for (int a = 0; a < 3; a++) {
                        float x = tris[q->prims[f + k]].v[v][a];
                        lo[a] = fminf(lo[a], x);
                        hi[a] = fmaxf(hi[a], x);
                    }
        } else
            for (uint32_t k = 0; k < c; k++)
                for (int a = 0; a < 3; a++) {
                    lo[a] = fminf(lo[a], q->bmin[f + k][a]);
                    hi[a] = fmaxf(hi[a], q->bmax[f + k][a]);
                }
        for (int a = 0; a < 3; a++) {
            q->bmin[i][a] = lo[a];
            q->bmax[i][a] = hi[a];
        }
    }
    return q->nnodes;
}

/* The refit relies on children lying after their parent (breadth-first). */
static int qbvh_children_after_parent(const cbvh_qbvh *q) {
    for (uint32_t i = 0; i < q->nnodes; i++)
        if (!(q->count[i] & CBVH_QBVH_LEAF) && q->first[i] <= i) return 0;
    return 1;
}

const char *cbvh_format_name(cbvh_accel_format f) {
    return f == CBVH_FORMAT_CBVH ? "cbvh" : f == CBVH_FORMAT_QBVH ? "qbvh" : f == CBVH_FORMAT_TLIST ? "tlist" : "float";
}

int cbvh_tlist_opts_parse(const char *s, cbvh_tlist_opts *t, char *err, size_t errlen) {
    memset(t, 0, sizeof *t);
    t->p.nlists = 6;
    t->p.order = CBVH_TLIST_EARLIEST_FIRST;
    char buf[128];
    if (strncmp(s, "tlist", 5) != 0 || (s[5] && s[5] != ':') || strlen(s) >= sizeof buf) {
        snprintf(err, errlen, "format '%s': expected tlist[:1|2|6|8][:earliest|:latest][:cull][:heads]", s);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", s + 5);
    /* Split on ':' by hand: callers may be inside their own strtok loop.  Each
     * group (count, order, cull, heads) at most once: "tlist:6:2" would
     * otherwise silently mean 2. */
    int seen[4] = {0, 0, 0, 0};
    for (char *k = buf[0] ? buf + 1 : NULL, *next; k; k = next) {
        next = strchr(k, ':');
        if (next) *next++ = 0;
        int group = isdigit((unsigned char)k[0]) ? 0 : strcmp(k, "earliest") == 0 || strcmp(k, "latest") == 0 ? 1
                    : strcmp(k, "cull") == 0                                                             ? 2
                    : strcmp(k, "heads") == 0                                                            ? 3
                                                                                                           : -1;
        if (group >= 0 && seen[group]++) {
            static const char *const what[4] = {"a list count", "an order", "cull", "heads"};
            snprintf(err, errlen, "format '%s': %s given twice", s, what[group]);
            return -1;
        }
        if (strcmp(k, "1") == 0 || strcmp(k, "2") == 0 || strcmp(k, "6") == 0 || strcmp(k, "8") == 0)
            t->p.nlists = k[0] - '0';
        else if (strcmp(k, "earliest") == 0)
            t->p.order = CBVH_TLIST_EARLIEST_FIRST;
        else if (strcmp(k, "latest") == 0)
            t->p.order = CBVH_TLIST_LATEST_LAST;
        else if (strcmp(k, "cull") == 0)
            t->p.cull_back = 1;
        else if (strcmp(k, "heads") == 0)
            t->poly_heads = t->cell_heads = 1;
        else {
            snprintf(err, errlen, "format '%s': unknown tlist option '%s' (lists 1|2|6|8, earliest|latest, cull, heads)",
                     s, k);
            return -1;
        }
    }
    return 0;
}

void cbvh_tlist_opts_name(const cbvh_tlist_opts *t, char *out, size_t n) {
    snprintf(out, n, "tlist:%d:%s%s%s", t->p.nlists ? t->p.nlists : 6,
             t->p.order == CBVH_TLIST_LATEST_LAST ? "latest" : "earliest", t->p.cull_back ? ":cull" : "",
             t->poly_heads || t->cell_heads ? ":heads" : "");
}

/* Per-screen-cell heads for a pinhole camera: the image split into at most
 * 16 x 16 cells, each cell's primary rays bounded by the cone of its four
 * corner directions (widened by 2^-16 rad for the float rounding of pixel
 * directions). */
static int build_cell_heads(tracer *T, char *err, size_t errlen) {
    const cbvh_camera *c = &T->d->camera;
    free(T->cell_head);
    T->cell_head = NULL;
    if (!T->o->tlist.cell_heads || c->type != CBVH_CAM_PINHOLE) return 0;
    T->cell_w = (c->width + 15) / 16;
    T->cell_h = (c->height + 15) / 16;
    int ncx = (c->width + T->cell_w - 1) / T->cell_w, ncy = (c->height + T->cell_h - 1) / T->cell_h;
    T->cell_head = calloc((size_t)ncx * (size_t)ncy * CBVH_TLIST_MAX, sizeof *T->cell_head);
    if (!T->cell_head) cbvh_out_of_memory("tile lists");
    for (int cy = 0; cy < ncy; cy++)
        for (int cx = 0; cx < ncx; cx++) {
            int x0 = cx * T->cell_w, y0 = cy * T->cell_h;
            int x1 = x0 + T->cell_w < c->width ? x0 + T->cell_w : c->width;
            int y1 = y0 + T->cell_h < c->height ? y0 + T->cell_h : c->height;
            float corner[4][3];
            const float X[4] = {(float)x0, (float)x1, (float)x1, (float)x0}, Y[4] = {(float)y0, (float)y0, (float)y1, (float)y1};
            for (int k = 0; k < 4; k++) pinhole_dir(c, X[k] / (float)c->width, Y[k] / (float)c->height, corner[k]);
            if (cbvh_tlist_cell_heads(&T->tl, T->tris, c->position, corner, 0x1p-16,
                                      &T->cell_head[((size_t)cy * (size_t)ncx + (size_t)cx) * CBVH_TLIST_MAX])) {
                snprintf(err, errlen, "tlist: cannot compute the screen-cell heads (non-finite camera)");
                return -1;
            }
        }
    return 0;
}

/* (Re)builds the sphere hierarchy and the lists for the current frame. */
static int build_tlists(tracer *T, char *err, size_t errlen) {
    if (T->have_tl) {
        cbvh_tlists_free(&T->tl);
        cbvh_bsh_free(&T->bsh);
        T->have_tl = 0;
    }
    cbvh_scene sc = T->d->mesh;
    sc.tris = T->tris;
    sc.nmorph = 0;
    sc.nkeys = 0;
    int nlists = T->o->tlist.p.nlists ? T->o->tlist.p.nlists : 6;
    /* Per-polygon heads cost about 2-10 us per triangle and list to
     * precompute; past this size that is many minutes: refuse up front. */
    if (T->o->tlist.poly_heads && (uint64_t)sc.ntris * (uint64_t)nlists > CBVH_FX_POLY_HEADS_MAX) {
        snprintf(err, errlen,
                 "tlist: per-polygon heads for %u triangles x %d lists exceed the limit of %llu (minutes of "
                 "precomputation); drop ':heads' or use fewer lists",
                 sc.ntris, nlists, (unsigned long long)CBVH_FX_POLY_HEADS_MAX);
        return -1;
    }
    cbvh_bsh_params bp;
    cbvh_bsh_default_params(&bp);
    if (cbvh_bsh_build(&sc, &bp, &T->bsh, err, errlen)) return -1;
    cbvh_tlist_params lp = T->o->tlist.p;
    lp.nlists = nlists;
    if (cbvh_tlists_build(&T->bsh, &sc, &lp, &T->tl, err, errlen)) {
        cbvh_bsh_free(&T->bsh);
        return -1;
    }
    T->have_tl = 1;
    if (T->o->tlist.poly_heads) {
        /* Secondary rays start at q = hit point + eps n: the margin covers eps
         * and the hit point's rounding (docs/tlist.md §7.1). */
        const cbvh_camera *c = &T->d->camera;
        float cmax = 0;
        for (uint32_t i = 0; i < sc.ntris; i++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) cmax = fmaxf(cmax, fabsf(sc.tris[i].v[v][a]));
        cmax += T->eps;
        for (int a = 0; a < 3; a++) cmax = fmaxf(cmax, fabsf(c->position[a]) + fabsf(c->aperture));
        float margin = cbvh_tlist_hitpoint_margin(T->eps, cmax);
        if (!isfinite(margin)) { /* coordinates near FLT_MAX: no binary32 margin covers the hit points */
            snprintf(err, errlen,
                     "tlist heads: coordinates up to %g leave no finite margin for the per-polygon heads "
                     "(docs/tlist.md 7.1); trace without :heads",
                     (double)cmax);
            return -1;
        }
        if (cbvh_tlists_poly_heads(&T->tl, T->tris, CBVH_TLIST_HEADS_REGULAR, margin, err, errlen)) return -1;
    }
    return build_cell_heads(T, err, errlen);
}

int cbvh_fx_run(const cbvh_scene_desc *d, const cbvh_fx_opts *o, cbvh_fx_result *r, char *err, size_t errlen) {
    memset(r, 0, sizeof *r);
    if (o->mant < CBVH_MANT_MIN || o->mant > CBVH_MANT_MAX) {
        snprintf(err, errlen, "--mant %d out of range %d..%d", o->mant, CBVH_MANT_MIN, CBVH_MANT_MAX);
        return -1;
    }
    if (o->format == CBVH_FORMAT_CBVH && cbvh_params_check(&o->params)) {
        snprintf(err, errlen, "bad CBVH parameters N=%d min_scale=%d (N in %d..%d, min_scale in %d..%d)",
                 o->params.quant_bits, o->params.min_scale, CBVH_N_MIN, CBVH_N_MAX, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL);
        return -1;
    }
    tracer T = {.d = d, .o = o, .res = r};
    r->frames = cbvh_scene_desc_frames(d);
    r->ntris = d->mesh.ntris;
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
    int rc = -1;
    double b0 = cpu_now();
    if (o->format != CBVH_FORMAT_TLIST && cbvh_build_sah(&frame0, 0, 0, &T.bvh, err, errlen)) {
        free(T.tris);
        return -1;
    }
    if (o->format == CBVH_FORMAT_CBVH) {
        if (compress(&T, NULL, err, errlen)) goto out;
        r->node_bytes = cbvh_tree_bytes(&T.tree);
    } else if (o->format == CBVH_FORMAT_QBVH) {
        if (cbvh_qbvh_from_bvh(&T.bvh, &T.qbvh, err, errlen)) goto out;
        T.have_qbvh = 1;
        if (cbvh_qbvh_stack_check(&T.qbvh, CBVH_QSTACK_COMPRESSED, err, errlen)) goto out;
        if (!qbvh_children_after_parent(&T.qbvh)) {
            snprintf(err, errlen, "qbvh: a child group lies before its parent (layout not breadth-first)");
            goto out;
        }
        r->node_bytes = cbvh_qbvh_node_bytes(&T.qbvh) + (uint64_t)T.qbvh.nprims * 4u;
    } else if (o->format == CBVH_FORMAT_TLIST) {
        if (o->tlist.p.cull_back && !o->one_sided) {
            snprintf(err, errlen, "tlist: back-face culling needs one-sided triangles (--one-sided)");
            goto out;
        }
        if (build_tlists(&T, err, errlen)) goto out;
        r->node_bytes = cbvh_tlists_bytes(&T.tl);
    } else
        r->node_bytes = cbvh_bvh_bytes(&T.bvh);
    r->build_cpu_seconds = cpu_now() - b0;
    size_t npx = (size_t)d->camera.width * (size_t)d->camera.height;
    if (d->camera.type == CBVH_CAM_FISHEYE) { /* only a fisheye leaves pixels without a ray */
        T.had_ray = calloc(npx, 1);
        if (!T.had_ray) cbvh_out_of_memory("fisheye pixel map");
    }
    for (T.frame = 0; T.frame < r->frames; T.frame++) {
        if (T.frame > 0) {
            /* Animation: move the vertices and refit (never for a static scene). */
            cbvh_scene_desc_frame(d, T.frame, T.tris);
            double t0 = cpu_now();
            if (o->format == CBVH_FORMAT_CBVH) {
                if (compress(&T, T.tris, err, errlen)) goto out; /* streaming refit */
                r->units.refit += T.bvh.nnodes;
            } else if (o->format == CBVH_FORMAT_QBVH)
                r->units.refit += qbvh_refit(&T.qbvh, T.tris); /* the QBVH's boxes, same topology */
            else if (o->format == CBVH_FORMAT_TLIST) {
                if (build_tlists(&T, err, errlen)) goto out; /* lists are not updatable: rebuilt */
                r->units.refit += T.bsh.nnodes;
            } else {
                cbvh_bvh_refit(&T.bvh, T.tris);
                r->units.refit += T.bvh.nnodes;
            }
            r->build_cpu_seconds += cpu_now() - t0;
            r->refits++;
        }
        trace_frame(&T);
    }
    for (size_t p = 0; T.had_ray && p < npx; p++) r->pixels_without_ray += !T.had_ray[p];
    rc = 0;
out:
    free(T.had_ray);
    if (T.have_tree) cbvh_tree_free(&T.tree);
    if (T.have_qbvh) cbvh_qbvh_free(&T.qbvh);
    if (T.have_tl) {
        cbvh_tlists_free(&T.tl);
        cbvh_bsh_free(&T.bsh);
    }
    free(T.cell_head);
    cbvh_bvh_free(&T.bvh);
    free(T.tris);
    return rc;
}

cbvh_fx_stats cbvh_fx_total(const cbvh_fx_result *r) {
    cbvh_fx_stats t = {0};
    for (int e = 0; e < CBVH_FX_COUNT; e++) {
        const cbvh_fx_stats *s = &r->fx[e];
        t.rays += s->rays;
        t.closest += s->closest;
        t.any += s->any;
        t.hits += s->hits;
        t.rejected += s->rejected;
        t.st.nodes += s->st.nodes;
        t.st.box_tests += s->st.box_tests;
        t.st.tri_tests += s->st.tri_tests;
        t.st.lines += s->st.lines;
        t.st.bytes += s->st.bytes;
        if (s->st.max_stack > t.st.max_stack) t.st.max_stack = s->st.max_stack;
        t.st.qstack_pushes += s->st.qstack_pushes;
        t.st.qstack_pops += s->st.qstack_pops;
        t.cpu_seconds += s->cpu_seconds;
    }
    return t;
}

void cbvh_fx_timing(const cbvh_scene_desc *d, cbvh_timing_params *tp) {
    cbvh_timing_defaults(tp);
    const cbvh_timing_overrides *o = &d->timing;
    if (!isnan(o->box_cycles)) tp->box_cycles = o->box_cycles;
    if (!isnan(o->tri_cycles)) tp->tri_cycles = o->tri_cycles;
    if (!isnan(o->fetch_latency)) tp->fetch_latency = o->fetch_latency;
    if (!isnan(o->dram_bytes_per_cycle)) tp->dram_bytes_per_cycle = o->dram_bytes_per_cycle;
    if (!isnan(o->clock_mhz)) tp->clock_mhz = o->clock_mhz;
}

