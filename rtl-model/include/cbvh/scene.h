/* Scenes: triangle soups (the paper's input layout: 3 vertices of 12 bytes per
 * triangle, plus a 4-byte primitive ID = the triangle's index), with an
 * optional morph animation for refitting studies.
 *
 * Loading files and procedural scenes lives in the host tool
 * (host/scene/scene_load.h); this header is what builders and traversal need. */
#ifndef CBVH_SCENE_H
#define CBVH_SCENE_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    float v[3][3]; /* v[vertex][axis] */
} cbvh_tri;

typedef struct {
    char name[64];
    cbvh_tri *tris; /* ntris triangles; primitive ID = index */
    uint32_t ntris;
    /* Optional morph animation (glTF morph targets): frame(t) =
     * base + sum_j w_j(t) * (morph[j] - base), weights linear between keys. */
    uint32_t nmorph;    /* number of morph targets (0: static scene) */
    cbvh_tri *morph;    /* nmorph * ntris absolute target positions */
    uint32_t nkeys;     /* keyframes (0: none) */
    float *key_time;    /* nkeys, seconds, increasing */
    float *key_weight;  /* nkeys * nmorph */
} cbvh_scene;

/* Frees every array and zeroes the struct (safe on a zeroed struct). */
void cbvh_scene_free(cbvh_scene *s);

/* 0 if the scene is usable by every builder: at least one triangle, every
 * vertex finite.  Else -1 and a one-line reason in err. */
int cbvh_scene_validate(const cbvh_scene *s, char *err, size_t errlen);

/* Bounding box of all vertices (scene must be non-empty). */
void cbvh_scene_bounds(const cbvh_scene *s, float lo[3], float hi[3]);

/* Bounding box of one triangle. */
static inline void cbvh_tri_bounds(const cbvh_tri *t, float lo[3], float hi[3]) {
    for (int a = 0; a < 3; a++) {
        float x = t->v[0][a], y = t->v[1][a], z = t->v[2][a];
        float mn = x < y ? x : y, mx = x < y ? y : x;
        lo[a] = mn < z ? mn : z;
        hi[a] = mx > z ? mx : z;
    }
}

/* Duration of the morph animation in seconds (0 if none). */
float cbvh_scene_duration(const cbvh_scene *s);

/* Vertex positions at time t (clamped to the key range) into out[ntris].
 * A static scene copies its triangles. */
void cbvh_scene_frame(const cbvh_scene *s, float t, cbvh_tri *out);

/* Procedural deformation for refitting studies: twist about the scene's
 * vertical (y) axis by `amount` radians per scene height, plus a sine wave of
 * relative amplitude `wave` along y; phase t.  Writes out[ntris]. */
void cbvh_scene_deform(const cbvh_scene *s, float amount, float wave, float t, cbvh_tri *out);

#endif
