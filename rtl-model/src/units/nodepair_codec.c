/* Node-pair codec: two compressed child boxes + leaf bits + pointers in one
 * 16-byte (N <= 6) or 24-byte (N >= 7) node pair (docs/datapath.md, unit 4).
 *
 * Node i of the pair occupies bytes [i*W/8, (i+1)*W/8), bit 0 = LSB of byte 0:
 *   bits [2aN, 2aN+N)      lower code of axis a (x, y, z)
 *   bits [2aN+N, 2aN+2N)   upper code of axis a
 *   bit  6N                leaf
 *   bits [6N+1, 6N+1+P)    pointer, P = min(32, W - 6N - 1)
 *   remaining bits         reserved, zero
 * Empty child: leaf = 1, pointer all ones, codes zero. */
#include <string.h>

#include "cbvh/datapath.h"
#include "units/grid.h"
#include "fast/unit_fast.h"

int cbvh_node_bits(int n) { return n <= 6 ? 64 : 96; }
size_t cbvh_nodepair_bytes(int n) { return (size_t)cbvh_node_bits(n) / 4u; }
int cbvh_node_ptr_bits(int n) {
    int p = cbvh_node_bits(n) - 6 * n - 1;
    return p > 32 ? 32 : p;
}

static uint32_t ptr_all_ones(int n) {
    int pb = cbvh_node_ptr_bits(n);
    return pb >= 32 ? 0xFFFFFFFFu : (1u << pb) - 1u;
}

/* A node as a little-endian bit string of up to 128 bits: bit i is bit
 * (i % 8) of byte i / 8.  Loaded into two 64-bit words so that fields are
 * read and written with shifts, not bit by bit. */
typedef struct {
    uint64_t w[2];
} node_bits;

static uint64_t load_le(const uint8_t *b, int nbytes) {
    uint64_t v = 0;
    for (int i = 0; i < nbytes; i++) v |= (uint64_t)b[i] << (8 * i);
    return v;
}

/* A node (8 or 12 bytes). */
static node_bits load_node(const uint8_t *b, int nbytes) {
    node_bits v = {{load_le(b, 8), nbytes > 8 ? load_le(b + 8, nbytes - 8) : 0}};
    return v;
}

static uint32_t get_bits(const node_bits *n, int pos, int width) {
    uint64_t x = n->w[pos >> 6] >> (pos & 63);
    if ((pos & 63) + width > 64) x |= n->w[(pos >> 6) + 1] << (64 - (pos & 63));
    return (uint32_t)(x & ((UINT64_C(1) << width) - 1));
}

/* Both directions check the node's context first, with the same rule, so
 * they reject the same contexts: relative codes depend on parent_scale -
 * scale, and a pair of two empty children runs no axis unit that would
 * (docs/datapath.md §9). */
static uint32_t node_ctx_check(const cbvh_params *p, const cbvh_node_ctx *ctx) {
    uint32_t st = 0;
    for (int a = 0; a < 3; a++) st |= cbvh_axis_ctx_check(p, &ctx->axis[a]);
    return st;
}

uint32_t cbvh_nodepair_encode(const cbvh_params *p, cbvh_encoding enc, const cbvh_node_ctx *ctx,
                              const cbvh_child_in child[2], uint8_t *bytes, cbvh_child_out out[2]) {
    int n = p->quant_bits;
    uint32_t st = cbvh_params_check(p);
    memset(out, 0, 2 * sizeof *out);
    if (st) return st;
    size_t nb = cbvh_nodepair_bytes(n);
    int w = cbvh_node_bits(n), pb = cbvh_node_ptr_bits(n);
    uint32_t ones = ptr_all_ones(n);
    st = node_ctx_check(p, ctx);
    if (st) {
        memset(bytes, 0, nb); /* bytes and outputs are zero */
        return st;
    }
    for (int c = 0; c < 2; c++) {
        uint8_t *bytes_c = bytes + (size_t)c * (size_t)w / 8u;
        cbvh_child_out *o = &out[c];
        if (child[c].empty) {
            o->empty = o->leaf = 1;
            o->ptr = ones;
            cbvh_fast_put_node(n, 0, 1, ones, bytes_c); /* writes the whole node */
            continue;
        }
        if (child[c].leaf ? child[c].ptr >= ones : (pb < 32 && child[c].ptr > ones)) st |= CBVH_ST_BAD_FORMAT;
        o->leaf = child[c].leaf != 0;
        o->ptr = child[c].ptr;
        uint64_t codes = 0;
        for (int a = 0; a < 3; a++) {
            const cbvh_axis_ctx *ac = &ctx->axis[a];
            st |= cbvh_axis_compress(p, child[c].lo[a], child[c].hi[a], ac->scale, ac->clb, &o->axis[a]);
            uint32_t lc, uc;
            cbvh_axis_store_codes(p, enc, ac, &o->axis[a], &lc, &uc);
            codes |= (uint64_t)lc << (2 * a * n) | (uint64_t)uc << (2 * a * n + n);
        }
        /* a pointer wider than its field is BAD_FORMAT: the pair is zeroed below */
        cbvh_fast_put_node(n, codes, o->leaf, o->ptr & ones, bytes_c);
    }
    if (st & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) {
        memset(bytes, 0, nb);
        memset(out, 0, 2 * sizeof *out);
    }
    return st;
}

uint32_t cbvh_nodepair_decode(const cbvh_params *p, cbvh_encoding enc, const cbvh_node_ctx *ctx,
                              const uint8_t *bytes, cbvh_child_out out[2]) {
    int n = p->quant_bits;
    uint32_t st = cbvh_params_check(p);
    memset(out, 0, 2 * sizeof *out);
    if (st) return st;
    int w = cbvh_node_bits(n), pb = cbvh_node_ptr_bits(n);
    uint32_t ones = ptr_all_ones(n);
    st = node_ctx_check(p, ctx);
    if (st) return st;
    for (int c = 0; c < 2; c++) {
        const node_bits nb_c = load_node(bytes + (size_t)c * (size_t)w / 8u, w / 8), *node = &nb_c;
        cbvh_child_out *o = &out[c];
        for (int pos = 6 * n + 1 + pb; pos < w; pos += 32) {
            int width = w - pos < 32 ? w - pos : 32;
            if (get_bits(node, pos, width)) st |= CBVH_ST_BAD_FORMAT;
        }
        o->leaf = (int)get_bits(node, 6 * n, 1);
        o->ptr = get_bits(node, 6 * n + 1, pb);
        if (o->leaf && o->ptr == ones) {
            o->empty = 1;
            for (int a = 0; a < 6; a++)
                if (get_bits(node, a * n, n)) st |= CBVH_ST_BAD_FORMAT;
            continue;
        }
        for (int a = 0; a < 3; a++)
            st |= cbvh_axis_decode(p, enc, &ctx->axis[a], get_bits(node, 2 * a * n, n),
                                   get_bits(node, 2 * a * n + n, n), &o->axis[a]);
    }
    if (st & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) memset(out, 0, 2 * sizeof *out);
    return st;
}
