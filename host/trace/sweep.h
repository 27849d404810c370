/* Accuracy vs time (docs/sweep.md): trace a scene's effects on the float BVH
 * and on the CBVH for every setting (coordinate bits N x ray-box mantissa M x
 * minimum scale E), on the same rays in one run, and prove every setting
 * returns the float BVH's hits ray by ray (same triangle and t bits for
 * closest-hit rays, same answer for any-hit rays: no false misses) and renders
 * the same image.  Optionally other formats — the QBVH (docs/qbvh.md), the
 * traversal lists (docs/tlist.md) — are traced on the same rays as more rows
 * (they have no N) and checked the same way.  The output side (table, JSON, chart, heat maps) is
 * host/cli/cmd_sweep.c. */
#ifndef CBVH_HOST_SWEEP_H
#define CBVH_HOST_SWEEP_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/format.h"
#include "trace/effects.h"
#include "scene/scene_file.h"
#include "trace/timing_model.h"

#define CBVH_SWEEP_MAX_LIST 16 /* values of --mant and of --min-scale */
#define CBVH_SWEEP_MAX_EXTRA 12 /* other formats (--formats) */

/* One more format traced after the CBVH settings, at the first M: any
 * format of the table (cbvh/format.h) but the float BVH (the reference) and
 * the CBVH (the swept one, the format with N). */
typedef struct {
    const cbvh_format *ops;
    char name[CBVH_FORMAT_NAME_MAX]; /* canonical: "qbvh", "tlist:6:earliest:cull:heads", ... */
} cbvh_sweep_format;

/* The other format a word of --formats or --heatmap names (its name, or its
 * name and options: cbvh_format_find), or NULL. */
const cbvh_format *cbvh_sweep_format_find(const char *spec);
/* cbvh_sweep_format_find and the format's options into *f: 0, or -1 with a
 * one-line reason. */
int cbvh_sweep_format_parse(const char *spec, cbvh_sweep_format *f, char *err, size_t errlen);
/* The syntax of --formats for messages: "cbvh[,qbvh][,tlist[:options]...]". */
void cbvh_sweep_formats_syntax(char *out, size_t n);
/* A format's label in rows and messages: its name, and " M=24" for a format
 * whose boxes go through the M-bit ray-box unit. */
void cbvh_sweep_format_label(const cbvh_sweep_format *f, int mant, char *out, size_t n);
/* How the hits line names the other formats: "" (none), " and the QBVH"
 * (one, without options: its title), " and the other formats". */
const char *cbvh_sweep_others(const cbvh_sweep_format *extra, int nextra, char *buf, size_t n);

typedef struct {
    int bits; /* N; 0 = the float BVH */
    int mant; /* M of the ray-box unit */
    int min_scale;
    int box_unit; /* index into cbvh_box_units: the CBVH rows' (--box-unit), 0 for other formats */
} cbvh_sweep_setting;

typedef struct {
    int bits_lo, bits_hi;
    int mant[CBVH_SWEEP_MAX_LIST], nmant;
    int min_scale[CBVH_SWEEP_MAX_LIST], nmin_scale;
    int spp; /* 0 = the scene's */
    cbvh_sweep_format extra[CBVH_SWEEP_MAX_EXTRA]; /* traced after the CBVH settings (M = mant[0]) */
    int nextra;
    int one_sided; /* triangles count only from their front side, every format (required by tlist culling) */
    /* The timing model's caches: every setting is traced once with ncaches
     * cache sizes in KB (0: none, INFINITY) of cache_ways ways; then `reps`
     * more times without them for the CPU-time column (0: none). */
    double cache_kb[CBVH_CACHES_MAX];
    int ncaches, cache_ways;
    int reps;
    /* The CBVH rows' box units (cbvh_format_params, indices into
     * cbvh_box_units, each once; none: exact): exact, and/or incremental at
     * X = texp.  The units are a dimension of the rows, outside M and E. */
    int box_unit[CBVH_BOX_UNITS], nbox_unit, texp;
    /* Test hook: pretend setting `corrupt_setting` (index into rows, nrows +
     * k = extra format k, -1 = none) returned a wrong answer for ray `corrupt_ray` (t off by one ulp
     * for a closest hit, the opposite answer for an any-hit ray); a ray the
     * float BVH did not trace is an error of cbvh_sweep_run. */
    int corrupt_setting;
    uint64_t corrupt_ray;
    /* Progress: setting (1-based; 0 the float BVH) of settings, camera row of
     * rows; rep: 0 for the traced pass, then the timed repetition 1..reps. */
    void (*progress)(void *ctx, const char *label, int setting, int settings, int row, int rows, int rep);
    void *ctx;
} cbvh_sweep_opts;

