/* Datapath benchmark: ns per operation and operations/s of the bit-exact
 * model's units on a scene-like input mix, against a naive float
 * implementation of the same quantization measured in the same run.
 *
 * usage: bench_datapath [--seconds S] [--seed N]
 *
 * Inputs: 4096 child boxes of a random scene (triangle-sized boxes, log-
 * uniform sizes 2^-8..2^2, scene extent +-64), each inside a parent node box
 * a few times larger; the parent gives the context (root_ctx).  The same
 * arrays are cycled, so the working set stays in L1/L2 like a hardware unit's
 * registers would. */
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbvh/datapath.h"
#include "cbvh/traversal_units.h"

/* The ray-sphere unit's exact path alone (rtl-model/src/units/ray_sphere_internal.h). */
uint32_t cbvh_ray_sphere_exact_only(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r, int *hit);

#define NB 4096 /* boxes per input set (power of two) */

typedef struct {
    cbvh_f32 lb, ub;      /* child box along one axis */
    cbvh_axis_ctx ctx;    /* parent context */
    uint32_t lc[2], uc[2]; /* stored codes: modulo, relative */
} axis_input;

static axis_input in[NB];
static cbvh_node_ctx nctx[NB / 8];
static cbvh_child_in nchild[NB / 8][2];
static uint8_t nbytes[NB / 8][24];
static const cbvh_params P = {CBVH_N_DEFAULT, CBVH_MIN_SCALE_DEFAULT};

static uint64_t rng_state;
static uint64_t rng(void) {
    uint64_t z = (rng_state += UINT64_C(0x9E3779B97F4A7C15));
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}
static double unit(void) { return (double)(rng() >> 11) * 0x1p-53; }

static void make_inputs(void) {
    for (int i = 0; i < NB; i++) {
        axis_input *x = &in[i];
        float centre = (float)(unit() * 128.0 - 64.0);
        float size = (float)ldexp(1.0, -8 + (int)(rng() % 10)) * (float)(0.5 + unit());
        if (rng() % 16 == 0) size = 0.0f; /* flat triangles (axis-aligned) */
        float lb = centre - (float)unit() * size, ub = lb + size;
        float grow = (float)ldexp(1.0, (int)(rng() % 6)); /* parent 1x..32x the child */
        float plb = lb - (float)unit() * size * grow - 1e-3f, pub = ub + (float)unit() * size * grow + 1e-3f;
        x->lb = cbvh_f32_of(lb);
        x->ub = cbvh_f32_of(ub);
        if (cbvh_axis_root_ctx(&P, cbvh_f32_of(plb), cbvh_f32_of(pub), &x->ctx)) abort();
        cbvh_axis_code c;
        if (cbvh_axis_compress(&P, x->lb, x->ub, x->ctx.scale, x->ctx.clb, &c)) abort();
        for (int enc = 0; enc < 2; enc++)
            cbvh_axis_store_codes(&P, (cbvh_encoding)enc, &x->ctx, &c, &x->lc[enc], &x->uc[enc]);
    }
    for (int i = 0; i < NB / 8; i++) {
        for (int c = 0; c < 2; c++) {
            for (int a = 0; a < 3; a++) {
                const axis_input *x = &in[(i * 6 + c * 3 + a) % NB];
                nchild[i][c].lo[a] = x->lb;
                nchild[i][c].hi[a] = x->ub;
            }
            nchild[i][c].leaf = c;
            nchild[i][c].ptr = (uint32_t)(rng() % 100000);
        }
        /* one context per pair: the union of the two children grown a bit */
        for (int a = 0; a < 3; a++) {
            float lo = fminf(cbvh_float_of(nchild[i][0].lo[a]), cbvh_float_of(nchild[i][1].lo[a])) - 0.01f;
            float hi = fmaxf(cbvh_float_of(nchild[i][0].hi[a]), cbvh_float_of(nchild[i][1].hi[a])) + 0.01f;
            if (cbvh_axis_root_ctx(&P, cbvh_f32_of(lo), cbvh_f32_of(hi), &nctx[i].axis[a])) abort();
        }
        cbvh_child_out out[2];
        if (cbvh_nodepair_encode(&P, CBVH_ENC_MODULO, &nctx[i], nchild[i], nbytes[i], out)) abort();
    }
}

/* Ray-sphere inputs (unit 9), like a traversal list's sphere elements: spheres
 * of radius 2^-8..2^2 in +-64, rays from the scene box; set 0: random
 * directions (nearly all misses), set 1: aimed inside the sphere (hits), set 2:
 * half and half.  tmax = +Inf or a finite culling bound. */
