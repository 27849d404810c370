/* Traversal core: closest-hit and any-hit over the float BVH (reference) and
 * the CBVH (decoding node pairs with the datapath units on the way), using
 * the bit-exact ray-box and ray-triangle units, with per-ray counters; and a
 * plain floating-point traversal of the float BVH for speed comparisons.
 * Spec: docs/traversal.md §5, §11. */
#ifndef CBVH_TRAVERSE_H
#define CBVH_TRAVERSE_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "cbvh/scene.h"
#include "cbvh/traversal_units.h"

#define CBVH_TRAV_STACK 256 /* entries; deeper trees are an error (-1) */
#define CBVH_LINE_BYTES 64

typedef struct cbvh_trav_stats {
    uint64_t nodes;      /* inner nodes whose node pair was fetched */
    uint64_t box_tests;  /* ray-box unit invocations (root box included) */
    uint64_t tri_tests;  /* ray-triangle unit invocations */
    uint64_t lines;      /* 64-byte lines fetched: node pairs, ID-array entries, triangles (no cache) */
    uint64_t bytes;      /* lines * 64 */
    uint32_t max_stack;  /* deepest stack occupancy */
    /* QBVH stack unit (unit 8) operations; 0 for the binary traversals. */
    uint64_t qstack_pushes; /* sort + push operations: one per inner node visited */
    uint64_t qstack_pops;   /* pop operations */
    /* The incremental ray-box unit (unit 10, cbvh_trace_cbvh_incr); 0 for the others. */
    uint64_t fp_box_hits;   /* children it hits that the exact unit (unit 6, same M) misses */
    uint64_t fp_tri_tests;  /* triangle tests in leaves reached through such a child */
} cbvh_trav_stats;

/* An observer of the traversals' memory reads, for a cache and timing model
 * (host/trace, docs/timing_model.md).  Every read the `lines` counter counts
 * is reported once: its kind, its byte address and size in the format's
 * memory image as hardware would store it (docs/traversal.md §5; the QBVH
 * reports its node as one 4-child record, docs/qbvh.md §3), and the ray's
 * counters so far (box and triangle tests before this read).  Kinds: a node
 * (node pair, QBVH node, list sphere element), primitive IDs (or a list's
 * triangle element: the entry that names the triangle), a triangle. */
typedef enum { CBVH_FETCH_NODE = 0, CBVH_FETCH_IDS = 1, CBVH_FETCH_TRI = 2 } cbvh_fetch_kind;
typedef struct {
    void (*fetch)(void *ctx, cbvh_fetch_kind kind, uint64_t addr, uint64_t size, const struct cbvh_trav_stats *so_far);
    void *ctx;
} cbvh_fetch_observer;

/* The observer every traversal reports to (NULL, the default: none; the
 * traversals then pay one test of a global per read).  Set it before tracing,
 * not while other threads trace; o must outlive its use. */
void cbvh_trav_set_observer(const cbvh_fetch_observer *o);
extern const cbvh_fetch_observer *cbvh_trav_observer;

typedef struct {
    int hit;
    uint32_t prim;       /* triangle index */
    cbvh_f32 t, b1, b2;  /* ray-triangle unit outputs of that triangle */
} cbvh_trav_hit;

/* Bit 0: any hit; bit 1: one-sided (a triangle counts only where
 * cbvh_tri_facing is +1: what back-face culling assumes). */
typedef enum {
    CBVH_TRAV_CLOSEST = 0,
    CBVH_TRAV_ANY = 1,
    CBVH_TRAV_FRONT_ONLY = 2,
    CBVH_TRAV_CLOSEST_FRONT = 2,
    CBVH_TRAV_ANY_FRONT = 3,
} cbvh_trav_mode;

/* Closest hit = the smallest (t bit pattern, triangle index) over all
 * triangles the ray-triangle unit hits with t in [tmin, tmax]; independent of
 * the visiting order because the box unit is conservative (§5).  Any hit = the
 * first such triangle found (hit = 1 iff one exists).
 * mant_bits is the box unit's M.  Stats are added to *st (not cleared).
 * 0, or -1 (stack overflow, decode error, ray rejected by a unit: NaN/Inf,
 * zero direction). */
int cbvh_trace_bvh(const cbvh_bvh *b, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits, cbvh_trav_mode mode,
                   cbvh_trav_hit *hit, cbvh_trav_stats *st);
int cbvh_trace_cbvh(const cbvh_tree *t, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits,
                    cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st);

