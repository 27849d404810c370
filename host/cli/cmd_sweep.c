/* cbvh sweep SCENE: what each bit of precision costs (docs/sweep.md).  The
 * float BVH and every CBVH setting trace the same rays in one run; costs are
 * printed relative to the float BVH, a chart and heat maps go to --out, and
 * every setting must return the float BVH's hits (exit 1 naming the first
 * differing ray otherwise).  --formats cbvh,qbvh,tlist... adds the QBVH and
 * traversal lists as more rows, checked the same way. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "cbvh/oom.h"
#include "util/chart_svg.h"
#include "cli/commands.h"
#include "cli/data_dir.h"
#include "util/image_png.h"
#include "util/parse_int.h"
#include "trace/cost_table.h"
#include "trace/model_eval.h"
#include "trace/sweep.h"

#define MAX_HEAT 16
#define MAX_FILES 64

static void usage(FILE *f) {
    fprintf(f,
            "usage: cbvh sweep SCENE [--bits LO..HI] [--mant M...] [--min-scale E...] [--spp K] [--json]\n"
            "                        [--out DIR] [--heatmap SETTING...] [--knee PCT] [--formats cbvh[,F...]]\n"
            "                        [--one-sided] [--cache KB...] [--reps K] [--cost-table DIR]\n"
            "                        [--timing K=V,...] [--box-unit U[,U]]\n"
            "  SCENE is a scene file (.scene, .json) or a mesh file / proc:NAME (its default scene,\n"
            "  docs/scenes.md).\n"
            "  Traces the scene's effects (docs/scenes.md) on the float BVH and on the CBVH for every\n"
            "  setting N x M x E, on the same rays, and prints per setting and effect: box and triangle\n"
            "  tests, bytes per ray, node memory, modelled time and CPU time, each relative to the float\n"
            "  BVH; proves every setting returns the float BVH's hits and image (exit 1 if not); says\n"
            "  where the knee is; writes a chart and heat maps (docs/sweep.md).\n"
            "  --bits LO..HI     coordinate bits N, within %d..%d (default 3..10; N alone = one value)\n"
            "  --mant M...       mantissa bits of the ray-box unit, %d..%d (default 24)\n"
            "  --min-scale E...  minimum grid scale, %d..%d (default %d)\n"
            "  --spp K           camera samples per pixel, 1..1024 (default: the scene's)\n"
            "  --out DIR         where the chart and heat maps go (default sweep-<scene name>)\n"
            "  --heatmap S...    settings to draw box tests per pixel for: float, N, N:M:E, or a traced format\n"
            "                    (qbvh, tlist...; default float 3 6 10, those in range, and every other format\n"
            "                    traced; N uses the first M, E)\n"
            "  --knee PCT        knee tolerance in percent, 0..1000 (default 10)\n"
            "  --formats F,...   formats compared with the float BVH: cbvh (default; always), and more rows:\n"
            "                    qbvh (4-ary QBVH with the compressed stack, docs/qbvh.md, at the first M),\n"
            "                    tlist[:1|2|6|8][:earliest|:latest][:cull][:heads] (traversal lists over a\n"
            "                    bounding-sphere hierarchy, docs/tlist.md; default 6 lists, earliest first)\n"
            "  --one-sided       triangles count only from their front side (counter-clockwise), on every\n"
            "                    format; needed by tlist:...:cull (back-face culling)\n"
            "  --box-unit U[,U]  the CBVH rows' box units: exact (unit 6, default), incremental[:X] (unit 10,\n"
            "                    Eq. 5 with X-bit distance exponents, 3..8, default 8; adds its false-positive\n"
            "                    box hits and the triangle tests under them per setting), or both, e.g.\n"
            "                    exact,incremental: every setting once per unit, on one Pareto front (heat maps:\n"
            "                    the first unit's)\n"
            "  --cache KB...     node and triangle cache sizes the timing model runs, each in KB (0 = no\n"
            "                    cache, inf = infinite), at most %d (default 64; docs/timing_model.md)\n"
            "  --reps K          timed repetitions for the CPU-time column, 1..%d (default 5): the median\n"
            "                    and the fastest and slowest are printed\n"
            "  --cost-table DIR  the RTL cost table, one JSON file per unit (default: gateware/cost\n"
            "                    beside the committed vectors)\n"
            "  --timing K=V,...  timing-model parameters over the scene file's (its timing keys,\n"
            "                    docs/scenes.md), e.g. rays_in_flight=256,box_cycles=1,tri_cycles=1\n"
            "  --json            machine-readable output on stdout\n"
            "  A list option (--mant, --min-scale, --heatmap, --formats, --cache) may be given once; any other\n"
            "  option given twice: the last wins.\n"
            "testing:\n"
            "  --test-corrupt S:R  pretend setting S (index in trace order) returned a wrong answer for\n"
            "                      ray R, to show the identity check fails (docs/sweep.md)\n",
            CBVH_N_MIN, CBVH_N_MAX, CBVH_MANT_MIN, CBVH_MANT_MAX, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL,
            CBVH_MIN_SCALE_DEFAULT, CBVH_CACHES_MAX,
            CBVH_REPS_MAX);
}


/* The sign and digits of an integer, the whole of s[0..n). */
static int is_int(const char *s, size_t n) {
    size_t i = n && (s[0] == '-' || s[0] == '+');
    if (i == n) return 0;
    for (; i < n; i++)
        if (s[i] < '0' || s[i] > '9') return 0;
    return 1;
}

/* An empty item in a comma list ("a,,b", ",a", "a,"). */
static int has_empty_item(const char *s) {
    size_t n = strlen(s);
    return n == 0 || s[0] == ',' || s[n - 1] == ',' || strstr(s, ",,") != NULL;
}

/* "24" or "8,12,24": a value of a list option (else the next option or the scene). */
static int is_int_list(const char *s) {
    if (has_empty_item(s)) return 0;
    for (const char *t = s; t; t = strchr(t, ',') ? strchr(t, ',') + 1 : NULL)
        if (!is_int(t, strcspn(t, ","))) return 0;
    return 1;
}

/* A list option given a second time: an error, not "the last wins" (that
 * silently dropped the first values; --mant 8 --mant 24 looks like two). */
static int list_again(const char *opt, int *given) {
    if ((*given)++) {
        fprintf(stderr, "cbvh sweep: %s given twice (all its values go after one %s)\n", opt, opt);
        return -1;
    }
    return 0;
}

/* The items of one value of a list option (is_int_list) appended to out
 * (n used of max): each in lo..hi and not given before.  0 or -1. */
static int add_values(const char *opt, const char *a, long lo, long hi, int *out, int *n, int max) {
    for (const char *t = a; t; t = strchr(t, ',') ? strchr(t, ',') + 1 : NULL) {
        size_t len = strcspn(t, ",");
        char item[32];
        long v;
        if (len >= sizeof item || (memcpy(item, t, len), item[len] = 0, cbvh_parse_long(item, lo, hi, &v))) {
            fprintf(stderr, "cbvh sweep: %s expects integers in %ld..%ld, got '%.*s'\n", opt, lo, hi, (int)len, t);
            return -1;
        }
        if (*n == max) {
            fprintf(stderr, "cbvh sweep: %s takes at most %d values\n", opt, max);
            return -1;
        }
        for (int k = 0; k < *n; k++)
            if (out[k] == v) { /* the same setting twice would be traced and charted twice */
                fprintf(stderr, "cbvh sweep: %s: %ld given twice\n", opt, v);
                return -1;
            }
        out[(*n)++] = (int)v;
    }
    return 0;
}

/* A list option's values: first (getopt's optarg), then the following
 * arguments that are integer lists too (optind moves past them).  Returns
 * the count, -1 on error. */
static int parse_list(const char *opt, const char *first, int argc, char **argv, long lo, long hi, int *out,
                      int max) {
    int n = 0;
    if (!is_int_list(first)) {
        fprintf(stderr, "cbvh sweep: %s expects integers in %ld..%ld, got '%s'\n", opt, lo, hi, first);
        return -1;
    }
    for (const char *a = first; a; a = optind < argc && is_int_list(argv[optind]) ? argv[optind++] : NULL)
        if (add_values(opt, a, lo, hi, out, &n, max)) return -1;
    return n;
}

/* --box-unit U[,U]: each of exact, incremental[:X] at most once; the rows
 * run through them in the order given.  0 or -1 with the message. */