typedef struct {
    cbvh_ray ray;
    cbvh_f32 c[3], r;
} sphere_input;
static sphere_input sph[3][NB];

static void make_sphere_inputs(void) {
    for (int set = 0; set < 3; set++)
        for (int i = 0; i < NB; i++) {
            sphere_input *x = &sph[set][i];
            float c[3], o[3], r = (float)ldexp(1.0, -8 + (int)(rng() % 10)) * (float)(0.5 + unit());
            int aim = set == 1 || (set == 2 && (i & 1));
            for (int a = 0; a < 3; a++) {
                c[a] = (float)(unit() * 128.0 - 64.0);
                o[a] = (float)(unit() * 128.0 - 64.0);
                x->c[a] = cbvh_f32_of(c[a]);
                x->ray.o[a] = cbvh_f32_of(o[a]);
            }
            for (int a = 0; a < 3; a++) {
                float d = aim ? c[a] - o[a] + (float)((unit() - 0.5) * r) : (float)(unit() * 2.0 - 1.0);
                x->ray.d[a] = cbvh_f32_of(d);
            }
            x->r = cbvh_f32_of(r);
            x->ray.tmin = 0;
            x->ray.tmax = rng() % 2 ? CBVH_F32_POS_INF : cbvh_f32_of((float)(unit() * 4.0));
        }
}

/* Float baseline: the textbook discriminant test in binary32 (not exact). */
static int naive_sphere(const sphere_input *x) {
    float o[3], d[3], w[3], A = 0, B = 0, C = 0;
    for (int a = 0; a < 3; a++) {
        o[a] = cbvh_float_of(x->ray.o[a]);
        d[a] = cbvh_float_of(x->ray.d[a]);
        w[a] = cbvh_float_of(x->c[a]) - o[a];
        A += d[a] * d[a];
        B += w[a] * d[a];
        C += w[a] * w[a];
    }
    float r = cbvh_float_of(x->r), tmax = cbvh_float_of(x->ray.tmax);
    float t = B / A;
    t = t < 0 ? 0 : t > tmax ? tmax : t;
    return A * t * t - 2 * B * t + C <= r * r;
}

/* ---- naive float baselines (not bit-exact: float ops, round to nearest) ---- */
typedef struct {
    uint32_t lb_mod, ub_mod;
    int child_scale;
    float clb, cub;
} naive_code;

static void naive_compress_ldexpf(int n, int min_scale, float lb, float ub, int e, naive_code *o) {
    float k = floorf(ldexpf(lb, -e)), l = floorf(ldexpf(ub, -e)) + 1.0f;
    int32_t ki = (int32_t)k, li = (int32_t)l;
    uint32_t mask = (1u << n) - 1u;
    o->lb_mod = (uint32_t)ki & mask;
    o->ub_mod = (uint32_t)li & mask;
    int cs = e - n + ilogbf((float)(li - ki - 1) * 2.0f + 1.0f); /* ~ceil(log2(cells)) */
    o->child_scale = cs < min_scale ? min_scale : cs;
    o->clb = ldexpf(k, e);
    o->cub = ldexpf(l, e);
}

/* 2^x as a float built from its bits (|x| <= 126) */
static float pow2f(int x) { return cbvh_float_of(cbvh_f32_make(0, x, 0)); }

static void naive_compress_mul(int n, int min_scale, float lb, float ub, int e, naive_code *o) {
    float inv = pow2f(-e), step = pow2f(e);
    float k = floorf(lb * inv), l = floorf(ub * inv) + 1.0f;
    int32_t ki = (int32_t)k, li = (int32_t)l;
    uint32_t mask = (1u << n) - 1u;
    o->lb_mod = (uint32_t)ki & mask;
    o->ub_mod = (uint32_t)li & mask;
    uint32_t cells = (uint32_t)(li - ki);
    int cs = e - n + (cells > 1 ? 32 - __builtin_clz(cells - 1u) : 0);
    o->child_scale = cs < min_scale ? min_scale : cs;
    o->clb = k * step;
    o->cub = l * step;
}