/* The float BVH laid out for the plain floating-point traversal (what a
 * software renderer builds from it, as Embree builds its own): one 64-byte
 * record per inner node with both children's boxes, so one line is read per
 * node visited.  Records are in the BVH's depth-first order. */
#define CBVH_FBVH_LEAF 0x80000000u /* child entry of a leaf */
typedef struct {
    float box[12];       /* ((plane * 3) + axis) * 2 + child, plane 0 = lo, 1 = hi */
    uint32_t child[2];   /* inner child: record index; leaf: CBVH_FBVH_LEAF | its first primitive */
    uint32_t count[2];   /* leaf child: its primitive count; inner: 0 */
} cbvh_fbvh_node;

typedef struct {
    const cbvh_bvh *bvh; /* not owned: leaves, primitive IDs and the counters' addresses */
    cbvh_fbvh_node *nodes; /* 64-byte aligned */
    uint32_t nnodes;
    uint32_t root, root_count; /* the root as a child entry (child[], count[]) */
    float root_box[12];  /* the root's box as child 0 (child 1 a copy) */
} cbvh_fbvh;

/* 0, or -1 with a one-line reason (out of memory, not a tree, more than 2^31
 * nodes or primitives).  f->bvh points to b, which must outlive f. */
int cbvh_fbvh_build(const cbvh_bvh *b, cbvh_fbvh *out, char *err, size_t errlen);
void cbvh_fbvh_free(cbvh_fbvh *f);

/* Plain floating-point traversal of the float BVH (docs/traversal.md §11):
 * a conservative binary64 slab test (never a false miss) instead of the M-bit
 * box unit, the ray-triangle unit for triangles.  Same hit rules and counters
 * as cbvh_trace_bvh (addresses of the float BVH's own nodes), so the closest
 * hit is the same bit for bit and the any-hit flag the same; box tests and
 * visiting order are its own.  The software baseline a renderer would use;
 * 0, or -1 (stack overflow, a ray the units reject). */
int cbvh_trace_bvh_float(const cbvh_fbvh *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                         cbvh_trav_hit *hit, cbvh_trav_stats *st);

/* The instruction set of the wide float traversals' box tests
 * (cbvh_trace_qbvh_float, cbvh_trace_f8bvh_float; docs/traversal.md §15):
 * AVX when the library was built for x86-64 by GCC or Clang and the CPU
 * and OS support it, else the baseline (SSE2 or plain C).  Both run the same
 * binary64 operations per box, so hits, counters and visiting order are the
 * same.  cbvh_wide_float_limit_isa caps the choice (tests and benchmarks
 * compare the two; call it before tracing, not while other threads trace). */
typedef enum { CBVH_WIDE_ISA_BASE = 0, CBVH_WIDE_ISA_AVX = 1 } cbvh_wide_isa;
cbvh_wide_isa cbvh_wide_float_isa(void);
void cbvh_wide_float_limit_isa(cbvh_wide_isa max);
const char *cbvh_wide_isa_name(cbvh_wide_isa isa);

/* The precision of the wide float traversals' box lanes (docs/traversal.md
 * §16): binary32 (the default) where the ray and the tree's planes are
 * small enough for its error bound (magnitudes within 2^62), binary64
 * otherwise; cbvh_wide_float_box32(0) keeps every box on binary64 (tests
 * and benchmarks compare the two; set before tracing).  Either way never a
 * false miss, so the hits are the same; box-test counts may differ. */
void cbvh_wide_float_box32(int on);
int cbvh_wide_float_box32_on(void);

/* The CBVH decoded once (docs/traversal.md §12): per node pair, what
 * cbvh_trace_cbvh derives from it on every visit — both children's planes
 * u + r 2^e, u + s 2^e when every one is exact in binary64, their pointers
 * and leaf and empty bits; apart, the pair's context (u and e of each axis)
 * and the relative coordinates r, s for the box unit's fallback.  The
 * records come from the same decode (decode_fast.h) and the same context
 * derivation as the traversal's, so tracing with them gives
 * cbvh_trace_cbvh's outputs and counters bit for bit; only the decode's
 * repetition is gone.  The planes are kept in binary32 when every one is
 * exact there (one 64-byte line per pair: the traversal reads nothing else
 * unless the filter cannot decide), else in binary64 in a second array.
 * 64 + 40 bytes per pair, 96 more for a pair with binary64 planes (the CBVH
 * itself: 16 or 24). */
