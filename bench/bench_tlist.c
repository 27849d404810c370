/* Traversal lists (seed 004) vs the float BVH, on the same rays in one run.
 *
 * For each scene and each option (1/2/6/8 lists x earliest-first/latest-last
 * x back-face culling off/on x heads off/per-polygon/per-cell/both): sphere elements visited
 * (= sphere tests) and triangle tests per ray, list memory and redundancy
 * (elements / (spheres + triangles of the hierarchy)), rays/s, and rays/s
 * relative to cbvh_trace_bvh (binned-SAH float BVH) timed interleaved with it
 * in chunks of 256 rays (thread CPU time; rays/s best of K passes, the ratio
 * is the median over the K passes).  Closest hit; with culling both sides run one-sided
 * (CBVH_TRAV_FRONT_ONLY), as culling requires.  Every hit is checked against
 * the float BVH's (triangle and t bits); a mismatch aborts.
 *
 * Rays: bench_rays.h (half pinhole-camera rays, half random rays), plus one
 * secondary ray per front hit of a camera ray made as host/trace/effects.c makes
 * them (origin fl(o + t d) + eps n, direction uniform in the front
 * hemisphere).  Heads "cell": camera rays start at their 8x8-pixel cell's
 * head (cbvh_tlist_cell_heads, the paper's frustum culling); "poly":
 * secondary rays at the regular per-polygon head (cbvh_tlist_poly_head, the
 * lookup incl. its exact facing test is timed); "both"; random rays always
 * start at 0 (no head applies).  pre_ms = time to compute both kinds.
 *
 * usage: bench_tlist [--rays R] [--reps K] [--json FILE] [SCENE...]
 *        (default: the bundled bunny) */
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbvh/tlist.h"
#define BENCH_NAME "bench_tlist"
#include "bench_json.h"
#include "bench_rays.h"

#define CELL 8

typedef struct {
    cbvh_ray r;
    uint32_t from; /* secondary: the triangle it leaves; camera: cell index; random: UINT32_MAX */
    int kind;      /* 0 camera, 1 random, 2 secondary */
} bray;

/* Secondary rays from the front hits of the camera rays (host/trace/effects.c). */
static int make_secondary(const cbvh_scene *s, const cbvh_bvh *b, const cbvh_ray *cam, int ncam, float eps, bray *out) {
    int k = 0;
    for (int i = 0; i < ncam; i++) {
        cbvh_trav_hit h;
        cbvh_trav_stats st = {0};
        if (cbvh_trace_bvh(b, s->tris, &cam[i], 24, CBVH_TRAV_CLOSEST_FRONT, &h, &st) || !h.hit) continue;
        const cbvh_tri *tr = &s->tris[h.prim];
        float t = bf(h.t), o[3], d[3], p[3], n[3], e1[3], e2[3], w[3];
        for (int a = 0; a < 3; a++) {
            o[a] = bf(cam[i].o[a]);
            d[a] = bf(cam[i].d[a]);
            p[a] = o[a] + t * d[a];
            e1[a] = tr->v[1][a] - tr->v[0][a];
            e2[a] = tr->v[2][a] - tr->v[0][a];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        float nl = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(nl > 0)) continue;
        for (int a = 0; a < 3; a++) n[a] /= nl;
        if (n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0)
            for (int a = 0; a < 3; a++) n[a] = -n[a];
        float z = unit() * 2 - 1, phi = 6.2831853f * unit(), sz = sqrtf(fmaxf(0, 1 - z * z));
        w[0] = sz * cosf(phi);
        w[1] = sz * sinf(phi);
        w[2] = z;
        if (w[0] * n[0] + w[1] * n[1] + w[2] * n[2] < 0)
            for (int a = 0; a < 3; a++) w[a] = -w[a];
        if (w[0] == 0 && w[1] == 0 && w[2] == 0) continue;
        bray *r = &out[k++];
        for (int a = 0; a < 3; a++) {
            r->r.o[a] = fb(p[a] + eps * n[a]);
            r->r.d[a] = fb(w[a]);
        }
        r->r.tmin = 0;
        r->r.tmax = CBVH_F32_POS_INF;
        r->from = h.prim;
        r->kind = 2;
    }
    return k;
}

/* Thread CPU time: the VM is shared, so preemption is not charged to a run. */
static double cpu(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
    double bvh_secs, tl_secs;
    cbvh_trav_stats bvh, tl;
} timing;

#define CHUNK 256

/* One pass over the rays, the float BVH and the list traversal interleaved
 * in chunks of CHUNK rays, so load changes hit both alike. */