static void naive_decode(int n, int min_scale, const cbvh_axis_ctx *ctx, uint32_t lc, uint32_t uc, naive_code *o) {
    uint32_t mask = (1u << n) - 1u;
    int sh = ctx->parent_scale - ctx->scale;
    uint32_t pmod = sh >= n ? 0 : (ctx->lb_mod << sh) & mask;
    uint32_t r = (lc - pmod) & mask, s = (uc - pmod) & mask;
    if (s == 0) s = mask + 1u;
    float step = pow2f(ctx->scale), u = cbvh_float_of(ctx->clb);
    o->lb_mod = lc;
    o->ub_mod = uc;
    int cs = ctx->scale - n + (s - r > 1 ? 32 - __builtin_clz(s - r - 1u) : 0);
    o->child_scale = cs < min_scale ? min_scale : cs;
    o->clb = u + (float)r * step;
    o->cub = u + (float)s * step;
}

/* ---- timing ---- */
static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static volatile uint32_t sink;
static double min_seconds = 0.2;

#define SINK_CODE(c) ((c).lb_mod ^ (c).ub_mod ^ (uint32_t)(c).child_scale ^ (c).clb ^ (c).cub)

/* Runs BODY over all NB inputs repeatedly for >= min_seconds, best of 5 runs
 * (the best run is the one least disturbed by other processes);
 * returns ns per operation (ops_per_input operations per input). */
#define TIME_LOOP(result, ops_per_input, count, BODY)                                                                  \
    do {                                                                                                               \
        double best = 1e30;                                                                                            \
        for (int run = 0; run < 5; run++) {                                                                            \
            long reps = 0;                                                                                             \
            uint32_t acc = 0;                                                                                          \
            double t0 = now(), t1;                                                                                     \
            do {                                                                                                       \
                for (int i = 0; i < (count); i++) { BODY }                                                             \
                reps++;                                                                                                \
            } while ((t1 = now()) - t0 < min_seconds);                                                                 \
            sink ^= acc;                                                                                               \
            double ns = (t1 - t0) * 1e9 / ((double)reps * (count) * (ops_per_input));                                  \
            if (ns < best) best = ns;                                                                                  \
        }                                                                                                              \
        result = best;                                                                                                 \
    } while (0)

static void row(const char *name, double ns, double base_ns, const char *base) {
    printf("%-28s %9.2f %12.1f", name, ns, 1e3 / ns);
    if (base_ns > 0)
        printf("   %-22s %8.2f   %6.2fx\n", base, base_ns, ns / base_ns);
    else
        printf("\n");
}

