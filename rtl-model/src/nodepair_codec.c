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
#include "grid.h"

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

static void put_bits(uint8_t *b, int pos, int width, uint32_t v) {
    for (int i = 0; i < width; i++, pos++) {
        uint8_t bit = (uint8_t)(1u << (pos & 7));
        if ((v >> i) & 1u)
            b[pos >> 3] |= bit;
        else
            b[pos >> 3] &= (uint8_t)~bit;
    }
}

static uint32_t get_bits(const uint8_t *b, int pos, int width) {
    uint32_t v = 0;
    for (int i = 0; i < width; i++, pos++) v |= (uint32_t)((b[pos >> 3] >> (pos & 7)) & 1u) << i;
    return v;
}

uint32_t cbvh_nodepair_encode(const cbvh_params *p, cbvh_encoding enc, const cbvh_node_ctx *ctx,
                              const cbvh_child_in child[2], uint8_t *bytes, cbvh_child_out out[2]) {
    int n = p->quant_bits;
    uint32_t st = cbvh_params_check(p);
    memset(out, 0, 2 * sizeof *out);
    if (st) return st;
    size_t nb = cbvh_nodepair_bytes(n);
    int w = cbvh_node_bits(n), pb = cbvh_node_ptr_bits(n);
    memset(bytes, 0, nb);
    uint32_t ones = ptr_all_ones(n);
    for (int c = 0; c < 2; c++) {
        uint8_t *node = bytes + (size_t)c * (size_t)w / 8u;
        cbvh_child_out *o = &out[c];
        if (child[c].empty) {
            o->empty = o->leaf = 1;
            o->ptr = ones;
            put_bits(node, 6 * n, 1, 1);
            put_bits(node, 6 * n + 1, pb, ones);
            continue;
        }
        if (child[c].leaf ? child[c].ptr >= ones : (pb < 32 && child[c].ptr > ones)) st |= CBVH_ST_BAD_FORMAT;
        o->leaf = child[c].leaf != 0;
        o->ptr = child[c].ptr;
        for (int a = 0; a < 3; a++) {
            const cbvh_axis_ctx *ac = &ctx->axis[a];
            st |= cbvh_axis_compress(p, child[c].lo[a], child[c].hi[a], ac->scale, &o->axis[a]);
            uint32_t lc, uc;
            cbvh_axis_store_codes(p, enc, ac, &o->axis[a], &lc, &uc);
            put_bits(node, 2 * a * n, n, lc);
            put_bits(node, 2 * a * n + n, n, uc);
        }
        put_bits(node, 6 * n, 1, (uint32_t)o->leaf);
        put_bits(node, 6 * n + 1, pb, o->ptr);
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
    for (int c = 0; c < 2; c++) {
        const uint8_t *node = bytes + (size_t)c * (size_t)w / 8u;
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