static int parse_box_units(const char *v, cbvh_sweep_opts *o) {
    char buf[64];
    if (strlen(v) >= sizeof buf) {
        fprintf(stderr, "cbvh sweep: --box-unit '%s' is too long\n", v);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", v);
    o->nbox_unit = 0;
    for (char *t = buf, *end; t; t = end) {
        end = strchr(t, ',');
        if (end) *end++ = 0;
        int u, x;
        if (cbvh_parse_box_unit("cbvh sweep", t, &u, &x)) return -1;
        for (int i = 0; i < o->nbox_unit; i++)
            if (o->box_unit[i] == u) {
                fprintf(stderr, "cbvh sweep: --box-unit: %s given twice\n", cbvh_box_units[u].name);
                return -1;
            }
        o->box_unit[o->nbox_unit++] = u;
        if (u == CBVH_FORMAT_BOX_INCREMENTAL) o->texp = x;
    }
    return 0;
}

typedef struct {
    int is_float;
    int xf;               /* 1 + index into the other formats, 0 = none */
    char fmt[48];         /* a format name given on the command line, resolved after parsing */
    int bits, mant, min_scale; /* mant/min_scale < -1000: the first of the lists */
    int explicit_all;
} heat_spec;

static int parse_heat(const char *s, heat_spec *h) {
    memset(h, 0, sizeof *h);
    if (strcmp(s, "float") == 0) {
        h->is_float = 1;
        return 0;
    }
    if (cbvh_sweep_format_find(s)) {
        cbvh_sweep_format f;
        char e[160];
        if (cbvh_sweep_format_parse(s, &f, e, sizeof e)) return -1;
        snprintf(h->fmt, sizeof h->fmt, "%s", f.name);
        return 0;
    }
    char buf[64], *p[3];
    snprintf(buf, sizeof buf, "%s", s);
    int n = 0;
    for (char *t = strtok(buf, ":"); t && n < 3; t = strtok(NULL, ":")) p[n++] = t;
    long v[3];
    if (n != 1 && n != 3) return -1;
    if (strlen(s) >= sizeof buf) return -1;
    for (int i = 0; i < n; i++)
        if (cbvh_parse_long(p[i], CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, &v[i])) return -1; /* wide enough for N, M and E */
    if (v[0] < CBVH_N_MIN || v[0] > CBVH_N_MAX) return -1;
    h->bits = (int)v[0];
    if (n == 3) {
        h->mant = (int)v[1];
        h->min_scale = (int)v[2];
        h->explicit_all = 1;
    }
    return 0;
}

/* What the progress line needs to know. */
typedef struct {
    int reps;
} sweep_cli_reps;

static void progress(void *ctx, const char *label, int setting, int settings, int row, int rows, int rep) {
    const sweep_cli_reps *r = ctx;
    if (row % 8 && row != rows - 1) return;
    if (rep)
        fprintf(stderr, "\rtiming %d/%d %d/%d %-18s row %d/%d   ", rep, r->reps, setting, settings, label, row + 1,
                rows);
    else
        fprintf(stderr, "\rsweep %d/%d %-18s row %d/%d   ", setting, settings, label, row + 1, rows);
}

/* "sweep-" + the scene file's name without directory and extension. */
static void default_out(const char *scene, char *out, size_t n) {
    const char *b = strrchr(scene, '/');
    b = b ? b + 1 : scene;
    const char *dot = strrchr(b, '.');
    size_t len = dot && dot > b ? (size_t)(dot - b) : strlen(b);
    snprintf(out, n, "sweep-%.*s", (int)len, b);
}


static const char *metric_names[SWEEP_NMETRICS] = {"box tests", "triangle tests", "bytes", "modelled time",
                                                  "CPU time", "modelled energy"};
static const char *metric_keys[SWEEP_NMETRICS] = {"box_per_ray", "tri_per_ray", "bytes_per_ray", "model_ns_per_ray",
                                                 "cpu_us_per_ray", "energy_nj_per_ray"};

static void print_rel(double r) {
    if (isnan(r))
        printf(" %7s", "-");
    else if (isinf(r))
        printf(" %7s", "inf");
    else
        printf(" %7.3f", r);
}

/* " x1.234", or " -" / " x inf" where the float BVH did none. */
static void print_x(double r) {
    if (isnan(r))
        printf(" -");
    else if (isinf(r))
        printf(" x inf");
    else
        printf(" x%.3f", r);
}

/* JSON has no NaN or infinity: a ratio without a finite value is null. */
static void json_rel(cJSON *o, const char *key, double r) {
    if (isfinite(r))
        cJSON_AddNumberToObject(o, key, r);
    else
        cJSON_AddNullToObject(o, key);
}

static void text_row(const char *setting, const char *effect, const cbvh_fx_stats *s, const cbvh_fx_stats *f,
                     uint64_t mem, uint64_t fmem, const cbvh_machine *ms, const cbvh_machine *mf, const char *same) {
    double p[SWEEP_NMETRICS], q[SWEEP_NMETRICS];
    cbvh_sweep_per_ray(s, ms, p);
    cbvh_sweep_per_ray(f, mf, q);
    printf("%-28s %-17s %8llu %8.2f %7.2f %8.1f %9.1f %7.2f |", setting, effect, (unsigned long long)s->rays,
           p[SWEEP_BOX], p[SWEEP_TRI], p[SWEEP_BYTES], p[SWEEP_MODEL_NS], p[SWEEP_CPU_US]);
    print_rel(cbvh_ratio(p[SWEEP_BOX], q[SWEEP_BOX]));
    print_rel(cbvh_ratio(p[SWEEP_TRI], q[SWEEP_TRI]));
    print_rel(cbvh_ratio(p[SWEEP_BYTES], q[SWEEP_BYTES]));
    print_rel(cbvh_ratio((double)mem, (double)fmem));
    print_rel(cbvh_ratio(p[SWEEP_MODEL_NS], q[SWEEP_MODEL_NS]));
    print_rel(cbvh_fx_cpu_ratio(s, f));
    printf("  %s\n", same);
}

/* One set of rays' costs (per effect or total) against the float BVH's on the
 * same rays: the counters, and the timing model at every cache size of the
 * run (ms: the configuration's machines, mf: the float BVH's). */
static cJSON *json_costs(const cbvh_fx_stats *s, const cbvh_fx_stats *f, uint64_t mem, uint64_t fmem,
                         const cbvh_config_model *ms, const cbvh_config_model *mf) {
    double p[SWEEP_NMETRICS], q[SWEEP_NMETRICS];
    cbvh_sweep_per_ray(s, &ms->mc[0], p);
    cbvh_sweep_per_ray(f, &mf->mc[0], q);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "rays", (double)s->rays);
    cJSON_AddNumberToObject(o, "hits", (double)s->hits);
    cJSON_AddNumberToObject(o, "max_stack", s->st.max_stack);
    for (int m = 0; m < SWEEP_NMETRICS; m++) cJSON_AddNumberToObject(o, metric_keys[m], p[m]);
    cbvh_ray_metrics cm;
    cbvh_ray_metrics_of(s, &ms->mc[0], &cm);
    cJSON_AddNumberToObject(o, "cpu_us_per_ray_min", cm.cpu_lo);
    cJSON_AddNumberToObject(o, "cpu_us_per_ray_max", cm.cpu_hi);
    cJSON_AddNumberToObject(o, "cpu_reps", s->nreps);
    cJSON *r = cJSON_AddObjectToObject(o, "relative_to_float");
    static const char *rk[SWEEP_NMETRICS] = {"box_tests", "tri_tests", "bytes", "model_time", "cpu_time", "energy"};
    for (int m = 0; m < SWEEP_NMETRICS; m++)
        json_rel(r, rk[m], m == SWEEP_CPU_US ? cbvh_fx_cpu_ratio(s, f) : cbvh_ratio(p[m], q[m]));
    json_rel(r, "node_memory", cbvh_ratio((double)mem, (double)fmem));
    cJSON *model = cJSON_AddArrayToObject(o, "model");
    for (int c = 0; c < ms->ncaches; c++) {
        cbvh_ray_metrics a, b;
        cbvh_ray_metrics_of(s, &ms->mc[c], &a);
        cbvh_ray_metrics_of(f, &mf->mc[c], &b);
        cJSON *mo = cJSON_CreateObject();
        cJSON_AddItemToArray(model, mo);
        json_rel(mo, "cache_kb", ms->mc[c].cache_kb); /* null: infinite */
        cJSON_AddNumberToObject(mo, "ns_per_ray", a.model_ns);
        cbvh_model_json(mo, &a);
        /* the incremental unit's accepted boxes that unit 6 rejects, and the
         * triangle tests under them (0 for the exact unit and other formats) */
        cJSON_AddNumberToObject(mo, "false_positive_box_hits_per_ray", a.fp_box);
        cJSON_AddNumberToObject(mo, "extra_tri_tests_per_ray", a.fp_tri);
        cJSON *mr = cJSON_AddObjectToObject(mo, "relative_to_float");
        json_rel(mr, "time", cbvh_ratio(a.model_ns, b.model_ns));
        json_rel(mr, "energy", cbvh_ratio(a.energy_nj, b.energy_nj));
        json_rel(mr, "area", cbvh_ratio(a.area_lut4, b.area_lut4));
        json_rel(mr, "dram_bytes", cbvh_ratio(a.dram_bytes, b.dram_bytes));
    }
    return o;
}

