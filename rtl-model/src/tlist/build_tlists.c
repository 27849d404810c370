/* Traversal lists (seed 004 §2.1; docs/tlist.md §3-§5): the bounding-sphere
 * hierarchy flattened depth-first, once per direction class, with the
 * children of every node (child spheres and the node's own triangles
 * together) sorted along the list's direction, relative escape indices, and
 * optional exact back-face culling per list. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/tlist.h"


int cbvh_tlist_cone(int nlists, int l, float dir[3], float gen[6][3]) {
    int n = 0;
    memset(dir, 0, 3 * sizeof *dir);
    if (nlists == 1 || nlists == 2) {
        float sx = (nlists == 2 && l == 1) ? -1.0f : 1.0f;
        dir[0] = sx;
        if (nlists == 1) { /* every direction: +-x, +-y, +-z */
            for (int a = 0; a < 3; a++)
                for (int s = 0; s < 2; s++) {
                    memset(gen[n], 0, sizeof gen[n]);
                    gen[n++][a] = s ? -1.0f : 1.0f;
                }
            return n;
        }
        memset(gen[n], 0, sizeof gen[n]); /* the half space sx * d.x >= 0 */
        gen[n++][0] = sx;
        for (int a = 1; a < 3; a++)
            for (int s = 0; s < 2; s++) {
                memset(gen[n], 0, sizeof gen[n]);
                gen[n++][a] = s ? -1.0f : 1.0f;
            }
        return n;
    }
    if (nlists == 6) { /* sextant: axis a, sign; |d_a| >= the other two */
        int a = l / 2, b = (a + 1) % 3, c = (a + 2) % 3;
        float sa = (l & 1) ? -1.0f : 1.0f;
        dir[a] = sa;
        for (int k = 0; k < 4; k++) {
            gen[n][a] = sa;
            gen[n][b] = (k & 1) ? -1.0f : 1.0f;
            gen[n][c] = (k & 2) ? -1.0f : 1.0f;
            n++;
        }
        return n;
    }
    if (nlists == 8) { /* octant: bit a of l set = d_a negative */
        for (int a = 0; a < 3; a++) {
            float s = (l >> a & 1) ? -1.0f : 1.0f;
            dir[a] = s;
            memset(gen[n], 0, sizeof gen[n]);
            gen[n++][a] = s;
        }
        return n;
    }
    return 0;
}

int cbvh_tlist_pick(const cbvh_tlists *L, const cbvh_ray *ray) {
    const cbvh_f32 *d = ray->d;
    switch (L->p.nlists) {
    case 2: return (int)(d[0] >> 31);
    case 6: {
        uint32_t m0 = d[0] & ~CBVH_F32_SIGN, m1 = d[1] & ~CBVH_F32_SIGN, m2 = d[2] & ~CBVH_F32_SIGN;
        int a = (m0 >= m1 && m0 >= m2) ? 0 : (m1 >= m2 ? 1 : 2);
        return 2 * a + (int)(d[a] >> 31);
    }
    case 8: return (int)((d[0] >> 31) | (d[1] >> 31) << 1 | (d[2] >> 31) << 2);
    default: return 0;
    }
}

void cbvh_tlists_free(cbvh_tlists *L) {
    for (int l = 0; l < CBVH_TLIST_MAX; l++) free(L->list[l]);
    free(L->poly_head);
    memset(L, 0, sizeof *L);
}

uint64_t cbvh_tlists_bytes(const cbvh_tlists *L) {
    uint64_t b = 0;
    for (int l = 0; l < L->p.nlists && l < CBVH_TLIST_MAX; l++) b += (uint64_t)L->len[l] * CBVH_TLIST_ELEM_BYTES;
    if (L->poly_head) b += (uint64_t)L->ntris * (uint64_t)L->p.nlists * 4u;
    return b;
}

