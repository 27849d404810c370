/* The rays every traversal benchmark uses (same definition, so figures compare):
 * camera rays over a square image looking at the scene centre from outside its
 * box (first half) and random rays with origins in the box and directions
 * uniform on the sphere (second half); xorshift64, seeded by the caller. */
#ifndef CBVH_BENCH_RAYS_H
#define CBVH_BENCH_RAYS_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "cbvh/traverse.h"

static uint64_t rs = 1; /* generator state: set it before make_rays */

static uint64_t rnd(void) {
    rs ^= rs << 13;
    rs ^= rs >> 7;
    rs ^= rs << 17;
    return rs;
}
static float unit(void) { return (float)((double)(rnd() >> 11) / 9007199254740992.0); }
static cbvh_f32 fb(float f) {
    cbvh_f32 b;
    memcpy(&b, &f, sizeof b);
    return b;
}

static void make_rays(const float lo[3], const float hi[3], int n, cbvh_ray *rays) {
    float c[3], ext = 0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        if (hi[a] - lo[a] > ext) ext = hi[a] - lo[a];
    }
    if (ext <= 0) ext = 1;
    int ncam = n / 2, side = (int)ceil(sqrt((double)ncam));
    float eye[3] = {c[0] + 0.3f * ext, c[1] + 0.4f * ext, c[2] + 1.6f * ext};
    float w[3], len = 0; /* forward, then right/up from the y axis */
    for (int a = 0; a < 3; a++) w[a] = c[a] - eye[a], len += w[a] * w[a];
    len = sqrtf(len);
    for (int a = 0; a < 3; a++) w[a] /= len;
    float u[3] = {w[2], 0, -w[0]}, ul = sqrtf(u[0] * u[0] + u[2] * u[2]);
    for (int a = 0; a < 3; a++) u[a] /= ul;
    float v[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    for (int i = 0; i < n; i++) {
        cbvh_ray *r = &rays[i];
        float d[3], o[3];
        if (i < ncam) {
            float px = ((float)(i % side) + 0.5f) / (float)side * 2 - 1;
            float py = ((float)(i / side) + 0.5f) / (float)side * 2 - 1;
            for (int a = 0; a < 3; a++) {
                o[a] = eye[a];
                d[a] = w[a] + 0.45f * (px * u[a] + py * v[a]);
            }
        } else {
            float z = unit() * 2 - 1, phi = 6.2831853f * unit(), s = sqrtf(fmaxf(0, 1 - z * z));
            d[0] = s * cosf(phi);
            d[1] = s * sinf(phi);
            d[2] = z;
            for (int a = 0; a < 3; a++) o[a] = lo[a] + unit() * (hi[a] - lo[a]);
            if (d[0] == 0 && d[1] == 0 && d[2] == 0) d[0] = 1;
        }
        for (int a = 0; a < 3; a++) {
            r->o[a] = fb(o[a]);
            r->d[a] = fb(d[a]);
        }
        r->tmin = 0;
        r->tmax = CBVH_F32_POS_INF;
    }
}

#endif