/* Makes --out (and its parents); 0 or -1 (message printed). */
static int ensure_dir(const char *dir) {
    struct stat sb;
    if (stat(dir, &sb) == 0) {
        if (!S_ISDIR(sb.st_mode)) {
            fprintf(stderr, "cbvh sweep: --out %s: exists and is not a directory\n", dir);
            return -1;
        }
        return 0;
    }
    /* Like mkdir -p: the parents first. */
    char buf[1024];
    if (strlen(dir) >= sizeof buf) {
        fprintf(stderr, "cbvh sweep: --out %s: path too long\n", dir);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", dir);
    for (char *p = buf + 1; *p; p++)
        if (*p == '/') {
            *p = 0;
            if (mkdir(buf, 0777) && errno != EEXIST) break; /* reported below */
            *p = '/';
        }
    if (mkdir(dir, 0777) && errno != EEXIST) {
        fprintf(stderr, "cbvh sweep: --out %s: cannot create: %s\n", dir, strerror(errno));
        return -1;
    }
    return 0;
}

/* --out must take files before the sweep runs, not fail after it: create and
 * remove a temporary file there (access(W_OK) would pass for root on a
 * read-only directory and says nothing about a read-only file system). */
static int check_writable(const char *dir) {
    char tmp[1100];
    if (snprintf(tmp, sizeof tmp, "%s/.cbvh-sweep-XXXXXX", dir) >= (int)sizeof tmp) {
        fprintf(stderr, "cbvh sweep: --out %s: path too long\n", dir);
        return -1;
    }
    int fd = mkstemp(tmp);
    if (fd < 0) {
        fprintf(stderr, "cbvh sweep: --out %s: cannot write files there: %s\n", dir, strerror(errno));
        return -1;
    }
    close(fd);
    unlink(tmp);
    return 0;
}


/* ---- parse and validate: the command line --------------------------------- */

/* The options as given (parse_options), completed with their defaults and
 * checked against each other (validate_options). */
typedef struct {
    const char *scene, *outdir;
    char outbuf[1024]; /* the default --out */
    cbvh_sweep_opts run;
    int json;
    long knee_pct;
    heat_spec heat[MAX_HEAT];
    int nheat;
    int mant_given, ms_given, heat_given, formats_given, cache_given, unit_given; /* list options: once each */
    const char *cost_dir, *timing;
    sweep_cli_reps reps;
} sweep_cli;

enum {
    OPT_JSON = 256,
    OPT_BITS,
    OPT_MANT,
    OPT_MIN_SCALE,
    OPT_SPP,
    OPT_KNEE,
    OPT_OUT,
    OPT_HEATMAP,
    OPT_ONE_SIDED,
    OPT_FORMATS,
    OPT_CACHE,
    OPT_REPS,
    OPT_COST_TABLE,
    OPT_TIMING,
    OPT_BOX_UNIT,
    OPT_TEST_CORRUPT
};

static int parse_bits(const char *v, cbvh_sweep_opts *o) {
    char buf[64];
    snprintf(buf, sizeof buf, "%s", v);
    char *dd = strstr(buf, "..");
    long lo, hi;
    int bad;
    if (dd) {
        *dd = 0;
        bad = cbvh_parse_long(buf, CBVH_N_MIN, CBVH_N_MAX, &lo) || cbvh_parse_long(dd + 2, CBVH_N_MIN, CBVH_N_MAX, &hi) ||
              lo > hi;
    } else {
        bad = cbvh_parse_long(buf, CBVH_N_MIN, CBVH_N_MAX, &lo);
        hi = lo;
    }
    if (bad || strlen(v) >= sizeof buf) {
        fprintf(stderr, "cbvh sweep: --bits expects LO..HI or N within %d..%d (LO <= HI), got '%s'\n", CBVH_N_MIN,
                CBVH_N_MAX, v);
        return -1;
    }
    o->bits_lo = (int)lo;
    o->bits_hi = (int)hi;
    return 0;
}

/* A word --heatmap takes (else the next option or the scene). */
static int is_heat_word(const char *a) {
    return a[0] != '-' && (strcmp(a, "float") == 0 || cbvh_sweep_format_find(a) || (a[0] >= '0' && a[0] <= '9'));
}

/* --heatmap's settings: first, then the following heat words. */
static int parse_heatmaps(const char *first, int argc, char **argv, sweep_cli *c) {
    const char *a = is_heat_word(first) ? first : NULL;
    if (!a) {
        fprintf(stderr, "cbvh sweep: --heatmap expects float, N, N:M:E (N in %d..%d) or a format, got '%s'\n",
                CBVH_N_MIN, CBVH_N_MAX, first);
        return -1;
    }
    for (; a; a = optind < argc && is_heat_word(argv[optind]) ? argv[optind++] : NULL) {
        if (c->nheat == MAX_HEAT) {
            fprintf(stderr, "cbvh sweep: --heatmap takes at most %d settings\n", MAX_HEAT);
            return -1;
        }
        if (parse_heat(a, &c->heat[c->nheat])) {
            fprintf(stderr, "cbvh sweep: --heatmap expects float, N, N:M:E (N in %d..%d) or a format, got '%s'\n",
                    CBVH_N_MIN, CBVH_N_MAX, a);
            return -1;
        }
        c->nheat++;
    }
    return 0;
}

static int parse_formats(const char *v, cbvh_sweep_opts *o) {
    char buf[512], ferr[200] = "";
    size_t len = strlen(v);
    int cb = 0, bad = len >= sizeof buf || has_empty_item(v);
    if (!bad) memcpy(buf, v, len + 1);
    o->nextra = 0;
    for (char *t = bad ? NULL : strtok(buf, ","); t && !bad; t = strtok(NULL, ",")) {
        if (strcmp(t, "cbvh") == 0) {
            cb = 1;
            continue;
        }
        cbvh_sweep_format f;
        if (!cbvh_sweep_format_find(t))
            bad = 1;
        else if (cbvh_sweep_format_parse(t, &f, ferr, sizeof ferr))
            bad = 2;
        else if (o->nextra == CBVH_SWEEP_MAX_EXTRA) {
            snprintf(ferr, sizeof ferr, "at most %d formats besides cbvh", CBVH_SWEEP_MAX_EXTRA);
            bad = 2;
        } else {
            for (int k = 0; k < o->nextra; k++)
                if (strcmp(o->extra[k].name, f.name) == 0) {
                    snprintf(ferr, sizeof ferr, "format %s given twice", f.name);
                    bad = 2;
                }
            if (!bad) o->extra[o->nextra++] = f;
        }
    }
    if (bad == 2) {
        fprintf(stderr, "cbvh sweep: --formats: %s\n", ferr);
        return -1;
    }
    if (bad || !cb) {
        cbvh_sweep_formats_syntax(ferr, sizeof ferr);
        fprintf(stderr, "cbvh sweep: --formats expects %s, got '%s'\n", ferr, v);
        return -1;
    }
    return 0;
}

/* "64", "0,16,inf": a value of --cache (else the next option or the scene). */
static int is_cache_list(const char *s) {
    if (has_empty_item(s)) return 0;
    for (const char *t = s; t; t = strchr(t, ',') ? strchr(t, ',') + 1 : NULL) {
        size_t n = strcspn(t, ",");
        if (!is_int(t, n) && !(n == 3 && strncmp(t, "inf", 3) == 0)) return 0;
    }
    return 1;
}

/* --cache's sizes: first, then the following arguments that are cache lists. */
static int parse_caches(const char *first, int argc, char **argv, cbvh_sweep_opts *o) {
    if (!is_cache_list(first)) {
        fprintf(stderr, "cbvh sweep: --cache expects sizes in KB (0..%d, or inf), got '%s'\n", CBVH_CACHE_KB_MAX,
                first);
        return -1;
    }
    for (const char *a = first; a; a = optind < argc && is_cache_list(argv[optind]) ? argv[optind++] : NULL)
        for (const char *t = a; t; t = strchr(t, ',') ? strchr(t, ',') + 1 : NULL) {
            char item[32];
            size_t len = strcspn(t, ",");
            double kb;
            if (len >= sizeof item || (memcpy(item, t, len), item[len] = 0, cbvh_cache_kb_parse(item, &kb))) {
                fprintf(stderr, "cbvh sweep: --cache expects sizes in KB (0..%d, or inf), got '%.*s'\n",
                        CBVH_CACHE_KB_MAX, (int)len, t);
                return -1;
            }
            if (o->ncaches == CBVH_CACHES_MAX) {
                fprintf(stderr, "cbvh sweep: --cache takes at most %d sizes\n", CBVH_CACHES_MAX);
                return -1;
            }
            for (int k = 0; k < o->ncaches; k++)
                if (o->cache_kb[k] == kb) {
                    fprintf(stderr, "cbvh sweep: --cache: %s given twice\n", item);
                    return -1;
                }
            o->cache_kb[o->ncaches++] = kb;
        }
    return 0;
}

/* Test hook (docs/sweep.md): SETTING_INDEX:RAY_INDEX. */
static int parse_corrupt(const char *v, cbvh_sweep_opts *o) {
    long si, ri;
    char buf[64];
    snprintf(buf, sizeof buf, "%s", v);
    char *c = strchr(buf, ':');
    if (!c || (*c = 0, cbvh_parse_long(buf, 0, 100000, &si)) || cbvh_parse_long(c + 1, 0, 2000000000L, &ri)) {
        fprintf(stderr, "cbvh sweep: --test-corrupt expects SETTING:RAY, got '%s'\n", v);
        return -1;
    }
    o->corrupt_setting = (int)si;
    o->corrupt_ray = (uint64_t)ri;
    return 0;
}

static int set_scene(sweep_cli *c, const char *a) {
    if (c->scene) {
        fprintf(stderr, "cbvh sweep: more than one scene ('%s', '%s')\n", c->scene, a);
        return -1;
    }
    c->scene = a;
    return 0;
}

/* An option naming a directory: not empty.  0 or -1. */
static int directory(const char *opt, const char *v, const char **dst) {
    if (!v[0]) {
        fprintf(stderr, "cbvh sweep: %s expects a directory\n", opt);
        return -1;
    }
    *dst = v;
    return 0;
}

/* One option and its value ("" when missing: each option's own message). */
static int parse_option(int opt, const char *v, int argc, char **argv, sweep_cli *c) {
    cbvh_sweep_opts *o = &c->run;
    long n;
    switch (opt) {
    case OPT_JSON: c->json = 1; return 0;
    case OPT_ONE_SIDED: o->one_sided = 1; return 0;
    case OPT_BITS: return parse_bits(v, o);
    case OPT_MANT:
        if (list_again("--mant", &c->mant_given)) return -1;
        o->nmant = parse_list("--mant", v, argc, argv, CBVH_MANT_MIN, CBVH_MANT_MAX, o->mant, CBVH_SWEEP_MAX_LIST);
        return o->nmant < 0 ? -1 : 0;
    case OPT_MIN_SCALE:
        if (list_again("--min-scale", &c->ms_given)) return -1;
        o->nmin_scale = parse_list("--min-scale", v, argc, argv, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, o->min_scale, CBVH_SWEEP_MAX_LIST);
        return o->nmin_scale < 0 ? -1 : 0;
    case OPT_SPP:
        if (cbvh_parse_long(v, 1, 1024, &n)) {
            fprintf(stderr, "cbvh sweep: --spp expects an integer in 1..1024, got '%s'\n", v);
            return -1;
        }
        o->spp = (int)n;
        return 0;
    case OPT_KNEE:
        if (cbvh_parse_long(v, 0, 1000, &c->knee_pct)) {
            fprintf(stderr, "cbvh sweep: --knee expects a percentage in 0..1000, got '%s'\n", v);
            return -1;
        }
        return 0;
    case OPT_OUT: return directory("--out", v, &c->outdir);
    case OPT_HEATMAP:
        if (list_again("--heatmap", &c->heat_given)) return -1;
        return parse_heatmaps(v, argc, argv, c);
    case OPT_FORMATS:
        if (list_again("--formats", &c->formats_given)) return -1;
        return parse_formats(v, o);
    case OPT_BOX_UNIT:
        if (list_again("--box-unit", &c->unit_given)) return -1;
        return parse_box_units(v, o);
    case OPT_CACHE:
        if (list_again("--cache", &c->cache_given)) return -1;
        return parse_caches(v, argc, argv, o);
    case OPT_REPS:
        if (cbvh_parse_long(v, 1, CBVH_REPS_MAX, &n)) {
            fprintf(stderr, "cbvh sweep: --reps expects an integer in 1..%d, got '%s'\n", CBVH_REPS_MAX, v);
            return -1;
        }
        o->reps = (int)n;
        return 0;
    case OPT_TIMING:
        c->timing = v;
        return 0;
    case OPT_COST_TABLE: return directory("--cost-table", v, &c->cost_dir);
    default: /* OPT_TEST_CORRUPT */
        return parse_corrupt(v, o);
    }
}

/* 0: run; 1: --help printed; 2: bad input (one line printed). */
static int parse_options(int argc, char **argv, sweep_cli *c) {
    static const struct option lo[] = {{"help", no_argument, 0, 'h'},
                                       {"json", no_argument, 0, OPT_JSON},
                                       {"bits", required_argument, 0, OPT_BITS},
                                       {"mant", required_argument, 0, OPT_MANT},
                                       {"min-scale", required_argument, 0, OPT_MIN_SCALE},
                                       {"spp", required_argument, 0, OPT_SPP},
                                       {"knee", required_argument, 0, OPT_KNEE},
                                       {"out", required_argument, 0, OPT_OUT},
                                       {"heatmap", required_argument, 0, OPT_HEATMAP},
                                       {"one-sided", no_argument, 0, OPT_ONE_SIDED},
                                       {"formats", required_argument, 0, OPT_FORMATS},
                                       {"box-unit", required_argument, 0, OPT_BOX_UNIT},
                                       {"cache", required_argument, 0, OPT_CACHE},
                                       {"reps", required_argument, 0, OPT_REPS},
                                       {"cost-table", required_argument, 0, OPT_COST_TABLE},
                                       {"timing", required_argument, 0, OPT_TIMING},
                                       {"test-corrupt", required_argument, 0, OPT_TEST_CORRUPT},
                                       {0, 0, 0, 0}};
    memset(c, 0, sizeof *c);
    c->run = (cbvh_sweep_opts){
        .bits_lo = 3, .bits_hi = 10, .corrupt_setting = -1, .reps = 5, .texp = CBVH_RBI_TEXP_DEFAULT};
    c->cost_dir = cbvh_cost_dir();
    c->knee_pct = 10;
    int opt;
    optind = 0;
    opterr = 0;
    /* "-": the scene comes back in order (as 1), so that a list option can
     * take the arguments after its first value; ":": a missing value is ':' */
    while ((opt = getopt_long(argc, argv, "-:h", lo, NULL)) != -1) {
        int bad;
        if (opt == 'h') {
            usage(stdout);
            return 1;
        } else if (opt == 1)
            bad = set_scene(c, optarg);
        else if (opt == ':')
            bad = parse_option(optopt, "", argc, argv, c);
        else if (opt >= OPT_JSON)
            bad = parse_option(opt, optarg, argc, argv, c);
        else
            return cbvh_unknown_option("cbvh sweep", argv, optind);
        if (bad) return 2;
    }
    for (; optind < argc; optind++) /* after "--" */
        if (set_scene(c, argv[optind])) return 2;
    return 0;
}

/* Defaults, and the heat maps against what the sweep traces.  0 or 2. */
static int validate_options(sweep_cli *c) {
    cbvh_sweep_opts *o = &c->run;
    if (!c->scene) {
        fprintf(stderr, "cbvh sweep: no scene file given (see cbvh sweep --help)\n");
        return 2;
    }
    if (!o->nmant) o->mant[o->nmant++] = CBVH_MANT_MAX;
    if (!o->nbox_unit) o->box_unit[o->nbox_unit++] = CBVH_FORMAT_BOX_EXACT;
    if (!o->ncaches) o->cache_kb[o->ncaches++] = 64;
    c->reps.reps = o->reps;
    if (!o->nmin_scale) o->min_scale[o->nmin_scale++] = CBVH_MIN_SCALE_DEFAULT;
    if (!c->heat_given) {
        c->heat[c->nheat++] = (heat_spec){.is_float = 1};
        static const int def[] = {3, 6, 10};
        for (int k = 0; k < 3; k++)
            if (def[k] >= o->bits_lo && def[k] <= o->bits_hi) c->heat[c->nheat++] = (heat_spec){.bits = def[k]};
        for (int k = 0; k < o->nextra && c->nheat < MAX_HEAT; k++) c->heat[c->nheat++] = (heat_spec){.xf = k + 1};
    }
    /* Every heat-map setting must be one the sweep traces. */
    for (int h = 0; h < c->nheat; h++) {
        heat_spec *s = &c->heat[h];
        if (s->is_float || s->xf) continue;
        if (s->fmt[0]) {
            for (int k = 0; k < o->nextra; k++)
                if (strcmp(o->extra[k].name, s->fmt) == 0) s->xf = k + 1;
            if (!s->xf) {
                fprintf(stderr, "cbvh sweep: --heatmap %s needs --formats cbvh,%s\n", s->fmt, s->fmt);
                return 2;
            }
            continue;
        }
        if (!s->explicit_all) {
            s->mant = o->mant[0];
            s->min_scale = o->min_scale[0];
        }
        int inm = 0, ine = 0;
        for (int k = 0; k < o->nmant; k++) inm |= o->mant[k] == s->mant;
        for (int k = 0; k < o->nmin_scale; k++) ine |= o->min_scale[k] == s->min_scale;
        if (s->bits < o->bits_lo || s->bits > o->bits_hi || !inm || !ine) {
            fprintf(stderr, "cbvh sweep: --heatmap %d:%d:%d is not a setting of this sweep\n", s->bits, s->mant,
                    s->min_scale);
            return 2;
        }
    }
    /* The same map twice (also "6" and "6:24:-30") would be drawn twice. */
    for (int h = 0; h < c->nheat; h++)
        for (int g = 0; g < h; g++) {
            const heat_spec *s = &c->heat[h], *t = &c->heat[g];
            if (s->is_float != t->is_float || s->xf != t->xf ||
                (!s->is_float && !s->xf &&
                 (s->bits != t->bits || s->mant != t->mant || s->min_scale != t->min_scale)))
                continue;
            if (s->is_float)
                fprintf(stderr, "cbvh sweep: --heatmap: float given twice\n");
            else if (s->xf)
                fprintf(stderr, "cbvh sweep: --heatmap: %s given twice\n", o->extra[s->xf - 1].name);
            else
                fprintf(stderr, "cbvh sweep: --heatmap: setting %d:%d:%d given twice\n", s->bits, s->mant,
                        s->min_scale);
            return 2;
        }
    if (!c->outdir) {
        default_out(c->scene, c->outbuf, sizeof c->outbuf);
        c->outdir = c->outbuf;
    }
    return 0;
}

/* The number of settings the sweep traces: box unit x M x E x N, then the other formats. */
static int settings_count(const cbvh_sweep_opts *o) {
    return (o->bits_hi - o->bits_lo + 1) * o->nmant * o->nmin_scale * o->nbox_unit + o->nextra;
}

/* The checks that need the scene (the test hook's setting) and --out, before
 * anything is traced.  0 or 2. */
static int validate_run(const sweep_cli *c) {
    if (c->run.corrupt_setting >= settings_count(&c->run)) {
        fprintf(stderr, "cbvh sweep: --test-corrupt setting %d: the sweep has %d settings\n", c->run.corrupt_setting,
                settings_count(&c->run));
        return 2;
    }
    return ensure_dir(c->outdir) || check_writable(c->outdir) ? 2 : 0;
}

/* ---- compute: the sweep and the figures derived from it ------------------- */

typedef struct {
    cbvh_timing_params tp;
    cbvh_cost_table table;
    cbvh_sweep_result res;
    cbvh_fx_stats ftot; /* the float BVH's totals over effects */
    int nb, ncombo;     /* values of N; combinations box unit x M x E */
    int *bits;          /* the nb values of N */
    double *relv;       /* [metric * nrows + row]: total cost relative to the float BVH (first cache) */
    double tol;         /* the knee tolerance, a fraction */
    /* knee[c][m] for the four modelled metrics (CPU time is noisy: not a knee) */
    int knee[CBVH_BOX_UNITS * CBVH_SWEEP_MAX_LIST * CBVH_SWEEP_MAX_LIST][4];
    /* The timing model: configuration k = 0 the float BVH, 1..nrows the
     * settings, then the other formats; at each cache c. */
    int ncfg, ncaches;
    cbvh_config_model *cm;  /* [k] */
    cbvh_ray_metrics *tot;  /* [k * ncaches + c]: totals over effects */
    int *pareto;            /* [k * ncaches + c]: on the front of (time, energy, area) over all k and c */
    int best[CBVH_CACHES_MAX][CBVH_FX_COUNT + 1]; /* fastest k per cache, per effect ([CBVH_FX_COUNT]: total) */
    int best_cbvh[CBVH_CACHES_MAX];               /* fastest CBVH setting (k >= 1), total */
} sweep_figures;

static const cbvh_sweep_run_t *cfg_run(const cbvh_sweep_result *res, int k) {
    return k == 0 ? &res->ref : k <= res->nrows ? &res->rows[k - 1] : &res->extra[k - 1 - res->nrows];
}

/* The timing model of every configuration at every cache size: machines,
 * totals, the Pareto front and the fastest per cache and effect.  0 or -1. */
static int model_figures(const sweep_cli *c, const cbvh_scene_desc *d, sweep_figures *f, char *err, size_t errlen) {
    const cbvh_sweep_result *res = &f->res;
    f->ncfg = 1 + res->nrows + res->nextra;
    f->ncaches = c->run.ncaches;
    size_t npt = (size_t)f->ncfg * (size_t)f->ncaches;
    f->cm = calloc((size_t)f->ncfg, sizeof *f->cm);
    f->tot = calloc(npt, sizeof *f->tot);
    f->pareto = calloc(npt, sizeof *f->pareto);
    double (*cost)[3] = calloc(npt, sizeof *cost);
    double *v = calloc((size_t)f->ncfg, sizeof *v);
    if (!f->cm || !f->tot || !f->pareto || !cost || !v) cbvh_out_of_memory("sweep model figures");
    int rc = 0;
    for (int k = 0; k < f->ncfg && !rc; k++) {
        const cbvh_sweep_run_t *r = cfg_run(res, k);
        rc = cbvh_config_model_init(&f->cm[k], &r->r, &f->table, &f->tp, cbvh_box_units[r->s.box_unit].cost_unit,
                                    r->s.bits ? r->s.bits : CBVH_N_DEFAULT, r->s.mant, err, errlen);
        cbvh_fx_stats t = cbvh_fx_total(&r->r);
        for (int ci = 0; ci < f->ncaches && !rc; ci++) {
            cbvh_ray_metrics *m = &f->tot[(size_t)k * f->ncaches + ci];
            cbvh_ray_metrics_of(&t, &f->cm[k].mc[ci], m);
            cost[(size_t)k * f->ncaches + ci][0] = m->model_ns;
            cost[(size_t)k * f->ncaches + ci][1] = m->energy_nj;
            cost[(size_t)k * f->ncaches + ci][2] = m->area_lut4;
        }
    }
    if (!rc) {
        cbvh_pareto_front((const double(*)[3])cost, (int)npt, f->pareto);
        for (int ci = 0; ci < f->ncaches; ci++) {
            for (int e = 0; e <= CBVH_FX_COUNT; e++) {
                f->best[ci][e] = -1;
                if (e < CBVH_FX_COUNT && !d->effect[e].enabled) continue;
                for (int k = 0; k < f->ncfg; k++) {
                    const cbvh_sweep_run_t *r = cfg_run(res, k);
                    cbvh_ray_metrics m;
                    if (e == CBVH_FX_COUNT)
                        m = f->tot[(size_t)k * f->ncaches + ci];
                    else
                        cbvh_ray_metrics_of(&r->r.fx[e], &f->cm[k].mc[ci], &m);
                    v[k] = m.rays ? m.model_ns : NAN;
                }
                f->best[ci][e] = cbvh_argmin(v, f->ncfg);
            }
            for (int k = 0; k < f->ncfg; k++) v[k] = k >= 1 && k <= res->nrows ? f->tot[(size_t)k * f->ncaches + ci].model_ns : NAN;
            f->best_cbvh[ci] = cbvh_argmin(v, f->ncfg);
        }
    }
    free(cost);
    free(v);
    return rc;
}

static void free_figures(sweep_figures *f);

/* 0, or 2 with one line printed: the run could not be done (not a finding
 * about hits). */
static int compute(const sweep_cli *c, const cbvh_scene_desc *d, sweep_figures *f) {
    memset(f, 0, sizeof *f);
    cbvh_sweep_opts o = c->run;
    int tty = isatty(2);
    if (tty) {
        o.progress = progress;
        o.ctx = (void *)&c->reps;
    }
    cbvh_fx_timing(d, &f->tp);
    char err[1024];
    if (cbvh_timing_check(&f->tp, err, sizeof err) || (c->timing && cbvh_timing_set(&f->tp, c->timing, err, sizeof err))) {
        fprintf(stderr, "cbvh sweep: %s: %s\n", c->scene, err);
        return 2;
    }
    o.cache_ways = (int)f->tp.cache_ways;
    if (cbvh_cost_table_load(c->cost_dir, &f->table, err, sizeof err)) {
        fprintf(stderr, "cbvh sweep: %s\n", err);
        return 2;
    }
    if (cbvh_sweep_run(d, &o, &f->res, err, sizeof err)) {
        if (tty) fprintf(stderr, "\n");
        fprintf(stderr, "cbvh sweep: %s: %s\n", c->scene, err);
        cbvh_cost_table_free(&f->table);
        return 2;
    }
    if (tty) fprintf(stderr, "\r%78s\r", "");
    if (model_figures(c, d, f, err, sizeof err)) {
        fprintf(stderr, "cbvh sweep: %s\n", err);
        free_figures(f);
        return 2;
    }

    /* Relative totals per setting, for the knee and the chart (first cache). */
    const cbvh_sweep_result *res = &f->res;
    f->tol = (double)c->knee_pct / 100.0;
    f->nb = o.bits_hi - o.bits_lo + 1;
    f->ncombo = o.nbox_unit * o.nmant * o.nmin_scale;
    f->ftot = cbvh_fx_total(&res->ref.r);
    double fq[SWEEP_NMETRICS];
    cbvh_sweep_per_ray(&f->ftot, &f->cm[0].mc[0], fq);
    f->relv = calloc((size_t)res->nrows * SWEEP_NMETRICS, sizeof *f->relv);
    f->bits = calloc((size_t)f->nb, sizeof *f->bits);
    if (!f->relv || !f->bits) cbvh_out_of_memory("sweep chart data");
    for (int b = 0; b < f->nb; b++) f->bits[b] = o.bits_lo + b;
    for (int i = 0; i < res->nrows; i++) {
        cbvh_fx_stats t = cbvh_fx_total(&res->rows[i].r);
        double p[SWEEP_NMETRICS];
        cbvh_sweep_per_ray(&t, &f->cm[1 + i].mc[0], p);
        for (int m = 0; m < SWEEP_NMETRICS; m++) f->relv[(size_t)m * res->nrows + i] = cbvh_ratio(p[m], fq[m]);
    }
    for (int k = 0; k < f->ncombo; k++)
        for (int m = 0; m < 4; m++)
            f->knee[k][m] = cbvh_sweep_knee(f->bits, &f->relv[(size_t)m * res->nrows + k * f->nb], f->nb, f->tol);
    return 0;
}

static void free_figures(sweep_figures *f) {
    free(f->bits);
    free(f->relv);
    free(f->cm);
    free(f->tot);
    free(f->pareto);
    cbvh_cost_table_free(&f->table);
    cbvh_sweep_free(&f->res);
}

/* ---- write: charts, heat maps, image; then the table or the JSON ---------- */

/* The files written to --out, and the first one that could not be. */
typedef struct {
    char written[MAX_FILES][2100];
    int nwritten, nfailed;
    char failed[1100];
    double heat_max; /* the heat maps' common colour scale: 0 .. heat_max box tests */
    double diff_max; /* the largest |extra tests| of a pixel in any difference map (each has its own scale) */
} sweep_files;

static void file_done(sweep_files *w, const char *path, int failed, const char *err) {
    if (failed) {
        if (!w->nfailed++) snprintf(w->failed, sizeof w->failed, "%s", err);
    } else if (w->nwritten < MAX_FILES)
        snprintf(w->written[w->nwritten++], sizeof w->written[0], "%s", path);
}

/* After a CBVH setting's name when the sweep runs several box units: " " and
 * the unit's name (unit_sep, unit_name); else "" and "". */
static const char *unit_sep(const sweep_cli *c) { return c->run.nbox_unit > 1 ? " " : ""; }
static const char *unit_name(const sweep_cli *c, int box_unit) {
    return c->run.nbox_unit > 1 ? cbvh_box_units[box_unit].name : "";
}
/* Whether the incremental unit is among the box units. */
static int has_incremental(const sweep_cli *c) {
    for (int u = 0; u < c->run.nbox_unit; u++)
        if (c->run.box_unit[u] == CBVH_FORMAT_BOX_INCREMENTAL) return 1;
    return 0;
}

/* The table's name of configuration k (0 = the float BVH). */
static const char *cfg_name(const sweep_cli *c, const cbvh_sweep_result *res, int k, char *name, size_t n) {
    const cbvh_sweep_run_t *r = cfg_run(res, k);
    if (k == 0)
        snprintf(name, n, "float");
    else if (k > res->nrows)
        cbvh_sweep_format_label(&c->run.extra[k - 1 - res->nrows], r->s.mant, name, n);
    else
        snprintf(name, n, "N=%d M=%d E=%d%s%s", r->s.bits, r->s.mant, r->s.min_scale, unit_sep(c),
                 unit_name(c, r->s.box_unit));
    return name;
}


/* time-*.svg and energy-*.svg: the model's time and energy per ray against N,
 * one line per box unit and M (the first 11) and one for the float BVH, per
 * min scale and cache size. */
static void write_model_charts(const sweep_cli *c, const cbvh_scene_desc *d, const sweep_figures *f, sweep_files *w,
                               const double *x) {
    const cbvh_sweep_opts *o = &c->run;
    const char *mesh = strrchr(d->mesh_spec, '/');
    mesh = mesh ? mesh + 1 : d->mesh_spec;
    int nm = o->nbox_unit * o->nmant; /* series: each box unit, each M */
    nm = nm < 11 ? nm : 11;           /* 12 series at most: those and the float BVH */
    double *y = calloc((size_t)(nm + 1) * f->nb, sizeof *y);
    char (*names)[32] = calloc((size_t)nm + 1, sizeof *names);
    if (!y || !names) cbvh_out_of_memory("sweep model charts");
    for (int e = 0; e < o->nmin_scale; e++)
        for (int ci = 0; ci < f->ncaches; ci++)
            for (int q = 0; q < 2; q++) { /* 0: time, 1: energy */
                cbvh_svg_series ser[12];
                for (int mi = 0; mi < nm; mi++) { /* mi = unit * nmant + M's index */
                    snprintf(names[mi], sizeof names[mi], "CBVH M=%d%s%s", o->mant[mi % o->nmant], unit_sep(c),
                             unit_name(c, o->box_unit[mi / o->nmant]));
                    for (int b = 0; b < f->nb; b++) {
                        int row = (mi * o->nmin_scale + e) * f->nb + b; /* rows: each unit, M, E, N ascending */
                        const cbvh_ray_metrics *m = &f->tot[(size_t)(1 + row) * f->ncaches + ci];
                        y[(size_t)mi * f->nb + b] = q ? m->energy_nj : m->model_ns;
                    }
                    ser[mi] = (cbvh_svg_series){names[mi], &y[(size_t)mi * f->nb]};
                }
                snprintf(names[nm], sizeof names[nm], "float BVH");
                for (int b = 0; b < f->nb; b++)
                    y[(size_t)nm * f->nb + b] = q ? f->tot[ci].energy_nj : f->tot[ci].model_ns;
                ser[nm] = (cbvh_svg_series){names[nm], &y[(size_t)nm * f->nb]};
                int ok = 1;
                for (size_t i = 0; i < (size_t)(nm + 1) * f->nb; i++) ok &= isfinite(y[i]) != 0;
                if (!ok) continue;
                char tag[32], cn[32], path[2048], title[1400], err[1024];
                cbvh_cache_name_unit(o->cache_kb[ci], "", tag, sizeof tag);
                if (o->nmin_scale == 1)
                    snprintf(path, sizeof path, "%s/%s-C%s.svg", c->outdir, q ? "energy" : "time", tag);
                else
                    snprintf(path, sizeof path, "%s/%s-E%d-C%s.svg", c->outdir, q ? "energy" : "time",
                             o->min_scale[e], tag);
                char units[64] = ""; /* "exact", "exact and incremental" */
                for (int u = 0; u < o->nbox_unit; u++)
                    snprintf(units + strlen(units), sizeof units - strlen(units), "%s%s", u ? " and " : "",
                             cbvh_box_units[o->box_unit[u]].name);
                snprintf(title, sizeof title, "%s: modelled %s per ray, cache %s, min scale %d, %s box unit%s", mesh,
                         q ? "energy" : "time", cbvh_cache_name(o->cache_kb[ci], cn, sizeof cn), o->min_scale[e],
                         units, o->nbox_unit > 1 ? "s" : "");
                int bad = cbvh_svg_chart(path, title, "coordinate bits N", q ? "nJ per ray" : "ns per ray", x,
                                         (size_t)f->nb, ser, (size_t)nm + 1, err, sizeof err);
                file_done(w, path, bad, err);
            }
    free(y);
    free(names);
}

/* The setting of heat map h: its configuration. */
static const cbvh_sweep_run_t *heat_run(const sweep_cli *c, const cbvh_sweep_result *res, const heat_spec *hs) {
    if (hs->xf) return &res->extra[hs->xf - 1];
    if (!hs->is_float)
        for (int i = 0; i < res->nrows; i++)
            if (res->rows[i].s.bits == hs->bits && res->rows[i].s.mant == hs->mant &&
                res->rows[i].s.min_scale == hs->min_scale && res->rows[i].s.box_unit == c->run.box_unit[0])
                return &res->rows[i]; /* several box units: the first one's */
    return &res->ref;
}

static void heat_label(const sweep_cli *c, const heat_spec *hs, char *out, size_t n) {
    if (hs->is_float)
        snprintf(out, n, "float BVH");
    else if (hs->xf)
        snprintf(out, n, "%s", c->run.extra[hs->xf - 1].name);
    else
        snprintf(out, n, "CBVH N=%d M=%d E=%d%s%s", hs->bits, hs->mant, hs->min_scale, unit_sep(c),
                 unit_name(c, c->run.box_unit[0]));
}

static void heat_path(const sweep_cli *c, const heat_spec *hs, const char *prefix, char *path, size_t n) {
    if (hs->is_float)
        snprintf(path, n, "%s/%s-float.png", c->outdir, prefix);
    else if (hs->xf) {
        char fn[48];
        snprintf(fn, sizeof fn, "%s", c->run.extra[hs->xf - 1].name);
        for (char *p = fn; *p; p++)
            if (*p == ':') *p = '-';
        snprintf(path, n, "%s/%s-%s.png", c->outdir, prefix, fn);
    } else if (hs->explicit_all)
        snprintf(path, n, "%s/%s-N%d-M%d-E%d.png", c->outdir, prefix, hs->bits, hs->mant, hs->min_scale);
    else
        snprintf(path, n, "%s/%s-N%d.png", c->outdir, prefix, hs->bits);
}

/* heat-*.png: box tests per pixel on one colour scale; diff-*.png: extra box
 * and triangle tests per pixel against the float BVH, on one symmetric scale. */
static void write_heat_maps(const sweep_cli *c, const cbvh_scene_desc *d, const sweep_figures *f, sweep_files *w) {
    const cbvh_sweep_result *res = &f->res;
    const cbvh_sweep_run_t *hr[MAX_HEAT];
    size_t npx = (size_t)res->width * (size_t)res->height;
    double vmax = 0, dmax = 0;
    double *diff = calloc(npx, sizeof *diff);
    if (!diff) cbvh_out_of_memory("difference heat map");
    for (int h = 0; h < c->nheat; h++) {
        hr[h] = heat_run(c, res, &c->heat[h]);
        for (size_t p = 0; p < npx; p++) {
            if (hr[h]->box_px[p] > vmax) vmax = hr[h]->box_px[p];
            double x = fabs(hr[h]->box_px[p] + hr[h]->tri_px[p] - res->ref.box_px[p] - res->ref.tri_px[p]);
            if (!c->heat[h].is_float && x > dmax) dmax = x;
        }
    }
    if (!(vmax > 0)) vmax = 1;
    if (!(dmax > 0)) dmax = 1;
    w->heat_max = vmax;
    w->diff_max = dmax;
    const char *mesh = strrchr(d->mesh_spec, '/');
    mesh = mesh ? mesh + 1 : d->mesh_spec;
    char path[2048], title[1300], what[96], err[1024];
    for (int h = 0; h < c->nheat; h++) {
        const heat_spec *hs = &c->heat[h];
        heat_label(c, hs, what, sizeof what);
        heat_path(c, hs, "heat", path, sizeof path);
        snprintf(title, sizeof title, "%s: box tests per pixel, %s", mesh, what);
        cbvh_heatmap_style st = {title, "box tests per primary-ray pixel (frame 0, mean over samples)", 0, vmax, 0,
                                 512};
        file_done(w, path,
                  cbvh_heatmap_png(path, hr[h]->box_px, (unsigned)res->width, (unsigned)res->height, &st, NULL, err,
                                   sizeof err),
                  err);
        if (hs->is_float) continue;
        double dm = 0;
        for (size_t p = 0; p < npx; p++) {
            diff[p] = hr[h]->box_px[p] + hr[h]->tri_px[p] - res->ref.box_px[p] - res->ref.tri_px[p];
            if (fabs(diff[p]) > dm) dm = fabs(diff[p]);
        }
        heat_path(c, hs, "diff", path, sizeof path);
        snprintf(title, sizeof title, "%s: extra tests per pixel, %s - float BVH", mesh, what);
        cbvh_heatmap_style ds = {title, "box + triangle tests per pixel, minus the float BVH's (red: more)",
                                 -(dm > 0 ? dm : 1), dm > 0 ? dm : 1, 1, 512};
        file_done(w, path,
                  cbvh_heatmap_png(path, diff, (unsigned)res->width, (unsigned)res->height, &ds, NULL, err,
                                   sizeof err),
                  err);
    }
    free(diff);
}

static void write_files(const sweep_cli *c, const cbvh_scene_desc *d, const sweep_figures *f, sweep_files *w) {
    const cbvh_sweep_result *res = &f->res;
    const char *outdir = c->outdir;
    char path[2048], title[1400], err[1024];
    memset(w, 0, sizeof *w);
    double *x = calloc((size_t)f->nb, sizeof *x);
    if (!x) cbvh_out_of_memory("sweep chart axis");
    for (int b = 0; b < f->nb; b++) x[b] = f->bits[b];
    for (int k = 0; k < f->ncombo && w->nwritten < 8; k++) {
        const cbvh_sweep_setting *s = &res->rows[k * f->nb].s;
        if (f->ncombo == 1)
            snprintf(path, sizeof path, "%s/cost.svg", outdir);
        else
            snprintf(path, sizeof path, "%s/cost-M%d-E%d%s%s.svg", outdir, s->mant, s->min_scale,
                     c->run.nbox_unit > 1 ? "-" : "", unit_name(c, s->box_unit));
        const char *mesh = strrchr(d->mesh_spec, '/');
        snprintf(title, sizeof title, "%s: cost relative to the float BVH (M=%d, min scale %d%s%s%s)",
                 mesh ? mesh + 1 : d->mesh_spec, s->mant, s->min_scale, c->run.nbox_unit > 1 ? ", " : "",
                 unit_name(c, s->box_unit), c->run.nbox_unit > 1 ? " box unit" : "");
        /* Only the costs with a ratio (knee 0: the float BVH did none of it). */
        cbvh_svg_series ser[4];
        int nser = 0;
        for (int m = 0; m < 4; m++)
            if (f->knee[k][m])
                ser[nser++] = (cbvh_svg_series){metric_names[m], &f->relv[(size_t)m * res->nrows + k * f->nb]};
        if (!nser) continue;
        int bad = cbvh_svg_chart(path, title, "coordinate bits N", "cost / float BVH", x, (size_t)f->nb, ser,
                                 (size_t)nser, err, sizeof err);
        file_done(w, path, bad, err);
    }
    write_model_charts(c, d, f, w, x);
    free(x);
    write_heat_maps(c, d, f, w);
    snprintf(path, sizeof path, "%s/render-float.png", outdir);
    int bad = cbvh_png_write(path, res->ref.image, (unsigned)res->width, (unsigned)res->height, 1, err, sizeof err);
    file_done(w, path, bad, err);
}

/* The "effects" and "total" of configuration k against the float BVH's. */
static void json_effects(cJSON *o, const cbvh_scene_desc *d, const sweep_figures *f, int k) {
    const cbvh_sweep_run_t *ref = &f->res.ref, *r = cfg_run(&f->res, k);
    cJSON *ef = cJSON_AddObjectToObject(o, "effects");
    for (int e = 0; e < CBVH_FX_COUNT; e++)
        if (d->effect[e].enabled)
            cJSON_AddItemToObject(ef, cbvh_effect_name((cbvh_effect)e),
                                  json_costs(&r->r.fx[e], &ref->r.fx[e], r->r.node_bytes, ref->r.node_bytes, &f->cm[k],
                                             &f->cm[0]));
    cbvh_fx_stats t = cbvh_fx_total(&r->r);
    cJSON_AddItemToObject(o, "total", json_costs(&t, &f->ftot, r->r.node_bytes, ref->r.node_bytes, &f->cm[k], &f->cm[0]));
    cJSON_AddStringToObject(o, "box_unit", cbvh_box_units[r->s.box_unit].name);
    cJSON_AddNumberToObject(o, "area_lut4", f->tot[(size_t)k * f->ncaches].area_lut4);
    cJSON *pa = cJSON_AddArrayToObject(o, "pareto");
    for (int ci = 0; ci < f->ncaches; ci++) cJSON_AddItemToArray(pa, cJSON_CreateBool(f->pareto[(size_t)k * f->ncaches + ci]));
}

static void json_machine(cJSON *root, const sweep_cli *c, const sweep_figures *f) {
    cJSON *tj = cJSON_AddObjectToObject(root, "timing");
    cbvh_timing_json(tj, &f->tp, c->cost_dir);
    cJSON *ca = cJSON_AddArrayToObject(tj, "caches_kb");
    for (int ci = 0; ci < f->ncaches; ci++)
        cJSON_AddItemToArray(ca, isfinite(c->run.cache_kb[ci]) ? cJSON_CreateNumber(c->run.cache_kb[ci]) : cJSON_CreateNull());
    cJSON_AddNumberToObject(tj, "cpu_reps", c->run.reps);
    cJSON *un = cJSON_AddObjectToObject(tj, "units");
    const cbvh_timing_units *fu = &f->cm[0].mc[0].units;
    cJSON_AddItemToObject(un, "box", cbvh_unit_json(&fu->node));
    cJSON_AddItemToObject(un, "triangle", cbvh_unit_json(&fu->tri));
    if (f->res.nrows) {
        cJSON *dec = cJSON_AddArrayToObject(un, "decoder");
        for (int b = 0; b < f->nb; b++) cJSON_AddItemToArray(dec, cbvh_unit_json(&f->cm[1 + b].mc[0].units.dec));
    }
}

static void json_best(cJSON *root, const sweep_cli *c, const cbvh_scene_desc *d, const sweep_figures *f) {
    cJSON *bj = cJSON_AddArrayToObject(root, "best");
    char name[64];
    for (int ci = 0; ci < f->ncaches; ci++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(bj, o);
        json_rel(o, "cache_kb", c->run.cache_kb[ci]);
        for (int e = 0; e <= CBVH_FX_COUNT; e++) {
            int k = f->best[ci][e];
            if (k < 0) continue;
            cJSON_AddStringToObject(o, e == CBVH_FX_COUNT ? "total" : cbvh_effect_name((cbvh_effect)e),
                                    cfg_name(c, &f->res, k, name, sizeof name));
        }
        int kb = f->best_cbvh[ci];
        if (kb > 0) {
            const cbvh_ray_metrics *b = &f->tot[(size_t)kb * f->ncaches + ci], *fl = &f->tot[ci];
            cJSON_AddStringToObject(o, "best_cbvh", cfg_name(c, &f->res, kb, name, sizeof name));
            json_rel(o, "best_cbvh_time_vs_float", cbvh_ratio(b->model_ns, fl->model_ns));
            json_rel(o, "best_cbvh_energy_vs_float", cbvh_ratio(b->energy_nj, fl->energy_nj));
        }
    }
    (void)d;
}

static void write_json(const sweep_cli *c, const cbvh_scene_desc *d, const sweep_figures *f, const sweep_files *w) {
    static const char *knee_keys[4] = {"box_tests", "tri_tests", "bytes", "model_time"};
    const cbvh_sweep_result *res = &f->res;
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scene", c->scene);
    cJSON_AddStringToObject(root, "mesh", d->mesh_spec);
    cJSON_AddNumberToObject(root, "triangles", d->mesh.ntris);
    cJSON_AddNumberToObject(root, "width", res->width);
    cJSON_AddNumberToObject(root, "height", res->height);
    cJSON_AddNumberToObject(root, "spp", res->spp);
    cJSON_AddNumberToObject(root, "frames", res->frames);
    cJSON_AddNumberToObject(root, "rays", (double)res->ref_rays);
    int incr = has_incremental(c);
    cJSON *bu = cJSON_AddArrayToObject(root, "box_units");
    for (int u = 0; u < c->run.nbox_unit; u++)
        cJSON_AddItemToArray(bu, cJSON_CreateString(cbvh_box_units[c->run.box_unit[u]].name));
    if (c->run.nbox_unit == 1 && incr) cJSON_AddStringToObject(root, "box_unit", "incremental");
    if (incr) cJSON_AddNumberToObject(root, "texp", c->run.texp);
    json_machine(root, c, f);
    cJSON *fl = cJSON_AddObjectToObject(root, "float");
    cJSON_AddNumberToObject(fl, "node_bytes", (double)res->ref.r.node_bytes);
    json_effects(fl, d, f, 0);
    cJSON *rows = cJSON_AddArrayToObject(root, "settings");
    for (int i = 0; i < res->nrows; i++) {
        const cbvh_sweep_run_t *r = &res->rows[i];
        cJSON *row = cJSON_CreateObject();
        cJSON_AddNumberToObject(row, "bits", r->s.bits);
        cJSON_AddNumberToObject(row, "mant", r->s.mant);
        cJSON_AddNumberToObject(row, "min_scale", r->s.min_scale);
        cJSON_AddNumberToObject(row, "node_bytes", (double)r->r.node_bytes);
        cJSON_AddBoolToObject(row, "same_hits", r->same);
        if (!r->same) cJSON_AddStringToObject(row, "first_difference", r->why);
        if (r->s.box_unit == CBVH_FORMAT_BOX_INCREMENTAL) { /* totals over the effects */
            cbvh_fx_stats t = cbvh_fx_total(&r->r);
            cJSON_AddNumberToObject(row, "fp_box_hits", (double)t.st.fp_box_hits);
            cJSON_AddNumberToObject(row, "fp_tri_tests", (double)t.st.fp_tri_tests);
        }
        json_effects(row, d, f, 1 + i);
        cJSON_AddItemToArray(rows, row);
    }
    cJSON *fj = res->nextra ? cJSON_AddArrayToObject(root, "formats") : NULL;
    for (int k = 0; k < res->nextra; k++) {
        const cbvh_sweep_run_t *r = &res->extra[k];
        cJSON *qj = cJSON_CreateObject();
        cJSON_AddItemToArray(fj, qj);
        cJSON_AddStringToObject(qj, "format", c->run.extra[k].name);
        cJSON_AddNumberToObject(qj, "mant", r->s.mant);
        cJSON_AddNumberToObject(qj, "node_bytes", (double)r->r.node_bytes);
        cJSON_AddNumberToObject(qj, "qbvh_stack", (double)r->r.units.qbvh_stack);
        cJSON_AddNumberToObject(qj, "ray_sphere", (double)r->r.units.ray_sphere);
        cJSON_AddBoolToObject(qj, "same_hits", r->same);
        if (!r->same) cJSON_AddStringToObject(qj, "first_difference", r->why);
        json_effects(qj, d, f, 1 + res->nrows + k);
    }
    cJSON *kn = cJSON_AddArrayToObject(root, "knee");
    for (int k = 0; k < f->ncombo; k++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "box_unit", cbvh_box_units[res->rows[k * f->nb].s.box_unit].name);
        cJSON_AddNumberToObject(o, "mant", res->rows[k * f->nb].s.mant);
        cJSON_AddNumberToObject(o, "min_scale", res->rows[k * f->nb].s.min_scale);
        cJSON_AddNumberToObject(o, "tolerance", f->tol);
        cJSON_AddNumberToObject(o, "reference_bits", c->run.bits_hi);
        for (int m = 0; m < 4; m++)
            if (f->knee[k][m])
                cJSON_AddNumberToObject(o, knee_keys[m], f->knee[k][m]);
            else
                cJSON_AddNullToObject(o, knee_keys[m]); /* no ratio: the float BVH did none */
        cJSON_AddItemToArray(kn, o);
    }
    json_best(root, c, d, f);
    cJSON_AddBoolToObject(root, "same_hits", res->all_same);
    cJSON_AddNumberToObject(root, "heatmap_max_box_tests", w->heat_max);
    cJSON_AddNumberToObject(root, "diffmap_max_extra_tests", w->diff_max);
    cJSON *wr = cJSON_AddArrayToObject(root, "files");
    for (int k = 0; k < w->nwritten; k++) cJSON_AddItemToArray(wr, cJSON_CreateString(w->written[k]));
    cbvh_json_print(root, stdout);
    cJSON_Delete(root);
}

