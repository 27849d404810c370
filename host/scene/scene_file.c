/* Scene-file parser (docs/scenes.md): JSON through cJSON, strict about every
 * field (unknown keys are errors too, so a typo never silently drops an
 * effect). */
#include "scene/scene_file.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "cbvh/oom.h"
#include "scene/scene_load.h"
#include "trace/timing_model.h"
#include "util/json.h"

static const char *const fx_names[CBVH_FX_COUNT] = {"primary",          "hard_shadows", "soft_shadows",
                                                    "ambient_occlusion", "mirror",       "diffuse_bounce"};

const char *cbvh_effect_name(cbvh_effect e) { return (unsigned)e < CBVH_FX_COUNT ? fx_names[e] : "?"; }

typedef struct {
    const char *path;
    char *err;
    size_t errlen;
} pctx;

static int fail(pctx *c, const char *field, const char *fmt, ...) {
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (field && *field)
        snprintf(c->err, c->errlen, "%s: %s: %s", c->path, field, msg);
    else
        snprintf(c->err, c->errlen, "%s: %s", c->path, msg);
    /* one line, whatever a key or string in the file holds (a key may
     * contain "\n": found by fuzz_scene_file) */
    for (char *p = c->err; *p; p++)
        if ((unsigned char)*p < 0x20 || *p == 0x7F) *p = '?';
    return -1;
}

/* Every key of obj must be in the NULL-terminated list, and appear once (cJSON
 * keeps both copies of a repeated key and lookups see the first: the second
 * would be silently ignored). */
static int check_keys(pctx *c, const cJSON *obj, const char *field, const char *const *allowed) {
    const cJSON *it;
    cJSON_ArrayForEach(it, obj) {
        int ok = 0;
        for (const char *const *a = allowed; *a; a++)
            if (strcmp(*a, it->string) == 0) ok = 1;
        char f[160];
        snprintf(f, sizeof f, "%s%s%s", field, *field ? "." : "", it->string);
        if (!ok) return fail(c, f, "unknown field");
        for (const cJSON *p = obj->child; p != it; p = p->next)
            if (strcmp(p->string, it->string) == 0) return fail(c, f, "given twice");
    }
    return 0;
}

static void fieldname(char *buf, size_t n, const char *parent, const char *key) {
    snprintf(buf, n, "%s%s%s", parent, *parent ? "." : "", key);
}