/* One traced configuration (the float reference or a CBVH setting). */
typedef struct {
    cbvh_sweep_setting s;
    cbvh_fx_result r;
    double *box_px; /* width*height: box tests of the primary rays per pixel (frame 0, mean over samples) */
    double *tri_px; /* width*height: their triangle tests, likewise */
    uint8_t *image; /* width*height grey: shaded primary hits (frame 0, mean over samples) */
    /* Identity with the float reference (always 1 for the reference itself). */
    int same;
    uint64_t bad_ray; /* index of the first differing ray (in trace order) */
    int bad_px, bad_py, bad_frame;
    cbvh_effect bad_fx;
    char why[200]; /* one line naming the first difference */
} cbvh_sweep_run_t;

typedef struct {
    int width, height, spp, frames;
    uint64_t ref_rays;   /* rays the float reference traced */
    cbvh_sweep_run_t ref; /* float BVH */
    cbvh_sweep_run_t *rows; /* nrows CBVH settings: for each box unit, each M, each E, each N ascending */
    int nrows;
    int nextra;
    cbvh_sweep_run_t extra[CBVH_SWEEP_MAX_EXTRA]; /* the other formats' rows (s.bits = 0, s.mant = M) */
    int all_same; /* every CBVH setting and every other format */
} cbvh_sweep_result;

/* 0, or -1 with a one-line reason (bad option, build failure). */
int cbvh_sweep_run(const cbvh_scene_desc *d, const cbvh_sweep_opts *o, cbvh_sweep_result *res, char *err,
                   size_t errlen);
void cbvh_sweep_free(cbvh_sweep_result *res);

/* Per-ray costs of a set of rays (cbvh_ray_metrics_of on machine mc)
 * indexed for the sweep's loops over costs. */
enum { SWEEP_BOX = 0, SWEEP_TRI, SWEEP_BYTES, SWEEP_MODEL_NS, SWEEP_CPU_US, SWEEP_ENERGY, SWEEP_NMETRICS };
void cbvh_sweep_per_ray(const cbvh_fx_stats *s, const cbvh_machine *mc, double out[SWEEP_NMETRICS]);

/* The Pareto front of n points of three costs to minimise (time, energy,
 * area): front[i] = 1 iff no other point is at most as costly in all three
 * and cheaper in one.  A point with a NaN cost is never on it nor dominates;
 * equal points are all on it. */
void cbvh_pareto_front(const double (*cost)[3], int n, int *front);

/* The index of the smallest finite value of v[0..n) (ties: the first), -1
 * if none. */
int cbvh_argmin(const double *v, int n);

/* The knee of one cost curve: rel[i] is the relative cost at bits[i]
 * (ascending).  Returns the smallest bits[k] such that rel[j] <= (1 + tol) *
 * rel[n-1] for every j >= k: from N = knee on, more bits buy less than tol of
 * the cost.  n >= 1.  0 when a ratio is not finite (NaN: the float BVH and
 * the setting did none; infinity: only the setting did some): no knee. */
int cbvh_sweep_knee(const int *bits, const double *rel, int n, double tol);

#endif