/* "What accuracy costs in time": every configuration at every cache size. */
static void write_model_text(const sweep_cli *c, const cbvh_scene_desc *d, const sweep_figures *f) {
    const cbvh_sweep_result *res = &f->res;
    char line[400], name[64], cn[32];
    cbvh_machine_line(&f->tp, line, sizeof line);
    printf("\nWhat accuracy costs in time (timing model, docs/timing_model.md): %s\n", line);
    printf("%-28s %-11s %7s %9s %8s %10s %9s %6s %6s %6s %-13s %-20s | %7s %7s %7s  %s\n", "setting", "box", "cache",
           "ns/ray", "nJ/ray", "area LUT4", "DRAM B/r", "hit %", "fp box", "fp tri", "bound", "CPU us/ray [min-max]",
           "time", "energy", "area", "P");
    printf("%-28s %-11s %7s %9s %8s %10s %9s %6s %6s %6s %-13s %-20s | %25s\n", "", "unit", "", "", "", "", "", "", "",
           "", "", "", "x the float BVH (same cache)");
    for (int k = 0; k < f->ncfg; k++) {
        const cbvh_sweep_run_t *r = cfg_run(res, k);
        cfg_name(c, res, k, name, sizeof name);
        cbvh_fx_stats t = cbvh_fx_total(&r->r);
        int sphere = t.ops.ray_sphere > 0;
        for (int ci = 0; ci < f->ncaches; ci++) {
            const cbvh_ray_metrics *m = &f->tot[(size_t)k * f->ncaches + ci], *fl = &f->tot[ci];
            char cpu[40], fpb[16], fpt[16];
            snprintf(cpu, sizeof cpu, "%.2f [%.2f-%.2f]", m->cpu_us, m->cpu_lo, m->cpu_hi);
            snprintf(fpb, sizeof fpb, "%.2f", m->fp_box);
            snprintf(fpt, sizeof fpt, "%.2f", m->fp_tri);
            printf("%-28s %-11s %7s %9.1f %8.3f %10.0f %9.1f %6.1f %6s %6s %-13s %-20s |", name,
                   sphere ? "sphere" : cbvh_box_units[r->s.box_unit].name,
                   cbvh_cache_name(c->run.cache_kb[ci], cn, sizeof cn), m->model_ns, m->energy_nj, m->area_lut4,
                   m->dram_bytes, 100.0 * m->hit_rate, sphere ? "-" : fpb, sphere ? "-" : fpt,
                   cbvh_timing_bound_name(m->bound), cpu);
            print_rel(cbvh_ratio(m->model_ns, fl->model_ns));
            print_rel(cbvh_ratio(m->energy_nj, fl->energy_nj));
            print_rel(cbvh_ratio(m->area_lut4, fl->area_lut4));
            printf("  %s\n", f->pareto[(size_t)k * f->ncaches + ci] ? "*" : "");
        }
    }
    printf("P * = on the Pareto front of (time, energy, area) over every row and cache size. fp box / fp tri: false-"
           "positive box hits and the extra triangle tests they cause, per ray (those the incremental unit accepts and "
           "unit 6 at the same M rejects; none for the exact unit).\n");
    printf("fastest in modelled time (CPU time is the C model's own, not the accelerator's):\n");
    for (int ci = 0; ci < f->ncaches; ci++) {
        cbvh_cache_name(c->run.cache_kb[ci], cn, sizeof cn);
        for (int e = CBVH_FX_COUNT; e >= 0; e--) {
            int k = f->best[ci][e];
            if (k < 0) continue;
            const cbvh_sweep_run_t *r = cfg_run(res, k);
            cbvh_ray_metrics m, fm;
            if (e == CBVH_FX_COUNT) {
                m = f->tot[(size_t)k * f->ncaches + ci];
                fm = f->tot[ci];
            } else {
                cbvh_ray_metrics_of(&r->r.fx[e], &f->cm[k].mc[ci], &m);
                cbvh_ray_metrics_of(&res->ref.r.fx[e], &f->cm[0].mc[ci], &fm);
            }
            printf("  cache %-7s %-17s %-28s %9.1f ns/ray x%.3f, %8.3f nJ/ray x%.3f the float BVH's\n", cn,
                   e == CBVH_FX_COUNT ? "all effects:" : cbvh_effect_name((cbvh_effect)e),
                   cfg_name(c, res, k, name, sizeof name), m.model_ns, cbvh_ratio(m.model_ns, fm.model_ns),
                   m.energy_nj, cbvh_ratio(m.energy_nj, fm.energy_nj));
        }
        int kb = f->best_cbvh[ci];
        if (kb > 0) {
            const cbvh_ray_metrics *b = &f->tot[(size_t)kb * f->ncaches + ci], *fl = &f->tot[ci];
            printf("  cache %-7s best CBVH %s: time x%.3f, energy x%.3f, area x%.3f against the float BVH: CBVH %s\n",
                   cn, cfg_name(c, res, kb, name, sizeof name), cbvh_ratio(b->model_ns, fl->model_ns),
                   cbvh_ratio(b->energy_nj, fl->energy_nj), cbvh_ratio(b->area_lut4, fl->area_lut4),
                   b->model_ns < fl->model_ns ? "beats float in modelled time" : "does not beat float in modelled time");
        }
    }
    (void)d;
}

