/* List heads (seed 004 §3; docs/tlist.md §7): per-polygon heads for
 * secondary rays and per-screen-cell heads for primary rays.
 *
 * Both find, in list order, the first triangle element that a ray of the
 * class might hit, skipping whole subtrees whose sphere lies outside one
 * half-space that contains every such ray ("a half-space among the
 * aforementioned ones which a node does not intersect at all", §3.1).  The
 * traversal may start there: every triangle before it is unreachable, and the
 * elements after it are visited in the same depth-first order as from 0.
 *
 * Half-spaces are evaluated in binary64 with explicit error terms so the
 * exclusion is rigorous: an element is skipped only if it is outside by more
 * than a bound on every rounding error made. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/tlist.h"


/* Reachable points satisfy (x - p0) . m >= -slack_dist * |m| (true m), with
 * m known as md up to an absolute error err[a] per component.  For frustum
 * planes (angular) the allowance is tol * |x - p0| instead (ang = 1). */
typedef struct {
    double p0[3], md[3], err[3];
    double mlen, elen; /* |md|, |err| */
    double dist;       /* margin (distance) */
    double tol;        /* angular widening (frustum planes) */
} halfspace;

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* 1 if the ball (c, r) lies entirely outside h (no reachable point in it). */
static int ball_outside(const halfspace *h, const double c[3], double r) {
    if (h->mlen <= h->elen) return 0; /* normal not known well enough */
    double w[3], s = 0, e = 0, wl = 0;
    for (int a = 0; a < 3; a++) {
        w[a] = c[a] - h->p0[a];
        s += w[a] * h->md[a];
        e += fabs(w[a]) * h->err[a] + (fabs(c[a]) + fabs(h->p0[a])) * fabs(h->md[a]) * 0x1p-40;
        wl += w[a] * w[a];
    }
    wl = sqrt(wl) * (1 + 0x1p-40);
    double up = s + e + r * (h->mlen + h->elen) * (1 + 0x1p-40); /* >= sup of (x - p0) . m over the ball */
    double allow = h->dist * (h->mlen - h->elen) * (1 - 0x1p-40); /* <= margin * |m| */
    if (h->tol > 0) allow = h->tol * (wl + r) * h->mlen * (1 + 0x1p-40);
    return h->tol > 0 ? up < -allow - 0x1p-40 * h->mlen * (wl + r) : up < -allow;
}

static int element_outside(const halfspace *hs, int nh, const cbvh_tlist_elem *e, const cbvh_tri *tris) {
    if (e->escape >= 2 || e->escape == -1) {
        double c[3] = {cbvh_float_of(e->data[0]), cbvh_float_of(e->data[1]), cbvh_float_of(e->data[2])}, r = cbvh_float_of(e->data[3]);
        for (int k = 0; k < nh; k++)
            if (ball_outside(&hs[k], c, r)) return 1;
        return 0;
    }
    const cbvh_tri *t = &tris[e->data[0]];
    for (int k = 0; k < nh; k++) {
        int all = 1;
        for (int v = 0; v < 3 && all; v++) {
            double c[3] = {t->v[v][0], t->v[v][1], t->v[v][2]};
            all = ball_outside(&hs[k], c, 0);
        }
        if (all) return 1;
    }
    return 0;
}

/* First element of E[0..n) from which the traversal must start. */
static uint32_t first_needed(const cbvh_tlist_elem *E, uint32_t n, const halfspace *hs, int nh, const cbvh_tri *tris) {
    uint32_t i = 0;
    while (i < n) {
        const cbvh_tlist_elem *e = &E[i];
        int sphere = e->escape >= 2 || e->escape == -1;
        if (!element_outside(hs, nh, e, tris)) {
            if (!sphere) break;
            i++; /* descend */
            continue;
        }
        i = !sphere ? i + 1 : e->escape == -1 ? n : i + (uint32_t)e->escape;
    }
    /* Start at the spheres whose first child this is: they may still cull. */
    while (i > 0 && i <= n && (E[i - 1].escape >= 2 || E[i - 1].escape == -1)) i--;
    return i;
}

static void plane_const(halfspace *h, const double p0[3], double mx, double my, double mz, double dist) {
    memset(h, 0, sizeof *h);
    memcpy(h->p0, p0, sizeof h->p0);
    h->md[0] = mx;
    h->md[1] = my;
    h->md[2] = mz;
    h->mlen = sqrt(mx * mx + my * my + mz * mz);
    h->dist = dist;
}

/* Facet normals of list l's cone (m . d >= 0 on the closure of the cone). */
static int cone_facets(int nlists, int l, double m[4][3]) {
    memset(m, 0, 4 * sizeof *m);
    if (nlists == 2) {
        m[0][0] = l ? -1 : 1;
        return 1;
    }
    if (nlists == 6) {
        int a = l / 2, b = (a + 1) % 3, c = (a + 2) % 3;
        double s = (l & 1) ? -1 : 1;
        for (int k = 0; k < 4; k++) {
            m[k][a] = s;
            m[k][k < 2 ? b : c] = (k & 1) ? -1 : 1;
        }
        return 4;
    }
    if (nlists == 8) {
        for (int a = 0; a < 3; a++) m[a][a] = (l >> a & 1) ? -1 : 1;
        return 3;
    }
    return 0;
}

