/* The accelerator's CBVH datapath units, bit-exact and integer-defined.
 *
 * Spec: docs/datapath.md.  Names here follow the spec:
 *   N          quant_bits, coordinate width (3..10)
 *   e          scale, grid step 2^e (one per axis and node)
 *   r^, s^     lb_mod / ub_mod, modulo coordinates (Eq. 8)
 *   r, s       relative coordinates (Eq. 1); s = 2^N is stored as 0
 *   u, v       clb / cub, decoded (quantized) bounds
 *
 * One unit per source file:
 *   scale_estimator.c   Eq. 2 scale of a float box (root and estimated contexts)
 *   axis_compressor.c   Fig. 5 single-axis compressor
 *   axis_decoder.c      Fig. 4 single-axis decoder, modulo and relative
 *   nodepair_codec.c    the node-pair memory format */
#ifndef CBVH_DATAPATH_H
#define CBVH_DATAPATH_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/fp32.h"

#define CBVH_DATAPATH_VERSION 1

#define CBVH_N_MIN 3
#define CBVH_N_MAX 10
#define CBVH_N_DEFAULT 6            /* the paper's N: 36 coordinate bits + leaf + 27-bit pointer = 64 */
#define CBVH_SCALE_FLOOR (-126)     /* finest grid the hardware represents */
#define CBVH_SCALE_CEIL 126         /* coarsest scale any finite box needs */
#define CBVH_MIN_SCALE_DEFAULT (-30) /* paper, Sec. 5.1 */

/* Unit parameters (fixed per design point / vector file). */
typedef struct {
    int quant_bits; /* N */
    int min_scale;  /* every scale is clamped to >= min_scale */
} cbvh_params;

typedef enum { CBVH_ENC_MODULO = 0, CBVH_ENC_RELATIVE = 1 } cbvh_encoding;

/* Status bits returned by every unit (0 = fine).  With any of the REJECT bits
 * set, every other output of the unit is zero. */
enum {
    CBVH_ST_NAN_INF = 1u << 0,      /* a float input is NaN or Inf (see spec for -Inf in contexts) */
    CBVH_ST_INVERTED = 1u << 1,     /* lb > ub, or decoded r >= s */
    CBVH_ST_BAD_SCALE = 1u << 2,    /* scale outside [min_scale, 126] or parent_scale < scale */
    CBVH_ST_BAD_PARAM = 1u << 3,    /* N or min_scale outside the supported range */
    CBVH_ST_BAD_CODE = 1u << 4,     /* a stored coordinate is >= 2^N */
    CBVH_ST_BAD_FORMAT = 1u << 5,   /* node pair: reserved bits set, malformed empty marker, pointer too wide */
    CBVH_ST_NO_FIT = 1u << 6,       /* compressor: box spans more than 2^N cells at this scale (not a reject) */
    CBVH_ST_OUTSIDE = 1u << 7,      /* compressor: box leaves its node's window of 2^N cells (not a reject);
                                     * the ray units use bit 7 for CBVH_ST_ZERO_DIR (traversal_units.h) */
};
#define CBVH_ST_REJECT (CBVH_ST_NAN_INF | CBVH_ST_INVERTED | CBVH_ST_BAD_SCALE | CBVH_ST_BAD_PARAM | CBVH_ST_BAD_CODE)

/* Validates N and min_scale: 0 or CBVH_ST_BAD_PARAM. */
uint32_t cbvh_params_check(const cbvh_params *p);

/* ---- Scale estimator (Eq. 2) ------------------------------------------- */
/* Smallest e >= min_scale such that the box, quantized by Eq. 1 on the
 * zero-aligned grid 2^e, spans at most 2^N cells:
 *     floor(ub / 2^e) + 1 - floor(lb / 2^e) <= 2^N. */
uint32_t cbvh_scale_estimate(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int *scale);

/* ---- Single-axis compressor (Fig. 5) and decoder (Fig. 4) -------------- */
/* What one axis of one child box compresses/decodes to. */
typedef struct {
    uint32_t lb_mod;  /* r^ = k mod 2^N (child lower grid coordinate at `scale`) */
    uint32_t ub_mod;  /* s^ = l mod 2^N, l = floor(ub / 2^e) + 1 */
    int child_scale;  /* Eq. 2 scale of this box's own child grid */
    cbvh_f32 clb;     /* u = RD(k * 2^e); -Inf encodes -2^128 */
    cbvh_f32 cub;     /* v = RU(l * 2^e) */
} cbvh_axis_code;

