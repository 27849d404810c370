/* Format "tlist[:1|2|6|8][:earliest|:latest][:cull][:heads]": stackless
 * traversal lists over a bounding-sphere hierarchy (docs/tlist.md), traced
 * with the ray-sphere and ray-triangle units.  Secondary rays start at their
 * source triangle's per-polygon head, a pinhole camera's rays at their
 * screen cell's head (":heads", docs/tlist.md §7).  Refit: the hierarchy and
 * the lists are rebuilt, since culling and heads depend on the triangles'
 * normals and positions (lists are not updatable in place). */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/format.h"
#include "cbvh/oom.h"
#include "cbvh/tlist.h"

/* Largest triangles x lists for which per-polygon heads are precomputed
 * (about 2-10 us per triangle and list: past this, many minutes). */
#define CBVH_TLIST_POLY_HEADS_MAX 16000000u

typedef struct {
    cbvh_tlist_params p; /* lists, order, back-face culling */
    int poly_heads;      /* per-polygon list heads for secondary rays */
    int cell_heads;      /* per-screen-cell list heads for pinhole primary rays */
} options;

typedef struct {
    options t;
    cbvh_scene sc;  /* the frame being traced (triangles only) */
    float eps, origin_max;
    const cbvh_format_pinhole *pinhole;
    cbvh_bsh bsh;
    cbvh_tlists tl;
    int have_tl;
    uint32_t *cell_head; /* pinhole primary rays: per screen cell, per list */
    int cell_w, cell_h;  /* cell size in pixels */
} state;

/* Parses the spec into *t (defaults 6 lists, earliest first, no culling, no
 * heads; "heads" = both kinds).  0, or -1 with a one-line reason. */