static int poly_halfspaces(const cbvh_tri *t, int nlists, int l, int regular, double margin, halfspace hs[5]) {
    double v[3][3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) v[k][a] = t->v[k][a];
    int nh = 0;
    /* the triangle's plane: n = (v1 - v0) x (v2 - v0), front side n . x >= n . v0 */
    double e1[3], e2[3];
    for (int a = 0; a < 3; a++) {
        e1[a] = v[1][a] - v[0][a];
        e2[a] = v[2][a] - v[0][a];
    }
    halfspace *h = &hs[nh++];
    memset(h, 0, sizeof *h);
    memcpy(h->p0, v[0], sizeof h->p0);
    for (int a = 0; a < 3; a++) {
        int b = (a + 1) % 3, c = (a + 2) % 3;
        double p = e1[b] * e2[c], q = e1[c] * e2[b];
        h->md[a] = p - q;
        h->err[a] = (fabs(p) + fabs(q)) * 0x1p-50; /* rounding of e1, e2, the products and the difference */
    }
    h->mlen = sqrt(dot3(h->md, h->md)) * (1 - 0x1p-50);
    h->elen = sqrt(dot3(h->err, h->err)) * (1 + 0x1p-50);
    h->dist = margin;
    if (!regular) return nh;
    double m[4][3];
    int nf = cone_facets(nlists, l, m);
    for (int f = 0; f < nf; f++) { /* through the triangle's lowest vertex along m */
        int lo = 0;
        for (int k = 1; k < 3; k++)
            if (dot3(v[k], m[f]) < dot3(v[lo], m[f])) lo = k;
        plane_const(&hs[nh++], v[lo], m[f][0], m[f][1], m[f][2], margin);
    }
    return nh;
}

int cbvh_tlists_poly_heads(cbvh_tlists *L, const cbvh_tri *tris, cbvh_tlist_heads_kind kind, float margin, char *err,
                           size_t errlen) {
    if (kind != CBVH_TLIST_HEADS_SIMPLE && kind != CBVH_TLIST_HEADS_REGULAR) {
        snprintf(err, errlen, "tlist heads: unknown kind %d (1 simple, 2 regular)", (int)kind);
        return -1;
    }
    if (!(margin >= 0) || isinf(margin)) {
        snprintf(err, errlen, "tlist heads: margin must be finite and >= 0");
        return -1;
    }
    int nl = L->p.nlists;
    uint32_t *H = malloc((size_t)L->ntris * (size_t)nl * sizeof *H);
    if (!H) {
        snprintf(err, errlen, "tlist heads: out of memory for %u x %d heads", L->ntris, nl);
        return -1;
    }
    for (uint32_t t = 0; t < L->ntris; t++)
        for (int l = 0; l < nl; l++) {
            halfspace hs[5];
            int nh = poly_halfspaces(&tris[t], nl, l, kind == CBVH_TLIST_HEADS_REGULAR, margin, hs);
            H[(size_t)t * nl + l] = first_needed(L->list[l], L->len[l], hs, nh, tris);
        }
    free(L->poly_head);
    L->poly_head = H;
    return 0;
}

uint32_t cbvh_tlist_poly_head(const cbvh_tlists *L, int l, uint32_t from, const cbvh_tri *tris, const cbvh_ray *ray) {
    if (!L->poly_head || from >= L->ntris || l < 0 || l >= L->p.nlists) return 0;
    if (ray->tmin & CBVH_F32_SIGN && !cbvh_f32_is_zero(ray->tmin)) return 0;
    cbvh_f32 v[3][3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) v[k][a] = cbvh_f32_of(tris[from].v[k][a]);
    if (cbvh_tri_facing(ray->d, v[0], v[1], v[2]) > 0) return 0; /* heads the back side: not covered */
    return L->poly_head[(size_t)from * L->p.nlists + l];
}

float cbvh_tlist_hitpoint_margin(float eps, float coord_max) {
    /* |q - p*| <= eps (1 + 2^-19) + 2^-19 coord_max (docs/tlist.md §7.1); doubled. */
    double m = (double)fabsf(eps) * (1 + 0x1p-18) + (double)fabsf(coord_max) * 0x1p-18;
    float f = (float)m;
    if ((double)f < m) f = nextafterf(f, INFINITY);
    return f;
}

int cbvh_tlist_cell_heads(const cbvh_tlists *L, const cbvh_tri *tris, const float o[3], const float corner[4][3],
                          double tol, uint32_t head[CBVH_TLIST_MAX]) {
    for (int l = 0; l < CBVH_TLIST_MAX; l++) head[l] = 0;
    int ok = isfinite(o[0]) && isfinite(o[1]) && isfinite(o[2]) && tol >= 0x1p-30 && tol < 1;
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++) ok &= isfinite(corner[k][a]) != 0;
    if (!ok) return -1;
    double O[3] = {o[0], o[1], o[2]}, C[4][3];
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++) C[k][a] = corner[k][a];
    halfspace hs[4];
    int nh = 0;
    for (int k = 0; k < 4; k++) { /* side plane through o, C[k], C[k+1] */
        const double *a = C[k], *b = C[(k + 1) % 4];
        double m[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        double len = sqrt(dot3(m, m));
        if (!(len > 0)) continue;
        int pos = 0, neg = 0;
        for (int j = 0; j < 4; j++) {
            double d = dot3(m, C[j]) / (len * sqrt(dot3(C[j], C[j])));
            pos |= d > 1e-12;
            neg |= d < -1e-12;
        }
        if (pos && neg) continue; /* not a supporting plane (non-convex cell): skip */
        double s = neg ? -1 : 1;
        plane_const(&hs[nh], O, s * m[0] / len, s * m[1] / len, s * m[2] / len, 0);
        hs[nh].tol = tol;
        nh++;
    }
    for (int l = 0; l < L->p.nlists; l++) head[l] = first_needed(L->list[l], L->len[l], hs, nh, tris);
    return 0;
}