/* Traversal context of a node along one axis. */
typedef struct {
    int parent_scale; /* grid the node's own box is quantized on */
    int scale;        /* grid of the node's children (<= parent_scale) */
    uint32_t lb_mod;  /* node lower grid coordinate mod 2^N, at parent_scale */
    cbvh_f32 clb;     /* node decoded lower bound u; -Inf encodes -2^128 */
} cbvh_axis_ctx;

/* Compresses [lb, ub] on the grid 2^scale of the node whose decoded lower
 * bound is node_clb (its context's clb; -Inf = -2^128).  Status CBVH_ST_OUTSIDE
 * when the box leaves the node's window [g, g + 2^(N+scale)),
 * g = floor(node_clb / 2^scale) 2^scale: its codes would not decode to an
 * enclosing box under that node (docs/datapath.md §6).  A root, the only
 * child of a virtual node, passes its own lb. */
uint32_t cbvh_axis_compress(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int scale, cbvh_f32 node_clb,
                            cbvh_axis_code *out);

uint32_t cbvh_axis_decode(const cbvh_params *p, cbvh_encoding enc, const cbvh_axis_ctx *ctx, uint32_t lb_code,
                          uint32_t ub_code, cbvh_axis_code *out);

/* Validates a context: 0, or BAD_SCALE (scale < min_scale, parent_scale > 126,
 * parent_scale < scale), BAD_CODE (lb_mod >= 2^N), NAN_INF (clb NaN or +Inf;
 * -Inf encodes -2^128).  The decoder and the node-pair encoder apply it. */
uint32_t cbvh_axis_ctx_check(const cbvh_params *p, const cbvh_axis_ctx *ctx);

/* Stored codes of a compressed axis in the given encoding (relative: Eq. 1 with
 * s = 2^N stored as 0; modulo: the codes themselves). */
void cbvh_axis_store_codes(const cbvh_params *p, cbvh_encoding enc, const cbvh_axis_ctx *ctx,
                           const cbvh_axis_code *code, uint32_t *lb_code, uint32_t *ub_code);

/* Context of a child whose code was produced under ctx. */
cbvh_axis_ctx cbvh_axis_child_ctx(const cbvh_axis_ctx *ctx, const cbvh_axis_code *code);

/* Root context: the root box compressed at its estimated scale (one rule for
 * every scale, min_scale included). */
uint32_t cbvh_axis_root_ctx(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, cbvh_axis_ctx *ctx);

/* ---- Node-pair codec ----------------------------------------------------- */
typedef struct {
    cbvh_axis_ctx axis[3];
} cbvh_node_ctx;

typedef struct {
    cbvh_f32 lo[3], hi[3]; /* float box (x, y, z) */
    int leaf;              /* 1: ptr indexes the primitive-ID array */
    int empty;             /* 1: no child in this slot */
    uint32_t ptr;          /* child node-pair index, or first primitive-ID index */
} cbvh_child_in;

typedef struct {
    int leaf, empty;
    uint32_t ptr;
    cbvh_axis_code axis[3]; /* decoded box and child contexts */
} cbvh_child_out;

/* Node width W: 64 bits for N <= 6, 96 bits for N >= 7. */
int cbvh_node_bits(int quant_bits);
/* Bytes of one node pair: 16 (N <= 6) or 24. */
size_t cbvh_nodepair_bytes(int quant_bits);
/* Pointer field width P = min(32, W - 6N - 1); the all-ones value is reserved. */
int cbvh_node_ptr_bits(int quant_bits);

uint32_t cbvh_nodepair_encode(const cbvh_params *p, cbvh_encoding enc, const cbvh_node_ctx *ctx,
                              const cbvh_child_in child[2], uint8_t *bytes, cbvh_child_out out[2]);
uint32_t cbvh_nodepair_decode(const cbvh_params *p, cbvh_encoding enc, const cbvh_node_ctx *ctx,
                              const uint8_t *bytes, cbvh_child_out out[2]);

#endif
