/* The plain floating-point traversal of a wide float BVH, written once for
 * the 4-wide records of traverse_qbvh_float.c (docs/traversal.md §13) and
 * the 8-wide ones of traverse_f8bvh_float.c (§14).  Internal.
 *
 * A record of width W is {float pl[6W]; uint32_t child[W]; uint16_t count[W];
 * uint32_t valid; padding}: the children's planes at ((plane * 3) + axis) * W
 * + child, their entries (inner: record index; leaf: WIDE_LEAF | first) and
 * counts, and the mask of slots in use.  Boxes go through the plain float
 * traversal's conservative binary64 slab test (cbvh_ref_box4 / box8: the
 * same operations per box as cbvh_ref_box2_c, so the same proof: never a
 * false miss); triangles through the ray-triangle unit, so the closest hit
 * is the units' bit for bit. */
#ifndef CBVH_TRAVERSE_WIDE_FLOAT_H
#define CBVH_TRAVERSE_WIDE_FLOAT_H

#include <stddef.h>
#include <stdint.h>

#include "fast/ray_box_ref.h"
#include "traverse/traverse_common.h"
#include "traverse/traverse_plain.h"

#define WIDE_LEAF 0x80000000u

/* a width-W record's size (two 64-byte lines per four children) and its
 * fields' byte offsets */
#define WIDE_REC_BYTES(W) ((size_t)(W) * 32u)
#define WIDE_CHILD_AT(W) ((size_t)(W) * 24u)
#define WIDE_COUNT_AT(W) ((size_t)(W) * 28u)
#define WIDE_VALID_AT(W) ((size_t)(W) * 30u)

typedef struct {
    const unsigned char *recs; /* nrecs records of WIDE_REC_BYTES(W) */
    uint32_t nrecs;
    uint32_t root, root_count;   /* the root as a child entry */
    const float *root_box;       /* as child 0 and 1 of a pair (cbvh_ref_box2) */
    const cbvh_cbvh_dtri *leaf_tris; /* the leaf copy of leaf_src, or NULL */
    const cbvh_tri *leaf_src;
    const uint32_t *prims; /* the primitive array the leaves index */
    uint32_t nprims;
    int small_planes; /* every plane's magnitude <= 2^62 (the binary32 lanes may run) */
} wide_tree;

/* Bits set in a mask of W bits (the x86-64 baseline has no popcount
 * instruction: 4-bit lookups) and its lowest set bit: for W = 4 one lookup,
 * for W = 8 without a branch (m & -m isolates the bit, and 0x1D is a de
 * Bruijn sequence B(2, 3), so bits 5..7 of the product name it uniquely; a
 * branch on the low nibble cost the 8-wide traversal about 3 %). */
