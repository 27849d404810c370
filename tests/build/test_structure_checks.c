/* The four structural checkers can fail: for every rejection branch of
 * cbvh_bvh_check, cbvh_tree_check, cbvh_qbvh_check and cbvh_bsh_check, a valid
 * structure built from scenes/bunny-small.obj, corrupted in exactly that way,
 * is refused with that branch's message (so it is that branch that fired),
 * and accepted again once restored. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "cbvh/qbvh.h"
#include "cbvh/tlist.h"
#include "scene/scene_load.h"
#include "test_util.h"

#ifndef CBVH_SCENES_DIR
#error "CBVH_SCENES_DIR must name the scenes folder"
#endif

static char err[512];
static cbvh_scene bunny;

static void ok(int rc) {
    if (rc) fail_msg("a valid structure was rejected: %s", err);
}

/* rc is -1 and the message starts with the formatted text (the whole message
 * where every number in it is known). */
static void refused(int rc, const char *fmt, ...) {
    char want[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(want, sizeof want, fmt, ap);
    va_end(ap);
    if (rc != -1) fail_msg("accepted (rc %d), expected \"%s\"", rc, want);
    if (strncmp(err, want, strlen(want)) != 0) fail_msg("got \"%s\", expected \"%s\"", err, want);
}

/* The index rules every checker shares: ids[0] set to `past` (one past the
 * valid range), then ids[1] made a copy of ids[0]; each refused with fmt
 * naming the offending index, and the structure whole again afterwards. */
typedef int (*check_fn)(const void *obj);
static void index_cases(uint32_t *ids, uint32_t past, check_fn check, const void *obj, const char *fmt) {
    const uint32_t i0 = ids[0], i1 = ids[1];
    ids[0] = past;
    refused(check(obj), fmt, past);
    ids[0] = i0;
    ids[1] = i0;
    refused(check(obj), fmt, i0);
    ids[1] = i1;
    ok(check(obj));
}

static int group_setup(void **st) {
    (void)st;
    if (cbvh_scene_import(CBVH_SCENES_DIR "/bunny-small.obj", &bunny, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    return 0;
}

static int group_teardown(void **st) {
    (void)st;
    cbvh_scene_free(&bunny);
    return 0;
}

/* ---- cbvh_bvh_check ------------------------------------------------------ */

#define BVH_CHECK(b, s) cbvh_bvh_check(b, s, err, sizeof err)
static int bvh_check_bunny(const void *b) { return BVH_CHECK(b, &bunny); }

static void test_bvh_check(void **st) {
    (void)st;
    cbvh_bvh b;
    ok(cbvh_build_sah(&bunny, 0, 0, &b, err, sizeof err));
    ok(BVH_CHECK(&b, &bunny));
    const uint32_t nn = b.nnodes, np = b.nprims, r = b.root;
    /* A leaf (L) and a leaf with at least two primitives (L2). */
    uint32_t L = UINT32_MAX, L2 = UINT32_MAX;
    for (uint32_t i = 0; i < nn; i++) {
        if (!cbvh_bvh_is_leaf(&b.nodes[i])) continue;
        if (L == UINT32_MAX) L = i;
        if (L2 == UINT32_MAX && b.nodes[i].count >= 2) L2 = i;
    }
    assert_true(L != UINT32_MAX && L2 != UINT32_MAX && !cbvh_bvh_is_leaf(&b.nodes[r]));

    /* Root index past the nodes; a scene with one triangle less. */
    b.root = nn;
    refused(BVH_CHECK(&b, &bunny), "bvh: bad root or primitive count");
    b.root = r;
    cbvh_scene fewer = bunny;
    fewer.ntris--;
    refused(BVH_CHECK(&b, &fewer), "bvh: bad root or primitive count");
    ok(BVH_CHECK(&b, &bunny));

    /* A child index past the nodes; both children the same node (a DAG). */
    cbvh_bvh_node *root = &b.nodes[r];
    const uint32_t c1 = root->child[1];
    root->child[1] = nn;
    refused(BVH_CHECK(&b, &bunny), "bvh: node %u out of range or reached twice", nn);
    root->child[1] = root->child[0];
    refused(BVH_CHECK(&b, &bunny), "bvh: node %u out of range or reached twice", root->child[0]);
    root->child[1] = c1;
    ok(BVH_CHECK(&b, &bunny));

    /* A leaf range past prims[]: starting at nprims, and one whose end wraps
     * 32 bits (the check computes it in 64). */
    const uint32_t f = b.nodes[L].first;
    b.nodes[L].first = np;
    refused(BVH_CHECK(&b, &bunny), "bvh: leaf %u range out of bounds", L);
    b.nodes[L].first = UINT32_MAX;
    refused(BVH_CHECK(&b, &bunny), "bvh: leaf %u range out of bounds", L);
    b.nodes[L].first = f;
    ok(BVH_CHECK(&b, &bunny));

    /* A primitive index past the scene; a primitive listed twice. */
    index_cases(&b.prims[b.nodes[L2].first], np, bvh_check_bunny, &b, "bvh: primitive %u missing or in two leaves");

    /* Leaf L's box collapsed to its upper corner: inside its parent's, no
     * longer around its first triangle; the root's child 0 one ulp wider than
     * the root. */
    const cbvh_bvh_node leaf = b.nodes[L];
    for (int a = 0; a < 3; a++) b.nodes[L].lo[a] = b.nodes[L].hi[a];
    refused(BVH_CHECK(&b, &bunny), "bvh: leaf %u does not enclose triangle %u", L, b.prims[f]);
    b.nodes[L] = leaf;
    const uint32_t c0 = root->child[0];
    const float hx = b.nodes[c0].hi[0];
    b.nodes[c0].hi[0] = nextafterf(root->hi[0], INFINITY);
    refused(BVH_CHECK(&b, &bunny), "bvh: node %u does not enclose child %u", r, c0);
    b.nodes[c0].hi[0] = hx;
    ok(BVH_CHECK(&b, &bunny));
    /* NaN boxes: the root's lower x (it no longer encloses its child 0), and
     * all of leaf L's box (it no longer encloses its triangle; reached from
     * its parent, which reports it first). */
    const float rx = root->lo[0];
    root->lo[0] = NAN;
    refused(BVH_CHECK(&b, &bunny), "bvh: node %u does not enclose child ", r);
    root->lo[0] = rx;
    for (int a = 0; a < 3; a++) b.nodes[L].lo[a] = b.nodes[L].hi[a] = NAN;
    refused(BVH_CHECK(&b, &bunny), "bvh: node ");
    assert_non_null(strstr(err, "does not enclose"));
    b.nodes[L] = leaf;
    ok(BVH_CHECK(&b, &bunny));

    /* A leaf that drops its last primitive: that one is in no leaf. */
    b.nodes[L2].count--;
    refused(BVH_CHECK(&b, &bunny), "bvh: %u of %u nodes and %u of %u primitives reachable", nn, nn, np - 1, np);
    b.nodes[L2].count++;
    ok(BVH_CHECK(&b, &bunny));

    /* A node no parent points to (a copy of leaf L appended). */
    cbvh_bvh_node *grown = realloc(b.nodes, ((size_t)nn + 1) * sizeof *grown);
    assert_non_null(grown);
    b.nodes = grown;
    b.nodes[nn] = b.nodes[L];
    b.nnodes = nn + 1;
    refused(BVH_CHECK(&b, &bunny), "bvh: %u of %u nodes and %u of %u primitives reachable", nn, nn + 1, np, np);
    b.nnodes = nn;
    ok(BVH_CHECK(&b, &bunny));
    cbvh_bvh_free(&b);
}

/* ---- cbvh_tree_check ------------------------------------------------------- */

#define TREE_CHECK(t, b) cbvh_tree_check(t, b, err, sizeof err)

/* A field of a node (little-endian bit string, docs/datapath.md unit 4). */
static uint32_t get_field(const uint8_t *node, int pos, int width) {
    uint32_t v = 0;
    for (int i = 0; i < width; i++) v |= (uint32_t)((node[(pos + i) / 8] >> ((pos + i) % 8)) & 1u) << i;
    return v;
}
static void put_field(uint8_t *node, int pos, int width, uint32_t v) {
    for (int i = 0; i < width; i++) {
        uint8_t m = (uint8_t)(1u << ((pos + i) % 8));
        node[(pos + i) / 8] = (uint8_t)(((v >> i) & 1u) ? node[(pos + i) / 8] | m : node[(pos + i) / 8] & ~m);
    }
}

/* One pair format: N <= 6 (64-bit nodes) and N >= 7 (96-bit nodes) place the
 * leaf bit, pointer and reserved bits differently. */
static void tree_check_format(cbvh_bvh *b, int n, cbvh_encoding enc) {
    cbvh_compress_opts o = {{n, -30}, enc, 1, 0};
    cbvh_tree t;
    ok(cbvh_compress_topdown(b, &o, &t, err, sizeof err));
    ok(TREE_CHECK(&t, b));
    const uint32_t np = t.npairs, rp = t.root_pair, ni = t.nids;
    const int nbits = cbvh_node_bits(n), pbits = cbvh_node_ptr_bits(n);
    const int leaf_bit = 6 * n, ptr_pos = 6 * n + 1;
    assert_true(ptr_pos + pbits < nbits); /* both formats have reserved bits */

    /* Root pair past the pairs; an ID count that is not the BVH's. */
    t.root_pair = np;
    refused(TREE_CHECK(&t, b), "cbvh check: bad root pair or ID count");
    t.root_pair = rp;
    t.nids = ni - 1;
    refused(TREE_CHECK(&t, b), "cbvh check: bad root pair or ID count");
    t.nids = ni;
    ok(TREE_CHECK(&t, b));

    /* The root box (every ray's first test) and its context must be the BVH
     * root's: an empty x extent, a NaN, one scale off. */
    const cbvh_f32 hx0 = t.root_hi[0];
    t.root_hi[0] = t.root_lo[0];
    refused(TREE_CHECK(&t, b), "cbvh check: root box axis 0 is not the BVH root's box");
    t.root_hi[0] = 0x7FC00000u;
    refused(TREE_CHECK(&t, b), "cbvh check: root box axis 0 is not the BVH root's box");
    t.root_hi[0] = hx0;
    t.root_ctx.axis[1].scale++;
    refused(TREE_CHECK(&t, b), "cbvh check: root context axis 1 does not match the root box");
    t.root_ctx.axis[1].scale--;
    t.root_ctx.axis[2].lb_mod ^= 1u;
    refused(TREE_CHECK(&t, b), "cbvh check: root context axis 2 does not match the root box");
    t.root_ctx.axis[2].lb_mod ^= 1u;
    ok(TREE_CHECK(&t, b));

    /* The root pair's children are both inner nodes (bunny's root splits). */
    uint8_t *pair = t.pairs + (size_t)rp * t.pair_bytes, saved[32];
    assert_true(t.pair_bytes <= sizeof saved);
    memcpy(saved, pair, t.pair_bytes);
    cbvh_child_out co[2];
    assert_int_equal(cbvh_nodepair_decode(&t.params, t.enc, &t.root_ctx, pair, co), 0);
    assert_true(!co[0].leaf && !co[1].leaf && !co[0].empty && !co[1].empty);
    uint8_t *node1 = pair + nbits / 8; /* child 1: popped first */
    assert_int_equal(get_field(node1, ptr_pos, pbits), co[1].ptr);
    const cbvh_f32 cub1 = co[1].axis[0].cub; /* child 1's decoded upper x */

    /* Child 1 points back at the root pair (a cycle), or past the pairs. */
    put_field(node1, ptr_pos, pbits, rp);
    refused(TREE_CHECK(&t, b), "cbvh check: pair %u out of range or used twice", rp);
    put_field(node1, ptr_pos, pbits, np);
    refused(TREE_CHECK(&t, b), "cbvh check: pair %u out of range or used twice", np);
    memcpy(pair, saved, t.pair_bytes);
    ok(TREE_CHECK(&t, b));

    /* Child 1 flagged a leaf, and marked empty (leaf, all-ones pointer, codes
     * zero): the BVH has an inner node there. */
    put_field(node1, leaf_bit, 1, 1);
    refused(TREE_CHECK(&t, b), "cbvh check: pair %u child 1: leaf/empty flag differs from the BVH", rp);
    for (int a = 0; a < 6; a++) put_field(node1, a * n, n, 0);
    put_field(node1, ptr_pos, pbits, pbits >= 32 ? 0xFFFFFFFFu : (1u << pbits) - 1u);
    assert_int_equal(cbvh_nodepair_decode(&t.params, t.enc, &t.root_ctx, pair, co), 0);
    assert_true(co[1].empty);
    refused(TREE_CHECK(&t, b), "cbvh check: pair %u child 1: leaf/empty flag differs from the BVH", rp);
    memcpy(pair, saved, t.pair_bytes);

    /* A reserved bit set: the pair does not decode (BAD_FORMAT). */
    put_field(node1, nbits - 1, 1, 1);
    refused(TREE_CHECK(&t, b), "cbvh check: pair %u does not decode (status 0x20)", rp);
    memcpy(pair, saved, t.pair_bytes);
    ok(TREE_CHECK(&t, b));

    /* The float box of the root's child 1 one ulp past its decoded box. */
    cbvh_bvh_node *ch1 = &b->nodes[b->nodes[b->root].child[1]];
    const float hx = ch1->hi[0];
    ch1->hi[0] = nextafterf(bf(cub1), INFINITY);
    refused(TREE_CHECK(&t, b), "cbvh check: pair %u child 1 axis 0: decoded [", rp);
    ch1->hi[0] = hx;
    /* The last-ID flag of the leaf at ID 0 flipped. */
    t.ids[0] ^= CBVH_ID_LAST;
    refused(TREE_CHECK(&t, b), "cbvh check: leaf at ID 0: ID 0 wrong, reused or out of range");
    t.ids[0] ^= CBVH_ID_LAST;
    ok(TREE_CHECK(&t, b));

    /* One pair more than the tree reaches. */
    cbvh_tree big = t;
    big.pairs = calloc((size_t)np + 1, t.pair_bytes);
    assert_non_null(big.pairs);
    memcpy(big.pairs, t.pairs, (size_t)np * t.pair_bytes);
    big.npairs = np + 1;
    refused(TREE_CHECK(&big, b), "cbvh check: %u of %u pairs and %u of %u IDs reachable", np, np + 1, ni, ni);
    free(big.pairs);
    ok(TREE_CHECK(&t, b));
    cbvh_tree_free(&t);
}

static void test_tree_check(void **st) {
    (void)st;
    cbvh_bvh b;
    ok(cbvh_build_sah(&bunny, 0, 0, &b, err, sizeof err));
    ok(BVH_CHECK(&b, &bunny));
    tree_check_format(&b, 5, CBVH_ENC_RELATIVE);
    tree_check_format(&b, 8, CBVH_ENC_MODULO);
    cbvh_bvh_free(&b);
}

/* A one-triangle scene: the root is a leaf, its pair is {leaf, empty}. */
static void test_tree_check_root_leaf(void **st) {
    (void)st;
    cbvh_scene one = {0};
    one.ntris = 1;
    one.tris = calloc(1, sizeof *one.tris);
    assert_non_null(one.tris);
    one.tris[0] = (cbvh_tri){{{0, 0, 0}, {1, 0, 0.5f}, {0, 2, 1}}};
    cbvh_bvh b;
    ok(cbvh_build_lbvh(&one, &b, err, sizeof err));
    ok(BVH_CHECK(&b, &one));
    assert_true(b.nnodes == 1 && cbvh_bvh_is_leaf(&b.nodes[b.root]));
    const int n = 6;
    cbvh_compress_opts o = {{n, -30}, CBVH_ENC_MODULO, 1, 0};
    cbvh_tree t;
    ok(cbvh_compress_topdown(&b, &o, &t, err, sizeof err));
    assert_int_equal(t.npairs, 1);
    ok(TREE_CHECK(&t, &b));
    const size_t nb = (size_t)cbvh_node_bits(n) / 8;
    uint8_t saved[32];
    memcpy(saved, t.pairs, t.pair_bytes);
    /* The second slot holds a copy of the leaf instead of the empty marker. */
    memcpy(t.pairs + nb, t.pairs, nb);
    refused(TREE_CHECK(&t, &b), "cbvh check: root-leaf pair 0 has a second child");
    memcpy(t.pairs, saved, t.pair_bytes);
    /* The first slot empty instead of the leaf. */
    memcpy(t.pairs, t.pairs + nb, nb);
    refused(TREE_CHECK(&t, &b), "cbvh check: pair 0 child 0: leaf/empty flag differs from the BVH");
    memcpy(t.pairs, saved, t.pair_bytes);
    ok(TREE_CHECK(&t, &b));
    cbvh_tree_free(&t);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&one);
}

/* ---- cbvh_qbvh_check -------------------------------------------------------- */

#define QBVH_CHECK(q) cbvh_qbvh_check(q, &bunny, err, sizeof err)
static int qbvh_check_bunny(const void *q) { return QBVH_CHECK(q); }

static void test_qbvh_check(void **st) {
    (void)st;
    cbvh_bvh b;
    cbvh_qbvh q;
    ok(cbvh_build_sah(&bunny, 0, 0, &b, err, sizeof err));
    ok(cbvh_qbvh_from_bvh(&b, &q, err, sizeof err));
    cbvh_bvh_free(&b);
    ok(QBVH_CHECK(&q));
    const uint32_t nn = q.nnodes, nt = bunny.ntris;
    /* A leaf (L), a leaf with at least two primitives (L2); node 1 is inner. */
    uint32_t L = UINT32_MAX, L2 = UINT32_MAX;
    for (uint32_t i = 0; i < nn; i++) {
        if (!(q.count[i] & CBVH_QBVH_LEAF)) continue;
        if (L == UINT32_MAX) L = i;
        if (L2 == UINT32_MAX && (q.count[i] & ~CBVH_QBVH_LEAF) >= 2) L2 = i;
    }
    assert_true(L != UINT32_MAX && L2 != UINT32_MAX && !(q.count[1] & CBVH_QBVH_LEAF));

    q.nnodes = 0;
    refused(QBVH_CHECK(&q), "qbvh: no nodes");
    q.nnodes = nn;

    /* A leaf of no primitives, one starting past prims[], one running past it. */
    const uint32_t lf = q.first[L], lc = q.count[L];
    q.count[L] = CBVH_QBVH_LEAF;
    refused(QBVH_CHECK(&q), "qbvh: leaf %u has a bad primitive range", L);
    q.count[L] = lc;
    q.first[L] = q.nprims + 1;
    refused(QBVH_CHECK(&q), "qbvh: leaf %u has a bad primitive range", L);
    q.first[L] = q.nprims - 1;
    q.count[L] = 2 | CBVH_QBVH_LEAF;
    refused(QBVH_CHECK(&q), "qbvh: leaf %u has a bad primitive range", L);
    q.first[L] = lf;
    q.count[L] = lc;
    ok(QBVH_CHECK(&q));

    /* A primitive index past the scene; a primitive listed twice. */
    index_cases(&q.prims[q.first[L2]], nt, qbvh_check_bunny, &q, "qbvh: primitive %u out of range or in two leaves");

    /* Leaf L's box collapsed to its upper corner: still inside its parent's,
     * no longer around its first triangle. */
    float lmin[4];
    memcpy(lmin, q.bmin[L], sizeof lmin);
    for (int a = 0; a < 3; a++) q.bmin[L][a] = q.bmax[L][a];
    refused(QBVH_CHECK(&q), "qbvh: leaf %u does not enclose triangle %u", L, q.prims[q.first[L]]);
    memcpy(q.bmin[L], lmin, sizeof lmin);
    ok(QBVH_CHECK(&q));

    /* Node 1's children start at node 2, its sibling (already reached). */
    const uint32_t f1 = q.first[1];
    q.first[1] = 2;
    refused(QBVH_CHECK(&q), "qbvh: node 2 reached twice");
    q.first[1] = f1;
    /* Five children: not a QBVH group. */
    const uint32_t k1 = q.count[1];
    q.count[1] = 5;
    refused(QBVH_CHECK(&q), "qbvh: inner node 1 has a bad child group (5 at %u)", f1);
    q.count[1] = k1;
    ok(QBVH_CHECK(&q));

    /* Node 1's box one ulp past the root's. */
    const float hx = q.bmax[1][0];
    q.bmax[1][0] = nextafterf(q.bmax[0][0], INFINITY);
    refused(QBVH_CHECK(&q), "qbvh: node 0 does not enclose child 1");
    q.bmax[1][0] = hx;
    ok(QBVH_CHECK(&q));

    /* A leaf that drops its last primitive: that one is in no leaf. */
    q.count[L2]--;
    refused(QBVH_CHECK(&q), "qbvh: %u of %u primitives in leaves", nt - 1, nt);
    q.count[L2]++;
    ok(QBVH_CHECK(&q));

    /* A node appended after every group (a copy of leaf L): nobody's child. */
    float(*bmin)[4] = realloc(q.bmin, ((size_t)nn + 1) * sizeof *q.bmin);
    assert_non_null(bmin);
    q.bmin = bmin;
    float(*bmax)[4] = realloc(q.bmax, ((size_t)nn + 1) * sizeof *q.bmax);
    assert_non_null(bmax);
    q.bmax = bmax;
    uint32_t *first = realloc(q.first, ((size_t)nn + 1) * sizeof *q.first);
    assert_non_null(first);
    q.first = first;
    uint32_t *count = realloc(q.count, ((size_t)nn + 1) * sizeof *q.count);
    assert_non_null(count);
    q.count = count;
    memcpy(q.bmin[nn], q.bmin[L], sizeof q.bmin[nn]);
    memcpy(q.bmax[nn], q.bmax[L], sizeof q.bmax[nn]);
    q.first[nn] = q.first[L];
    q.count[nn] = q.count[L];
    q.nnodes = nn + 1;
    refused(QBVH_CHECK(&q), "qbvh: node %u unreachable (or reached after its group)", nn);
    q.nnodes = nn;
    ok(QBVH_CHECK(&q));
    cbvh_qbvh_free(&q);
}

/* ---- cbvh_bsh_check ---------------------------------------------------------- */

#define BSH_CHECK(h) cbvh_bsh_check(h, &bunny, err, sizeof err)
static int bsh_check_bunny(const void *h) { return BSH_CHECK(h); }

static void test_bsh_check(void **st) {
    (void)st;
    cbvh_bsh h;
    ok(cbvh_bsh_build(&bunny, NULL, &h, err, sizeof err));
    ok(BSH_CHECK(&h));
    const uint32_t nn = h.nnodes, nt = bunny.ntris;
    /* A leaf with at least two triangles (L); an inner node with at least two
     * children (I); the root's children are followed by other nodes. */
    uint32_t L = UINT32_MAX, I = UINT32_MAX;
    for (uint32_t i = 0; i < nn; i++) {
        if (L == UINT32_MAX && !h.nchild[i] && h.ntri[i] >= 2) L = i;
        if (I == UINT32_MAX && h.nchild[i] >= 2) I = i;
    }
    assert_true(L != UINT32_MAX && I != UINT32_MAX && h.first_child[0] + h.nchild[0] < nn);

    h.nnodes = 0;
    refused(BSH_CHECK(&h), "bsh: no nodes");
    h.nnodes = nn;

    /* Root sphere: negative radius, infinite radius, NaN centre. */
    const cbvh_f32 r0 = h.sphere[0][3], x0 = h.sphere[0][0];
    h.sphere[0][3] = fb(-1.0f);
    refused(BSH_CHECK(&h), "bsh: node 0 has a non-finite or negative sphere");
    h.sphere[0][3] = CBVH_F32_POS_INF;
    refused(BSH_CHECK(&h), "bsh: node 0 has a non-finite or negative sphere");
    h.sphere[0][3] = r0;
    h.sphere[0][0] = fb(NAN);
    refused(BSH_CHECK(&h), "bsh: node 0 has a non-finite or negative sphere");
    h.sphere[0][0] = x0;
    ok(BSH_CHECK(&h));

    /* Leaf L without its triangles: no triangles, no children. */
    const uint32_t lt = h.ntri[L], lf = h.first_tri[L];
    h.ntri[L] = 0;
    refused(BSH_CHECK(&h), "bsh: node %u is empty", L);
    h.ntri[L] = lt;
    /* Its triangle range past tri_ids[], and one whose end wraps 32 bits. */
    h.first_tri[L] = h.ntri_ids;
    refused(BSH_CHECK(&h), "bsh: node %u triangle range out of bounds", L);
    h.first_tri[L] = UINT32_MAX;
    refused(BSH_CHECK(&h), "bsh: node %u triangle range out of bounds", L);
    h.first_tri[L] = lf;
    ok(BSH_CHECK(&h));

    /* The root's children starting at the root itself. */
    const uint32_t rf = h.first_child[0];
    h.first_child[0] = 0;
    refused(BSH_CHECK(&h), "bsh: node 0 child range [0, +%u) invalid", h.nchild[0]);
    h.first_child[0] = rf;
    ok(BSH_CHECK(&h));

    /* Node K (fewer than 8 children, followed by other nodes) claims one
     * child more: the next node, which has its own parent. */
    uint32_t K = UINT32_MAX;
    for (uint32_t i = 0; i < nn && K == UINT32_MAX; i++)
        if (h.nchild[i] >= 1 && h.nchild[i] < 8 && h.first_child[i] + h.nchild[i] < nn) K = i;
    assert_true(K != UINT32_MAX);
    const uint32_t kn = h.nchild[K];
    h.nchild[K] = kn + 1;
    refused(BSH_CHECK(&h), "bsh: node %u has two parents", h.first_child[K] + kn);
    h.nchild[K] = kn;
    ok(BSH_CHECK(&h));

    /* Nine children: more than an octant split makes (the list builder's
     * scratch holds 8). */
    const uint32_t rn = h.nchild[0];
    assert_true(rf + 9 <= nn);
    h.nchild[0] = 9;
    refused(BSH_CHECK(&h), "bsh: node 0 has 9 children (at most 8)");
    h.nchild[0] = rn;
    ok(BSH_CHECK(&h));

    /* The recorded depth (it sizes the list builder's scratch) one off either way. */
    const uint32_t d = h.depth;
    assert_true(d >= 1);
    h.depth = d + 1;
    refused(BSH_CHECK(&h), "bsh: depth recorded as %u, the hierarchy is %u deep", d + 1, d);
    h.depth = d - 1;
    refused(BSH_CHECK(&h), "bsh: depth recorded as %u, the hierarchy is %u deep", d - 1, d);
    h.depth = d;
    ok(BSH_CHECK(&h));

    /* Leaf L drops its last triangle: the slot count still matches the scene
     * and no triangle is there twice, but one is in no node. */
    const uint32_t dropped = h.tri_ids[lf + lt - 1];
    h.ntri[L] = lt - 1;
    refused(BSH_CHECK(&h), "bsh: triangle %u is in no node", dropped);
    h.ntri[L] = lt;
    ok(BSH_CHECK(&h));

    /* Node I forgets its last child: that node has no parent. */
    h.nchild[I]--;
    refused(BSH_CHECK(&h), "bsh: node %u unreachable", h.first_child[I] + h.nchild[I]);
    h.nchild[I]++;
    ok(BSH_CHECK(&h));

    /* One triangle slot more than the scene has triangles. */
    h.ntri_ids++;
    refused(BSH_CHECK(&h), "bsh: %u triangle slots for %u triangles", nt + 1, nt);
    h.ntri_ids--;
    ok(BSH_CHECK(&h));

    /* A triangle index past the scene; a triangle listed twice. */
    index_cases(&h.tri_ids[lf], nt, bsh_check_bunny, &h, "bsh: triangle %u missing or twice");

    /* Radius +0 and -0 (-0 is not "negative": it fails as too small) at leaf
     * L, and +0 at the root, which is checked for every triangle. */
    const cbvh_f32 rl = h.sphere[L][3];
    h.sphere[L][3] = 0;
    refused(BSH_CHECK(&h), "bsh: sphere of node %u does not enclose vertex ", L);
    h.sphere[L][3] = CBVH_F32_SIGN;
    refused(BSH_CHECK(&h), "bsh: sphere of node %u does not enclose vertex ", L);
    h.sphere[L][3] = rl;
    h.sphere[0][3] = 0;
    refused(BSH_CHECK(&h), "bsh: sphere of node 0 does not enclose vertex ");
    h.sphere[0][3] = r0;
    ok(BSH_CHECK(&h));
    cbvh_bsh_free(&h);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bvh_check),
        cmocka_unit_test(test_tree_check),
        cmocka_unit_test(test_tree_check_root_leaf),
        cmocka_unit_test(test_qbvh_check),
        cmocka_unit_test(test_bsh_check),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
