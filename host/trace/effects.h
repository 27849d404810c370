/* Effects -> rays (docs/scenes.md §Effects): generate only the rays the
 * scene's effects call for, trace them with the units the chosen format needs
 * (float BVH, CBVH or QBVH), and count the cost per effect and the activity of every
 * unit.  Sampling is deterministic (seeded per pixel and sample), so the float
 * BVH and the CBVH see the same rays and, since their hits are identical
 * (docs/traversal.md §5), spawn the same secondary rays. */
#ifndef CBVH_HOST_EFFECTS_H
#define CBVH_HOST_EFFECTS_H

#include <stdint.h>

#include "cbvh/qbvh.h"
#include "cbvh/tlist.h"
#include "cbvh/traverse.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"

/* QBVH: the same binned-SAH float BVH collapsed to 4-ary (docs/qbvh.md),
 * traversed with the compressed 32-bit stack.  TLIST: the stackless
 * traversal lists over a bounding-sphere hierarchy (docs/tlist.md). */
typedef enum { CBVH_FORMAT_FLOAT = 0, CBVH_FORMAT_CBVH = 1, CBVH_FORMAT_QBVH = 2, CBVH_FORMAT_TLIST = 3 } cbvh_accel_format;

/* "float", "cbvh", "qbvh", "tlist". */
const char *cbvh_format_name(cbvh_accel_format f);

/* The options of the traversal-list format. */
typedef struct {
    cbvh_tlist_params p; /* lists, order, back-face culling */
    int poly_heads;      /* per-polygon list heads for secondary rays */
    int cell_heads;      /* per-screen-cell list heads for pinhole primary rays */
} cbvh_tlist_opts;

/* Largest triangles x lists for which format tlist precomputes per-polygon heads. */
#define CBVH_FX_POLY_HEADS_MAX 16000000u

/* Parses "tlist[:L][:earliest|:latest][:cull][:heads]" (L = 1, 2, 6, 8;
 * defaults 6 lists, earliest first, no culling, no heads; "heads" = both kinds).
 * 0, or -1 with a one-line reason. */
int cbvh_tlist_opts_parse(const char *s, cbvh_tlist_opts *t, char *err, size_t errlen);
/* The canonical spelling of the options, e.g. "tlist:6:earliest:cull:heads". */
void cbvh_tlist_opts_name(const cbvh_tlist_opts *t, char *out, size_t n);

/* One traced ray, as the observer sees it. */
typedef struct {
    cbvh_effect effect;
    cbvh_trav_mode mode;   /* closest hit (primary, mirror, bounce) or any hit (shadows, AO) */
    cbvh_ray ray;
    uint32_t source_prim;  /* triangle the ray leaves from; UINT32_MAX for camera rays */
    int light;             /* shadow rays: the light aimed at; else -1 */
    int frame;
    const cbvh_trav_hit *hit;
    const cbvh_trav_stats *st; /* this ray's own counters */
    int px, py;                /* camera pixel whose path the ray belongs to */
} cbvh_fx_ray;

typedef struct {
    cbvh_accel_format format;
    cbvh_params params; /* N and min_scale of the CBVH */
    int mant;           /* M of the ray-box unit (3..24) */
    int spp;            /* camera samples per pixel; 0 = the scene's */
    void (*on_ray)(void *ctx, const cbvh_fx_ray *r);       /* optional observer */
    void (*progress)(void *ctx, int frame, int frames, int row, int rows); /* optional */
    void *ctx;
    cbvh_tlist_opts tlist; /* format tlist (zeroed: the defaults of cbvh_tlist_opts_parse("tlist")) */
    int one_sided;         /* triangles count only from their front side (cbvh_tri_facing), every format */
} cbvh_fx_opts;

typedef struct {
    uint64_t rays;            /* rays traced */
    uint64_t closest, any;    /* traversals by kind */
    uint64_t hits;
    uint64_t rejected;        /* rays a unit rejected (NaN/Inf, zero direction): no hit */
    cbvh_trav_stats st;       /* summed counters; max_stack = deepest */
    double cpu_seconds;       /* time spent in traversal (per-ray monotonic clock, its cost removed) */
} cbvh_fx_stats;

/* Invocations per unit (docs/scenes.md §Units). */
typedef struct {
    uint64_t compressor;   /* axis compressions: 6 per node-pair encode or re-encode, 3 per root context */
    uint64_t decoder;      /* axis decodes: 6 per node pair fetched by a CBVH traversal */
    uint64_t ray_box;      /* ray-box tests */
    uint64_t ray_triangle; /* ray-triangle tests */
    uint64_t refit;        /* node boxes recomputed by refits (animated scenes only) */
    uint64_t qbvh_stack;   /* QBVH stack unit operations: sort + push (one per inner node visited) and pops */
    uint64_t ray_sphere;   /* ray-sphere tests (format tlist; its box_tests counter counts these) */
} cbvh_unit_activity;

typedef struct {
    cbvh_fx_stats fx[CBVH_FX_COUNT];
    cbvh_unit_activity units;
    int frames;
    uint32_t ntris;
    uint64_t node_bytes;     /* hierarchy + primitive IDs (frame 0) */
    uint64_t refits;         /* refit passes */
    /* Fisheye: camera samples (pixel x sample x frame) outside the image circle,
     * which make no ray; and pixels none of whose samples made a ray in any
     * frame (at most width x height). */
    uint64_t samples_without_ray;
    uint64_t pixels_without_ray;
    uint64_t hit_digest;     /* hash of every ray's hit (prim, t bits) */
    double build_cpu_seconds;
} cbvh_fx_result;

/* Builds the float BVH (binned SAH) of frame 0, compresses it (format cbvh,
 * bottom-up streaming), collapses it to a QBVH (format qbvh) or builds the
 * sphere hierarchy and its lists (format tlist), and for every frame: refits
 * (frames >= 1; the QBVH's own boxes are refitted bottom-up, its topology
 * kept; the lists are rebuilt, since culling and heads depend on the
 * triangles' normals and positions), then traces every enabled effect.  0,
 * or -1 with a one-line reason. */
int cbvh_fx_run(const cbvh_scene_desc *d, const cbvh_fx_opts *o, cbvh_fx_result *r, char *err, size_t errlen);

/* Sum over the effects of a result (max_stack = the deepest). */
cbvh_fx_stats cbvh_fx_total(const cbvh_fx_result *r);

/* Timing-model parameters for a scene: the defaults with the scene file's
 * overrides (docs/timing_model.md). */
void cbvh_fx_timing(const cbvh_scene_desc *d, cbvh_timing_params *tp);

#endif
