/* Stackless traversal of a traversal list (seed 004 §2.1, after Thrane and
 * Simonsen; docs/tlist.md §6).  Spheres: the ray-sphere unit (unit 9) on the
 * ray cut at trav_box_tmax (the best t so far bumped by one ulp, so no
 * acceptable triangle is culled); triangles, hit acceptance and byte
 * accounting: traverse_common.h, so hits equal cbvh_trace_bvh's bit for bit. */
#include "cbvh/tlist.h"
#include "traverse/traverse_common.h"

/* Memory image: list 0, list 1, ... (20-byte elements, each list starting on
 * a line), then the triangles (36 bytes each). */
static uint64_t list_base(const cbvh_tlists *L, int l) {
    uint64_t b = 0;
    for (int k = 0; k < l; k++) b += trav_align((uint64_t)L->len[k] * CBVH_TLIST_ELEM_BYTES);
    return b;
}

int cbvh_trace_tlist(const cbvh_tlists *L, int l, uint32_t head, const cbvh_tri *tris, const cbvh_ray *ray,
                     cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    trav_state ts;
    memset(&ts, 0, sizeof ts);
    memset(hit, 0, sizeof *hit);
    if (l < 0 || l >= L->p.nlists || l >= CBVH_TLIST_MAX || head > L->len[l]) return -1;
    if (!trav_ray_ok(&ts, ray, CBVH_MANT_MAX)) return -1;
    trav_set_ray(&ts, ray);
    ts.tris = tris;
    ts.mode = mode;
    ts.M = CBVH_MANT_MAX;
    const uint64_t base = list_base(L, l);
    ts.tris_base = list_base(L, L->p.nlists);
    const cbvh_tlist_elem *E = L->list[l];
    const uint32_t n = L->len[l];
    int rc = 0;
    cbvh_ray cut = *ray;
    for (uint32_t i = head; i < n;) {
        const cbvh_tlist_elem *e = &E[i];
        int32_t esc = e->escape;
        /* a triangle element names its triangle, as an ID entry does */
        trav_fetch(&ts, esc == 1 || esc == 0 ? CBVH_FETCH_IDS : CBVH_FETCH_NODE,
                   base + (uint64_t)i * CBVH_TLIST_ELEM_BYTES, CBVH_TLIST_ELEM_BYTES);
        if (esc == 1 || esc == 0) {
            trav_triangle(&ts, e->data[0]);
            if (ts.done || esc == 0) break;
            i++;
            continue;
        }
        ts.s.nodes++;
        ts.s.box_tests++;
        cut.tmax = trav_box_tmax(&ts);
        int in = 0;
        if (cbvh_ray_sphere(&cut, e->data, e->data[3], &in)) {
            rc = -1; /* a corrupt sphere: the builder never writes one */
            break;
        }
        if (in) i++;
        else if (esc < 0) break;
        else i += (uint32_t)esc;
    }
    trav_finish(&ts, hit, st);
    if (rc) memset(hit, 0, sizeof *hit);
    return rc;
}
