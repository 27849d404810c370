/* CBVH container: layout, initialisation, decode-and-check, SAH, compare. */
#include <stdio.h>
#include <stdlib.h>

#include "build/cbvh_layout.h"
#include "cbvh/oom.h"

void cbvh_tree_free(cbvh_tree *t) {
    free(t->pairs);
    free(t->ids);
    memset(t, 0, sizeof *t);
}

size_t cbvh_tree_bytes(const cbvh_tree *t) { return (size_t)t->npairs * t->pair_bytes + (size_t)t->nids * 4u; }

size_t cbvh_bvh_bytes(const cbvh_bvh *b) {
    uint32_t leaves, inner;
    cbvh_bvh_counts(b, &leaves, &inner);
    return (size_t)(inner ? inner : 1) * 64u + (size_t)b->nprims * 4u;
}

int cbvh_layout_make(const cbvh_bvh *b, cbvh_layout *l) {
    memset(l, 0, sizeof *l);
    l->order = malloc((size_t)b->nnodes * sizeof *l->order);
    l->slot = malloc((size_t)b->nnodes * sizeof *l->slot);
    uint32_t *stack = malloc(((size_t)b->nnodes + 1) * sizeof *stack);
    if (!l->order || !l->slot || !stack) {
        free(stack);
        cbvh_layout_free(l);
        return -1;
    }
    /* The post-order of cbvh_bvh_postorder (child 0, child 1, node), with
     * each node's slot assigned as it is emitted: one pass over the nodes.
     * Stack entries: node << 1 | children-pushed flag. */
    uint32_t sp = 0, k = 0;
    stack[sp++] = b->root << 1;
    while (sp) {
        uint32_t e = stack[--sp], i = e >> 1;
        const cbvh_bvh_node *n = &b->nodes[i];
        int emit = cbvh_bvh_is_leaf(n) || (e & 1u);
        if (emit ? k >= b->nnodes : sp + 3 > b->nnodes + 1) { /* only a node reached twice gets here */
            free(stack);
            cbvh_layout_free(l);
            return -1;
        }
        if (cbvh_bvh_is_leaf(n)) {
            l->order[k++] = i;
            l->slot[i] = l->nids;
            l->nids += n->count;
        } else if (e & 1u) {
            l->order[k++] = i;
            l->slot[i] = l->npairs++;
        } else {
            stack[sp++] = e | 1u;
            stack[sp++] = n->child[1] << 1;
            stack[sp++] = n->child[0] << 1;
        }
    }
    free(stack);
    if (cbvh_bvh_is_leaf(&b->nodes[b->root])) l->npairs = 1; /* {root leaf, empty} */
    return 0;
}

int cbvh_layout_count(const cbvh_bvh *b, cbvh_layout *l) {
    memset(l, 0, sizeof *l);
    l->slot = malloc((size_t)b->nnodes * sizeof *l->slot);
    if (!l->slot) return -1;
    uint32_t inner = 0;
    uint64_t ids = 0;
    for (uint32_t i = 0; i < b->nnodes; i++) {
        const cbvh_bvh_node *n = &b->nodes[i];
        if (cbvh_bvh_is_leaf(n))
            ids += n->count;
        else
            inner++;
    }
    l->npairs = cbvh_bvh_is_leaf(&b->nodes[b->root]) ? 1 : inner;
    l->nids = ids > UINT32_MAX ? UINT32_MAX : (uint32_t)ids;
    return 0;
}

void cbvh_layout_free(cbvh_layout *l) {
    free(l->order);
    free(l->slot);
    memset(l, 0, sizeof *l);
}

int cbvh_tree_init(cbvh_tree *t, const cbvh_bvh *b, const cbvh_compress_opts *o, const cbvh_layout *l, int fill_ids,
                   char *err, size_t errlen) {
    memset(t, 0, sizeof *t);
    if (cbvh_params_check(&o->params)) {
        snprintf(err, errlen, "cbvh: quant_bits %d or min_scale %d out of range", o->params.quant_bits,
                 o->params.min_scale);
        return -1;
    }
    int pb = cbvh_node_ptr_bits(o->params.quant_bits);
    uint64_t ones = pb >= 32 ? 0xFFFFFFFFu : (1u << pb) - 1u;
    if (l->npairs > ones || l->nids >= ones || l->nids >= CBVH_ID_LAST) {
        snprintf(err, errlen, "cbvh: %u node pairs / %u IDs do not fit %d-bit pointers", l->npairs, l->nids, pb);
        return -1;
    }
    t->params = o->params;
    t->enc = o->enc;
    t->pair_bytes = cbvh_nodepair_bytes(o->params.quant_bits);
    t->npairs = l->npairs;
    t->nids = l->nids;
    t->pairs = calloc(l->npairs, t->pair_bytes);
    t->ids = malloc((size_t)l->nids * sizeof *t->ids);
    if (!t->pairs || !t->ids) {
        cbvh_tree_free(t);
        snprintf(err, errlen, "cbvh: out of memory");
        return -1;
    }
    for (uint32_t i = 0; fill_ids && i < b->nnodes; i++)
        if (cbvh_bvh_is_leaf(&b->nodes[i])) cbvh_tree_put_ids(t, b, &b->nodes[i], l->slot[i]);
    const cbvh_bvh_node *r = &b->nodes[b->root];
    t->root_pair = l->npairs - 1;
    for (int a = 0; a < 3; a++) {
        t->root_lo[a] = cbvh_f32_of(r->lo[a]);
        t->root_hi[a] = cbvh_f32_of(r->hi[a]);
        uint32_t st = cbvh_axis_root_ctx(&o->params, t->root_lo[a], t->root_hi[a], &t->root_ctx.axis[a]);
        if (st) {
            snprintf(err, errlen, "cbvh: root box axis %d rejected (status 0x%x)", a, st);
            cbvh_tree_free(t);
            return -1;
        }
    }
    return 0;
}

