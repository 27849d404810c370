/* Scene files: what a scene calls for (docs/scenes.md).
 *
 * A scene file is a JSON object naming a mesh (or proc:NAME), a camera,
 * lights, materials, the effects to render with their sample counts, and an
 * optional animation.  cbvh trace generates only the rays those effects call
 * for (host/trace/effects.h).  Every bad field is a one-line error naming the file
 * and the field. */
#ifndef CBVH_HOST_SCENE_FILE_H
#define CBVH_HOST_SCENE_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/scene.h"

typedef enum {
    CBVH_FX_PRIMARY = 0,
    CBVH_FX_HARD_SHADOWS,
    CBVH_FX_SOFT_SHADOWS,
    CBVH_FX_AMBIENT_OCCLUSION,
    CBVH_FX_MIRROR,
    CBVH_FX_DIFFUSE_BOUNCE,
    CBVH_FX_COUNT
} cbvh_effect;

/* "primary", "hard_shadows", ... (the scene-file spelling). */
const char *cbvh_effect_name(cbvh_effect e);

typedef enum { CBVH_CAM_PINHOLE = 0, CBVH_CAM_THIN_LENS, CBVH_CAM_FISHEYE } cbvh_camera_type;

typedef struct {
    cbvh_camera_type type;
    int width, height;
    float position[3], target[3], up[3];
    float fov;            /* degrees: vertical (pinhole, thin lens), full circle (fisheye) */
    float aperture;       /* thin lens: lens radius */
    float focus_distance; /* thin lens: distance of the plane in focus */
    int spp;              /* camera samples per pixel */
} cbvh_camera;

typedef enum { CBVH_LIGHT_POINT = 0, CBVH_LIGHT_AREA } cbvh_light_type;

typedef struct {
    cbvh_light_type type;
    float position[3]; /* point: the point; area: the centre */
    float u[3], v[3];  /* area: the parallelogram spans position +- u/2 +- v/2 */
} cbvh_light;

typedef enum { CBVH_MAT_DIFFUSE = 0, CBVH_MAT_MIRROR } cbvh_material_type;

typedef struct {
    char name[32];
    cbvh_material_type type;
} cbvh_material;

typedef struct {
    int enabled;
    int samples;    /* rays per shading point (per area light for soft shadows) */
    float distance; /* ambient occlusion: ray length (scene units) */
    int max_depth;  /* mirror: reflections per path */
} cbvh_effect_cfg;

typedef enum { CBVH_ANIM_NONE = 0, CBVH_ANIM_MORPH, CBVH_ANIM_TWIST } cbvh_anim_type;

typedef struct {
    cbvh_anim_type type;
    int frames;          /* >= 2: frame 0 is built, every later frame refits */
    float t0, t1;        /* morph: animation time range (s); twist: phase range */
    float amount, wave;  /* twist: radians per scene height, relative wave amplitude */
} cbvh_animation;

/* Timing-model overrides (docs/timing_model.md); NaN = default. */
typedef struct {
    double box_cycles, tri_cycles, fetch_latency, dram_bytes_per_cycle, clock_mhz;
    double rays_in_flight, cache_hit_latency, cache_ways, unit_cycle_scale, dram_pj_per_byte, sram_pj_per_word;
    double issue_width;
} cbvh_timing_overrides;

#define CBVH_MAX_LIGHTS 16
#define CBVH_MAX_MATERIALS 16

typedef struct {
    char path[1024];    /* the scene file (for messages) */
    char mesh_spec[1024]; /* resolved mesh path or proc:NAME[:SIZE] */
    cbvh_scene mesh;    /* the loaded mesh (+ floor triangles appended) */
    uint32_t mesh_tris; /* triangles of the mesh itself (the floor follows) */
    uint8_t *tri_material; /* material index per triangle (mesh.ntris) */
    cbvh_camera camera;
    cbvh_light lights[CBVH_MAX_LIGHTS];
    int nlights;
    cbvh_material materials[CBVH_MAX_MATERIALS];
    int nmaterials;
    cbvh_effect_cfg effect[CBVH_FX_COUNT];
    cbvh_animation anim;
    cbvh_timing_overrides timing;
    uint64_t seed;
} cbvh_scene_desc;

/* Parse a scene file and load its mesh.  0, or -1 with a one-line message in
 * err ("FILE: field: problem").  *out is zeroed on failure. */
int cbvh_scene_file_load(const char *path, cbvh_scene_desc *out, char *err, size_t errlen);

/* The same from a string; `path` names it in messages and its directory is
 * where a relative mesh path is looked up. */
int cbvh_scene_file_parse(const char *text, const char *path, cbvh_scene_desc *out, char *err, size_t errlen);

/* The default scene of a bare mesh (host/scene/scene_default.c, docs/scenes.md):
 * 256x192 pinhole at centre + (0.45, 0.35, 1.9) x the largest extent E, looking at
 * the centre (y up, 35 degrees); one point light at centre + (1, 2, 1) E; a diffuse
 * floor 3x the mesh; primary, hard shadows, ambient occlusion (2 samples, distance
 * 0.2 E); seed 1. */
int cbvh_scene_file_default(const char *mesh, cbvh_scene_desc *out, char *err, size_t errlen);
/* A scene file, or the default scene of a mesh file / proc:NAME. */
int cbvh_scene_file_open(const char *arg, cbvh_scene_desc *out, char *err, size_t errlen);

void cbvh_scene_desc_free(cbvh_scene_desc *d);

/* Triangles of frame f (0 .. frames-1; a static scene has one frame) into
 * out[mesh.ntris]: the animated mesh, then the static floor. */
void cbvh_scene_desc_frame(const cbvh_scene_desc *d, int f, cbvh_tri *out);

static inline int cbvh_scene_desc_frames(const cbvh_scene_desc *d) {
    return d->anim.type == CBVH_ANIM_NONE ? 1 : d->anim.frames;
}

#endif
