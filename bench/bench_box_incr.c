/* The incremental ray-box unit (unit 10, docs/traversal.md §17): what M and N
 * cost in culling, and what the model's unit costs in time.
 *
 * usage: bench_box_incr [--children K] [--reps R] [--seed S] [--json FILE]
 *
 * 1. False positives and looseness per N (3..10) and M (6, 8, 12, 16, 24),
 *    X = 8: K children (default 200,000) per design point along scene-like
 *    chains of boxes (tests/common/rbi_chain.h: a ray, a root grid box near
 *    the origin, two children per node on its child grid, descending into a
 *    child the incremental unit hits, as a traversal does).  Each child is
 *    tested by the incremental unit, by the exact unit at M = 24 (the
 *    reference) and by the exact unit at the same M (what rounding once to M
 *    bits costs, without the incremental steps).
 *      fp_incr   children the incremental unit hits and the exact unit at 24 misses,
 *                per child tested (and per exact miss)
 *      fp_exactM the same for the exact unit at M
 *      wider     (t_far - t_near) of the incremental unit / that of the exact
 *                unit at 24, minus 1, over children both hit (median, p90, p99,
 *                mean): the box's own width is the unit, so tiny boxes far down
 *                a tree give large ratios
 *      slack     the same widening divided by the exact |t_far|, in units of
 *                2^-M (one M-bit ulp of the distance is 1..2 units): what the
 *                rounding steps add up to along the chain (median, p99)
 * 2. Throughput on one core: box tests/s of cbvh_ray_box_incr against the
 *    exact unit, cbvh_ray_box (and with its ray prepared once, as the
 *    traversals call it), on the same 16,384 recorded children (N = 6, M = 8),
 *    R repetitions (default 7) of about 0.2 s of this thread's CPU time each:
 *    min / median / max.
 * The false-positive check is also an assertion: a child the exact unit hits
 * and the incremental unit misses makes the bench exit 1. */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_json.h"
#include "cbvh/ray_box_incr.h"
#include "fast/ray_prep.h"
#include "fast/rbi_fast.h"
#include "rbi_chain.h"

/* CPU time of this thread: the machines this runs on are shared, and a
 * preempted repetition must not count as slow. */