/* Decoded box of a child as floats (-Inf for -2^128 is fine as a float). */
static void child_box(const cbvh_child_out *o, float lo[3], float hi[3]) {
    for (int a = 0; a < 3; a++) lo[a] = cbvh_float_of(o->axis[a].clb), hi[a] = cbvh_float_of(o->axis[a].cub);
}

int cbvh_tree_check(const cbvh_tree *t, const cbvh_bvh *b, char *err, size_t errlen) {
    typedef struct {
        uint32_t pair, node;
        cbvh_node_ctx ctx;
    } item;
    item *stack = malloc(((size_t)t->npairs + 2) * sizeof *stack);
    uint8_t *seen = calloc(t->npairs ? t->npairs : 1, 1);
    uint8_t *idseen = calloc(t->nids ? t->nids : 1, 1);
    int rc = -1;
    uint32_t sp = 0, pairs = 0, ids = 0;
    if (!stack || !seen || !idseen) cbvh_out_of_memory("CBVH check buffers");
    if (t->root_pair >= t->npairs || t->nids != b->nprims) {
        snprintf(err, errlen, "cbvh check: bad root pair or ID count");
        goto out;
    }
    /* The root box is the first thing every ray is tested against, and its
     * context decodes the whole tree: both must be the BVH root's. */
    const cbvh_bvh_node *r = &b->nodes[b->root < b->nnodes ? b->root : 0];
    for (int a = 0; a < 3; a++) {
        cbvh_axis_ctx want;
        if (t->root_lo[a] != cbvh_f32_of(r->lo[a]) || t->root_hi[a] != cbvh_f32_of(r->hi[a]) ||
            cbvh_axis_root_ctx(&t->params, t->root_lo[a], t->root_hi[a], &want)) {
            snprintf(err, errlen, "cbvh check: root box axis %d is not the BVH root's box", a);
            goto out;
        }
        const cbvh_axis_ctx *c = &t->root_ctx.axis[a];
        if (c->parent_scale != want.parent_scale || c->scale != want.scale || c->lb_mod != want.lb_mod ||
            c->clb != want.clb) {
            snprintf(err, errlen, "cbvh check: root context axis %d does not match the root box", a);
            goto out;
        }
    }
    stack[sp++] = (item){t->root_pair, b->root, t->root_ctx};
    while (sp) {
        item it = stack[--sp];
        if (it.pair >= t->npairs || seen[it.pair]) {
            snprintf(err, errlen, "cbvh check: pair %u out of range or used twice", it.pair);
            goto out;
        }
        seen[it.pair] = 1;
        pairs++;
        cbvh_child_out o[2];
        uint32_t st = cbvh_nodepair_decode(&t->params, t->enc, &it.ctx, t->pairs + (size_t)it.pair * t->pair_bytes, o);
        if (st & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) {
            snprintf(err, errlen, "cbvh check: pair %u does not decode (status 0x%x)", it.pair, st);
            goto out;
        }
        const cbvh_bvh_node *x = &b->nodes[it.node];
        int root_leaf = cbvh_bvh_is_leaf(x);
        for (int c = 0; c < 2; c++) {
            if (root_leaf && c == 1) {
                if (!o[1].empty) {
                    snprintf(err, errlen, "cbvh check: root-leaf pair %u has a second child", it.pair);
                    goto out;
                }
                continue;
            }
            uint32_t cn = root_leaf ? it.node : x->child[c];
            const cbvh_bvh_node *ch = &b->nodes[cn];
            if (o[c].empty || o[c].leaf != cbvh_bvh_is_leaf(ch)) {
                snprintf(err, errlen, "cbvh check: pair %u child %d: leaf/empty flag differs from the BVH", it.pair, c);
                goto out;
            }
            float lo[3], hi[3];
            child_box(&o[c], lo, hi);
            for (int a = 0; a < 3; a++)
                if (!(lo[a] <= ch->lo[a] && hi[a] >= ch->hi[a])) {
                    snprintf(err, errlen,
                             "cbvh check: pair %u child %d axis %d: decoded [%a, %a] does not enclose [%a, %a]",
                             it.pair, c, a, (double)lo[a], (double)hi[a], (double)ch->lo[a], (double)ch->hi[a]);
                    goto out;
                }
            if (o[c].leaf) {
                for (uint32_t j = 0; j < ch->count; j++) {
                    uint32_t k = o[c].ptr + j;
                    uint32_t want = b->prims[ch->first + j] | (j + 1 == ch->count ? CBVH_ID_LAST : 0u);
                    if (k >= t->nids || idseen[k] || t->ids[k] != want) {
                        snprintf(err, errlen, "cbvh check: leaf at ID %u: ID %u wrong, reused or out of range",
                                 o[c].ptr, k);
                        goto out;
                    }
                    idseen[k] = 1;
                    ids++;
                }
            } else {
                item nx = {o[c].ptr, cn, {{{0}}}};
                cbvh_child_ctx3(&it.ctx, &o[c], &nx.ctx);
                stack[sp++] = nx;
            }
        }
    }
    if (pairs != t->npairs || ids != t->nids) {
        snprintf(err, errlen, "cbvh check: %u of %u pairs and %u of %u IDs reachable", pairs, t->npairs, ids, t->nids);
        goto out;
    }
    rc = 0;
out:
    free(stack);
    free(seen);
    free(idseen);
    return rc;
}