static const uint8_t wide_ones4[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
static const uint8_t wide_low4[16] = {0, 0, 1, 0, 2, 0, 1, 0, 3, 0, 1, 0, 2, 0, 1, 0};
static const uint8_t wide_debruijn8[8] = {0, 1, 6, 2, 7, 5, 4, 3};

static inline int wide_ones(int W, unsigned m) {
#ifdef __POPCNT__
    (void)W;
    return __builtin_popcount(m);
#else
    return W == 4 ? wide_ones4[m & 15u] : wide_ones4[m & 15u] + wide_ones4[m >> 4 & 15u];
#endif
}
static inline int wide_low(int W, unsigned m) {
#ifdef __POPCNT__
    (void)W;
    return __builtin_ctz(m);
#else
    return W == 4 ? wide_low4[m & 15u] : wide_debruijn8[(m & (0u - m)) * 0x1Du >> 5 & 7u];
#endif
}

/* The traversal (W = 4 or 8, a constant at each call): the nearest hit child
 * is visited next without a push, the others pushed farthest first (ties by
 * slot); max_stack counts the visited entry.  Counters: nodes = records
 * visited, box tests = their slots in use plus one for the root,
 * WIDE_REC_BYTES(W) per record. */
static inline int wide_trace(int W, const wide_tree *f, const cbvh_tri *tris, const cbvh_ray *ray,
                             cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    trav_state ts;
    if (trav_begin(&ts, hit, ray, CBVH_MANT_MAX, tris, mode, (uint64_t)f->nrecs * WIDE_REC_BYTES(W), f->nprims))
        return -1;
    cbvh_ref_ray r;
    r.tmin = 0, r.tmin32 = 0; /* each set below where read (GCC cannot tell) */
    int small = 0; /* the binary32 lanes run (§16), the root test too; no binary64 preparation */
    if (f->small_planes && cbvh_wide_float_box32_on()) {
        cbvh_ref_prepare32(ray, &r);
        small = r.small;
    }
    if (!small) cbvh_ref_prepare(ray, &r);
    const cbvh_cbvh_dtri *lt = f->leaf_tris && f->leaf_src == tris ? f->leaf_tris : NULL;
    const unsigned char *recs = f->recs;
    plain_entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    uint64_t nodes = 0, boxes = 0;
    double cull;
    int have = plain_root(&ts, &r, f->root_box, &cull);
    double tl[8];
    uint32_t e = f->root, cnt = f->root_count;
    if (have) max_stack = 1;
    while (have) {
        if (e & WIDE_LEAF) {
            if (plain_leaf(&ts, e & ~WIDE_LEAF, cnt, lt, f->prims, &cull)) break;
        } else {
            /* the record's fields (through void *: they are the struct's members) */
            const unsigned char *n = recs + (size_t)e * WIDE_REC_BYTES(W);
            const float *pl = (const void *)n;
            const uint32_t *child = (const void *)(n + WIDE_CHILD_AT(W));
            const uint16_t *count = (const void *)(n + WIDE_COUNT_AT(W));
            unsigned valid = *(const uint32_t *)(const void *)(n + WIDE_VALID_AT(W));
            nodes++;
            boxes += (uint64_t)wide_ones(W, valid);
            unsigned m;
            if (r.general) {
                int hh[8];
                cbvh_ref_boxw_any(&r, pl, W, cull, hh, tl);
                m = 0;
                for (int c = 0; c < W; c++) m |= (unsigned)hh[c] << c;
            } else if (small) {
                m = (unsigned)(W == 4 ? cbvh_ref_box4_32(&r, pl, (float)cull, tl)
                                      : cbvh_ref_box8_32(&r, pl, (float)cull, tl));
            } else {
                m = (unsigned)(W == 4 ? cbvh_ref_box4(&r, pl, cull, tl) : cbvh_ref_box8(&r, pl, cull, tl));
            }
            m &= valid;
            int nh = wide_ones(W, m), next;
            if (sp + nh > CBVH_TRAV_STACK) return -1;
            if (nh == 0) {
                have = plain_pop(stack, &sp, cull, &e, &cnt);
                continue;
            } else if (nh == 1) {
                next = wide_low(W, m);
            } else if (nh == 2) { /* the common case: one comparison (ties: the lower slot first) */
                int a = wide_low(W, m), b = wide_low(W, m & (m - 1));
                if (tl[b] < tl[a]) {
                    next = b;
                    b = a;
                } else {
                    next = a;
                }
                plain_push(stack, &sp, child[b], count[b], tl[b]);
                if (!(child[b] & WIDE_LEAF)) __builtin_prefetch(recs + (size_t)child[b] * WIDE_REC_BYTES(W));
            } else { /* by t_lo, ties by slot (insertion sort in slot order) */
                int ord[8] = {0}, k = 0;
                for (unsigned mm = m; mm; mm &= mm - 1) {
                    int c = wide_low(W, mm), j = k++;
                    while (j > 0 && tl[ord[j - 1]] > tl[c]) {
                        ord[j] = ord[j - 1];
                        j--;
                    }
                    ord[j] = c;
                }
                for (int j = k - 1; j > 0; j--) {
                    int c = ord[j];
                    plain_push(stack, &sp, child[c], count[c], tl[c]);
                    if (!(child[c] & WIDE_LEAF)) __builtin_prefetch(recs + (size_t)child[c] * WIDE_REC_BYTES(W));
                }
                next = ord[0];
            }
            if ((uint32_t)sp + 1u > max_stack) max_stack = (uint32_t)sp + 1u;
            e = child[next];
            cnt = count[next];
            if (!(tl[next] > cull)) continue; /* the pop's cull check (rounding can leave t_lo above cull) */
        }
        have = plain_pop(stack, &sp, cull, &e, &cnt);
    }
    plain_finish(&ts, nodes, boxes, nodes * (WIDE_REC_BYTES(W) / CBVH_LINE_BYTES), max_stack, hit, st);
    return 0;
}

/* The loop compiled for AVX (traverse_wide_float_avx.c, built with -mavx
 * where the compiler targets x86-64 and defines CBVH_WIDE_AVX) for W = 4
 * and 8, and the choice between it and this build's (wide_isa.c). */
#ifdef CBVH_WIDE_AVX
int cbvh_wide_trace_avx4(const wide_tree *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                         cbvh_trav_hit *hit, cbvh_trav_stats *st);
int cbvh_wide_trace_avx8(const wide_tree *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                         cbvh_trav_hit *hit, cbvh_trav_stats *st);
#endif

static inline int wide_trace_isa(int W, const wide_tree *f, const cbvh_tri *tris, const cbvh_ray *ray,
                                 cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
#ifdef CBVH_WIDE_AVX
    if (cbvh_wide_float_isa() == CBVH_WIDE_ISA_AVX)
        return W == 4 ? cbvh_wide_trace_avx4(f, tris, ray, mode, hit, st)
                      : cbvh_wide_trace_avx8(f, tris, ray, mode, hit, st);
#endif
    return wide_trace(W, f, tris, ray, mode, hit, st);
}

#endif