static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static int cmp_d(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
static double pct(const double *v, long n, double p) { return n ? v[(long)(p * (double)(n - 1))] : NAN; }
static double f(cbvh_f32 x) { return (double)cbvh_float_of(x); }

typedef struct {
    int N, M;
    long children, ex_hits, ex_miss, fp_incr, fp_exactM, both, false_miss;
    double depth_sum;
    long chains;
    double loose_med, loose_p90, loose_p99, loose_mean;
    double slack_med, slack_p99; /* widening / |exact t_far|, in units of 2^-M */
} row;

static void measure(row *r, long K, uint64_t seed, double *buf, double *buf2) {
    cbvh_rbi_params p = {r->N, r->M, 8};
    uint64_t rng = seed ^ ((uint64_t)r->N << 40) ^ ((uint64_t)r->M << 48);
    long nl = 0, ns = 0;
    while (r->children < K) {
        rbi_chain c;
        if (rbi_chain_start(&c, &p, &rng, RBI_SCENE)) continue;
        r->chains++;
        rbi_child ch[2];
        int more = 1;
        while (more && r->children < K) {
            more = rbi_chain_step(&c, ch);
            for (int j = 0; j < 2; j++) {
                const rbi_child *x = &ch[j];
                cbvh_box_result em;
                cbvh_ray_box(&c.ray, r->M, x->g, &em);
                r->children++;
                r->ex_hits += x->ex.hit;
                r->ex_miss += !x->ex.hit;
                r->fp_incr += x->inc.hit && !x->ex.hit;
                r->fp_exactM += em.hit && !x->ex.hit;
                r->false_miss += x->ex.hit && !x->inc.hit;
                if (x->ex.hit && x->inc.hit) {
                    double we = f(x->ex.t_far) - f(x->ex.t_near), wi = f(x->inc.t_far) - f(x->inc.t_near);
                    if (we > 0 && isfinite(we) && isfinite(wi)) buf[nl++] = wi / we - 1.0;
                    double tf = fabs(f(x->ex.t_far));
                    if (tf > 0 && isfinite(tf) && isfinite(wi)) buf2[ns++] = ldexp((wi - we) / tf, r->M);
                    r->both++;
                }
            }
        }
        r->depth_sum += c.depth;
    }
    qsort(buf, (size_t)nl, sizeof *buf, cmp_d);
    double s = 0;
    for (long i = 0; i < nl; i++) s += buf[i];
    r->loose_mean = nl ? s / (double)nl : NAN;
    r->loose_med = pct(buf, nl, 0.5);
    r->loose_p90 = pct(buf, nl, 0.9);
    r->loose_p99 = pct(buf, nl, 0.99);
    qsort(buf2, (size_t)ns, sizeof *buf2, cmp_d);
    r->slack_med = pct(buf2, ns, 0.5);
    r->slack_p99 = pct(buf2, ns, 0.99);
}

/* ---- throughput ---------------------------------------------------------- */
#define NREC 16384
typedef struct {
    int ray; /* index into the ray arrays */
    uint32_t r[3], sp[3];
    cbvh_rbi_planes T;
    cbvh_rbi_axis ax[3];
    cbvh_grid_axis g[3];
} rec;
static rec recs[NREC];
static cbvh_ray rays[NREC];
static cbvh_rbi_ray rrays[NREC];
static cbvh_rb_ray preps[NREC];
static cbvh_rbi_fray fpreps[NREC];
static cbvh_rbi_fnode fnodes[NREC];

typedef struct {
    const char *name;
    double mps[64];
    double min, med, max;
} timing;

static void summarize(timing *t, int reps) {
    double v[64];
    memcpy(v, t->mps, sizeof(double) * (size_t)reps);
    qsort(v, (size_t)reps, sizeof *v, cmp_d);
    t->min = v[0];
    t->med = v[reps / 2];
    t->max = v[reps - 1];
}

static volatile uint32_t sink;

int main(int argc, char **argv) {
    long K = 200000;
    int reps = 7;
    uint64_t seed = 0x5EEDB0C5;
    const char *json = NULL;
    static const struct option opts[] = {{"children", required_argument, 0, 'k'},
                                         {"reps", required_argument, 0, 'r'},
                                         {"seed", required_argument, 0, 's'},
                                         {"json", required_argument, 0, 'j'},
                                         {"help", no_argument, 0, 'h'},
                                         {0, 0, 0, 0}};
    int o;
    while ((o = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        if (o == 'k') K = atol(optarg);
        else if (o == 'r') reps = atoi(optarg);
        else if (o == 's') seed = strtoull(optarg, NULL, 0);
        else if (o == 'j') json = optarg;
        else {
            printf("usage: bench_box_incr [--children K] [--reps R] [--seed S] [--json FILE]\n");
            return o == 'h' ? 0 : 2;
        }
    }
    if (K < 1000 || reps < 1 || reps > 64) {
        fprintf(stderr, "bench_box_incr: --children >= 1000, --reps 1..64\n");
        return 2;
    }
    static const int Ms[5] = {6, 8, 12, 16, 24};
    row rows[8 * 5];
    int nrows = 0;
    double *buf = malloc(sizeof(double) * (size_t)(K + 2)), *buf2 = malloc(sizeof(double) * (size_t)(K + 2));
    if (!buf || !buf2) return 2;
    long false_miss = 0;
    printf("False positives and looseness (scene-like chains, X = 8, %ld children per point; reference: the exact unit at M = 24)\n",
           K);
    printf("%3s %3s %9s %9s %12s %10s %10s %9s %9s %9s %9s %9s %6s\n", "N", "M", "exact hit", "fp_incr",
           "fp_incr/miss", "fp_exactM", "wider med", "p90", "p99", "mean", "slack med", "p99", "depth");
    for (int N = 3; N <= 10; N++)
        for (int m = 0; m < 5; m++) {
            row *r = &rows[nrows++];
            memset(r, 0, sizeof *r);
            r->N = N;
            r->M = Ms[m];
            measure(r, K, seed, buf, buf2);
            false_miss += r->false_miss;
            printf("%3d %3d %8.1f%% %8.2f%% %11.2f%% %9.2f%% %10.3g %9.3g %9.3g %9.3g %9.2f %9.2f %6.1f\n", N, r->M,
                   100.0 * (double)r->ex_hits / (double)r->children,
                   100.0 * (double)r->fp_incr / (double)r->children,
                   100.0 * (double)r->fp_incr / (double)(r->ex_miss ? r->ex_miss : 1),
                   100.0 * (double)r->fp_exactM / (double)r->children, r->loose_med, r->loose_p90, r->loose_p99,
                   r->loose_mean, r->slack_med, r->slack_p99, r->depth_sum / (double)r->chains);
            fflush(stdout);
        }
    free(buf);
    free(buf2);

    /* throughput: record NREC children (N 6, M 8) */
    cbvh_rbi_params p = {6, 8, 8};
    uint64_t rng = seed ^ 0x7412;
    int n = 0, nr = 0;
    while (n < NREC) {
        rbi_chain c;
        if (rbi_chain_start(&c, &p, &rng, RBI_SCENE)) continue;
        rays[nr] = c.ray;
        rrays[nr] = c.rr;
        cbvh_rb_prepare(&rays[nr], &preps[nr]);
        cbvh_rbi_fprep(&p, &rrays[nr], &fpreps[nr]);
        rbi_child ch[2];
        int more = 1;
        while (more && n < NREC) {
            cbvh_rbi_planes T = c.T;
            more = rbi_chain_step(&c, ch);
            for (int j = 0; j < 2 && n < NREC; j++, n++) {
                recs[n].ray = nr;
                recs[n].T = T;
                int e[3] = {ch[j].ax[0].e, ch[j].ax[1].e, ch[j].ax[2].e};
                cbvh_rbi_fnode_of(&fpreps[nr], &T, e, &fnodes[n]);
                for (int a = 0; a < 3; a++) recs[n].r[a] = ch[j].ax[a].r, recs[n].sp[a] = ch[j].ax[a].sp;
                memcpy(recs[n].ax, ch[j].ax, sizeof recs[n].ax);
                memcpy(recs[n].g, ch[j].g, sizeof recs[n].g);
            }
        }
        nr++;
    }
    for (int i = 0; i < NREC; i++) preps[i].ray = &rays[i]; /* rays[] does not move */
    enum { NU = 4 };
    timing tm[NU] = {{"incremental (cbvh_ray_box_incr)", {0}, 0, 0, 0},
                     {"incremental, ray and node prepared", {0}, 0, 0, 0},
                     {"exact (cbvh_ray_box)", {0}, 0, 0, 0},
                     {"exact, ray prepared (cbvh_ray_box_prep)", {0}, 0, 0, 0}};
    for (int rep = 0; rep < reps; rep++)
        for (int u = 0; u < NU; u++) {
            long tests = 0;
            double t0 = now(), t1;
            uint32_t acc = 0;
            do {
                for (int i = 0; i < NREC; i++) {
                    const rec *x = &recs[i];
                    if (u == 0) {
                        cbvh_rbi_result res;
                        acc += cbvh_ray_box_incr(&p, &rrays[x->ray], &x->T, x->ax, &res) + (uint32_t)res.hit;
                    } else if (u == 1) { /* as a traversal runs it: the child's distances kept for its stack */
                        cbvh_rbi_fnode ch;
                        double tn, tf;
                        const cbvh_rbi_fray *fr = &fpreps[x->ray];
                        int hit = cbvh_rbi_ftest(fr, cbvh_rbi_d(rays[x->ray].tmax), &fnodes[i], x->r, x->sp, &ch, &tn, &tf);
                        acc += (uint32_t)hit + (hit ? cbvh_rbi_f(ch.t[0][0]) ^ cbvh_rbi_f(ch.t[2][1]) : 0u);
                    } else if (u == 2) {
                        cbvh_box_result res;
                        acc += cbvh_ray_box(&rays[x->ray], 24, x->g, &res) + (uint32_t)res.hit;
                    } else {
                        cbvh_box_result res;
                        const cbvh_rb_ray *pr = &preps[x->ray];
                        acc += cbvh_ray_box_prep(pr, pr->ray->tmax, 24, x->g, &res) + (uint32_t)res.hit;
                    }
                }
                tests += NREC;
                t1 = now();
            } while (t1 - t0 < 0.2);
            sink = acc;
            tm[u].mps[rep] = (double)tests / (t1 - t0) / 1e6;
        }
    printf("\nThroughput, one core (thread CPU time), %d children recorded from %d rays (N 6, M 8), %d repetitions of >= 0.2 s:\n",
           NREC, nr, reps);
    printf("%-42s %10s %10s %10s %14s\n", "unit", "min M/s", "median", "max", "prepared/this");
    for (int u = 0; u < NU; u++) summarize(&tm[u], reps);
    for (int u = 0; u < NU; u++) {
        printf("%-42s %10.2f %10.2f %10.2f %13.2fx\n", tm[u].name, tm[u].min, tm[u].med, tm[u].max,
               tm[1].med / tm[u].med);
    }

    if (json) {
        cJSON *root = cJSON_CreateObject(), *arr = cJSON_AddArrayToObject(root, "design_points");
        cJSON_AddNumberToObject(root, "children_per_point", (double)K);
        cJSON_AddNumberToObject(root, "texp", 8);
        for (int i = 0; i < nrows; i++) {
            const row *r = &rows[i];
            cJSON *o2 = cJSON_CreateObject();
            cJSON_AddNumberToObject(o2, "N", r->N);
            cJSON_AddNumberToObject(o2, "M", r->M);
            cJSON_AddNumberToObject(o2, "children", (double)r->children);
            cJSON_AddNumberToObject(o2, "exact_hits", (double)r->ex_hits);
            cJSON_AddNumberToObject(o2, "fp_incr", (double)r->fp_incr);
            cJSON_AddNumberToObject(o2, "fp_exact_M", (double)r->fp_exactM);
            cJSON_AddNumberToObject(o2, "loose_median", r->loose_med);
            cJSON_AddNumberToObject(o2, "loose_p90", r->loose_p90);
            cJSON_AddNumberToObject(o2, "loose_p99", r->loose_p99);
            cJSON_AddNumberToObject(o2, "loose_mean", r->loose_mean);
            cJSON_AddNumberToObject(o2, "slack_median_ulpM", r->slack_med);
            cJSON_AddNumberToObject(o2, "slack_p99_ulpM", r->slack_p99);
            cJSON_AddNumberToObject(o2, "mean_depth", r->depth_sum / (double)r->chains);
            cJSON_AddItemToArray(arr, o2);
        }
        cJSON *th = cJSON_AddArrayToObject(root, "throughput_mtests_per_s");
        for (int u = 0; u < NU; u++) {
            cJSON *o2 = cJSON_CreateObject();
            cJSON_AddStringToObject(o2, "unit", tm[u].name);
            cJSON_AddNumberToObject(o2, "min", tm[u].min);
            cJSON_AddNumberToObject(o2, "median", tm[u].med);
            cJSON_AddNumberToObject(o2, "max", tm[u].max);
            cJSON_AddItemToArray(th, o2);
        }
        int rc = bench_json_write(root, json);
        cJSON_Delete(root);
        if (rc) {
            fprintf(stderr, "bench_box_incr: cannot write %s\n", json);
            return 2;
        }
    }
    if (false_miss) {
        printf("FAIL: %ld children the exact unit hits were missed by the incremental unit\n", false_miss);
        return 1;
    }
    return 0;
}
