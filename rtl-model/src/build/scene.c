/* Scene helpers: validation, bounds, morph frames and a procedural deformation. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/scene.h"

void cbvh_scene_free(cbvh_scene *s) {
    free(s->tris);
    free(s->morph);
    free(s->key_time);
    free(s->key_weight);
    memset(s, 0, sizeof *s);
}

int cbvh_scene_validate(const cbvh_scene *s, char *err, size_t errlen) {
    if (s->ntris == 0 || !s->tris) {
        snprintf(err, errlen, "scene '%s' has no triangles", s->name);
        return -1;
    }
    if (s->ntris >= 0x80000000u) {
        snprintf(err, errlen, "scene '%s' has %u triangles; IDs must fit in 31 bits", s->name, s->ntris);
        return -1;
    }
    /* Fast flat scan (exponent all ones = NaN/Inf), then locate for the message. */
    const float *f = &s->tris[0].v[0][0];
    uint32_t bad = 0;
    for (size_t i = 0; i < (size_t)s->ntris * 9u; i++) {
        uint32_t w;
        memcpy(&w, &f[i], sizeof w);
        bad |= (uint32_t)((w & 0x7F800000u) == 0x7F800000u);
    }
    for (uint32_t i = 0; bad && i < s->ntris; i++)
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++)
                if (!isfinite(s->tris[i].v[v][a])) {
                    snprintf(err, errlen, "scene '%s': triangle %u has a non-finite vertex coordinate", s->name, i);
                    return -1;
                }
    for (uint64_t i = 0; i < (uint64_t)s->nmorph * s->ntris; i++)
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++)
                if (!isfinite(s->morph[i].v[v][a])) {
                    snprintf(err, errlen, "scene '%s': a morph target has a non-finite vertex coordinate", s->name);
                    return -1;
                }
    return 0;
}

void cbvh_scene_bounds(const cbvh_scene *s, float lo[3], float hi[3]) {
    for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
    for (uint32_t i = 0; i < s->ntris; i++)
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) {
                float x = s->tris[i].v[v][a];
                if (x < lo[a]) lo[a] = x;
                if (x > hi[a]) hi[a] = x;
            }
}

float cbvh_scene_duration(const cbvh_scene *s) {
    return s->nkeys ? s->key_time[s->nkeys - 1] - s->key_time[0] : 0.0f;
}

void cbvh_scene_frame(const cbvh_scene *s, float t, cbvh_tri *out) {
    memcpy(out, s->tris, (size_t)s->ntris * sizeof *out);
    if (!s->nmorph || !s->nkeys) return;
    /* Weights at t: linear between the surrounding keys, clamped at the ends. */
    uint32_t k = 0;
    while (k + 1 < s->nkeys && s->key_time[k + 1] <= t) k++;
    float f = 0.0f;
    if (k + 1 < s->nkeys && t > s->key_time[k]) f = (t - s->key_time[k]) / (s->key_time[k + 1] - s->key_time[k]);
    uint32_t k1 = k + 1 < s->nkeys ? k + 1 : k;
    for (uint32_t j = 0; j < s->nmorph; j++) {
        float w = (1.0f - f) * s->key_weight[(size_t)k * s->nmorph + j] + f * s->key_weight[(size_t)k1 * s->nmorph + j];
        if (w == 0.0f) continue;
        const cbvh_tri *m = s->morph + (size_t)j * s->ntris;
        for (uint32_t i = 0; i < s->ntris; i++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) out[i].v[v][a] += w * (m[i].v[v][a] - s->tris[i].v[v][a]);
    }
}

void cbvh_scene_deform(const cbvh_scene *s, float amount, float wave, float t, cbvh_tri *out) {
    float lo[3], hi[3];
    cbvh_scene_bounds(s, lo, hi);
    float cx = 0.5f * (lo[0] + hi[0]), cz = 0.5f * (lo[2] + hi[2]);
    float h = hi[1] - lo[1], w = hi[0] - lo[0];
    if (h <= 0.0f) h = 1.0f;
    if (w <= 0.0f) w = 1.0f;
    for (uint32_t i = 0; i < s->ntris; i++)
        for (int v = 0; v < 3; v++) {
            const float *p = s->tris[i].v[v];
            float ang = amount * (p[1] - lo[1]) / h;
            float c = cosf(ang), sn = sinf(ang);
            float x = p[0] - cx, z = p[2] - cz;
            out[i].v[v][0] = cx + c * x - sn * z;
            out[i].v[v][2] = cz + sn * x + c * z;
            out[i].v[v][1] = p[1] + wave * h * sinf(6.2831853f * (p[0] - lo[0]) / w + t);
        }
}
