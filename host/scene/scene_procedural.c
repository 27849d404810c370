/* Procedural scenes for what real files lack (generated in memory). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_load.h"

static int alloc_tris(cbvh_scene *s, uint64_t n, char *err, size_t errlen) {
    if (n == 0 || n >= 0x80000000u) {
        snprintf(err, errlen, "procedural scene '%s': bad size (%llu triangles)", s->name, (unsigned long long)n);
        return -1;
    }
    s->tris = malloc((size_t)n * sizeof *s->tris);
    if (!s->tris) {
        snprintf(err, errlen, "procedural scene '%s': out of memory for %llu triangles", s->name,
                 (unsigned long long)n);
        return -1;
    }
    s->ntris = (uint32_t)n;
    return 0;
}

static void set_tri(cbvh_tri *t, const float a[3], const float b[3], const float c[3]) {
    memcpy(t->v[0], a, 12);
    memcpy(t->v[1], b, 12);
    memcpy(t->v[2], c, 12);
}

/* Height field z(x, y) on [-1,1]^2 triangulated as n x n cells. */
static void grid(cbvh_tri *t, unsigned n, float (*height)(float, float)) {
    size_t k = 0;
    for (unsigned j = 0; j < n; j++)
        for (unsigned i = 0; i < n; i++) {
            float x0 = -1.0f + 2.0f * (float)i / (float)n, x1 = -1.0f + 2.0f * (float)(i + 1) / (float)n;
            float y0 = -1.0f + 2.0f * (float)j / (float)n, y1 = -1.0f + 2.0f * (float)(j + 1) / (float)n;
            float a[3] = {x0, y0, height(x0, y0)}, b[3] = {x1, y0, height(x1, y0)};
            float c[3] = {x1, y1, height(x1, y1)}, d[3] = {x0, y1, height(x0, y1)};
            set_tri(&t[k++], a, b, c);
            set_tri(&t[k++], a, c, d);
        }
}

/* Cloth: flat at exactly z = -0.4 (a degenerate axis for most subtrees),
 * draped over a sphere of radius 0.35 in the middle. */
static float cloth_height(float x, float y) {
    float r2 = x * x + y * y;
    if (r2 >= 0.35f * 0.35f) return -0.4f;
    return -0.4f + 0.6f * (0.35f * 0.35f - r2) / (0.35f * 0.35f);
}

static float wave_height(float x, float y) { return 0.1f * sinf(3.0f * x) * cosf(2.0f * y); }

/* UV sphere: 2 * seg * (seg/2) triangles (poles included as slivers). */
static size_t sphere(cbvh_tri *t, unsigned seg, const float c[3], float r) {
    unsigned rings = seg / 2;
    size_t k = 0;
    for (unsigned j = 0; j < rings; j++)
        for (unsigned i = 0; i < seg; i++) {
            float th0 = 3.14159265f * (float)j / (float)rings, th1 = 3.14159265f * (float)(j + 1) / (float)rings;
            float ph0 = 6.2831853f * (float)i / (float)seg, ph1 = 6.2831853f * (float)(i + 1) / (float)seg;
            float p[4][3];
            float th[4] = {th0, th0, th1, th1}, ph[4] = {ph0, ph1, ph1, ph0};
            for (int q = 0; q < 4; q++) {
                p[q][0] = c[0] + r * sinf(th[q]) * cosf(ph[q]);
                p[q][1] = c[1] + r * cosf(th[q]);
                p[q][2] = c[2] + r * sinf(th[q]) * sinf(ph[q]);
            }
            set_tri(&t[k++], p[0], p[1], p[2]);
            set_tri(&t[k++], p[0], p[2], p[3]);
        }
    return k;
}

/* A size outside a scene's range is an error, never clamped: the spec then
 * always says what was built.  size 0 = the scene's default. */
static int size_ok(const char *name, unsigned size, unsigned lo, unsigned hi, const char *unit, char *err,
                   size_t errlen) {
    if (size == 0 || (size >= lo && size <= hi)) return 1;
    snprintf(err, errlen, "procedural scene '%s': size %u out of range %u..%u (%s)", name, size, lo, hi, unit);
    return 0;
}

int cbvh_scene_procedural(const char *name, unsigned size, cbvh_scene *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "proc:%s", name);
    if (strcmp(name, "cloth") == 0 || strcmp(name, "wave") == 0) {
        int cloth = name[0] == 'c';
        if (!size_ok(name, size, 1, 20000, "grid cells per side", err, errlen)) return -1;
        unsigned n = size ? size : cloth ? 256 : 64;
        if (alloc_tris(out, 2ull * n * n, err, errlen)) return -1;
        grid(out->tris, n, cloth ? cloth_height : wave_height);
        return 0;
    }
    if (strcmp(name, "far") == 0) {
        if (!size_ok(name, size, 4, 4096, "sphere segments", err, errlen)) return -1;
        unsigned seg = size ? size : 48;
        if (alloc_tris(out, (uint64_t)seg * (seg / 2) * 2, err, errlen)) return -1;
        const float c[3] = {1000.3f, -2000.7f, 3000.1f};
        sphere(out->tris, seg, c, 0.01f);
        return 0;
    }
    if (strcmp(name, "instanced") == 0) {
        /* size x size sphere instances of 80 x 40 x 2 = 6400 triangles;
         * 40 x 40 -> 10,240,000 triangles.  Radii and positions vary so the
         * instances are not all identical. */
        if (!size_ok(name, size, 1, 200, "instances per side", err, errlen)) return -1;
        unsigned n = size ? size : 40;
        const unsigned seg = 80;
        size_t per = (size_t)seg * (seg / 2) * 2;
        if (alloc_tris(out, (uint64_t)n * n * per, err, errlen)) return -1;
        cbvh_tri *proto = malloc(per * sizeof *proto);
        if (!proto) {
            cbvh_scene_free(out);
            snprintf(err, errlen, "procedural scene 'instanced': out of memory");
            return -1;
        }
        const float zero[3] = {0, 0, 0};
        sphere(proto, seg, zero, 1.0f);
        size_t k = 0;
        for (unsigned j = 0; j < n; j++)
            for (unsigned i = 0; i < n; i++) {
                float r = 0.6f + 0.3f * (float)((i * 7 + j * 13) % 5) / 4.0f;
                float ox = 2.5f * (float)i, oy = 0.5f * (float)((i + j) % 3), oz = 2.5f * (float)j;
                for (size_t t = 0; t < per; t++, k++)
                    for (int v = 0; v < 3; v++) {
                        out->tris[k].v[v][0] = ox + r * proto[t].v[v][0];
                        out->tris[k].v[v][1] = oy + r * proto[t].v[v][1];
                        out->tris[k].v[v][2] = oz + r * proto[t].v[v][2];
                    }
            }
        free(proto);
        return 0;
    }
    snprintf(err, errlen, "unknown procedural scene '%s' (cloth, far, instanced, wave)", name);
    return -1;
}
