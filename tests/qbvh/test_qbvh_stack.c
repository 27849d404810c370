/* The QBVH stack unit (docs/qbvh.md §2) against an independent reference: a
 * plain array stack of node IDs and a sort by (missed, t, index), over millions
 * of random child masks / hit times (ties included), plus exhaustive offset
 * blocks, the 2^26 limit and the printed pseudocode's errata. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/qbvh.h"
#include "cbvh/traversal_units.h"
#include "test_util.h"

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

static uint64_t rs = 0x1234567887654321ull;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }

/* Reference sort: insertion sort on (missed, value of t as a double, index). */
static double fval(uint32_t b) {
    return (double)cbvh_float_of(b); /* the FPU as an independent oracle; -0 == +0 */
}
static void ref_sort(const uint32_t t[4], unsigned mask, int order[4], int *nhit) {
    int n = 0;
    for (int c = 0; c < 4; c++) order[c] = c;
    for (int i = 1; i < 4; i++)
        for (int j = i; j > 0; j--) {
            int a = order[j - 1], b = order[j];
            int ma = !((mask >> a) & 1), mb = !((mask >> b) & 1);
            int swap = ma != mb ? mb < ma : (!ma && fval(t[a]) != fval(t[b])) ? fval(t[b]) < fval(t[a]) : b < a;
            if (!swap) break;
            order[j - 1] = b;
            order[j] = a;
        }
    for (int c = 0; c < 4; c++) n += (mask >> c) & 1;
    *nhit = n;
}

static uint32_t rnd_time(const uint32_t pool[3]) {
    switch (rnd() % 4) {
    case 0: return pool[rnd() % 3]; /* ties */
    case 1: return (uint32_t)(rnd() % 2) << 31; /* +-0 */
    default: {
        uint32_t x = (uint32_t)rnd() & 0x7F7FFFFFu; /* finite, positive */
        return x;
    }
    }
}

/* Random push/pop sequences: compressed stack vs a plain array stack. */
static void random_sequences(long ops) {
    enum { CAP = 4096 };
    static uint32_t cs[CAP], ps[CAP * 3];
    int ch = 0, ph = 0;
    long pushes = 0, pops = 0;
    for (long i = 0; i < ops; i++) {
        if (rnd() % 2 == 0 && ch < CAP) {
            uint32_t t[4], pool[3] = {(uint32_t)rnd() & 0x7F7FFFFFu, (uint32_t)rnd() & 0x7F7FFFFFu, 0x3F800000u};
            for (int c = 0; c < 4; c++) t[c] = rnd_time(pool);
            unsigned mask = (unsigned)(rnd() % 16);
            uint32_t first;
            switch (rnd() % 4) {
            case 0: first = CBVH_QSTACK_ID_LIMIT - 1u - (uint32_t)(rnd() % 8); break;
            case 1: first = (uint32_t)(rnd() % 16); break;
            default: first = (uint32_t)(rnd() % CBVH_QSTACK_ID_LIMIT); break;
            }
            uint8_t order[4];
            int nhit, rorder[4], rn;
            uint32_t st = cbvh_qstack_sort(t, mask, order, &nhit);
            ref_sort(t, mask, rorder, &rn);
            CHECK(st == 0 && nhit == rn, "sort status %u nhit %d ref %d", st, nhit, rn);
            for (int c = 0; c < 4; c++)
                CHECK(order[c] == rorder[c], "order[%d] = %d, ref %d (mask %x)", c, order[c], rorder[c], mask);
            uint32_t e;
            st = cbvh_qstack_push(first, order, nhit, &e);
            CHECK(st == 0, "push status %u", st);
            if (nhit >= 2) {
                cs[ch++] = e;
                for (int k = nhit - 1; k >= 1; k--) ps[ph++] = first + (uint32_t)rorder[k];
                pushes++;
            } else {
                CHECK(e == 0, "push with %d hits wrote %08x", nhit, e);
            }
        } else if (ch > 0) {
            uint32_t node, next;
            int keep;
            cbvh_qstack_pop(cs[ch - 1], &node, &next, &keep);
            if (keep) cs[ch - 1] = next;
            else ch--;
            CHECK(ph > 0 && node == ps[ph - 1], "pop gave %u, reference %u", node, ph ? ps[ph - 1] : 0);
            ph--;
            pops++;
        }
        /* the compressed stack is empty exactly when the plain one is */
        CHECK((ch == 0) == (ph == 0), "stack emptiness differs: %d entries vs %d", ch, ph);
    }
    printf("random sequences: %ld operations, %ld pushes, %ld pops\n", ops, pushes, pops);
}

