/* Stackless traversal lists over a bounding-sphere hierarchy (seed 004,
 * Toczek, Houzet, Mancini 2010).  Spec: docs/tlist.md.
 *
 *   rtl-model/src/tlist/build_bsh.c       the bounding-sphere hierarchy (octree-like
 *                                   top-down split; big triangles stay at the node)
 *   rtl-model/src/tlist/build_tlists.c    flattening into 1, 2, 6 or 8 depth-first lists
 *                                   with relative escape indices
 *   rtl-model/src/tlist/tlist_heads.c     per-polygon and per-screen-cell list heads
 *   rtl-model/src/tlist/traverse_tlist.c  the stackless traversal loop
 *   rtl-model/src/units/ray_sphere.c      the ray-sphere unit (unit 9, in libcbvh) */
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
 * and its children's spheres' contents (checked on vertices); at most 8
 * children per node, children after their parent, and `depth` the
 * hierarchy's (the list builder sizes its scratch by both).  0 or -1 + reason. */
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

/* The direction class of list l (docs/tlist.md §3): its sorting direction
 * dir (+-e_a, or (+-1, +-1, +-1) for octants) and the extreme rays gen[] of the
 * closure of the directions cbvh_tlist_pick assigns to it (returns how many:
 * 6 for 1 list, 5 for 2, 4 for sextants, 3 for octants; 0 for a bad nlists). */
int cbvh_tlist_cone(int nlists, int l, float dir[3], float gen[6][3]);
/* Back-face culling rule: 1 iff cbvh_tri_facing <= 0 at every extreme ray of
 * list l's cone, i.e. no direction of the list sees the triangle's front. */
int cbvh_tlist_culled(int nlists, int l, const cbvh_tri *t);

/* Traverse list `l` from element `head` (0 = the list's start).  Same result
 * definition as cbvh_trace_bvh (closest = smallest (t bits, triangle index)),
 * so hits equal the float BVH's bit for bit.  The sphere unit culls with the
 * current best t.  Stats: nodes = sphere elements visited, box_tests = sphere
 * tests, tri_tests, lines/bytes of elements and triangles fetched; max_stack 0.
 * 0 or -1 (ray rejected by a unit). */
int cbvh_trace_tlist(const cbvh_tlists *L, int l, uint32_t head, const cbvh_tri *tris, const cbvh_ray *ray,
                     cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st);

/* ---- list heads (seed 004 §3; docs/tlist.md §7) ----------------------------
 * Per-polygon heads.  For triangle t and list l, the head skips every element
 * before the first triangle element that a ray of this class might hit:
 *   origin o within distance `margin` of triangle t (the hit point it leaves
 *   from, with its rounding error and offset), direction d in list l's cone
 *   with d . n_t >= 0 (cbvh_tri_facing(d, t) <= 0: it leaves on the front
 *   side or along the plane), tmin >= 0.
 * SIMPLE skips only what lies entirely behind t's plane (more than margin);
 * REGULAR also what lies behind one of the cone's facet planes through the
 * triangle (moved back by margin).  Heads go into L->poly_head (replacing any).
 * margin >= 0, finite.  0 or -1 + reason. */
typedef enum { CBVH_TLIST_HEADS_SIMPLE = 1, CBVH_TLIST_HEADS_REGULAR = 2 } cbvh_tlist_heads_kind;
int cbvh_tlists_poly_heads(cbvh_tlists *L, const cbvh_tri *tris, cbvh_tlist_heads_kind kind, float margin, char *err,
                           size_t errlen);
/* The element a secondary ray leaving triangle `from` starts at in list l:
 * poly_head[from * nlists + l] when heads exist and the ray leaves on the
 * front side (exact facing <= 0) with tmin >= 0, else 0.  The origin condition
 * (within margin of the triangle) is the caller's. */
uint32_t cbvh_tlist_poly_head(const cbvh_tlists *L, int l, uint32_t from, const cbvh_tri *tris, const cbvh_ray *ray);
/* A margin for secondary rays whose origin is q = fl(fl(o + t d) + eps n)
 * (host/trace/effects.c): eps plus the rounding error of the hit point, where
 * coord_max bounds |coordinate| of every vertex, incoming-ray origin and hit
 * point.  docs/tlist.md §7.1. */
float cbvh_tlist_hitpoint_margin(float eps, float coord_max);

/* Per-screen-cell heads for primary rays of a pinhole camera: rays with
 * origin exactly o, tmin >= 0 and a direction in the cone spanned by the four
 * corner directions (given in order around the cell), widened by the angle
 * tol (radians, >= 2^-30; covers pixel directions rounded just outside the
 * cell).  head[l] = first element of list l that such a ray may need, for
 * every list (len[l] when none).  0, or -1 on bad input (non-finite values). */
int cbvh_tlist_cell_heads(const cbvh_tlists *L, const cbvh_tri *tris, const float o[3], const float corner[4][3],
                          double tol, uint32_t head[CBVH_TLIST_MAX]);

#endif