static double area3(const float lo[3], const float hi[3], int perim) {
    double dx = (double)hi[0] - lo[0], dy = (double)hi[1] - lo[1], dz = (double)hi[2] - lo[2];
    return perim ? dx + dy + dz : 2.0 * (dx * dy + dy * dz + dz * dx);
}

double cbvh_tree_sah(const cbvh_tree *t) {
    typedef struct {
        uint32_t pair;
        cbvh_node_ctx ctx;
    } item;
    float rlo[3], rhi[3];
    for (int a = 0; a < 3; a++) rlo[a] = cbvh_float_of(t->root_lo[a]), rhi[a] = cbvh_float_of(t->root_hi[a]);
    int perim = !(area3(rlo, rhi, 0) > 0.0);
    double ar = area3(rlo, rhi, perim);
    if (!(ar > 0.0)) return 0.0;
    item *stack = malloc(((size_t)t->npairs + 2) * sizeof *stack);
    if (!stack) cbvh_out_of_memory("CBVH cost stack");
    uint32_t sp = 0, visits = 0;
    stack[sp++] = (item){t->root_pair, t->root_ctx};
    double cost = 0.0;
    int root_inner = 0;
    while (sp) {
        item it = stack[--sp];
        if (it.pair >= t->npairs || ++visits > t->npairs) {
            free(stack);
            return -1.0;
        }
        cbvh_child_out o[2];
        if (cbvh_nodepair_decode(&t->params, t->enc, &it.ctx, t->pairs + (size_t)it.pair * t->pair_bytes, o) &
            (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) {
            free(stack);
            return -1.0;
        }
        if (!o[1].empty) root_inner = 1;
        for (int c = 0; c < 2; c++) {
            if (o[c].empty) continue;
            float lo[3], hi[3];
            child_box(&o[c], lo, hi);
            double a = area3(lo, hi, perim) / ar;
            if (o[c].leaf) {
                uint32_t k = o[c].ptr, cnt = 0;
                while (k < t->nids) {
                    cnt++;
                    if (t->ids[k++] & CBVH_ID_LAST) break;
                }
                cost += a * cnt;
            } else {
                cost += a;
                item nx = {o[c].ptr, {{{0}}}};
                cbvh_child_ctx3(&it.ctx, &o[c], &nx.ctx);
                stack[sp++] = nx;
            }
        }
    }
    free(stack);
    /* The float root is an inner node counted once, like cbvh_bvh_sah; a leaf
     * root was counted through its decoded box above. */
    return root_inner ? cost + 1.0 : cost;
}

long cbvh_tree_diff(const cbvh_tree *a, const cbvh_tree *b) {
    if (a->params.quant_bits != b->params.quant_bits || a->params.min_scale != b->params.min_scale ||
        a->enc != b->enc || a->npairs != b->npairs || a->nids != b->nids || a->root_pair != b->root_pair ||
        memcmp(a->root_lo, b->root_lo, sizeof a->root_lo) || memcmp(a->root_hi, b->root_hi, sizeof a->root_hi) ||
        memcmp(&a->root_ctx, &b->root_ctx, sizeof a->root_ctx))
        return 0;
    size_t n = (size_t)a->npairs * a->pair_bytes;
    for (size_t i = 0; i < n; i++)
        if (a->pairs[i] != b->pairs[i]) return (long)i;
    for (size_t i = 0; i < a->nids; i++)
        if (a->ids[i] != b->ids[i]) return (long)(n + 4 * i);
    return -1;
}
