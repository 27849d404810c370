/* Unit 8: the QBVH compressed stack entry (seed 000, Bogolepov & Ulyanov) and
 * the 5-comparator sort of the children's hit times.  Integer-only; spec and
 * errata of the printed pseudocode: docs/qbvh.md. */
#include "cbvh/qbvh_stack.h"

/* Comparator key (missed, t, index): a total order, so the network's output
 * is the unique sorted permutation whatever the ties. */
static int before(const int64_t key[4], uint32_t hit_mask, uint8_t a, uint8_t b) {
    int ma = !((hit_mask >> a) & 1u), mb = !((hit_mask >> b) & 1u);
    if (ma != mb) return ma < mb;
    if (!ma && key[a] != key[b]) return key[a] < key[b];
    return a < b;
}

static void cmp_swap(const int64_t key[4], uint32_t hit_mask, uint8_t order[4], int i, int j) {
    if (before(key, hit_mask, order[j], order[i])) {
        uint8_t x = order[i];
        order[i] = order[j];
        order[j] = x;
    }
}

uint32_t cbvh_qstack_sort(const uint32_t t[4], uint32_t hit_mask, uint8_t order[4], int *nhit) {
    uint32_t st = 0;
    if (hit_mask > 15u) st |= CBVH_ST_BAD_PARAM;
    for (int c = 0; c < 4 && !st; c++)
        if (((hit_mask >> c) & 1u) && cbvh_f32_is_nan(t[c])) st |= CBVH_ST_NAN_INF;
    if (st) {
        for (int c = 0; c < 4; c++) order[c] = 0;
        *nhit = 0;
        return st;
    }
    int64_t key[4];
    for (int c = 0; c < 4; c++) {
        order[c] = (uint8_t)c;
        key[c] = ((hit_mask >> c) & 1u) ? cbvh_f32_key(t[c]) : 0;
    }
    cmp_swap(key, hit_mask, order, 0, 1);
    cmp_swap(key, hit_mask, order, 2, 3);
    cmp_swap(key, hit_mask, order, 0, 2);
    cmp_swap(key, hit_mask, order, 1, 3);
    cmp_swap(key, hit_mask, order, 1, 2);
    int n = 0;
    for (int c = 0; c < 4; c++) n += (int)((hit_mask >> c) & 1u);
    *nhit = n;
    return 0;
}

/* The 6-bit offset block o0 | o1 << 2 | o2 << 4 for deferred children
 * order[1 .. nhit-1] (nhit >= 2): a missing far child repeats the previous
 * offset.  -1 if the arguments are invalid. */
static int offsets_for(const uint8_t order[4], int nhit) {
    if (nhit < 0 || nhit > 4) return -1;
    unsigned seen = 0;
    for (int c = 0; c < 4; c++) {
        if (order[c] > 3) return -1;
        seen |= 1u << order[c];
    }
    if (seen != 15u) return -1;
    if (nhit < 2) return 0;
    unsigned o0 = order[1], o1 = nhit >= 3 ? order[2] : o0, o2 = nhit >= 4 ? order[3] : o1;
    return (int)(o0 | o1 << 2 | o2 << 4);
}

/* Pop on the offset block: the popped offset, the shifted block (o1, o2, o2)
 * and whether the entry stays.  This is the pseudocode's
 * mask | ((mask << 2) & 0x30) with mask = block >> 2 taken unsigned. */
static unsigned offsets_pop(unsigned block, unsigned *next, int *keep) {
    unsigned node = block & 3u, mask = block >> 2;
    *keep = (mask & 3u) != node;
    *next = *keep ? ((mask | ((mask << 2) & 0x30u)) & 0x3Fu) : 0u;
    return node;
}

uint32_t cbvh_qstack_push(uint32_t first, const uint8_t order[4], int nhit, uint32_t *entry) {
    int off = offsets_for(order, nhit);
    uint32_t st = 0;
    if (off < 0) st |= CBVH_ST_BAD_PARAM;
    if (first >= CBVH_QSTACK_ID_LIMIT) st |= CBVH_ST_BAD_CODE;
    *entry = 0;
    if (st) return st;
    if (nhit >= 2) *entry = first | (uint32_t)off << CBVH_QSTACK_ID_BITS;
    return 0;
}

uint32_t cbvh_qstack_pop(uint32_t entry, uint32_t *node, uint32_t *next, int *keep) {
    uint32_t id = entry & (CBVH_QSTACK_ID_LIMIT - 1u);
    unsigned nb;
    unsigned o = offsets_pop(entry >> CBVH_QSTACK_ID_BITS, &nb, keep);
    *node = id + o;
    *next = *keep ? id | (uint32_t)nb << CBVH_QSTACK_ID_BITS : 0u;
    return 0;
}

uint64_t cbvh_qstack_push_wide(uint32_t first, const uint8_t order[4], int nhit) {
    int off = offsets_for(order, nhit);
    if (off < 0 || nhit < 2) return 0;
    return (uint64_t)first | (uint64_t)off << 32;
}

uint32_t cbvh_qstack_pop_wide(uint64_t entry, uint64_t *next, int *keep) {
    uint32_t id = (uint32_t)entry;
    unsigned nb;
    unsigned o = offsets_pop((unsigned)(entry >> 32) & 0x3Fu, &nb, keep);
    *next = *keep ? (uint64_t)id | (uint64_t)nb << 32 : 0u;
    return id + o;
}