/* Every permutation x nhit 0..4: push then pop until exhausted returns
 * exactly order[1 .. nhit-1]; the wide entry does the same. */
static void exhaustive_push_pop(void) {
    int perms = 0;
    for (int p = 0; p < 256; p++) {
        uint8_t o[4] = {(uint8_t)(p & 3), (uint8_t)(p >> 2 & 3), (uint8_t)(p >> 4 & 3), (uint8_t)(p >> 6 & 3)};
        int ok = o[0] != o[1] && o[0] != o[2] && o[0] != o[3] && o[1] != o[2] && o[1] != o[3] && o[2] != o[3];
        for (int nhit = 0; nhit <= 4; nhit++) {
            uint32_t e;
            uint32_t st = cbvh_qstack_push(100, o, nhit, &e);
            if (!ok) {
                CHECK(st == CBVH_ST_BAD_PARAM && e == 0, "non-permutation accepted");
                continue;
            }
            perms += nhit == 0;
            CHECK(st == 0, "push status %u", st);
            uint64_t w = cbvh_qstack_push_wide(100, o, nhit);
            CHECK((uint32_t)w == (nhit >= 2 ? 100u : 0u) && (w >> 32) == (nhit >= 2 ? e >> 26 : 0),
                  "wide entry %016llx vs %08x", (unsigned long long)w, e);
            if (nhit < 2) continue;
            int k = 1, keep = 1;
            while (keep) {
                uint32_t node, next;
                uint64_t wn;
                int wkeep;
                cbvh_qstack_pop(e, &node, &next, &keep);
                uint32_t wnode = cbvh_qstack_pop_wide(w, &wn, &wkeep);
                CHECK(k < nhit && node == 100u + o[k], "pop %d gave %u want %u", k, node, 100u + o[k]);
                CHECK(wnode == node && wkeep == keep, "wide pop differs");
                e = next;
                w = wn;
                k++;
            }
            CHECK(k == nhit, "exhausted after %d pops, want %d", k - 1, nhit - 1);
        }
    }
    CHECK(perms == 24, "%d permutations", perms);
    CHECK(cbvh_qstack_push(0, (const uint8_t[4]){0, 1, 2, 3}, 5, &(uint32_t){0}) == CBVH_ST_BAD_PARAM, "nhit 5");
}

/* The printed Pop() read literally with a signed int (arithmetic >>), and with
 * the precedence "fixed" the wrong way: both differ from the unit, which is
 * the pseudocode's intent (docs/qbvh.md, errata E3/E4). */
