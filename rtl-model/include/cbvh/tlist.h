/* Stackless traversal lists over a bounding-sphere hierarchy (seed 004,
 * Toczek, Houzet, Mancini 2010).  Spec: docs/tlist.md.
 *
 *   rtl-model/src/build_bsh.c       the bounding-sphere hierarchy (octree-like
 *                                   top-down split; big triangles stay at the node)
 *   rtl-model/src/build_tlists.c    flattening into 1, 2, 6 or 8 depth-first lists
 *                                   with relative escape indices
 *   rtl-model/src/tlist_heads.c     per-polygon and per-screen-cell list heads
 *   rtl-model/src/traverse_tlist.c  the stackless traversal loop
 *   rtl-model/src/ray_sphere.c      the ray-sphere unit (unit 9, in libcbvh) */
#ifndef CBVH_TLIST_H
#define CBVH_TLIST_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/scene.h"
#include "cbvh/traverse.h"

/* ---- the bounding-sphere hierarchy ----------------------------------------
 * Node i: sphere (centre = centre of the tight box of its triangles, radius =
 * smallest enclosing every vertex of them, rounded so the binary32 sphere
 * encloses them exactly); child nodes child[first_child[i] ..
 * first_child[i] + nchild[i]); triangles kept at the node tri_ids[first_tri[i]
 * .. first_tri[i] + ntri[i]) (the big ones, or all of a leaf's). */
typedef struct {
    uint32_t leaf_max;  /* a node with at most this many triangles is a leaf (default 4) */
    uint32_t big_ratio; /* a triangle stays at the node when its bounding radius * big_ratio
                           >= the node's radius (default 2: bigger than half the node) */
    uint32_t max_depth; /* split limit (default 32) */
} cbvh_bsh_params;

typedef struct {
    uint32_t nnodes;
    cbvh_f32 (*sphere)[4]; /* cx, cy, cz, r (binary32 bit patterns) */
    uint32_t *first_child, *nchild; /* children are contiguous in node order */
    uint32_t *first_tri, *ntri;
    uint32_t *tri_ids;
    uint32_t ntri_ids;
    uint32_t depth;
} cbvh_bsh;

void cbvh_bsh_default_params(cbvh_bsh_params *p);
int cbvh_bsh_build(const cbvh_scene *s, const cbvh_bsh_params *p, cbvh_bsh *out, char *err, size_t errlen);
/* Every triangle exactly once; every sphere encloses its triangles' vertices
 * and its children's spheres' contents (checked on vertices).  0 or -1 + reason. */
int cbvh_bsh_check(const cbvh_bsh *h, const cbvh_scene *s, char *err, size_t errlen);
void cbvh_bsh_free(cbvh_bsh *h);

/* ---- the lists ------------------------------------------------------------
 * Element: a 32-bit relative escape index + a 128-bit word (the paper's
 * layout, 20 bytes).  escape == 1: a triangle (data[0] = triangle index);
 * escape == 0: the last element, a triangle; escape >= 2: a sphere
 * (data = cx, cy, cz, r), whose subtree ends just before element i + escape;
 * escape == -1: a sphere with no super-sibling (a miss ends the traversal). */
#define CBVH_TLIST_ELEM_BYTES 20u
#define CBVH_TLIST_MAX 8

typedef struct {
    int32_t escape;
    uint32_t data[4];
} cbvh_tlist_elem;

typedef enum { CBVH_TLIST_EARLIEST_FIRST = 0, CBVH_TLIST_LATEST_LAST = 1 } cbvh_tlist_order;

typedef struct {
    int nlists;              /* 1, 2, 6 (sextants) or 8 (octants) */
    cbvh_tlist_order order;
    int cull_back;           /* drop triangles no ray of the list can hit from the front */
} cbvh_tlist_params;

typedef struct {
    cbvh_tlist_params p;
    cbvh_tlist_elem *list[CBVH_TLIST_MAX];
    uint32_t len[CBVH_TLIST_MAX];
    uint32_t ntris;          /* triangles of the scene */
    /* Per-polygon heads (NULL if not computed): head of list l for rays that
     * leave triangle t on its front side = poly_head[t * nlists + l]. */
    uint32_t *poly_head;
} cbvh_tlists;

int cbvh_tlists_build(const cbvh_bsh *h, const cbvh_scene *s, const cbvh_tlist_params *p, cbvh_tlists *out,
                      char *err, size_t errlen);
void cbvh_tlists_free(cbvh_tlists *L);
/* Bytes of all lists (CBVH_TLIST_ELEM_BYTES per element) and of the heads. */
uint64_t cbvh_tlists_bytes(const cbvh_tlists *L);

/* The list for a ray, from the bits of its direction only (exact, integer):
 * 1 list: 0; 2 lists: sign of d.x; 6: the axis of largest |d| (ties: x, then
 * y) and its sign; 8: the three signs (-0 counts as negative). */
int cbvh_tlist_pick(const cbvh_tlists *L, const cbvh_ray *ray);

/* Traverse list `l` from element `head` (0 = the list's start).  Same result
 * definition as cbvh_trace_bvh (closest = smallest (t bits, triangle index)),
 * so hits equal the float BVH's bit for bit.  The sphere unit culls with the
 * current best t.  Stats: nodes = sphere elements visited, box_tests = sphere
 * tests, tri_tests, lines/bytes of elements and triangles fetched; max_stack 0.
 * 0 or -1 (ray rejected by a unit). */
int cbvh_trace_tlist(const cbvh_tlists *L, int l, uint32_t head, const cbvh_tri *tris, const cbvh_ray *ray,
                     cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st);

#endif