int main(int argc, char **argv) {
    uint64_t seed = 1;
    static const struct option opts[] = {{"seconds", required_argument, 0, 't'}, {"seed", required_argument, 0, 's'}, {0, 0, 0, 0}};
    int ch;
    while ((ch = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        char *end;
        if (ch == 't') {
            min_seconds = strtod(optarg, &end);
            if (*end || !(min_seconds > 0)) { fprintf(stderr, "error: --seconds needs a positive number\n"); return 2; }
        } else if (ch == 's') {
            seed = strtoull(optarg, &end, 0);
            if (*end) { fprintf(stderr, "error: --seed needs an integer\n"); return 2; }
        } else {
            fprintf(stderr, "usage: %s [--seconds S] [--seed N]\n", argv[0]);
            return 2;
        }
    }
    rng_state = seed;
    make_inputs();
    make_sphere_inputs();

    double t_comp, t_dmod, t_drel, t_est, t_enc, t_dec, t_nl, t_nm, t_nd;
    TIME_LOOP(t_comp, 1, NB, {
        cbvh_axis_code c;
        acc += cbvh_axis_compress(&P, in[i].lb, in[i].ub, in[i].ctx.scale, in[i].ctx.clb, &c);
        acc += SINK_CODE(c);
    });
    TIME_LOOP(t_nl, 1, NB, {
        naive_code c;
        naive_compress_ldexpf(P.quant_bits, P.min_scale, cbvh_float_of(in[i].lb), cbvh_float_of(in[i].ub), in[i].ctx.scale, &c);
        acc += c.lb_mod ^ c.ub_mod ^ (uint32_t)c.child_scale ^ cbvh_f32_of(c.clb) ^ cbvh_f32_of(c.cub);
    });
    TIME_LOOP(t_nm, 1, NB, {
        naive_code c;
        naive_compress_mul(P.quant_bits, P.min_scale, cbvh_float_of(in[i].lb), cbvh_float_of(in[i].ub), in[i].ctx.scale, &c);
        acc += c.lb_mod ^ c.ub_mod ^ (uint32_t)c.child_scale ^ cbvh_f32_of(c.clb) ^ cbvh_f32_of(c.cub);
    });
    TIME_LOOP(t_dmod, 1, NB, {
        cbvh_axis_code c;
        acc += cbvh_axis_decode(&P, CBVH_ENC_MODULO, &in[i].ctx, in[i].lc[0], in[i].uc[0], &c);
        acc += SINK_CODE(c);
    });
    TIME_LOOP(t_drel, 1, NB, {
        cbvh_axis_code c;
        acc += cbvh_axis_decode(&P, CBVH_ENC_RELATIVE, &in[i].ctx, in[i].lc[1], in[i].uc[1], &c);
        acc += SINK_CODE(c);
    });
    TIME_LOOP(t_nd, 1, NB, {
        naive_code c;
        naive_decode(P.quant_bits, P.min_scale, &in[i].ctx, in[i].lc[0], in[i].uc[0], &c);
        acc += c.lb_mod ^ c.ub_mod ^ (uint32_t)c.child_scale ^ cbvh_f32_of(c.clb) ^ cbvh_f32_of(c.cub);
    });
    TIME_LOOP(t_est, 1, NB, {
        int e;
        acc += cbvh_scale_estimate(&P, in[i].lb, in[i].ub, &e);
        acc += (uint32_t)e;
    });
    TIME_LOOP(t_enc, 1, NB / 8, {
        cbvh_child_out out[2];
        uint8_t bytes[24];
        acc += cbvh_nodepair_encode(&P, CBVH_ENC_MODULO, &nctx[i], nchild[i], bytes, out);
        acc += bytes[3] ^ out[1].axis[2].cub;
    });
    TIME_LOOP(t_dec, 1, NB / 8, {
        cbvh_child_out out[2];
        acc += cbvh_nodepair_decode(&P, CBVH_ENC_MODULO, &nctx[i], nbytes[i], out);
        acc += out[1].axis[2].cub;
    });

    double t_sph[3], t_sph_exact[3], t_sph_naive[3];
    int sph_hits[3] = {0, 0, 0};
    for (int set = 0; set < 3; set++) {
        const sphere_input *sx = sph[set];
        for (int i = 0; i < NB; i++) {
            int h, he;
            cbvh_ray_sphere(&sx[i].ray, sx[i].c, sx[i].r, &h);
            cbvh_ray_sphere_exact_only(&sx[i].ray, sx[i].c, sx[i].r, &he);
            if (h != he) abort(); /* the fast path never changes a result */
            sph_hits[set] += h;
        }
        TIME_LOOP(t_sph[set], 1, NB, {
            int h;
            acc += cbvh_ray_sphere(&sx[i].ray, sx[i].c, sx[i].r, &h);
            acc += (uint32_t)h;
        });
        TIME_LOOP(t_sph_exact[set], 1, NB, {
            int h;
            acc += cbvh_ray_sphere_exact_only(&sx[i].ray, sx[i].c, sx[i].r, &h);
            acc += (uint32_t)h;
        });
        TIME_LOOP(t_sph_naive[set], 1, NB, { acc += (uint32_t)naive_sphere(&sx[i]); });
    }

    printf("cbvh datapath benchmark: N=%d, min_scale=%d, %d scene-like boxes, best of 5 x >= %.2f s\n", P.quant_bits,
           P.min_scale, NB, min_seconds);
    printf("ratio = model ns/op / baseline ns/op (below 1: the bit-exact model is faster)\n");
    printf("%-28s %9s %12s   %-22s %8s   %7s\n", "unit", "ns/op", "Mops/s", "baseline (naive float)", "ns/op",
           "ratio");
    row("axis_compress", t_comp, t_nl, "floorf+ldexpf");
    row("", t_comp, t_nm, "floorf+mul by 2^-e");
    row("axis_decode (modulo)", t_dmod, t_nd, "float add (modulo)");
    row("axis_decode (relative)", t_drel, t_nd, "float add (modulo)");
    row("scale_estimate", t_est, 0, "");
    row("nodepair_encode (pair)", t_enc, 0, "");
    row("nodepair_decode (pair)", t_dec, 0, "");
    static const char *const sph_names[3] = {"ray_sphere (misses)", "ray_sphere (hits)", "ray_sphere (50/50)"};
    for (int set = 0; set < 3; set++) {
        char name[64];
        snprintf(name, sizeof name, "%s %d%%", sph_names[set], (int)(100.0 * sph_hits[set] / NB + 0.5));
        row(name, t_sph[set], t_sph_exact[set], "exact path only");
        row("", t_sph[set], t_sph_naive[set], "float discriminant");
    }
    printf("target: >= 100 Mops/s single-axis compressions on one core: %s (%.1f Mops/s)\n",
           1e3 / t_comp >= 100.0 ? "MET" : "NOT MET", 1e3 / t_comp);
    return 0;
}