int cbvh_tlist_culled(int nlists, int l, const cbvh_tri *t) {
    float dir[3], gen[6][3];
    int ng = cbvh_tlist_cone(nlists, l, dir, gen);
    cbvh_f32 v[3][3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) v[k][a] = cbvh_f32_of(t->v[k][a]);
    for (int g = 0; g < ng; g++) {
        cbvh_f32 d[3] = {cbvh_f32_of(gen[g][0]), cbvh_f32_of(gen[g][1]), cbvh_f32_of(gen[g][2])};
        if (cbvh_tri_facing(d, v[0], v[1], v[2]) > 0) return 0; /* some direction of the cone sees the front */
    }
    return 1;
}

/* One child of a node while sorting: a child sphere or a triangle at the node. */
typedef struct {
    double key;
    uint32_t kind; /* 0 sphere, 1 triangle */
    uint32_t id;   /* node or triangle index */
} item;

static int item_cmp(const void *pa, const void *pb) {
    const item *a = pa, *b = pb;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    if (a->kind != b->kind) return a->kind < b->kind ? -1 : 1;
    return a->id < b->id ? -1 : a->id > b->id;
}

typedef struct {
    const cbvh_bsh *h;
    const cbvh_tri *tris;
    const uint8_t *keep;  /* per triangle: 1 if in this list */
    const uint32_t *sub;  /* per node: kept triangles in its subtree */
    double dir[3], dlen;
    int latest;
    cbvh_tlist_elem *out;
    uint32_t n, len;
    item *scratch;        /* 8 + max triangles at a node, per depth level */
    uint32_t scratch_stride;
} flat;

static double sphere_key(const flat *F, uint32_t node) {
    const cbvh_f32 *s = F->h->sphere[node];
    double c = F->dir[0] * cbvh_float_of(s[0]) + F->dir[1] * cbvh_float_of(s[1]) + F->dir[2] * cbvh_float_of(s[2]);
    double r = (double)cbvh_float_of(s[3]) * F->dlen;
    return F->latest ? c + r : c - r;
}

static double tri_key(const flat *F, uint32_t t) {
    const cbvh_tri *T = &F->tris[t];
    double k = 0;
    for (int v = 0; v < 3; v++) {
        double p = F->dir[0] * T->v[v][0] + F->dir[1] * T->v[v][1] + F->dir[2] * T->v[v][2];
        if (v == 0 || (F->latest ? p > k : p < k)) k = p;
    }
    return k;
}

static void emit(flat *F, uint32_t node, uint32_t level) {
    const cbvh_bsh *h = F->h;
    uint32_t me = F->n++;
    F->out[me].data[0] = h->sphere[node][0];
    F->out[me].data[1] = h->sphere[node][1];
    F->out[me].data[2] = h->sphere[node][2];
    F->out[me].data[3] = h->sphere[node][3];
    item *it = F->scratch + (size_t)level * F->scratch_stride;
    uint32_t k = 0;
    for (uint32_t c = 0; c < h->nchild[node]; c++) {
        uint32_t ch = h->first_child[node] + c;
        if (F->sub[ch]) it[k++] = (item){sphere_key(F, ch), 0, ch};
    }
    for (uint32_t j = 0; j < h->ntri[node]; j++) {
        uint32_t t = h->tri_ids[h->first_tri[node] + j];
        if (F->keep[t]) it[k++] = (item){tri_key(F, t), 1, t};
    }
    qsort(it, k, sizeof *it, item_cmp);
    for (uint32_t j = 0; j < k; j++) {
        if (it[j].kind == 0) {
            emit(F, it[j].id, level + 1); /* uses the scratch of level + 1: it[] stays intact */
        } else {
            cbvh_tlist_elem *e = &F->out[F->n++];
            e->escape = 1;
            e->data[0] = it[j].id;
            e->data[1] = e->data[2] = e->data[3] = 0;
        }
    }
    F->out[me].escape = F->n == F->len ? -1 : (int32_t)(F->n - me);
}

