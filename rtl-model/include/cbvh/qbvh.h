/* QBVH (seed 000, Bogolepov & Ulyanov): a binned-SAH binary BVH collapsed
 * into a 4-ary BVH whose siblings are contiguous, traversed with the paper's
 * compressed 32-bit stack entry.  Spec: docs/qbvh.md. */
#ifndef CBVH_QBVH_H
#define CBVH_QBVH_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/bvh.h"
#include "cbvh/qbvh_stack.h" /* the stack unit: its entry layout and ID limit */
#include "cbvh/traverse.h"

/* ---- the QBVH (rtl-model/src/qbvh/build_qbvh.c) --------------------------------
 * Structure of arrays, node 0 = root (its own box in bmin/bmax[0]).  Node i:
 *   inner: children first[i] .. first[i]+count[i]-1 (2..4), contiguous
 *   leaf (count[i] & CBVH_QBVH_LEAF): primitives prims[first[i] ..
 *         first[i] + (count[i] & ~CBVH_QBVH_LEAF)).
 * Memory image (bytes): bmin, bmax as 16-byte float4 (x, y, z, pad) and the
 * info pair (first, count) as 8 bytes: 40 bytes per node. */
#define CBVH_QBVH_LEAF 0x80000000u
#define CBVH_QBVH_NODE_BYTES 40u

typedef struct {
    uint32_t nnodes;
    float (*bmin)[4], (*bmax)[4];
    uint32_t *first, *count;
    uint32_t *prims; /* triangle indices, grouped by leaf */
    uint32_t nprims;
    uint32_t max_first; /* largest first-child ID of an inner node (0 if none) */
    uint32_t depth;     /* levels below the root (0: the root is a leaf) */
} cbvh_qbvh;

void cbvh_qbvh_free(cbvh_qbvh *q);

/* Collapse a binary BVH (any builder; the paper uses cbvh_build_sah) into a
 * QBVH: each node takes up to 4 children by repeatedly opening the inner
 * child of largest surface area (of equal areas, the leftmost); children
 * keep the binary left-to-right order and are laid out breadth-first.  0, or
 * -1 + one-line reason. */
int cbvh_qbvh_from_bvh(const cbvh_bvh *b, cbvh_qbvh *out, char *err, size_t errlen);

/* Structure check: every node reachable once, counts 2..4, every primitive in
 * one leaf, boxes enclose children / triangles.  0 or -1 + reason. */
int cbvh_qbvh_check(const cbvh_qbvh *q, const cbvh_scene *s, char *err, size_t errlen);

/* Bytes of the node arrays (CBVH_QBVH_NODE_BYTES per node). */
size_t cbvh_qbvh_node_bytes(const cbvh_qbvh *q);

/* ---- refit (rtl-model/src/qbvh/refit_qbvh.c) -------------------------------
 * The QBVH's own boxes recomputed bottom-up for moved vertices (same triangle
 * count), topology kept: no re-collapse.  One pass from the last node to the
 * root, which sees every child before its parent because children lie after
 * their parent (breadth-first, as cbvh_qbvh_from_bvh lays them out; checked
 * once by cbvh_qbvh_refit_check: 0, or -1 + reason).  Returns the number of
 * node boxes recomputed (every node). */
int cbvh_qbvh_refit_check(const cbvh_qbvh *q, char *err, size_t errlen);
uint64_t cbvh_qbvh_refit(cbvh_qbvh *q, const cbvh_tri *tris);

/* ---- traversal (rtl-model/src/qbvh/traverse_qbvh.c) ---------------------------- */
typedef enum {
    CBVH_QSTACK_AUTO = 0,       /* compressed 32-bit if the tree fits 2^26, else wide */
    CBVH_QSTACK_COMPRESSED = 1, /* the paper's 32-bit entry (the unit); error past 2^26 */
    CBVH_QSTACK_WIDE = 2,       /* 64-bit entry, same algorithm */
    CBVH_QSTACK_PLAIN = 3,      /* one node ID per entry (comparison) */
} cbvh_qstack_kind;