#define CBVH_DEC_LEAF0 1u  /* flags: child 0 a leaf, ... */
#define CBVH_DEC_EMPTY0 4u /* ... child 0 empty (child 1: the bit doubled) */
#define CBVH_DEC_EXACT 16u /* every plane exact in binary64: the binary64 box filter applies */
#define CBVH_DEC_F32 32u   /* with EXACT: every plane exact in binary32 too, kept in pl */
#define CBVH_DEC_2LINES 64u /* the pair's bytes in the CBVH's memory image span two lines (the counters) */
typedef struct {
    float pl[2][3][2];        /* [lower, upper][axis][child] with F32; an empty child's box is a dummy; else 0 */
    uint32_t child[2];        /* pointer: a pair index, or a leaf's first ID */
    uint32_t wide;            /* EXACT without F32: the planes' index in wide[]; else 0 */
    uint8_t flags;
    uint8_t pad[3];
} cbvh_cbvh_dnode;

typedef struct {
    double pl[2][3][2]; /* as in cbvh_cbvh_dnode, in binary64 */
} cbvh_cbvh_dwide;

typedef struct {
    uint16_t r[2][3], s[2][3]; /* [child][axis]; s in [1, 2^N]; an empty child: 0, 1 */
    cbvh_f32 clb[3];           /* u: the context's lower bound per axis */
    int8_t scale[3];           /* e: the context's scale per axis, in [-126, 126] */
    uint8_t pad;
} cbvh_cbvh_drel;

typedef struct {
    cbvh_f32 v[3][3]; /* the triangle's vertices */
    uint32_t id;      /* its ID as in the tree's ID array (CBVH_ID_LAST included) */
} cbvh_cbvh_dtri;

typedef struct {
    const cbvh_tree *tree;  /* not owned; must outlive the decoded copy */
    int usable;             /* 0: every pair is decoded on its visit (see cbvh_cbvh_decode) */
    cbvh_cbvh_dnode *nodes; /* npairs records, 64-byte aligned, indexed by pair */
    cbvh_cbvh_drel *rel;    /* npairs, indexed by pair */
    cbvh_cbvh_dwide *wide;  /* nwide binary64 plane sets, indexed by cbvh_cbvh_dnode.wide */
    uint32_t nwide;
    const cbvh_tri *leaf_src; /* the triangles copied into leaf_tris (cbvh_cbvh_decode_leaves), or NULL */
    cbvh_cbvh_dtri *leaf_tris; /* tree->nids records in ID order: a leaf's triangles side by side */
} cbvh_cbvh_decoded;

/* Decode every pair reachable from the root.  0, or -1 with a one-line reason
 * (out of memory).  usable = 0 (and tracing then decodes per visit, exactly as
 * cbvh_trace_cbvh) when the fast paths are compiled out, or when the tree is
 * one the traversal's fast decode does not take (parameters or a context it
 * does not check, a pair the node-pair unit would reject, a pointer out of
 * range, a pair reached twice): those trees keep every error and counter of
 * cbvh_trace_cbvh. */
int cbvh_cbvh_decode(const cbvh_tree *t, cbvh_cbvh_decoded *out, char *err, size_t errlen);

/* Optionally, the leaves too: a copy of each ID's triangle in ID order, so a
 * leaf's triangles are read side by side instead of through the ID array.
 * Tracing uses it when given the same tris pointer (which must not change
 * while the copy is in use) and reads tris otherwise.  0 (copy made, or not:
 * decoded copy not usable, an ID not below ntris), or -1 with a one-line
 * reason (out of memory).  40 bytes per ID. */
int cbvh_cbvh_decode_leaves(cbvh_cbvh_decoded *d, const cbvh_tri *tris, uint32_t ntris, char *err, size_t errlen);
void cbvh_cbvh_decoded_free(cbvh_cbvh_decoded *d);

/* cbvh_trace_cbvh(d->tree, ...) with the pairs' decodes taken from d: the same
 * return value, hit and counters (lines and bytes of the CBVH's own memory
 * image), bit for bit. */
int cbvh_trace_cbvh_decoded(const cbvh_cbvh_decoded *d, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits,
                            cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st);

/* Lines covered by [addr, addr + size). */
static inline uint64_t cbvh_lines_touched(uint64_t addr, uint64_t size) {
    return size ? (addr + size - 1) / CBVH_LINE_BYTES - addr / CBVH_LINE_BYTES + 1 : 0;
}

#endif