static void run_pair(const cbvh_bvh *b, const cbvh_tlists *L, const cbvh_tri *tris, const bray *R, int n,
                     cbvh_trav_mode mode, int heads, const uint32_t *cell_head, cbvh_trav_hit *hb, cbvh_trav_hit *ht,
                     timing *T) {
    memset(T, 0, sizeof *T);
    const int nl = L->p.nlists;
    for (int c0 = 0; c0 < n; c0 += CHUNK) {
        int c1 = c0 + CHUNK < n ? c0 + CHUNK : n;
        double t0 = cpu();
        for (int i = c0; i < c1; i++)
            if (cbvh_trace_bvh(b, tris, &R[i].r, 24, mode, &hb[i], &T->bvh)) die("bvh", "ray rejected");
        double t1 = cpu();
        for (int i = c0; i < c1; i++) {
            int l = cbvh_tlist_pick(L, &R[i].r);
            uint32_t h = 0;
            if ((heads & 1) && R[i].kind == 2) h = cbvh_tlist_poly_head(L, l, R[i].from, tris, &R[i].r);
            else if ((heads & 2) && R[i].kind == 0) h = cell_head[(size_t)R[i].from * nl + l];
            if (cbvh_trace_tlist(L, l, h, tris, &R[i].r, mode, &ht[i], &T->tl)) die("tlist", "ray rejected");
        }
        double t2 = cpu();
        T->bvh_secs += t1 - t0;
        T->tl_secs += t2 - t1;
    }
}

static int dcmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void check_hits(const char *scene, const char *opt, const cbvh_trav_hit *a, const cbvh_trav_hit *b, int n) {
    for (int i = 0; i < n; i++)
        if (a[i].hit != b[i].hit || (a[i].hit && (a[i].prim != b[i].prim || a[i].t != b[i].t))) {
            fprintf(stderr, "bench_tlist: %s %s: ray %d hit differs from the float BVH\n", scene, opt, i);
            exit(1);
        }
}