/* 0, or -1 + reason if `kind` cannot address this tree (compressed entry and
 * a first-child ID >= 2^26). */
int cbvh_qbvh_stack_check(const cbvh_qbvh *q, cbvh_qstack_kind kind, char *err, size_t errlen);

/* Closest hit / any hit with the ray-box unit (float boxes, M = mant_bits)
 * and the ray-triangle unit; same result definition as cbvh_trace_bvh
 * (docs/traversal.md §5), so the closest hit equals the binary BVH's bit for
 * bit.  Stats: nodes = inner nodes visited, max_stack = deepest number of
 * stack entries (deferred work only).  0, or -1 (ray rejected, stack
 * overflow, or the tree does not fit the stack kind). */
int cbvh_trace_qbvh(const cbvh_qbvh *q, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits,
                    cbvh_trav_mode mode, cbvh_qstack_kind kind, cbvh_trav_hit *hit, cbvh_trav_stats *st);

/* ---- plain floating-point traversal of the QBVH (rtl-model/src/qbvh/traverse_qbvh_float.c)
 * What a software renderer runs on the float BVH collapsed 4-wide
 * (docs/traversal.md §13): one 128-byte record per inner node with its
 * children's four boxes as [lower, upper][axis][child] binary32, tested by
 * the conservative binary64 slab test of the plain float traversal
 * (cbvh_trace_bvh_float; four lanes, never a false miss) or its binary32
 * lanes where the ray and planes allow (docs/traversal.md §16), triangles by
 * the ray-triangle unit.  Same hit rules as cbvh_trace_bvh, so the closest hit
 * equals it bit for bit (ties go to the lowest primitive ID whatever the
 * order) and the any-hit flag too. */
#define CBVH_FQBVH_LEAF 0x80000000u /* child entry of a leaf: | its first index into prims */
typedef struct {
    float pl[24];       /* plane (0 lower, 1 upper) of axis a of child c at ((plane * 3) + a) * 4 + c */
    uint32_t child[4];  /* inner child: record index; leaf: CBVH_FQBVH_LEAF | first */
    uint16_t count[4];  /* leaf child: its primitive count (1 .. 65535); inner: 0 */
    uint32_t valid;     /* bit c: slot c holds a child (2 to 4 do) */
    uint32_t pad;
} cbvh_fqbvh_node;

typedef struct {
    const cbvh_qbvh *q;     /* not owned */
    cbvh_fqbvh_node *nodes; /* 64-byte aligned, one per inner node, breadth-first */
    uint32_t nnodes;
    uint32_t root, root_count; /* the root as a child entry */
    float root_box[12];        /* the root's box as child 0 and 1 of a pair (cbvh_ref_box2) */
    const cbvh_tri *leaf_src;  /* the triangles copied into leaf_tris, or NULL */
    cbvh_cbvh_dtri *leaf_tris; /* q->nprims records in prims order: a leaf's triangles side by side */
    int small_planes;          /* every plane's magnitude <= 2^62: the binary32 box lanes may run (§16) */
} cbvh_fqbvh;

/* 0, or -1 with a one-line reason (out of memory, a leaf of more than 65535
 * primitives, more than 2^31 nodes).  f->q points to q, which must outlive
 * f.  With tris (ntris triangles), each leaf's triangles are also copied
 * next to their IDs (q->nprims * 40 bytes); tracing reads the copy only
 * when given the same tris pointer.  NULL: no copy. */
int cbvh_fqbvh_build(const cbvh_qbvh *q, const cbvh_tri *tris, uint32_t ntris, cbvh_fqbvh *out, char *err,
                     size_t errlen);
void cbvh_fqbvh_free(cbvh_fqbvh *f);

/* Stats: nodes = inner nodes visited, box tests = their children (2..4),
 * 128 bytes (two lines) per node; 0, or -1 (stack overflow, a ray the units
 * reject). */
int cbvh_trace_qbvh_float(const cbvh_fqbvh *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                          cbvh_trav_hit *hit, cbvh_trav_stats *st);

#endif
