/* Acceleration formats behind one table of functions, as the host's backends
 * are behind theirs: the float BVH (the reference), the CBVH, the QBVH and the
 * traversal lists.  A format is one file in rtl-model/src/formats/ with one
 * entry in the table (rtl-model/src/formats/format_table.c); the host's tracer
 * (host/trace/effects.c) and its commands hold only the chosen format's
 * opaque state and call these functions, never a format by name.
 *
 * Life of a format: parse its spec ("tlist:6:cull"), build it from frame 0's
 * triangles, trace rays (closest or any hit: the mode), refit it for every
 * further frame of an animated scene, read its bytes, free it.  The hardware
 * units it keeps busy are counted in a cbvh_unit_activity (docs/scenes.md
 * §Units): its build and refits add as they go, its traversal counters are
 * turned into unit invocations once per run (units).
 *
 * Every format returns the float BVH's hits bit for bit (docs/traversal.md §5):
 * what tests/trace checks through this table for every entry. */
#ifndef CBVH_FORMAT_H
#define CBVH_FORMAT_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/datapath.h"
#include "cbvh/scene.h"
#include "cbvh/traverse.h"

/* Invocations per hardware unit (docs/scenes.md §Units). */
typedef struct {
    uint64_t compressor;   /* axis compressions: 6 per node-pair encode or re-encode, 3 per root context */
    uint64_t decoder;      /* axis decodes: 6 per node pair fetched by a CBVH traversal */
    uint64_t ray_box;      /* ray-box tests */
    uint64_t ray_triangle; /* ray-triangle tests */
    uint64_t refit;        /* node boxes recomputed by refits (animated scenes only) */
    uint64_t qbvh_stack;   /* QBVH stack unit operations: sort + push (one per inner node visited) and pops */
    uint64_t ray_sphere;   /* ray-sphere tests (format tlist; its box_tests counter counts these) */
} cbvh_unit_activity;

/* What every format is built with; each uses what its flags say. */
typedef struct {
    cbvh_params cbvh; /* N and min scale (CBVH_FORMAT_USES_N) */
    int mant;         /* M of the ray-box unit, CBVH_MANT_MIN..CBVH_MANT_MAX (CBVH_FORMAT_USES_MANT) */
    int one_sided;    /* rays are traced with CBVH_TRAV_FRONT_ONLY (back-face culling needs it) */
    int box_unit;     /* CBVH_FORMAT_BOX_EXACT (0) or CBVH_FORMAT_BOX_INCREMENTAL (CBVH_FORMAT_BOX_UNIT) */
    int texp;         /* X of the incremental unit's distances, 3..8; 0 = 8 (CBVH_FORMAT_BOX_UNIT) */
} cbvh_format_params;

#define CBVH_FORMAT_BOX_EXACT 0       /* unit 6: every plane distance exact, rounded once (docs/traversal.md §3) */
#define CBVH_FORMAT_BOX_INCREMENTAL 1 /* unit 10: Eq. 5, the parent's distances on the stack (§17) */

/* A pinhole camera's primary rays: origin `position`, direction dir(ctx, u,
 * v) through the image point (u, v) in [0, 1]^2 (u across, v down). */
typedef struct {
    int width, height; /* pixels */
    float position[3];
    void (*dir)(const void *ctx, float u, float v, float out[3]);
    const void *ctx;
} cbvh_format_pinhole;

/* Everything a build reads.  What the rays will be lets a format start them
 * further along (the traversal lists' heads, docs/tlist.md §7). */
typedef struct {
    const char *spec;               /* as cbvh_format_parse accepted it */
    cbvh_format_params p;
    const cbvh_scene *scene;        /* frame 0 (its morph targets and keys are not read) */
    float eps;                      /* secondary rays leave a hit point offset eps along its normal */
    float origin_max;               /* bound on |coordinate| of every camera-ray origin */
    const cbvh_format_pinhole *pinhole; /* camera rays come from this pinhole camera (must outlive the
                                           state); NULL: another camera */
} cbvh_format_input;