static int parse_options(const char *s, options *t, char *err, size_t errlen) {
    memset(t, 0, sizeof *t);
    t->p.nlists = 6;
    t->p.order = CBVH_TLIST_EARLIEST_FIRST;
    char buf[128];
    if (strncmp(s, "tlist", 5) != 0 || (s[5] && s[5] != ':') || strlen(s) >= sizeof buf) {
        snprintf(err, errlen, "format '%s': expected tlist[:1|2|6|8][:earliest|:latest][:cull][:heads]", s);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", s + 5);
    /* Split on ':' by hand: callers may be inside their own strtok loop.  Each
     * group (count, order, cull, heads) at most once: "tlist:6:2" would
     * otherwise silently mean 2. */
    int seen[4] = {0, 0, 0, 0};
    for (char *k = buf[0] ? buf + 1 : NULL, *next; k; k = next) {
        next = strchr(k, ':');
        if (next) *next++ = 0;
        int group = isdigit((unsigned char)k[0]) ? 0 : strcmp(k, "earliest") == 0 || strcmp(k, "latest") == 0 ? 1
                    : strcmp(k, "cull") == 0                                                             ? 2
                    : strcmp(k, "heads") == 0                                                            ? 3
                                                                                                           : -1;
        if (group >= 0 && seen[group]++) {
            static const char *const what[4] = {"a list count", "an order", "cull", "heads"};
            snprintf(err, errlen, "format '%s': %s given twice", s, what[group]);
            return -1;
        }
        if (strcmp(k, "1") == 0 || strcmp(k, "2") == 0 || strcmp(k, "6") == 0 || strcmp(k, "8") == 0)
            t->p.nlists = k[0] - '0';
        else if (strcmp(k, "earliest") == 0)
            t->p.order = CBVH_TLIST_EARLIEST_FIRST;
        else if (strcmp(k, "latest") == 0)
            t->p.order = CBVH_TLIST_LATEST_LAST;
        else if (strcmp(k, "cull") == 0)
            t->p.cull_back = 1;
        else if (strcmp(k, "heads") == 0)
            t->poly_heads = t->cell_heads = 1;
        else {
            snprintf(err, errlen, "format '%s': unknown tlist option '%s' (lists 1|2|6|8, earliest|latest, cull, heads)",
                     s, k);
            return -1;
        }
    }
    return 0;
}

/* The canonical spelling, e.g. "tlist:6:earliest:cull:heads". */
static int parse(const char *spec, char *canon, size_t n, char *err, size_t errlen) {
    options t;
    if (parse_options(spec, &t, err, errlen)) return -1;
    snprintf(canon, n, "tlist:%d:%s%s%s", t.p.nlists, t.p.order == CBVH_TLIST_LATEST_LAST ? "latest" : "earliest",
             t.p.cull_back ? ":cull" : "", t.poly_heads || t.cell_heads ? ":heads" : "");
    return 0;
}

static void describe(const cbvh_format_params *p, char *out, size_t n) {
    (void)p;
    snprintf(out, n, "sphere hierarchy + lists");
}

/* Per-screen-cell heads for a pinhole camera: the image split into at most
 * 16 x 16 cells, each cell's primary rays bounded by the cone of its four
 * corner directions (widened by 2^-16 rad for the float rounding of pixel
 * directions). */
static int build_cell_heads(state *s, char *err, size_t errlen) {
    const cbvh_format_pinhole *c = s->pinhole;
    free(s->cell_head);
    s->cell_head = NULL;
    if (!s->t.cell_heads || !c) return 0;
    s->cell_w = (c->width + 15) / 16;
    s->cell_h = (c->height + 15) / 16;
    int ncx = (c->width + s->cell_w - 1) / s->cell_w, ncy = (c->height + s->cell_h - 1) / s->cell_h;
    s->cell_head = calloc((size_t)ncx * (size_t)ncy * CBVH_TLIST_MAX, sizeof *s->cell_head);
    if (!s->cell_head) cbvh_out_of_memory("tile lists");
    for (int cy = 0; cy < ncy; cy++)
        for (int cx = 0; cx < ncx; cx++) {
            int x0 = cx * s->cell_w, y0 = cy * s->cell_h;
            int x1 = x0 + s->cell_w < c->width ? x0 + s->cell_w : c->width;
            int y1 = y0 + s->cell_h < c->height ? y0 + s->cell_h : c->height;
            float corner[4][3];
            const float X[4] = {(float)x0, (float)x1, (float)x1, (float)x0}, Y[4] = {(float)y0, (float)y0, (float)y1, (float)y1};
            for (int k = 0; k < 4; k++) c->dir(c->ctx, X[k] / (float)c->width, Y[k] / (float)c->height, corner[k]);
            if (cbvh_tlist_cell_heads(&s->tl, s->sc.tris, c->position, corner, 0x1p-16,
                                      &s->cell_head[((size_t)cy * (size_t)ncx + (size_t)cx) * CBVH_TLIST_MAX])) {
                snprintf(err, errlen, "tlist: cannot compute the screen-cell heads (non-finite camera)");
                return -1;
            }
        }
    return 0;
}

/* (Re)builds the sphere hierarchy, the lists and their heads for s->sc. */
static int build_lists(state *s, char *err, size_t errlen) {
    if (s->have_tl) {
        cbvh_tlists_free(&s->tl);
        cbvh_bsh_free(&s->bsh);
        s->have_tl = 0;
    }
    const cbvh_scene *sc = &s->sc;
    int nlists = s->t.p.nlists;
    /* Per-polygon heads cost about 2-10 us per triangle and list to
     * precompute; past this size that is many minutes: refuse up front. */
    if (s->t.poly_heads && (uint64_t)sc->ntris * (uint64_t)nlists > CBVH_TLIST_POLY_HEADS_MAX) {
        snprintf(err, errlen,
                 "tlist: per-polygon heads for %u triangles x %d lists exceed the limit of %llu (minutes of "
                 "precomputation); drop ':heads' or use fewer lists",
                 sc->ntris, nlists, (unsigned long long)CBVH_TLIST_POLY_HEADS_MAX);
        return -1;
    }
    cbvh_bsh_params bp;
    cbvh_bsh_default_params(&bp);
    if (cbvh_bsh_build(sc, &bp, &s->bsh, err, errlen)) return -1;
    if (cbvh_tlists_build(&s->bsh, sc, &s->t.p, &s->tl, err, errlen)) {
        cbvh_bsh_free(&s->bsh);
        return -1;
    }
    s->have_tl = 1;
    if (s->t.poly_heads) {
        /* Secondary rays start at q = hit point + eps n: the margin covers eps
         * and the hit point's rounding (docs/tlist.md §7.1). */
        float cmax = 0;
        for (uint32_t i = 0; i < sc->ntris; i++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) cmax = fmaxf(cmax, fabsf(sc->tris[i].v[v][a]));
        cmax += s->eps;
        cmax = fmaxf(cmax, s->origin_max);
        float margin = cbvh_tlist_hitpoint_margin(s->eps, cmax);
        if (!isfinite(margin)) { /* coordinates near FLT_MAX: no binary32 margin covers the hit points */
            snprintf(err, errlen,
                     "tlist heads: coordinates up to %g leave no finite margin for the per-polygon heads "
                     "(docs/tlist.md 7.1); trace without :heads",
                     (double)cmax);
            return -1;
        }
        if (cbvh_tlists_poly_heads(&s->tl, sc->tris, CBVH_TLIST_HEADS_REGULAR, margin, err, errlen)) return -1;
    }
    return build_cell_heads(s, err, errlen);
}

static void release(void *st) {
    state *s = st;
    if (s->have_tl) {
        cbvh_tlists_free(&s->tl);
        cbvh_bsh_free(&s->bsh);
    }
    free(s->cell_head);
    free(s);
}

static int build(const cbvh_format_input *in, void **st, cbvh_unit_activity *u, char *err, size_t errlen) {
    (void)u;
    options t;
    if (parse_options(in->spec, &t, err, errlen)) return -1;
    if (t.p.cull_back && !in->p.one_sided) {
        snprintf(err, errlen, "tlist: back-face culling needs one-sided triangles (--one-sided)");
        return -1;
    }
    state *s = calloc(1, sizeof *s);
    if (!s) cbvh_out_of_memory("format state");
    s->t = t;
    s->sc = *in->scene;
    s->sc.nmorph = 0;
    s->sc.nkeys = 0;
    s->eps = in->eps;
    s->origin_max = in->origin_max;
    s->pinhole = in->pinhole;
    if (build_lists(s, err, errlen)) {
        release(s);
        return -1;
    }
    *st = s;
    return 0;
}

static int refit(void *st, const cbvh_tri *tris, cbvh_unit_activity *u, char *err, size_t errlen) {
    state *s = st;
    s->sc.tris = (cbvh_tri *)tris; /* only read: the builders take the scene const */
    if (build_lists(s, err, errlen)) return -1;
    u->refit += s->bsh.nnodes;
    return 0;
}

/* Where a ray starts in list l (docs/tlist.md §7): a camera ray of a pinhole
 * camera at its screen cell's head; a secondary ray at its source triangle's
 * head when it leaves on the front side; else the list's start. */
static uint32_t head(const state *s, const cbvh_tri *tris, const cbvh_ray *r, int l, const cbvh_format_from *from) {
    if (from->src_prim == UINT32_MAX) {
        if (!s->cell_head) return 0;
        int cx = from->px / s->cell_w, cy = from->py / s->cell_h;
        int ncx = (s->pinhole->width + s->cell_w - 1) / s->cell_w;
        return s->cell_head[((size_t)cy * (size_t)ncx + (size_t)cx) * CBVH_TLIST_MAX + (size_t)l];
    }
    return s->t.poly_heads ? cbvh_tlist_poly_head(&s->tl, l, from->src_prim, tris, r) : 0;
}

static int trace(const void *st, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                 const cbvh_format_from *from, cbvh_trav_hit *hit, cbvh_trav_stats *ts) {
    const state *s = st;
    int l = cbvh_tlist_pick(&s->tl, ray);
    return cbvh_trace_tlist(&s->tl, l, head(s, tris, ray, l, from), tris, ray, mode, hit, ts);
}

/* The lists and their per-polygon heads. */
static uint64_t bytes(const void *st) { return cbvh_tlists_bytes(&((const state *)st)->tl); }

/* The lists' "box tests" are sphere tests. */
static void units(const cbvh_trav_stats *sum, cbvh_unit_activity *u) {
    u->ray_sphere += sum->box_tests;
    u->ray_triangle += sum->tri_tests;
}

const cbvh_format cbvh_format_tlist = {
    .name = "tlist", .title = "traversal-list", .memory = "list", .flags = CBVH_FORMAT_OPTIONS, .parse = parse,
    .help = "tlist[:1|2|6|8][:earliest|:latest][:cull][:heads]: traversal lists over a\n"
            "bounding-sphere hierarchy (docs/tlist.md; default 6 lists, earliest first)",
    .build_note = "sphere hierarchy + lists", .refit_note = ", rebuilt per frame",
    .describe = describe, .build = build, .refit = refit, .trace = trace, .bytes = bytes, .units = units, .free = release};