static uint32_t paper_pop_signed(uint32_t entry, int *keep, uint32_t *next) {
    int64_t data = (int32_t)entry; /* int data = Stack[head] */
    /* cppcheck-suppress shiftNegativeLHS ; the paper's int shift (implementation-defined, arithmetic on gcc/clang) */
    int64_t mask = data >> 26; /* sign-extends when o2 >= 2 */
    int64_t node = mask & 3;
    mask >>= 2;
    *keep = (mask & 3) != node;
    uint64_t um = (uint64_t)mask; /* the sign-extended bits, shifted as GLSL would (no C UB) */
    *next = *keep ? (uint32_t)(((uint64_t)data & 0x03FFFFFF) | (((um | ((um << 2) & 0x30)) << 26) & 0xFFFFFFFF)) : 0;
    return (uint32_t)((data & 0x03FFFFFF) + node);
}
static uint32_t paper_pop_paren(uint32_t entry, int *keep, uint32_t *next) {
    uint32_t mask = entry >> 26, node = mask & 3;
    mask >>= 2;
    *keep = (mask & 3) != node;
    *next = *keep ? (entry & 0x03FFFFFFu) | (((mask | (mask << 2)) & 0x30u) << 26) : 0;
    return (entry & 0x03FFFFFFu) + node;
}
static void errata(void) {
    int diff_signed = 0, diff_paren = 0, same_unsigned = 0;
    for (uint32_t b = 0; b < 64; b++) {
        uint32_t e = 12345u | b << 26, n1, x1, n2, x2, n3, x3;
        int k1, k2, k3;
        cbvh_qstack_pop(e, &n1, &x1, &k1);
        n2 = paper_pop_signed(e, &k2, &x2);
        n3 = paper_pop_paren(e, &k3, &x3);
        diff_signed += n1 != n2 || k1 != k2 || x1 != x2;
        diff_paren += n1 != n3 || k1 != k3 || x1 != x3;
        /* the unit == the pseudocode with unsigned data and C/GLSL precedence */
        uint32_t m = e >> 26, node = m & 3;
        m >>= 2;
        int kk = (m & 3) != node;
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wparentheses"
        uint32_t xx = kk ? (e & 0x03FFFFFFu) | ((m | (m << 2) & 0x30u) << 26) : 0; /* the printed grouping */
#pragma GCC diagnostic pop
        same_unsigned += n1 == (e & 0x03FFFFFFu) + node && k1 == kk && x1 == xx;
    }
    CHECK(same_unsigned == 64, "unit differs from the unsigned pseudocode in %d blocks", 64 - same_unsigned);
    CHECK(diff_signed > 0, "signed reading should differ (sign extension)");
    CHECK(diff_paren > 0, "(mask | mask << 2) & 0x30 should differ");
    printf("errata: signed data differs in %d of 64 offset blocks, wrong parenthesisation in %d\n", diff_signed,
           diff_paren);
}

/* 2^26: the last ID works, the first ID past it is rejected, never wrapped. */
static void id_limit(void) {
    const uint8_t o[4] = {3, 0, 2, 1};
    uint32_t e, node, next;
    int keep;
    CHECK(cbvh_qstack_push(CBVH_QSTACK_ID_LIMIT - 1u, o, 4, &e) == 0, "last ID rejected");
    cbvh_qstack_pop(e, &node, &next, &keep);
    CHECK(node == CBVH_QSTACK_ID_LIMIT - 1u && keep, "pop at the limit: %u", node);
    cbvh_qstack_pop(next, &node, &next, &keep);
    CHECK(node == CBVH_QSTACK_ID_LIMIT + 1u, "ID + offset past 2^26 must not wrap: %u", node);
    for (uint32_t f = CBVH_QSTACK_ID_LIMIT; f < CBVH_QSTACK_ID_LIMIT + 4u; f++) {
        e = 0xDEADBEEF;
        CHECK(cbvh_qstack_push(f, o, 4, &e) == CBVH_ST_BAD_CODE && e == 0, "ID %u not rejected", f);
    }
    e = 1;
    CHECK(cbvh_qstack_push(0xFFFFFFFFu, o, 1, &e) == CBVH_ST_BAD_CODE && e == 0, "ID checked with one hit too");
    CHECK(cbvh_qstack_push_wide(CBVH_QSTACK_ID_LIMIT + 5u, o, 3) >> 32 == (0u | 2u << 2 | 2u << 4),
          "wide entry holds IDs past 2^26");
    uint8_t ord[4];
    int nhit;
    const uint32_t tn[4] = {0x3F800000u, 0x7FC00000u, 0, 0};
    CHECK(cbvh_qstack_sort(tn, 3, ord, &nhit) == CBVH_ST_NAN_INF, "NaN hit time");
    CHECK(cbvh_qstack_sort(tn, 1, ord, &nhit) == 0 && nhit == 1 && ord[0] == 0, "NaN of a missed child ignored");
    CHECK(cbvh_qstack_sort(tn, 16, ord, &nhit) == CBVH_ST_BAD_PARAM, "mask 16");
}

int main(void) {
#ifdef CBVH_SANITIZE
    long ops = 2000000;
#else
    long ops = 20000000;
#endif
    exhaustive_push_pop();
    errata();
    id_limit();
    random_sequences(ops);
    printf("%s (%d failures)\n", fails ? "FAILED" : "ok", fails);
    return fails ? 1 : 0;
}