static void write_text(const sweep_cli *c, const cbvh_scene_desc *d, const sweep_figures *f, const sweep_files *w) {
    const cbvh_sweep_result *res = &f->res;
    int nb = f->nb;
    char cn[32];
    printf("scene %s: %s, %u triangles, %dx%d, %d spp, %d frame%s; %llu rays per setting\n", c->scene, d->mesh_spec,
           d->mesh.ntris, res->width, res->height, res->spp, res->frames, res->frames > 1 ? "s" : "",
           (unsigned long long)res->ref_rays);
    printf("model ns: the timing model at cache %s (docs/timing_model.md; every cache size below); CPU us: the "
           "median of %d timed repetitions\n\n",
           cbvh_cache_name(c->run.cache_kb[0], cn, sizeof cn), c->run.reps);
    printf("%-28s %-17s %8s %8s %7s %8s %9s %7s | %7s %7s %7s %7s %7s %7s  %s\n", "setting", "effect", "rays",
           "box/ray", "tri/ray", "B/ray", "model ns", "CPU us", "box", "tri", "bytes", "memory", "model", "CPU",
           "hits");
    printf("%-28s %-17s %8s %8s %7s %8s %9s %7s | %55s\n", "", "", "", "", "", "", "", "",
           "relative to the float BVH ----------------------------");
    char name[64];
    for (int k = 0; k < f->ncfg; k++) {
        const cbvh_sweep_run_t *r = cfg_run(res, k);
        cfg_name(c, res, k, name, sizeof name);
        const char *same = k == 0 ? "reference" : r->same ? "same" : "DIFFERENT";
        for (int e = 0; e < CBVH_FX_COUNT; e++)
            if (d->effect[e].enabled)
                text_row(name, cbvh_effect_name((cbvh_effect)e), &r->r.fx[e], &res->ref.r.fx[e], r->r.node_bytes,
                         res->ref.r.node_bytes, &f->cm[k].mc[0], &f->cm[0].mc[0], same);
        cbvh_fx_stats t = cbvh_fx_total(&r->r);
        text_row(name, "total", &t, &f->ftot, r->r.node_bytes, res->ref.r.node_bytes, &f->cm[k].mc[0],
                 &f->cm[0].mc[0], same);
    }
    if (has_incremental(c)) {
        printf("\nincremental box unit (X=%d) on the CBVH rows: false-positive box hits per ray (share of its box "
               "tests: unit 6 at the same M rejects them), triangle tests under them per ray (share), totals:\n",
               c->run.texp);
        for (int i = 0; i < res->nrows; i++) {
            if (res->rows[i].s.box_unit != CBVH_FORMAT_BOX_INCREMENTAL) continue;
            cbvh_fx_stats t = cbvh_fx_total(&res->rows[i].r);
            double n = t.rays ? (double)t.rays : 1.0;
            printf("  N=%d M=%d E=%d: %.2f (%.1f%%), %.2f (%.1f%%)\n", res->rows[i].s.bits, res->rows[i].s.mant,
                   res->rows[i].s.min_scale, (double)t.st.fp_box_hits / n,
                   100.0 * cbvh_ratio((double)t.st.fp_box_hits, (double)t.st.box_tests),
                   (double)t.st.fp_tri_tests / n, 100.0 * cbvh_ratio((double)t.st.fp_tri_tests, (double)t.st.tri_tests));
        }
    }
    printf("\nnode memory: float BVH %llu B", (unsigned long long)res->ref.r.node_bytes);
    for (int b = 0; b < nb; b++)
        printf(", N=%d %llu B", res->rows[b].s.bits, (unsigned long long)res->rows[b].r.node_bytes);
    for (int k = 0; k < res->nextra; k++)
        printf(", %s %llu B", c->run.extra[k].name, (unsigned long long)res->extra[k].r.node_bytes);
    printf("\n");
    printf("knee = smallest N from which every finer N costs at most %ld%% more than N=%d (totals over effects):\n",
           c->knee_pct, c->run.bits_hi);
    int no_knee = 0;
    for (int k = 0; k < f->ncombo; k++) {
        printf("  M=%d E=%d%s%s:", res->rows[k * nb].s.mant, res->rows[k * nb].s.min_scale, unit_sep(c),
               unit_name(c, res->rows[k * nb].s.box_unit));
        for (int m = 0; m < 4; m++) {
            if (f->knee[k][m])
                printf("%s %s N=%d", m ? "," : "", metric_names[m], f->knee[k][m]);
            else
                printf("%s %s -", m ? "," : "", metric_names[m]);
            no_knee |= !f->knee[k][m];
        }
        printf("\n");
    }
    if (no_knee) printf("  (-: the float BVH did none of it, so there is no ratio and no knee)\n");
    for (int k = 0; k < f->ncombo; k++)
        for (int b = 0; b < nb; b++)
            if (f->bits[b] == 6 && res->rows[k * nb].s.mant == CBVH_MANT_MAX) {
                printf("paper (Viitanen et al., CBVH at N=6): box tests x1.08, triangle tests x1.13; here (M=%d "
                       "E=%d%s%s): box tests",
                       res->rows[k * nb].s.mant, res->rows[k * nb].s.min_scale, unit_sep(c),
                       unit_name(c, res->rows[k * nb].s.box_unit));
                print_x(f->relv[(size_t)SWEEP_BOX * res->nrows + k * nb + b]);
                printf(", triangle tests");
                print_x(f->relv[(size_t)SWEEP_TRI * res->nrows + k * nb + b]);
                printf("\n");
            }
    write_model_text(c, d, f);
    char others[CBVH_FORMAT_NAME_MAX + 16];
    if (res->all_same)
        printf("hits: all %d settings%s%s return the float BVH's hits on all %llu rays (same triangle and t bits; no "
               "false misses) and render the same %dx%d image\n",
               res->nrows, cbvh_sweep_others(c->run.extra, res->nextra, others, sizeof others),
               c->run.one_sided ? " (one-sided)" : "", (unsigned long long)res->ref_rays, res->width, res->height);
    else {
        for (int i = 0; i < res->nrows; i++)
            if (!res->rows[i].same)
                printf("hits: N=%d M=%d E=%d DIFFERENT from the float BVH: %s\n", res->rows[i].s.bits,
                       res->rows[i].s.mant, res->rows[i].s.min_scale, res->rows[i].why);
        for (int k = 0; k < res->nextra; k++)
            if (!res->extra[k].same)
                printf("hits: %s DIFFERENT from the float BVH: %s\n", c->run.extra[k].name, res->extra[k].why);
    }
    printf("heat maps: box tests per primary-ray pixel, colour scale 0..%.1f for all; difference maps: extra box + "
           "triangle tests per pixel against the float BVH, each on its own scale symmetric around 0 (largest |extra| "
           "%.1f)\n",
           w->heat_max, w->diff_max);
    for (int k = 0; k < w->nwritten; k++) printf("wrote %s\n", w->written[k]);
}

