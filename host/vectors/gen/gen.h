/* The vector generator's units (docs/vectors.md, "Generator"), private to
 * host/vectors: what every unit's file shares.
 *
 * One file per unit in host/vectors/gen/ holds all of that unit's cases --
 * structured and random (level 1 and level 2), the ray units' exact-path
 * cases and the cases appended by later generators -- and exports one
 * vg_unit; vecgen.c lists them in one table.  A new unit is one file here
 * and one table entry.  Everything here is integer-only: inputs are built as
 * binary32 bit patterns, so the files are identical on every host. */
#ifndef CBVH_HOST_VECGEN_GEN_H
#define CBVH_HOST_VECGEN_GEN_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/datapath.h"
#include "cbvh/fp32.h"
#include "vectors/vecgen.h"

/* ---- PRNG: splitmix64 seeds xoshiro256** --------------------------------- */

typedef struct {
    uint64_t s[4];
} rng_t;

static inline uint64_t splitmix64(uint64_t *x) {
    uint64_t z = (*x += UINT64_C(0x9E3779B97F4A7C15));
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}

static inline uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static inline uint64_t rng_next(rng_t *r) {
    uint64_t *s = r->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

static inline void rng_seed(rng_t *r, uint64_t seed) {
    for (int i = 0; i < 4; i++) r->s[i] = splitmix64(&seed);
}

/* Uniform in [0, n) (n > 0); the tiny modulo bias does not matter here. */
static inline uint64_t rnd_below(rng_t *r, uint64_t n) { return rng_next(r) % n; }
static inline int64_t rnd_range(rng_t *r, int64_t lo, int64_t hi) {
    return lo + (int64_t)rnd_below(r, (uint64_t)(hi - lo) + 1);
}

/* ---- binary32 patterns --------------------------------------------------- */

static inline cbvh_f32 neg(cbvh_f32 x) { return x ^ CBVH_F32_SIGN; }
static inline cbvh_f32 up(cbvh_f32 x) { return x == CBVH_F32_MAX ? x : cbvh_f32_next_up(x); }
static inline cbvh_f32 down(cbvh_f32 x) { return x == (CBVH_F32_MAX | CBVH_F32_SIGN) ? x : cbvh_f32_next_down(x); }
/* n * 2^e exactly (|n| < 2^24 and the value in range: the callers ensure it). */
static inline cbvh_f32 dyadic(int64_t n, int e) { return cbvh_f32_add_dyadic(n, e, 0, 0, CBVH_RND_DOWN); }

#define F_NEG_0_4 0xBECCCCCDu /* -0.4f: the cloth plane */
#define F_ONE 0x3F800000u
#define F_HALF 0x3F000000u
#define F_THIRD 0x3EAAAAABu
#define F_QNAN 0x7FC00000u
#define F_TWO40 0x53800000u /* 2^40 */
#define F_TWO24 0x4B800000u /* 2^24 */

/* NaNs (quiet, signalling, negative) and both infinities. */
#define N_NAN_INF 6
extern const cbvh_f32 vg_nan_inf[N_NAN_INF];

/* Random float with TestFloat-like structure: random sign, an exponent that
 * is often near the interesting ones, and a significand with runs of ones. */
cbvh_f32 vg_rnd_float(rng_t *r);

typedef struct {
    cbvh_f32 lo, hi;
} box_t;

/* A random box: a random float plus a random extent in ulps (often tiny). */
box_t vg_rnd_box(rng_t *r);
/* A random sub-box of [lo, hi] (finite, lo <= hi). */
box_t vg_rnd_sub_box(rng_t *r, box_t in);

/* ---- the vector list ------------------------------------------------------ */

typedef struct {
    const cbvh_vecgen_spec *spec;
    cbvh_layout lay;
    rng_t rng;
    uint32_t *in;
    size_t n, cap;
    int oom;
    int random_only; /* level 2's extra part: random cases only */
    uint64_t stream; /* the file's stream seed (seed ^ FNV-1a(stem)), for cases from streams of their own */
    int N;         /* quant_bits */
    int ms;        /* min_scale */
    uint32_t mask; /* 2^N - 1 */
} gen_t;

/* Appends one input vector (lay.n_in words, each cut to its field). */
void vg_emit(gen_t *g, const uint32_t *in);

static inline int valid_scale_word(int e) { return e >= -128 && e <= 127; }

/* ---- cases shared by several units ------------------------------------------- */

/* Structured boxes shared by the estimator and the compressor.  step thins
 * the pattern loops (1 = all). */
size_t vg_structured_boxes(box_t *out, size_t max, int step);
/* NaN/Inf bounds and inverted boxes, each passed to put with the scale. */
void vg_box_rejects(gen_t *g, void (*put)(gen_t *, cbvh_f32, cbvh_f32, int), int scale);

/* Root boxes for the decoder and node-pair chains. */
#define N_ROOT 14
extern const box_t vg_root_boxes[N_ROOT];

/* Ray origins and directions along one axis, shared by the ray-box and
 * ray-sphere units. */
#define N_RB_ORIG 8
#define N_RB_DIR 8
extern const cbvh_f32 vg_ray_orig[N_RB_ORIG], vg_ray_dir[N_RB_DIR];

/* x + j 2^e rounded in direction mode, for a finite x or -Inf (-2^128):
 * integer-only, through the model's exact sum. */
cbvh_f32 vg_add_cells(cbvh_f32 x, int64_t j, int e, cbvh_rnd mode);

/* A node context's window at its child scale (datapath.md §6): its first and
 * last binary32 and the first past it (has_past 0: the window reaches past
 * FLT_MAX). */
typedef struct {
    cbvh_f32 first, last, past;
    int has_past;
} vg_window;
vg_window vg_window_of(const cbvh_axis_ctx *c, int n);

/* Exact-path helpers (see vg_unit.exact): a random odd integer with exactly
 * `bits` bits (bits >= 2); a random normal float of either sign with
 * exponent in [elo, ehi]; x nudged by one ulp either way, or unchanged (2 in 3). */
int64_t vg_rnd_odd_bits(rng_t *r, int bits);
cbvh_f32 vg_rnd_f32_in(rng_t *r, int elo, int ehi);
cbvh_f32 vg_nudge(rng_t *r, cbvh_f32 x);

/* ---- one unit's generator ------------------------------------------------------ */

typedef struct {
    const char *unit; /* its name in the unit table (cbvh/unit_table.h) */
    /* The size of a level-1 file before the appended cases (the committed
     * set stays small). */
    size_t level1;
    /* Level 1's structured cases (unless g->random_only), then random cases
     * until g->n reaches target; level 2 calls it again with random_only. */
    void (*gen)(gen_t *g, size_t target);
    /* Generator 2, ray units: the exact-path cases (docs/vectors.md,
     * "Exact-path cases"), n_exact of them at level 1.  The ray units' fast
     * paths and binary64 filters decide most inputs; an RTL implementation
     * has only the exact datapath, and its hard cases are the ones the
     * filters leave to the model's exact path: exact ties (a ray through an
     * edge or vertex, a tangent, a segment ending on a sphere), quotients
     * that are exactly representable or land on the M-bit grid, results next
     * to the binary32 subnormal border, and planes or origins beyond 62-bit
     * fixed point.  These are built constructively from small integers
     * scaled by powers of two, so every case is exact by construction (not
     * selected by running the model: the files do not depend on the model's
     * fast paths), from a stream of their own so the random part before and
     * level 2's part after are those of generator 1.
     * tests/vectors/test_exact_paths.c checks how many of them reach the
     * exact path.  NULL for the other units. */
    void (*exact)(gen_t *g, rng_t *rng, int count);
    int n_exact;
    /* Cases appended after the level-1 part, with no random draws from the
     * file's stream: generator 3's reject combinations and the structured
     * cases of later generators.  Which status bits an input with several
     * faults at once gets (a NaN bound and a bad scale, a bad code in an
     * inverted child, ...) is each unit's own rule: one bit from an order of
     * checks for the axis units, the QBVH stack and the triangle unit, an OR
     * with stated exceptions for the node pairs, the ray-box and the sphere
     * unit (datapath.md §9-§10, traversal.md §3, §4, §10.2, qbvh.md §2).
     * Generators 1 and 2 had (almost) single faults only, so independent RTL
     * that chose other rules passed them (docs/gateware.md). */
    void (*appended)(gen_t *g);
    /* The default set: one file per N = 3..10 (per_n), else N = 6 only (the
     * unit's results depend on neither N nor min_scale); extra_min_scales
     * adds N = 6 with min_scale -126 and -10. */
    int per_n, extra_min_scales;
} vg_unit;

#endif