int cbvh_tlists_build(const cbvh_bsh *h, const cbvh_scene *s, const cbvh_tlist_params *p, cbvh_tlists *out,
                      char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    if (!p || (p->nlists != 1 && p->nlists != 2 && p->nlists != 6 && p->nlists != 8)) {
        snprintf(err, errlen, "tlists: number of lists must be 1, 2, 6 or 8 (got %d)", p ? p->nlists : 0);
        return -1;
    }
    if (p->order != CBVH_TLIST_EARLIEST_FIRST && p->order != CBVH_TLIST_LATEST_LAST) {
        snprintf(err, errlen, "tlists: unknown node order %d", (int)p->order);
        return -1;
    }
    if (!h->nnodes || h->ntri_ids != s->ntris) {
        snprintf(err, errlen, "tlists: hierarchy does not match the scene (%u triangles vs %u)", h->ntri_ids,
                 s->ntris);
        return -1;
    }
    out->p = *p;
    out->p.cull_back = p->cull_back != 0;
    out->ntris = s->ntris;
    uint8_t *keep = malloc(s->ntris);
    uint32_t *sub = malloc((size_t)h->nnodes * sizeof *sub);
    uint32_t maxt = 0;
    for (uint32_t i = 0; i < h->nnodes; i++)
        if (h->ntri[i] > maxt) maxt = h->ntri[i];
    flat F = {.h = h, .tris = s->tris, .keep = keep, .sub = sub, .latest = p->order == CBVH_TLIST_LATEST_LAST};
    F.scratch_stride = 8 + maxt;
    F.scratch = malloc((size_t)(h->depth + 1) * F.scratch_stride * sizeof *F.scratch);
    if (!keep || !sub || !F.scratch) {
        snprintf(err, errlen, "tlists: out of memory");
        goto fail;
    }
    for (int l = 0; l < p->nlists; l++) {
        float dir[3], gen[6][3];
        cbvh_tlist_cone(p->nlists, l, dir, gen);
        for (int a = 0; a < 3; a++) F.dir[a] = dir[a];
        F.dlen = sqrt(F.dir[0] * F.dir[0] + F.dir[1] * F.dir[1] + F.dir[2] * F.dir[2]);
        for (uint32_t t = 0; t < s->ntris; t++) keep[t] = !(out->p.cull_back && cbvh_tlist_culled(p->nlists, l, &s->tris[t]));
        uint64_t len = 0;
        for (uint32_t i = h->nnodes; i-- > 0;) { /* children have larger indices */
            uint64_t k = 0;
            for (uint32_t j = 0; j < h->ntri[i]; j++) k += keep[h->tri_ids[h->first_tri[i] + j]];
            for (uint32_t c = 0; c < h->nchild[i]; c++) k += sub[h->first_child[i] + c];
            sub[i] = (uint32_t)k;
            len += k ? 1 : 0;
        }
        len += sub[0];
        if (len >= (1u << 31)) {
            snprintf(err, errlen, "tlists: list of %llu elements exceeds the 31-bit escape index",
                     (unsigned long long)len);
            goto fail;
        }
        out->len[l] = (uint32_t)len;
        if (!len) continue; /* every triangle culled: an empty list, every ray misses */
        out->list[l] = malloc((size_t)len * sizeof *out->list[l]);
        if (!out->list[l]) {
            snprintf(err, errlen, "tlists: out of memory for %llu elements", (unsigned long long)len);
            goto fail;
        }
        F.out = out->list[l];
        F.n = 0;
        F.len = (uint32_t)len;
        emit(&F, 0, 0);
        out->list[l][len - 1].escape = 0; /* the last element is a triangle: 0 ends the traversal */
    }
    free(keep);
    free(sub);
    free(F.scratch);
    return 0;
fail:
    free(keep);
    free(sub);
    free(F.scratch);
    cbvh_tlists_free(out);
    return -1;
}