/* The first setting whose hits differ, and a file not written: one line
 * each on stderr.  The exit status. */
static int report(const sweep_cli *c, const sweep_figures *f, const sweep_files *w) {
    const cbvh_sweep_result *res = &f->res;
    for (int i = 0; i < res->nrows + res->nextra; i++) {
        const cbvh_sweep_run_t *r = i < res->nrows ? &res->rows[i] : &res->extra[i - res->nrows];
        if (r->same) continue;
        if (i < res->nrows)
            fprintf(stderr, "cbvh sweep: setting N=%d M=%d E=%d differs from the float BVH: %s\n", r->s.bits,
                    r->s.mant, r->s.min_scale, r->why);
        else {
            char name[CBVH_FORMAT_NAME_MAX + 16];
            cbvh_sweep_format_label(&c->run.extra[i - res->nrows], r->s.mant, name, sizeof name);
            fprintf(stderr, "cbvh sweep: %s differs from the float BVH: %s\n", name, r->why);
        }
        break;
    }
    if (w->nfailed)
        fprintf(stderr, "cbvh sweep: %s%s\n", w->failed, w->nfailed > 1 ? " (and more output files not written)" : "");
    int status = res->all_same ? 0 : 1;
    return w->nfailed && !status ? 2 : status; /* an output file not written */
}

int cmd_sweep(int argc, char **argv) {
    sweep_cli c;
    int rc = parse_options(argc, argv, &c);
    if (rc) return rc == 1 ? 0 : 2;
    if (validate_options(&c)) return 2;
    cbvh_scene_desc d;
    char err[1024];
    if (cbvh_scene_file_open(c.scene, &d, err, sizeof err)) {
        fprintf(stderr, "cbvh sweep: %s\n", err);
        return 2;
    }
    sweep_figures f;
    if (validate_run(&c) || compute(&c, &d, &f)) {
        cbvh_scene_desc_free(&d);
        return 2;
    }
    sweep_files w;
    write_files(&c, &d, &f, &w);
    /* A file not written: no JSON (its "files" would pass for a complete run),
     * only the error line, as trace and run print no JSON on an error. */
    if (c.json && !w.nfailed)
        write_json(&c, &d, &f, &w);
    else if (!c.json)
        write_text(&c, &d, &f, &w);
    rc = report(&c, &f, &w);
    free_figures(&f);
    cbvh_scene_desc_free(&d);
    return rc;
}
