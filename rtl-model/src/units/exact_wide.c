/* Exact wide dyadic arithmetic (see exact_wide.h).  Integer-only. */
#include "units/exact_wide.h"

#include <stdlib.h>
#include <string.h>

#define L CBVH_XW_LIMBS

static void norm(cbvh_xw *x) {
    while (x->n > 0 && x->m[x->n - 1] == 0) x->n--;
    int z = 0; /* drop whole zero limbs at the bottom: keeps numbers short */
    while (z < x->n && x->m[z] == 0) z++;
    if (z) {
        memmove(x->m, x->m + z, (size_t)(x->n - z) * sizeof x->m[0]);
        x->n -= z;
        x->exp += 32 * z;
    }
    if (x->n == 0) {
        x->neg = 0;
        x->exp = 0;
    }
}

/* The model's widths are bounded (docs/traversal.md §2); exceeding them is a
 * bug in the model, not an input error. */
static void need(int n) {
    if (n > L) abort();
}

void cbvh_xw_zero(cbvh_xw *x) {
    x->neg = 0;
    x->exp = 0;
    x->n = 0;
}

void cbvh_xw_from_int(cbvh_xw *x, int64_t v, int exp) {
    uint64_t m = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
    x->neg = v < 0;
    x->exp = exp;
    x->m[0] = (uint32_t)m;
    x->m[1] = (uint32_t)(m >> 32);
    x->n = 2;
    norm(x);
}

void cbvh_xw_from_f32(cbvh_xw *x, cbvh_f32 f) {
    int s, e;
    uint32_t sig;
    cbvh_f32_break(f, &s, &sig, &e);
    cbvh_xw_from_int(x, s ? -(int64_t)sig : (int64_t)sig, e);
}

/* dst = src << sh (bits); returns limbs used. dst may not alias src. */
static int mag_shl(uint32_t *dst, const uint32_t *src, int n, int sh) {
    if (n == 0) return 0;
    int w = sh / 32, b = sh % 32;
    need(n + w + 1);
    memset(dst, 0, (size_t)w * sizeof *dst);
    uint32_t carry = 0;
    for (int i = 0; i < n; i++) {
        dst[w + i] = (src[i] << b) | carry;
        carry = b ? src[i] >> (32 - b) : 0;
    }
    dst[w + n] = carry;
    int m = w + n + 1;
    while (m > 0 && dst[m - 1] == 0) m--;
    return m;
}

static int mag_cmp(const uint32_t *a, int na, const uint32_t *b, int nb) {
    if (na != nb) return na > nb ? 1 : -1;
    for (int i = na - 1; i >= 0; i--)
        if (a[i] != b[i]) return a[i] > b[i] ? 1 : -1;
    return 0;
}

/* r = a + b; r may alias a. */
static int mag_add(uint32_t *r, const uint32_t *a, int na, const uint32_t *b, int nb) {
    int n = na > nb ? na : nb;
    need(n + 1);
    uint64_t c = 0;
    for (int i = 0; i < n; i++) {
        c += (uint64_t)(i < na ? a[i] : 0) + (i < nb ? b[i] : 0);
        r[i] = (uint32_t)c;
        c >>= 32;
    }
    r[n] = (uint32_t)c;
    return c ? n + 1 : n;
}

/* r = a - b with a >= b; r may alias a. */
static int mag_sub(uint32_t *r, const uint32_t *a, int na, const uint32_t *b, int nb) {
    int64_t br = 0;
    for (int i = 0; i < na; i++) {
        int64_t d = (int64_t)a[i] - (i < nb ? b[i] : 0) - br;
        br = d < 0;
        r[i] = (uint32_t)(d + (br ? ((int64_t)1 << 32) : 0));
    }
    int n = na;
    while (n > 0 && r[n - 1] == 0) n--;
    return n;
}

static int mag_bitlen(const uint32_t *a, int n) {
    if (n == 0) return 0;
    return 32 * (n - 1) + cbvh_bitlen64(a[n - 1]);
}

/* r = x, copying only the limbs in use (the struct is large). */
static void copy(cbvh_xw *r, const cbvh_xw *x, int flip) {
    r->neg = x->n ? x->neg ^ flip : 0;
    r->exp = x->exp;
    r->n = x->n;
    if (r != x) memcpy(r->m, x->m, (size_t)x->n * sizeof x->m[0]);
}