/* Where a traced ray comes from. */
typedef struct {
    uint32_t src_prim; /* the triangle it leaves from (on the ray's side); UINT32_MAX: a camera ray */
    int px, py;        /* a camera ray: its pixel */
} cbvh_format_from;

#define CBVH_FORMAT_USES_N 1u       /* built with N and min scale (the CBVH) */
#define CBVH_FORMAT_USES_MANT 2u    /* its boxes go through the M-bit ray-box unit */
#define CBVH_FORMAT_OPTIONS 4u      /* spelled name[:option...] */
#define CBVH_FORMAT_REFERENCE 8u    /* the float BVH, whose hits every format must return */
#define CBVH_FORMAT_STACK_UNIT 16u  /* its traversal runs the QBVH stack unit (unit 8) */
#define CBVH_FORMAT_BOX_UNIT 32u    /* takes the box unit (box_unit, texp): exact or incremental */

#define CBVH_FORMAT_NAME_MAX 48 /* a canonical spec with its terminating NUL */

typedef struct cbvh_format {
    const char *name;   /* "cbvh": --format's word, and the prefix of its options */
    const char *title;  /* in sentences: "CBVH hits differ from the float BVH" */
    const char *help;   /* "cbvh: the CBVH against the float BVH (default)"; may hold '\n' */
    const char *memory; /* what its bytes are: "node" or "list" */
    const char *build_note; /* what a build does: "QBVH: SAH build + 4-ary collapse" */
    const char *refit_note; /* appended for an animated scene: "; refits: ..." (or "") */
    unsigned flags;     /* CBVH_FORMAT_* */
    /* Formats with options: checks spec (name or name:option...) and writes
     * its canonical spelling (at most CBVH_FORMAT_NAME_MAX bytes); 0, or -1
     * with a one-line reason.  NULL: the spec is the name. */
    int (*parse)(const char *spec, char *canon, size_t n, char *err, size_t errlen);
    /* Its parameters in words: "N=6, M=24, min scale -30, modulo". */
    void (*describe)(const cbvh_format_params *p, char *out, size_t n);
    /* 0 with *state set, or -1 with a one-line reason (nothing to free). */
    int (*build)(const cbvh_format_input *in, void **state, cbvh_unit_activity *u, char *err, size_t errlen);
    /* The triangles moved (same count): update for them.  0 or -1 + reason. */
    int (*refit)(void *state, const cbvh_tri *tris, cbvh_unit_activity *u, char *err, size_t errlen);
    /* One ray, closest or any hit; counters added to *st.  0, or -1 (a ray
     * the units reject, a stack overflow): no hit. */
    int (*trace)(const void *state, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                 const cbvh_format_from *from, cbvh_trav_hit *hit, cbvh_trav_stats *st);
    /* Bytes of the hierarchy (and what else it stores per triangle). */
    uint64_t (*bytes)(const void *state);
    /* The units its traversals ran, from the counters summed over them. */
    void (*units)(const cbvh_trav_stats *sum, cbvh_unit_activity *u);
    void (*free)(void *state); /* a state a build returned */
} cbvh_format;

/* The formats, in the order of the table (the reference first); n = how many. */
const cbvh_format *const *cbvh_formats(size_t *n);

/* The format a spec names: its name exactly, or for a format with options
 * its name followed by anything (the format's parse judges the rest).  NULL
 * if none. */
const cbvh_format *cbvh_format_find(const char *spec);

/* cbvh_format_find and the format's parse: *f and the canonical spelling, or
 * -1 with a one-line reason (an unknown name: "format 'x': expected float,
 * cbvh, ..."). */
int cbvh_format_parse(const char *spec, const cbvh_format **f, char *canon, size_t n, char *err, size_t errlen);

/* The names as a list for messages: "float, cbvh, qbvh or tlist[:options]". */
void cbvh_format_names(char *out, size_t n);

#endif