int main(int argc, char **argv) {
    rs = 0x51ED2701F00DULL; /* the seed of the figures in docs/results.md */
    int nrays = 10000, reps = 2, ns = 0;
    const char *specs[64], *json = NULL;
    for (int i = 1; i < argc; i++) {
        if (int_option(argc, argv, &i, "--rays", 2, 10000000, &nrays) ||
            int_option(argc, argv, &i, "--reps", 1, 100, &reps))
            continue;
        if (!strcmp(argv[i], "--json") && i + 1 < argc) {
            json = argv[++i];
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: bench_tlist [--rays R] [--reps K] [--json FILE] [SCENE...]\n");
            return 2;
        } else if (ns < 64) {
            specs[ns++] = argv[i];
        }
    }
    if (!ns) specs[ns++] = CBVH_SCENES_DIR "/bunny-small.obj";
    cJSON *jroot = cJSON_CreateObject(), *jscenes = cJSON_AddArrayToObject(jroot, "scenes");
    cJSON_AddNumberToObject(jroot, "rays_requested", nrays);
    cJSON_AddNumberToObject(jroot, "reps", reps);
    char err[512];
    for (int si = 0; si < ns; si++) {
        cbvh_scene s;
        cbvh_bvh b;
        load_scene(specs[si], &s, &b, "sah");
        const char *base = scene_base(specs[si]);
        double tb0 = now();
        cbvh_bsh h;
        if (cbvh_bsh_build(&s, NULL, &h, err, sizeof err)) die("bsh", err);
        double bsh_secs = now() - tb0;
        float lo[3], hi[3];
        cbvh_scene_bounds(&s, lo, hi);
        /* rays: camera + random (bench_rays.h), then secondary */
        cbvh_ray *base_rays = malloc((size_t)nrays * sizeof *base_rays);
        bray *R = malloc((size_t)nrays * 2 * sizeof *R);
        if (!base_rays || !R) die("rays", "out of memory");
        make_rays(lo, hi, nrays, base_rays);
        camera C;
        camera_of(lo, hi, nrays, &C);
        int ncell = (C.side + CELL - 1) / CELL;
        for (int i = 0; i < nrays; i++) {
            R[i].r = base_rays[i];
            R[i].kind = i < C.ncam ? 0 : 1;
            R[i].from = i < C.ncam ? (uint32_t)((i / C.side) / CELL * ncell + (i % C.side) / CELL) : UINT32_MAX;
        }
        float dg[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
        float diag = sqrtf(dg[0] * dg[0] + dg[1] * dg[1] + dg[2] * dg[2]);
        float eps = 1e-4f * diag;
        if (!(eps > 0)) eps = 1e-6f;
        int nsec = make_secondary(&s, &b, base_rays, C.ncam, eps, R + nrays);
        int n = nrays + nsec;
        float cm = 0;
        for (uint32_t t = 0; t < s.ntris; t++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) cm = fmaxf(cm, fabsf(s.tris[t].v[v][a]));
        for (int a = 0; a < 3; a++) cm = fmaxf(cm, fabsf(C.eye[a]));
        float margin = cbvh_tlist_hitpoint_margin(eps, cm);
        cbvh_trav_hit *hb[2], *ht = malloc((size_t)n * sizeof *ht);
        hb[0] = malloc((size_t)n * sizeof *hb[0]);
        hb[1] = malloc((size_t)n * sizeof *hb[1]);
        uint32_t *cell_head = malloc((size_t)ncell * ncell * CBVH_TLIST_MAX * sizeof *cell_head);
        if (!ht || !hb[0] || !hb[1] || !cell_head) die("hits", "out of memory");
        printf("\n%s: %u triangles, %u spheres (depth %u, built in %.0f ms); %d rays: %d camera, %d random, %d secondary; "
               "closest hit, best of %d\n",
               base, s.ntris, h.nnodes, h.depth, 1e3 * bsh_secs, n, C.ncam, nrays - C.ncam, nsec, reps);
        printf("%-5s %-8s %-4s %-5s | %8s %8s %8s | %9s %9s %6s | %8s %8s | %10s %10s %6s\n", "lists", "order", "cull",
               "heads", "nodes/r", "sph/r", "tri/r", "list_KiB", "head_KiB", "redund", "culled%", "pre_ms", "tl_r/s",
               "bvh_r/s", "vs_bvh");
        cJSON *jsc = cJSON_CreateObject(), *jopts = NULL;
        cJSON_AddStringToObject(jsc, "scene", base);
        cJSON_AddNumberToObject(jsc, "triangles", s.ntris);
        cJSON_AddNumberToObject(jsc, "spheres", h.nnodes);
        cJSON_AddNumberToObject(jsc, "depth", h.depth);
        cJSON_AddNumberToObject(jsc, "rays", n);
        cJSON_AddNumberToObject(jsc, "camera_rays", C.ncam);
        cJSON_AddNumberToObject(jsc, "secondary_rays", nsec);
        jopts = cJSON_AddArrayToObject(jsc, "options");
        cJSON_AddItemToArray(jscenes, jsc);
        static const int nls[4] = {1, 2, 6, 8};
        static const char *hname[4] = {"off", "poly", "cell", "both"};
        struct {
            double secs;
            cbvh_trav_stats st;
        } tbest[2] = {{1e30, {0}}, {1e30, {0}}};
        double nodes_of[4][2][2][4], rate_of[4][2][2][4];
        for (int li = 0; li < 4; li++)
            for (int ord = 0; ord < 2; ord++)
                for (int cull = 0; cull < 2; cull++) {
                    cbvh_tlist_params p = {nls[li], (cbvh_tlist_order)ord, cull};
                    cbvh_tlists L;
                    if (cbvh_tlists_build(&h, &s, &p, &L, err, sizeof err)) die("tlists", err);
                    uint64_t elems = 0, culled = 0;
                    for (int l = 0; l < p.nlists; l++) elems += L.len[l];
                    for (int l = 0; l < p.nlists && cull; l++)
                        for (uint32_t t = 0; t < s.ntris; t++) culled += cbvh_tlist_culled(p.nlists, l, &s.tris[t]);
                    double list_kib = (double)elems * CBVH_TLIST_ELEM_BYTES / 1024;
                    double t0 = now();
                    if (cbvh_tlists_poly_heads(&L, s.tris, CBVH_TLIST_HEADS_REGULAR, margin, err, sizeof err))
                        die("heads", err);
                    for (int cy = 0; cy < ncell; cy++)
                        for (int cx = 0; cx < ncell; cx++) {
                            float cor[4][3];
                            int x0 = cx * CELL, y0 = cy * CELL, x1 = x0 + CELL, y1 = y0 + CELL;
                            cam_dir(&C, (float)x0, (float)y0, cor[0]);
                            cam_dir(&C, (float)x1, (float)y0, cor[1]);
                            cam_dir(&C, (float)x1, (float)y1, cor[2]);
                            cam_dir(&C, (float)x0, (float)y1, cor[3]);
                            uint32_t hd[CBVH_TLIST_MAX];
                            if (cbvh_tlist_cell_heads(&L, s.tris, C.eye, cor, 1e-5, hd)) die("cell heads", "bad cell");
                            memcpy(&cell_head[(size_t)(cy * ncell + cx) * p.nlists], hd, (size_t)p.nlists * sizeof *hd);
                        }
                    double pre_ms = 1e3 * (now() - t0);
                    double head_kib = (double)L.ntris * p.nlists * 4 / 1024;
                    cbvh_trav_mode mode = cull ? CBVH_TRAV_CLOSEST_FRONT : CBVH_TRAV_CLOSEST;
                    for (int heads = 0; heads < 4; heads++) { /* bit 0: per-polygon, bit 1: per-cell */
                        timing one, keep = {0};
                        double best_tl = 1e30, best_b = 1e30, ratio[100] = {0};
                        for (int k = 0; k < reps; k++) {
                            run_pair(&b, &L, s.tris, R, n, mode, heads, cell_head, hb[cull], ht, &one);
                            ratio[k] = one.bvh_secs / one.tl_secs;
                            if (one.tl_secs < best_tl) best_tl = one.tl_secs;
                            if (one.bvh_secs < best_b) best_b = one.bvh_secs;
                            keep = one;
                            if (one.bvh_secs < tbest[cull].secs) {
                                tbest[cull].secs = one.bvh_secs;
                                tbest[cull].st = one.bvh;
                            }
                        }
                        qsort(ratio, (size_t)reps, sizeof *ratio, dcmp);
                        const cbvh_trav_stats tst = keep.tl;
                        char opt[64];
                        snprintf(opt, sizeof opt, "lists=%d order=%d cull=%d heads=%s", p.nlists, ord, cull, hname[heads]);
                        check_hits(base, opt, hb[cull], ht, n);
                        double rate = n / best_tl, brate = n / best_b, rel = ratio[reps / 2]; /* median ratio */
                        nodes_of[li][ord][cull][heads] = (double)tst.nodes / n;
                        rate_of[li][ord][cull][heads] = rel;
                        printf("%-5d %-8s %-4s %-5s | %8.1f %8.1f %8.2f | %9.1f %9.1f %6.3f | %8.2f %8.0f | %10.0f %10.0f "
                               "%6.3f\n",
                               p.nlists, ord ? "latest" : "earliest", cull ? "on" : "off", hname[heads],
                               (double)tst.nodes / n, (double)tst.box_tests / n, (double)tst.tri_tests / n,
                               list_kib, (heads & 1) ? head_kib : 0.0, (double)elems / (h.nnodes + s.ntris),
                               cull ? 100.0 * culled / ((double)s.ntris * p.nlists) : 0.0, heads ? pre_ms : 0.0, rate,
                               brate, rel);
                        fflush(stdout);
                        cJSON *jo = cJSON_CreateObject();
                        cJSON_AddNumberToObject(jo, "lists", p.nlists);
                        cJSON_AddStringToObject(jo, "order", ord ? "latest_last" : "earliest_first");
                        cJSON_AddBoolToObject(jo, "cull_back", cull);
                        cJSON_AddStringToObject(jo, "heads", hname[heads]);
                        cJSON_AddNumberToObject(jo, "nodes_per_ray", (double)tst.nodes / n);
                        cJSON_AddNumberToObject(jo, "sphere_tests_per_ray", (double)tst.box_tests / n);
                        cJSON_AddNumberToObject(jo, "tri_tests_per_ray", (double)tst.tri_tests / n);
                        cJSON_AddNumberToObject(jo, "bytes_per_ray", (double)tst.bytes / n);
                        cJSON_AddNumberToObject(jo, "list_bytes", (double)elems * CBVH_TLIST_ELEM_BYTES);
                        cJSON_AddNumberToObject(jo, "head_bytes", (heads & 1) ? (double)L.ntris * p.nlists * 4 : 0);
                        cJSON_AddNumberToObject(jo, "redundancy", (double)elems / (h.nnodes + s.ntris));
                        cJSON_AddNumberToObject(jo, "culled_fraction", cull ? (double)culled / ((double)s.ntris * p.nlists) : 0);
                        cJSON_AddNumberToObject(jo, "heads_precompute_ms", heads ? pre_ms : 0);
                        cJSON_AddNumberToObject(jo, "rays_per_s", rate);
                        cJSON_AddNumberToObject(jo, "bvh_rays_per_s", brate);
                        cJSON_AddNumberToObject(jo, "speed_vs_bvh", rel);
                        cJSON_AddNumberToObject(jo, "bvh_nodes_per_ray", (double)tbest[cull].st.nodes / n);
                        cJSON_AddNumberToObject(jo, "bvh_box_tests_per_ray", (double)tbest[cull].st.box_tests / n);
                        cJSON_AddNumberToObject(jo, "bvh_tri_tests_per_ray", (double)tbest[cull].st.tri_tests / n);
                        { /* per ray kind (untimed pass): camera, random, secondary */
                            static const char *kname[3] = {"camera", "random", "secondary"};
                            cbvh_trav_stats ks[3];
                            int kn[3] = {0, 0, 0};
                            memset(ks, 0, sizeof ks);
                            for (int i = 0; i < n; i++) {
                                int l = cbvh_tlist_pick(&L, &R[i].r);
                                uint32_t h0 = 0;
                                if ((heads & 1) && R[i].kind == 2) h0 = cbvh_tlist_poly_head(&L, l, R[i].from, s.tris, &R[i].r);
                                else if ((heads & 2) && R[i].kind == 0) h0 = cell_head[(size_t)R[i].from * p.nlists + l];
                                cbvh_trace_tlist(&L, l, h0, s.tris, &R[i].r, mode, &ht[i], &ks[R[i].kind]);
                                kn[R[i].kind]++;
                            }
                            for (int k = 0; k < 3; k++) {
                                char key[48];
                                snprintf(key, sizeof key, "nodes_per_ray_%s", kname[k]);
                                cJSON_AddNumberToObject(jo, key, kn[k] ? (double)ks[k].nodes / kn[k] : 0);
                                snprintf(key, sizeof key, "tri_tests_per_ray_%s", kname[k]);
                                cJSON_AddNumberToObject(jo, key, kn[k] ? (double)ks[k].tri_tests / kn[k] : 0);
                            }
                        }
                        cJSON_AddItemToArray(jopts, jo);
                    }
                    cbvh_tlists_free(&L);
                }
        printf("float BVH (SAH): two-sided %.1f inner nodes, %.1f box tests, %.2f tri tests per ray; one-sided %.1f / "
               "%.1f / %.2f\n",
               (double)tbest[0].st.nodes / n, (double)tbest[0].st.box_tests / n, (double)tbest[0].st.tri_tests / n,
               (double)tbest[1].st.nodes / n, (double)tbest[1].st.box_tests / n, (double)tbest[1].st.tri_tests / n);
        /* the paper's comparisons: 6 lists vs 1 (all optimisations on), and the
         * spread of nodes/ray over the optimisations at 6 lists (Table 1) */
        double mn = 1e30, mx = 0, ref = nodes_of[2][1][0][0];
        for (int o = 0; o < 2; o++)
            for (int c = 0; c < 2; c++)
                for (int hh = 0; hh < 4; hh++) {
                    mn = fmin(mn, nodes_of[2][o][c][hh]);
                    mx = fmax(mx, nodes_of[2][o][c][hh]);
                }
        printf("6 vs 1 list (latest last, culling, heads): rays/s x%.3f, nodes/ray x%.3f; 6 lists: optimisations move "
               "nodes/ray from %.1f (latest last, no culling, no heads) to %.1f .. %.1f (%+.1f%% .. %+.1f%%)\n",
               rate_of[2][1][1][3] / rate_of[0][1][1][3], nodes_of[2][1][1][3] / nodes_of[0][1][1][3], ref, mn, mx,
               100 * (mn / ref - 1), 100 * (mx / ref - 1));
        cJSON_AddNumberToObject(jsc, "six_vs_one_speed", rate_of[2][1][1][3] / rate_of[0][1][1][3]);
        cJSON_AddNumberToObject(jsc, "six_vs_one_nodes", nodes_of[2][1][1][3] / nodes_of[0][1][1][3]);
        free(base_rays);
        free(R);
        free(ht);
        free(hb[0]);
        free(hb[1]);
        free(cell_head);
        cbvh_bsh_free(&h);
        cbvh_bvh_free(&b);
        cbvh_scene_free(&s);
    }
    printf("\npaper (GTX 280, bunny 69k tris): 6 lists beat 1 by 5-15 %%; optimisations change nodes/ray by up to "
           "19.8 %% (Table 1); fps flat (memory bound)\n");
    if (json && bench_json_write(jroot, json)) die(json, "cannot write the JSON file");
    cJSON_Delete(jroot);
    return 0;
}