/* r = a + (-1)^flip b. */
static void add_signed(cbvh_xw *r, const cbvh_xw *a, const cbvh_xw *b, int flip) {
    if (a->n == 0) {
        copy(r, b, flip);
        return;
    }
    if (b->n == 0) {
        copy(r, a, 0);
        return;
    }
    int bneg = b->neg ^ flip;
    int e0 = a->exp < b->exp ? a->exp : b->exp;
    (void)e0;
#ifdef __SIZEOF_INT128__
    if (a->n <= 2 && b->n <= 2 && a->exp - e0 <= 60 && b->exp - e0 <= 60) {
        /* fast path: both aligned magnitudes fit in 124 bits */
        typedef unsigned __int128 u128;
        u128 ma = ((u128)(a->n > 1 ? a->m[1] : 0) << 32 | a->m[0]) << (a->exp - e0);
        u128 mb = ((u128)(b->n > 1 ? b->m[1] : 0) << 32 | b->m[0]) << (b->exp - e0);
        u128 mr;
        int neg;
        if (a->neg == bneg) {
            mr = ma + mb;
            neg = a->neg;
        } else if (ma >= mb) {
            mr = ma - mb;
            neg = a->neg;
        } else {
            mr = mb - ma;
            neg = bneg;
        }
        for (int i = 0; i < 4; i++) r->m[i] = (uint32_t)(mr >> (32 * i));
        r->n = 4;
        r->neg = neg;
        r->exp = e0;
        norm(r);
        return;
    }
#endif
    /* align both to the lower exponent */
    uint32_t ta[L + 2], tb[L + 2];
    int e = a->exp < b->exp ? a->exp : b->exp;
    int na = mag_shl(ta, a->m, a->n, a->exp - e);
    int nb = mag_shl(tb, b->m, b->n, b->exp - e);
    cbvh_xw out;
    out.exp = e;
    if (a->neg == bneg) {
        out.neg = a->neg;
        out.n = mag_add(out.m, ta, na, tb, nb);
    } else {
        int c = mag_cmp(ta, na, tb, nb);
        if (c >= 0) {
            out.neg = a->neg;
            out.n = mag_sub(out.m, ta, na, tb, nb);
        } else {
            out.neg = bneg;
            out.n = mag_sub(out.m, tb, nb, ta, na);
        }
    }
    norm(&out);
    copy(r, &out, 0);
}

void cbvh_xw_add(cbvh_xw *r, const cbvh_xw *a, const cbvh_xw *b) { add_signed(r, a, b, 0); }
void cbvh_xw_sub(cbvh_xw *r, const cbvh_xw *a, const cbvh_xw *b) { add_signed(r, a, b, 1); }

void cbvh_xw_mul(cbvh_xw *r, const cbvh_xw *a, const cbvh_xw *b) {
    cbvh_xw out;
    if (a->n == 0 || b->n == 0) {
        cbvh_xw_zero(r);
        return;
    }
#ifdef __SIZEOF_INT128__
    if (a->n <= 2 && b->n <= 2) { /* fast path: 64 x 64 bits */
        typedef unsigned __int128 u128;
        uint64_t ma = (uint64_t)(a->n > 1 ? a->m[1] : 0) << 32 | a->m[0];
        uint64_t mb = (uint64_t)(b->n > 1 ? b->m[1] : 0) << 32 | b->m[0];
        u128 p = (u128)ma * mb;
        int neg = a->neg != b->neg, exp = a->exp + b->exp;
        for (int i = 0; i < 4; i++) r->m[i] = (uint32_t)(p >> (32 * i));
        r->n = 4;
        r->neg = neg;
        r->exp = exp;
        norm(r);
        return;
    }
#endif
    need(a->n + b->n);
    memset(out.m, 0, (size_t)(a->n + b->n) * sizeof out.m[0]);
    for (int i = 0; i < a->n; i++) {
        uint64_t c = 0;
        for (int j = 0; j < b->n; j++) {
            c += (uint64_t)a->m[i] * b->m[j] + out.m[i + j];
            out.m[i + j] = (uint32_t)c;
            c >>= 32;
        }
        out.m[i + b->n] = (uint32_t)c;
    }
    out.n = a->n + b->n;
    out.neg = a->neg != b->neg;
    out.exp = a->exp + b->exp;
    norm(&out);
    copy(r, &out, 0);
}

int cbvh_xw_cmp(const cbvh_xw *a, const cbvh_xw *b) {
    cbvh_xw d;
    cbvh_xw_sub(&d, a, b);
    return cbvh_xw_sign(&d);
}