/* Optional number in [lo, hi] (open ends with lo_open/hi_open). */
static int get_num(pctx *c, const cJSON *obj, const char *parent, const char *key, double lo, int lo_open, double hi,
                   double *v, int required) {
    char f[160];
    fieldname(f, sizeof f, parent, key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return required ? fail(c, f, "missing") : 0;
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
        return fail(c, f, "expected a number %s%g, %g]", lo_open ? "in (" : "in [", lo, hi);
    double x = it->valuedouble;
    if (x < lo || (lo_open && x == lo) || x > hi) {
        /* The first of %.6g .. %.17g that reads back as x: %.9g printed
         * 179.0000001 as 179, a value the message then called out of range (0, 179]. */
        char xs[32];
        for (int prec = 6; prec <= 17; prec++) {
            snprintf(xs, sizeof xs, "%.*g", prec, x);
            if (strtod(xs, NULL) == x) break;
        }
        return fail(c, f, "%s is out of range %s%g, %g]", xs, lo_open ? "(" : "[", lo, hi);
    }
    *v = x;
    return 1;
}

static int get_int(pctx *c, const cJSON *obj, const char *parent, const char *key, long lo, long hi, int *v,
                   int required) {
    char f[160];
    fieldname(f, sizeof f, parent, key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return required ? fail(c, f, "missing") : 0;
    if (!cJSON_IsNumber(it) || it->valuedouble != floor(it->valuedouble) || it->valuedouble < lo ||
        it->valuedouble > hi)
        return fail(c, f, "expected an integer in %ld..%ld", lo, hi);
    *v = (int)it->valuedouble;
    return 1;
}

static int get_vec3(pctx *c, const cJSON *obj, const char *parent, const char *key, float v[3], int required) {
    char f[160];
    fieldname(f, sizeof f, parent, key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return required ? fail(c, f, "missing") : 0;
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 3) return fail(c, f, "expected [x, y, z]");
    for (int a = 0; a < 3; a++) {
        const cJSON *e = cJSON_GetArrayItem(it, a);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
            return fail(c, f, "expected [x, y, z] of finite numbers");
        v[a] = (float)e->valuedouble;
    }
    return 1;
}

static const char *get_str(pctx *c, const cJSON *obj, const char *parent, const char *key, int required, int *rc) {
    char f[160];
    fieldname(f, sizeof f, parent, key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    *rc = 0;
    if (!it) {
        if (required) *rc = fail(c, f, "missing");
        return NULL;
    }
    if (!cJSON_IsString(it) || !it->valuestring[0]) {
        *rc = fail(c, f, "expected a non-empty string");
        return NULL;
    }
    return it->valuestring;
}

static float len3(const float v[3]) { return sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

static int parse_camera(pctx *c, const cJSON *cam, cbvh_scene_desc *d) {
    static const char *const keys[] = {"type", "width", "height", "position", "target", "up", "fov",
                                       "aperture", "focus_distance", "spp", NULL};
    cbvh_camera *k = &d->camera;
    if (!cJSON_IsObject(cam)) return fail(c, "camera", "expected an object");
    if (check_keys(c, cam, "camera", keys)) return -1;
    int rc;
    const char *type = get_str(c, cam, "camera", "type", 0, &rc);
    if (rc) return -1;
    k->type = CBVH_CAM_PINHOLE;
    if (type) {
        if (strcmp(type, "pinhole") == 0)
            k->type = CBVH_CAM_PINHOLE;
        else if (strcmp(type, "thin_lens") == 0)
            k->type = CBVH_CAM_THIN_LENS;
        else if (strcmp(type, "fisheye") == 0)
            k->type = CBVH_CAM_FISHEYE;
        else
            return fail(c, "camera.type", "unknown camera '%s' (pinhole, thin_lens, fisheye)", type);
    }
    k->width = 64;
    k->height = 48;
    k->spp = 1;
    if (get_int(c, cam, "camera", "width", 1, 4096, &k->width, 0) < 0) return -1;
    if (get_int(c, cam, "camera", "height", 1, 4096, &k->height, 0) < 0) return -1;
    if (get_int(c, cam, "camera", "spp", 1, 1024, &k->spp, 0) < 0) return -1;
    if (get_vec3(c, cam, "camera", "position", k->position, 1) < 0) return -1;
    if (get_vec3(c, cam, "camera", "target", k->target, 1) < 0) return -1;
    k->up[0] = 0, k->up[1] = 1, k->up[2] = 0;
    if (get_vec3(c, cam, "camera", "up", k->up, 0) < 0) return -1;
    float fwd[3] = {k->target[0] - k->position[0], k->target[1] - k->position[1], k->target[2] - k->position[2]};
    float fl = len3(fwd);
    if (!(fl > 0)) return fail(c, "camera.target", "equals camera.position (no view direction)");
    float cr[3] = {fwd[1] * k->up[2] - fwd[2] * k->up[1], fwd[2] * k->up[0] - fwd[0] * k->up[2],
                   fwd[0] * k->up[1] - fwd[1] * k->up[0]};
    if (!(len3(cr) > 1e-6f * fl * len3(k->up))) return fail(c, "camera.up", "zero or parallel to the view direction");
    double fov = k->type == CBVH_CAM_FISHEYE ? 180.0 : 45.0;
    if (get_num(c, cam, "camera", "fov", 0, 1, k->type == CBVH_CAM_FISHEYE ? 360.0 : 179.0, &fov, 0) < 0) return -1;
    k->fov = (float)fov;
    double ap = 0, fd = fl;
    int has_ap = get_num(c, cam, "camera", "aperture", 0, 1, 1e30, &ap, k->type == CBVH_CAM_THIN_LENS);
    if (has_ap < 0) return -1;
    int has_fd = get_num(c, cam, "camera", "focus_distance", 0, 1, 1e30, &fd, 0);
    if (has_fd < 0) return -1;
    if (k->type != CBVH_CAM_THIN_LENS && (has_ap || has_fd))
        return fail(c, has_ap ? "camera.aperture" : "camera.focus_distance", "only for \"type\": \"thin_lens\"");
    k->aperture = (float)ap;
    k->focus_distance = (float)fd;
    return 0;
}

static int parse_lights(pctx *c, const cJSON *arr, cbvh_scene_desc *d) {
    if (!cJSON_IsArray(arr)) return fail(c, "lights", "expected an array");
    int i = 0;
    const cJSON *l;
    cJSON_ArrayForEach(l, arr) {
        char f[64];
        snprintf(f, sizeof f, "lights[%d]", i);
        if (i >= CBVH_MAX_LIGHTS) return fail(c, f, "too many lights (at most %d)", CBVH_MAX_LIGHTS);
        if (!cJSON_IsObject(l)) return fail(c, f, "expected an object");
        static const char *const keys[] = {"type", "position", "u", "v", NULL};
        if (check_keys(c, l, f, keys)) return -1;
        cbvh_light *L = &d->lights[i];
        int rc;
        const char *type = get_str(c, l, f, "type", 1, &rc);
        if (rc) return -1;
        char tf[80];
        snprintf(tf, sizeof tf, "%s.type", f);
        if (strcmp(type, "point") == 0)
            L->type = CBVH_LIGHT_POINT;
        else if (strcmp(type, "area") == 0)
            L->type = CBVH_LIGHT_AREA;
        else
            return fail(c, tf, "unknown light '%s' (point, area)", type);
        if (get_vec3(c, l, f, "position", L->position, 1) < 0) return -1;
        int need = L->type == CBVH_LIGHT_AREA;
        int hu = get_vec3(c, l, f, "u", L->u, need), hv = hu < 0 ? -1 : get_vec3(c, l, f, "v", L->v, need);
        if (hu < 0 || hv < 0) return -1;
        if (!need && (hu || hv)) return fail(c, f, "u/v only for \"type\": \"area\"");
        if (need) {
            float n[3] = {L->u[1] * L->v[2] - L->u[2] * L->v[1], L->u[2] * L->v[0] - L->u[0] * L->v[2],
                          L->u[0] * L->v[1] - L->u[1] * L->v[0]};
            if (!(len3(n) > 0)) return fail(c, f, "u and v span no area");
        }
        i++;
    }
    d->nlights = i;
    return 0;
}

static int find_material(const cbvh_scene_desc *d, const char *name) {
    for (int i = 0; i < d->nmaterials; i++)
        if (strcmp(d->materials[i].name, name) == 0) return i;
    return -1;
}

static int parse_materials(pctx *c, const cJSON *arr, cbvh_scene_desc *d) {
    if (!cJSON_IsArray(arr)) return fail(c, "materials", "expected an array");
    int i = 0;
    const cJSON *m;
    cJSON_ArrayForEach(m, arr) {
        char f[64];
        snprintf(f, sizeof f, "materials[%d]", i);
        if (i >= CBVH_MAX_MATERIALS) return fail(c, f, "too many materials (at most %d)", CBVH_MAX_MATERIALS);
        if (!cJSON_IsObject(m)) return fail(c, f, "expected an object");
        static const char *const keys[] = {"name", "type", NULL};
        if (check_keys(c, m, f, keys)) return -1;
        int rc;
        const char *name = get_str(c, m, f, "name", 1, &rc);
        if (rc) return -1;
        if (strlen(name) >= sizeof d->materials[i].name) return fail(c, f, "name longer than 31 characters");
        if (find_material(d, name) >= 0) return fail(c, f, "duplicate material name '%s'", name);
        const char *type = get_str(c, m, f, "type", 1, &rc);
        if (rc) return -1;
        cbvh_material *M = &d->materials[i];
        snprintf(M->name, sizeof M->name, "%s", name);
        if (strcmp(type, "diffuse") == 0)
            M->type = CBVH_MAT_DIFFUSE;
        else if (strcmp(type, "mirror") == 0)
            M->type = CBVH_MAT_MIRROR;
        else {
            char tf[80];
            snprintf(tf, sizeof tf, "%s.type", f);
            return fail(c, tf, "unknown material '%s' (diffuse, mirror)", type);
        }
        d->nmaterials = ++i;
    }
    if (i == 0) return fail(c, "materials", "empty");
    return 0;
}

static int effect_by_name(const char *s) {
    for (int e = 0; e < CBVH_FX_COUNT; e++)
        if (strcmp(s, fx_names[e]) == 0) return e;
    return -1;
}

static int parse_effects(pctx *c, const cJSON *arr, cbvh_scene_desc *d) {
    if (!cJSON_IsArray(arr)) return fail(c, "effects", "expected an array of effect names or objects");
    int i = 0;
    const cJSON *it;
    cJSON_ArrayForEach(it, arr) {
        char f[64];
        snprintf(f, sizeof f, "effects[%d]", i++);
        const char *name = NULL;
        if (cJSON_IsString(it))
            name = it->valuestring;
        else if (cJSON_IsObject(it)) {
            int rc;
            name = get_str(c, it, f, "effect", 1, &rc);
            if (rc) return -1;
        } else
            return fail(c, f, "expected an effect name or {\"effect\": NAME, ...}");
        int e = effect_by_name(name);
        if (e < 0)
            return fail(c, f,
                        "unknown effect '%s' (primary, hard_shadows, soft_shadows, ambient_occlusion, mirror, "
                        "diffuse_bounce)",
                        name);
        cbvh_effect_cfg *E = &d->effect[e];
        if (E->enabled) return fail(c, f, "effect '%s' listed twice", name);
        E->enabled = 1;
        E->samples = 1;
        E->max_depth = 1;
        E->distance = NAN; /* AO default set once the mesh is known */
        if (!cJSON_IsObject(it)) continue;
        /* Which options each effect takes. */
        static const char *const k_plain[] = {"effect", NULL};
        static const char *const k_samples[] = {"effect", "samples", NULL};
        static const char *const k_ao[] = {"effect", "samples", "distance", NULL};
        static const char *const k_mirror[] = {"effect", "max_depth", NULL};
        const char *const *keys = k_plain;
        if (e == CBVH_FX_SOFT_SHADOWS || e == CBVH_FX_DIFFUSE_BOUNCE) keys = k_samples;
        if (e == CBVH_FX_AMBIENT_OCCLUSION) keys = k_ao;
        if (e == CBVH_FX_MIRROR) keys = k_mirror;
        char ef[96];
        snprintf(ef, sizeof ef, "%s(%s)", f, name);
        if (check_keys(c, it, ef, keys)) return -1;
        if (get_int(c, it, ef, "samples", 1, 4096, &E->samples, 0) < 0) return -1;
        if (get_int(c, it, ef, "max_depth", 1, 16, &E->max_depth, 0) < 0) return -1;
        double dist;
        int hd = get_num(c, it, ef, "distance", 0, 1, 1e30, &dist, 0);
        if (hd < 0) return -1;
        if (hd) E->distance = (float)dist;
    }
    if (i == 0) return fail(c, "effects", "empty (name at least \"primary\")");
    if (!d->effect[CBVH_FX_PRIMARY].enabled)
        for (int e = 1; e < CBVH_FX_COUNT; e++)
            if (d->effect[e].enabled)
                return fail(c, "effects", "'%s' needs 'primary' (camera rays find the surfaces it starts from)",
                            fx_names[e]);
    return 0;
}

static int parse_animation(pctx *c, const cJSON *a, cbvh_scene_desc *d) {
    if (!cJSON_IsObject(a)) return fail(c, "animation", "expected an object");
    static const char *const keys[] = {"type", "frames", "time", "amount", "wave", NULL};
    if (check_keys(c, a, "animation", keys)) return -1;
    int rc;
    const char *type = get_str(c, a, "animation", "type", 1, &rc);
    if (rc) return -1;
    cbvh_animation *A = &d->anim;
    if (strcmp(type, "morph") == 0)
        A->type = CBVH_ANIM_MORPH;
    else if (strcmp(type, "twist") == 0)
        A->type = CBVH_ANIM_TWIST;
    else
        return fail(c, "animation.type", "unknown animation '%s' (morph, twist)", type);
    A->frames = 2;
    if (get_int(c, a, "animation", "frames", 2, 1000, &A->frames, 0) < 0) return -1;
    A->t0 = 0;
    A->t1 = 1;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(a, "time");
    if (t) {
        if (!cJSON_IsArray(t) || cJSON_GetArraySize(t) != 2 || !cJSON_IsNumber(cJSON_GetArrayItem(t, 0)) ||
            !cJSON_IsNumber(cJSON_GetArrayItem(t, 1)) || !isfinite(cJSON_GetArrayItem(t, 0)->valuedouble) ||
            !isfinite(cJSON_GetArrayItem(t, 1)->valuedouble) ||
            !(cJSON_GetArrayItem(t, 0)->valuedouble < cJSON_GetArrayItem(t, 1)->valuedouble))
            return fail(c, "animation.time", "expected [start, end] with start < end");
        A->t0 = (float)cJSON_GetArrayItem(t, 0)->valuedouble;
        A->t1 = (float)cJSON_GetArrayItem(t, 1)->valuedouble;
    }
    double amount = 0.5, wave = 0.02;
    int ha = get_num(c, a, "animation", "amount", -100, 0, 100, &amount, 0);
    if (ha < 0) return -1;
    int hw = get_num(c, a, "animation", "wave", 0, 0, 1, &wave, 0);
    if (hw < 0) return -1;
    if (A->type == CBVH_ANIM_MORPH && (ha || hw))
        return fail(c, ha ? "animation.amount" : "animation.wave", "only for \"type\": \"twist\"");
    A->amount = (float)amount;
    A->wave = (float)wave;
    return 0;
}

static int parse_timing(pctx *c, const cJSON *t, cbvh_scene_desc *d) {
    if (!cJSON_IsObject(t)) return fail(c, "timing", "expected an object");
    static const char *const keys[] = {"box_cycles",      "tri_cycles",        "fetch_latency",
                                       "dram_bytes_per_cycle", "clock_mhz",   "rays_in_flight",
                                       "cache_hit_latency", "cache_ways",     "unit_cycle_scale",
                                       "dram_pj_per_byte", "sram_pj_per_word", "issue_width", NULL};
    /* rates (bandwidth, clock, rays in flight, cycle scale) bounded away from 0 */
    static const double lo[] = {0, 0, 0, CBVH_TIMING_RATE_MIN, CBVH_TIMING_RATE_MIN, CBVH_TIMING_RATE_MIN, 0, 1,
                                CBVH_TIMING_RATE_MIN, 0, 0, 1};
    if (check_keys(c, t, "timing", keys)) return -1;
    cbvh_timing_overrides *o = &d->timing;
    double *dst[] = {&o->box_cycles,     &o->tri_cycles,        &o->fetch_latency,    &o->dram_bytes_per_cycle,
                     &o->clock_mhz,      &o->rays_in_flight,    &o->cache_hit_latency, &o->cache_ways,
                     &o->unit_cycle_scale, &o->dram_pj_per_byte, &o->sram_pj_per_word, &o->issue_width};
    for (int i = 0; keys[i]; i++)
        if (get_num(c, t, "timing", keys[i], lo[i], 0, i == 7 ? 64 : i == 11 ? 1024 : CBVH_TIMING_MAX, dst[i], 0) < 0)
            return -1;
    return 0;
}

/* Two triangles under the mesh (y = lowest vertex), `size` times the mesh's
 * largest extent wide, centred below it. */
static void add_floor(cbvh_scene_desc *d, float size, uint8_t mat) {
    float lo[3], hi[3];
    cbvh_scene_bounds(&d->mesh, lo, hi);
    float ext = 0;
    for (int a = 0; a < 3; a++)
        if (hi[a] - lo[a] > ext) ext = hi[a] - lo[a];
    float h = 0.5f * size * ext, cx = 0.5f * (lo[0] + hi[0]), cz = 0.5f * (lo[2] + hi[2]), y = lo[1];
    float p[4][3] = {{cx - h, y, cz - h}, {cx + h, y, cz - h}, {cx + h, y, cz + h}, {cx - h, y, cz + h}};
    int idx[2][3] = {{0, 2, 1}, {0, 3, 2}};
    uint32_t n = d->mesh.ntris;
    for (int t = 0; t < 2; t++) {
        for (int v = 0; v < 3; v++) memcpy(d->mesh.tris[n + t].v[v], p[idx[t][v]], sizeof p[0]);
        d->tri_material[n + t] = mat;
    }
    d->mesh.ntris = n + 2;
}

static int resolve_mesh(pctx *c, const char *mesh, cbvh_scene_desc *d) {
    if (strncmp(mesh, "proc:", 5) == 0 || mesh[0] == '/') {
        if (snprintf(d->mesh_spec, sizeof d->mesh_spec, "%s", mesh) >= (int)sizeof d->mesh_spec)
            return fail(c, "mesh", "path too long");
        return 0;
    }
    const char *slash = strrchr(c->path, '/');
    int dirlen = slash ? (int)(slash - c->path) + 1 : 0;
    if (snprintf(d->mesh_spec, sizeof d->mesh_spec, "%.*s%s", dirlen, c->path, mesh) >= (int)sizeof d->mesh_spec)
        return fail(c, "mesh", "path too long");
    return 0;
}

/* The line of text that position at is on. */
static int line_at(const char *text, const char *at) {
    int line = 1;
    if (at && at >= text)
        for (const char *p = text; p < at && *p; p++) line += *p == '\n';
    return line;
}

int cbvh_scene_file_parse(const char *text, const char *path, cbvh_scene_desc *d, char *err, size_t errlen) {
    memset(d, 0, sizeof *d);
    pctx c = {path, err, errlen};
    snprintf(d->path, sizeof d->path, "%s", path);
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithOpts(text, &end, 1);
    if (!root) {
        fail(&c, NULL, "line %d: not valid JSON", line_at(text, cJSON_GetErrorPtr()));
        return -1;
    }
    /* cJSON ends a string at a \u0000 escape: "a.obj\u0000x" would load a.obj. */
    size_t len = strlen(text), nul = cbvh_json_find_nul(text, len);
    if (nul < len) {
        cJSON_Delete(root);
        fail(&c, NULL, "line %d: a string holds \\u0000 (NUL), which no name or path can hold", line_at(text, text + nul));
        return -1;
    }
    int rc = -1;
    d->timing.box_cycles = d->timing.tri_cycles = d->timing.fetch_latency = d->timing.dram_bytes_per_cycle =
        d->timing.clock_mhz = d->timing.rays_in_flight = d->timing.cache_hit_latency = d->timing.cache_ways =
            d->timing.unit_cycle_scale = d->timing.dram_pj_per_byte = d->timing.sram_pj_per_word =
                d->timing.issue_width = NAN;
    d->seed = 1;
    static const char *const keys[] = {"mesh", "camera", "lights", "materials", "mesh_material", "floor",
                                       "effects", "animation", "timing", "seed", NULL};
    if (!cJSON_IsObject(root)) {
        fail(&c, NULL, "expected a JSON object at the top level");
        goto out;
    }
    if (check_keys(&c, root, "", keys)) goto out;
    int src;
    const char *mesh = get_str(&c, root, "", "mesh", 1, &src);
    if (src) goto out;
    if (resolve_mesh(&c, mesh, d)) goto out;
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (!cam) {
        fail(&c, "camera", "missing");
        goto out;
    }
    if (parse_camera(&c, cam, d)) goto out;
    const cJSON *lights = cJSON_GetObjectItemCaseSensitive(root, "lights");
    if (lights && parse_lights(&c, lights, d)) goto out;
    const cJSON *mats = cJSON_GetObjectItemCaseSensitive(root, "materials");
    if (mats) {
        if (parse_materials(&c, mats, d)) goto out;
    } else {
        snprintf(d->materials[0].name, sizeof d->materials[0].name, "default");
        d->materials[0].type = CBVH_MAT_DIFFUSE;
        d->nmaterials = 1;
    }
    int mesh_mat = 0;
    const char *mm = get_str(&c, root, "", "mesh_material", 0, &src);
    if (src) goto out;
    if (mm && (mesh_mat = find_material(d, mm)) < 0) {
        fail(&c, "mesh_material", "no material named '%s'", mm);
        goto out;
    }
    int floor_mat = -1;
    double floor_size = 3.0;
    const cJSON *fl = cJSON_GetObjectItemCaseSensitive(root, "floor");
    if (fl) {
        static const char *const fkeys[] = {"material", "size", NULL};
        if (!cJSON_IsObject(fl)) {
            fail(&c, "floor", "expected an object");
            goto out;
        }
        if (check_keys(&c, fl, "floor", fkeys)) goto out;
        const char *fm = get_str(&c, fl, "floor", "material", 0, &src);
        if (src) goto out;
        floor_mat = 0;
        if (fm && (floor_mat = find_material(d, fm)) < 0) {
            fail(&c, "floor.material", "no material named '%s'", fm);
            goto out;
        }
        if (get_num(&c, fl, "floor", "size", 0, 1, 1e6, &floor_size, 0) < 0) goto out;
    }
    const cJSON *fx = cJSON_GetObjectItemCaseSensitive(root, "effects");
    if (!fx) {
        fail(&c, "effects", "missing");
        goto out;
    }
    if (parse_effects(&c, fx, d)) goto out;
    if (d->effect[CBVH_FX_HARD_SHADOWS].enabled && d->nlights == 0) {
        fail(&c, "effects", "'hard_shadows' needs at least one light");
        goto out;
    }
    if (d->effect[CBVH_FX_SOFT_SHADOWS].enabled) {
        int area = 0;
        for (int i = 0; i < d->nlights; i++) area += d->lights[i].type == CBVH_LIGHT_AREA;
        if (!area) {
            fail(&c, "effects", "'soft_shadows' needs at least one area light");
            goto out;
        }
    }
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(root, "animation");
    if (an && parse_animation(&c, an, d)) goto out;
    const cJSON *tm = cJSON_GetObjectItemCaseSensitive(root, "timing");
    if (tm && parse_timing(&c, tm, d)) goto out;
    const cJSON *sd = cJSON_GetObjectItemCaseSensitive(root, "seed");
    if (sd) {
        if (!cJSON_IsNumber(sd) || sd->valuedouble != floor(sd->valuedouble) || sd->valuedouble < 0 ||
            sd->valuedouble > 4294967295.0) {
            fail(&c, "seed", "expected an integer in 0..4294967295");
            goto out;
        }
        d->seed = (uint64_t)sd->valuedouble;
    }

    /* The mesh last: every field error is reported before a slow import. */
    char merr[512];
    if (cbvh_scene_open(d->mesh_spec, &d->mesh, merr, sizeof merr)) {
        fail(&c, "mesh", "%s", merr);
        goto out;
    }
    if (cbvh_scene_validate(&d->mesh, merr, sizeof merr)) {
        fail(&c, "mesh", "%s", merr);
        goto out;
    }
    if (d->anim.type == CBVH_ANIM_MORPH && !(d->mesh.nmorph && d->mesh.nkeys)) {
        fail(&c, "animation.type", "'morph' but mesh '%s' has no morph animation", d->mesh_spec);
        goto out;
    }
    d->mesh_tris = d->mesh.ntris;
    uint32_t total = d->mesh.ntris + (floor_mat >= 0 ? 2 : 0);
    cbvh_tri *tris = realloc(d->mesh.tris, (size_t)total * sizeof *tris);
    d->tri_material = malloc(total);
    if (!tris || !d->tri_material) cbvh_out_of_memory("scene triangles");
    d->mesh.tris = tris;
    memset(d->tri_material, mesh_mat, total);
    if (floor_mat >= 0) add_floor(d, (float)floor_size, (uint8_t)floor_mat);
    if (d->effect[CBVH_FX_AMBIENT_OCCLUSION].enabled && isnan(d->effect[CBVH_FX_AMBIENT_OCCLUSION].distance)) {
        float lo[3], hi[3];
        cbvh_scene_bounds(&d->mesh, lo, hi);
        float dg[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
        d->effect[CBVH_FX_AMBIENT_OCCLUSION].distance = 0.1f * len3(dg);
    }
    rc = 0;
out:
    cJSON_Delete(root);
    if (rc) {
        cbvh_scene_desc_free(d);
        snprintf(d->path, sizeof d->path, "%s", path);
    }
    return rc;
}

int cbvh_scene_file_load(const char *path, cbvh_scene_desc *d, char *err, size_t errlen) {
    memset(d, 0, sizeof *d);
    /* A FIFO would block in fopen, a device be read to the size limit. */
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "%s: not a regular file%s, not a scene file", path,
                 S_ISDIR(st.st_mode) ? " (a directory)" : "");
        return -1;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    if (!buf) cbvh_out_of_memory("scene file buffer");
    size_t got;
    while ((got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
        n += got;
        if (n + 1 == cap) {
            if (cap >= (16u << 20)) {
                fclose(f);
                free(buf);
                snprintf(err, errlen, "%s: larger than 16 MiB, not a scene file", path);
                return -1;
            }
            cap *= 2;
            buf = realloc(buf, cap);
            if (!buf) cbvh_out_of_memory("scene file buffer");
        }
    }
    int rerr = ferror(f) ? errno : 0;
    fclose(f);
    if (rerr) {
        free(buf);
        snprintf(err, errlen, "%s: cannot read: %s", path, strerror(rerr));
        return -1;
    }
    buf[n] = 0;
    if (strlen(buf) != n) {
        free(buf);
        snprintf(err, errlen, "%s: contains a NUL byte, not a scene file", path);
        return -1;
    }
    int rc = cbvh_scene_file_parse(buf, path, d, err, errlen);
    free(buf);
    return rc;
}

void cbvh_scene_desc_free(cbvh_scene_desc *d) {
    cbvh_scene_free(&d->mesh);
    free(d->tri_material);
    memset(d, 0, sizeof *d);
}

void cbvh_scene_desc_frame(const cbvh_scene_desc *d, int f, cbvh_tri *out) {
    const cbvh_scene *m = &d->mesh;
    int frames = cbvh_scene_desc_frames(d);
    float t = frames > 1 ? d->anim.t0 + (d->anim.t1 - d->anim.t0) * (float)f / (float)(frames - 1) : 0;
    /* The animated mesh is the first mesh_tris triangles; view it alone. */
    cbvh_scene mesh = *m;
    mesh.ntris = d->mesh_tris;
    if (d->anim.type == CBVH_ANIM_MORPH)
        cbvh_scene_frame(&mesh, t, out);
    else if (d->anim.type == CBVH_ANIM_TWIST)
        cbvh_scene_deform(&mesh, d->anim.amount * t, d->anim.wave, 6.2831853f * t, out); /* twist grows with t */
    else
        memcpy(out, m->tris, (size_t)d->mesh_tris * sizeof *out);
    memcpy(out + d->mesh_tris, m->tris + d->mesh_tris, (size_t)(m->ntris - d->mesh_tris) * sizeof *out);
}
