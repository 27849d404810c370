/* Effects -> rays (docs/scenes.md §Effects): generate only the rays the
 * scene's effects call for, trace them with the units the chosen format needs
 * (any format of the table in cbvh/format.h), and count the cost per effect
 * and the activity of every unit.  Sampling is deterministic (seeded per pixel and sample), so the float
 * BVH and the CBVH see the same rays and, since their hits are identical
 * (docs/traversal.md §5), spawn the same secondary rays. */
#ifndef CBVH_HOST_EFFECTS_H
#define CBVH_HOST_EFFECTS_H

#include <stdint.h>

#include "cbvh/format.h"
#include "cbvh/traverse.h"
#include "scene/scene_file.h"
#include "trace/memsim.h"
#include "trace/metrics.h"
#include "trace/timing_model.h"

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
    const char *format; /* a format's spec (cbvh/format.h): "float" (NULL: float), "cbvh", "qbvh", "tlist:6:cull" */
    cbvh_params params; /* N and min_scale of the CBVH */
    int mant;           /* M of the ray-box unit (3..24) */
    int spp;            /* camera samples per pixel; 0 = the scene's */
    void (*on_ray)(void *ctx, const cbvh_fx_ray *r);       /* optional observer */
    void (*progress)(void *ctx, int frame, int frames, int row, int rows); /* optional */
    void *ctx;
    int one_sided;         /* triangles count only from their front side (cbvh_tri_facing), every format */
    /* The timing model's caches (docs/timing_model.md §3): ncaches sizes in KB
     * (0: none, INFINITY: infinite), cache_ways ways; with ncaches = 0 no read
     * is observed.  steps: optional, each ray's steps for the event-driven
     * check (trace/memsim.h). */
    const double *cache_kb;
    int ncaches;
    int cache_ways;
    cbvh_step_log *steps;
    int box_unit, texp;    /* the box unit of a format that takes one (cbvh_format_params) */
} cbvh_fx_opts;

/* A run: counters per effect (cbvh_fx_stats, trace/metrics.h) and invocations
 * per unit (cbvh_unit_activity, cbvh/format.h). */
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
    double cache_kb[CBVH_CACHES_MAX]; /* the caches modelled (cbvh_fx_stats.mem) */
    int ncaches;
    unsigned format_flags;   /* the format's CBVH_FORMAT_* flags */
    char format[CBVH_FORMAT_NAME_MAX]; /* its canonical spec */
} cbvh_fx_result;

/* Builds the chosen format from frame 0's triangles (cbvh/format.h) and for
 * every frame: refits it (frames >= 1, the format's refit), then traces every
 * enabled effect.  0, or -1 with a one-line reason (a bad format spec
 * included). */
int cbvh_fx_run(const cbvh_scene_desc *d, const cbvh_fx_opts *o, cbvh_fx_result *r, char *err, size_t errlen);

/* Sum over the effects of a result (max_stack = the deepest). */
cbvh_fx_stats cbvh_fx_total(const cbvh_fx_result *r);

/* Timing-model parameters for a scene: the defaults with the scene file's
 * overrides (docs/timing_model.md). */
void cbvh_fx_timing(const cbvh_scene_desc *d, cbvh_timing_params *tp);

/* One more timed repetition of a run: rep's CPU time per effect appended to
 * main's (cbvh_fx_stats.cpu_rep), if rep traced the same rays with the same
 * hits (else -1, nothing appended). */
int cbvh_fx_add_rep(cbvh_fx_result *main, const cbvh_fx_result *rep);

/* The box units a CBVH is traced and timed with, indexed by
 * cbvh_format_params.box_unit (CBVH_FORMAT_BOX_EXACT, _INCREMENTAL): the
 * name in tables and the unit of the RTL cost table (trace/cost_table.h) the
 * timing model charges for each box test: the exact unit 6 ("ray_box") or
 * the incremental unit 10 of seed 003's Eq. 5 ("ray_box_incr"). */
typedef struct {
    const char *name, *cost_unit;
} cbvh_box_unit;
#define CBVH_BOX_UNITS 2
extern const cbvh_box_unit cbvh_box_units[CBVH_BOX_UNITS];

/* The units of a run's format (trace/timing_model.h): the node unit is the
 * sphere unit for the traversal lists, else box_unit ("ray_box" or
 * "ray_box_incr"); the decoder for a format with N (the CBVH), the stack
 * unit for one that runs it (the QBVH).  n, m: the design point.  0, or -1
 * with a one-line reason. */
int cbvh_fx_units(const cbvh_fx_result *r, const cbvh_cost_table *t, const cbvh_timing_params *tp,
                  const char *box_unit, int n, int m, cbvh_timing_units *u, char *err, size_t errlen);

#endif