cbvh_f32 cbvh_xw_div_round(const cbvh_xw *a, const cbvh_xw *b, int bits, cbvh_rnd mode) {
    if (a->n == 0 || b->n == 0) return 0;
    int neg = a->neg != b->neg;
    /* Quotient with P = bits + 2 significant bits (or P + 1) plus sticky:
     * A = |a| * 2^sa, B = |b| * 2^sb with bitlen(A) = bitlen(B) + P. */
    const int P = bits + 2;
    uint32_t A[L + 2], B[L + 2];
    int la = mag_bitlen(a->m, a->n), lb = mag_bitlen(b->m, b->n);
    int sh = lb + P - la, sa = sh > 0 ? sh : 0, sb = sh > 0 ? 0 : -sh;
    int na = mag_shl(A, a->m, a->n, sa);
    uint64_t q = 0;
    int nb, sticky;
#ifdef __SIZEOF_INT128__
    if (na <= 4 && lb + sb <= 64) {
        /* fast path: A < 2^128, B < 2^64 - one 128-bit division gives the same Q and sticky */
        typedef unsigned __int128 u128;
        u128 a128 = 0;
        for (int i = na - 1; i >= 0; i--) a128 = a128 << 32 | A[i];
        uint64_t b64 = 0;
        for (int i = b->n - 1; i >= 0; i--) b64 = b64 << 32 | b->m[i];
        b64 <<= sb;
        q = (uint64_t)(a128 / b64);
        sticky = a128 % b64 != 0;
        goto rounded_q;
    }
#endif
#ifdef __SIZEOF_INT128__
    {
        /* Wide operands: estimate Q from the top 64 bits of B' = |b| << sb and
         * the same bit range of A (Q_est - 2 <= Q <= Q_est + 1, since
         * B' >= 2^64), then correct exactly: R = A - (Q_est - 2) B' and subtract
         * B' while R >= B' (at most 4 times).  Same Q and sticky as the
         * bit-by-bit division below, in one multiply-subtract pass. */
        typedef unsigned __int128 u128;
        nb = mag_shl(B, b->m, b->n, sb);
        int pos = mag_bitlen(B, nb) - 64; /* > 0 here */
        uint64_t bt = 0;
        u128 at = 0;
        for (int i = pos / 32; i < nb; i++) {
            int sh = 32 * i - pos;
            bt |= sh >= 0 ? (uint64_t)B[i] << sh : (uint64_t)B[i] >> -sh;
        }
        for (int i = pos / 32; i < na; i++) {
            int sh = 32 * i - pos;
            at |= sh >= 0 ? (u128)A[i] << sh : (u128)(A[i] >> -sh);
        }
        u128 qe128 = at / bt;
        uint32_t q0 = qe128 >= 2 ? (uint32_t)(qe128 - 2) : 0; /* < 2^(P+1) <= 2^27 */
        uint32_t T[L + 3];
        uint64_t c = 0;
        need(nb + 1);
        for (int i = 0; i < nb; i++) {
            c += (uint64_t)B[i] * q0;
            T[i] = (uint32_t)c;
            c >>= 32;
        }
        T[nb] = (uint32_t)c;
        int nt = nb + 1;
        while (nt > 0 && T[nt - 1] == 0) nt--;
        na = mag_sub(A, A, na, T, nt); /* A >= q0 B' */
        q = q0;
        while (mag_cmp(A, na, B, nb) >= 0) {
            na = mag_sub(A, A, na, B, nb);
            q++;
        }
        sticky = na != 0;
        goto rounded_q;
    }
#endif
    nb = mag_shl(B, b->m, b->n, sb + P); /* B << P: the top quotient bit */
    /* A / B < 2^(P+1): restoring division, P + 1 quotient bits. */
    for (int i = P; i >= 0; i--) {
        q <<= 1;
        if (mag_cmp(A, na, B, nb) >= 0) {
            na = mag_sub(A, A, na, B, nb);
            q |= 1;
        }
        /* B >>= 1 (exact: B had sb + P >= i trailing zero bits' worth of shift) */
        for (int k = 0; k < nb; k++) B[k] = (B[k] >> 1) | (k + 1 < nb ? B[k + 1] << 31 : 0);
        while (nb > 0 && B[nb - 1] == 0) nb--;
    }
    sticky = na != 0;
#ifdef __SIZEOF_INT128__
rounded_q:;
#endif
    /* value = (q + frac) * 2^qe, frac in [0,1) nonzero iff sticky */
    int qe = a->exp - sa - b->exp + sb;
    int away = neg ? (mode == CBVH_RND_DOWN) : (mode == CBVH_RND_UP);
    int len = cbvh_bitlen64(q);
    if (len > bits) { /* round to `bits` significant bits in the chosen direction */
        int d = len - bits;
        uint64_t rem = q & ((UINT64_C(1) << d) - 1);
        q >>= d;
        qe += d;
        if ((rem || sticky) && away) q++;

        return cbvh_f32_pack(neg, q, qe, mode);
    }
    /* (cannot happen: len >= P > bits) */
    return cbvh_f32_pack(neg, (q << 1) | (uint64_t)sticky, qe - 1, mode);
}
