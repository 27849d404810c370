/* cbvh sweep SCENE: what each bit of precision costs (docs/sweep.md).  The
 * float BVH and every CBVH setting trace the same rays in one run; costs are
 * printed relative to the float BVH, a chart and heat maps go to --out, and
 * every setting must return the float BVH's hits (exit 1 naming the first
 * differing ray otherwise).  --formats cbvh,qbvh,tlist... adds the QBVH and
 * traversal lists as more rows, checked the same way. */
#include <errno.h>
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
#include "util/image_png.h"
#include "util/parse_int.h"
#include "trace/sweep.h"

#define MAX_HEAT 16

static void usage(FILE *f) {
    fprintf(f,
            "usage: cbvh sweep SCENE [--bits LO..HI] [--mant M...] [--min-scale E...] [--spp K] [--json]\n"
            "                        [--out DIR] [--heatmap SETTING...] [--knee PCT] [--formats cbvh[,F...]]\n"
            "                        [--one-sided]\n"
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
            "  --json            machine-readable output on stdout\n"
            "  A list option (--mant, --min-scale, --heatmap, --formats) may be given once; any other\n"
            "  option given twice: the last wins.\n"
            "testing:\n"
            "  --test-corrupt S:R  pretend setting S (index in trace order) returned a wrong answer for\n"
            "                      ray R, to show the identity check fails (docs/sweep.md)\n",
            CBVH_N_MIN, CBVH_N_MAX, CBVH_MANT_MIN, CBVH_MANT_MAX, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL,
            CBVH_MIN_SCALE_DEFAULT);
}

static int is_int(const char *s) {
    if (*s == '-' || *s == '+') s++;
    if (!*s) return 0;
    for (; *s; s++)
        if (*s < '0' || *s > '9') return 0;
    return 1;
}

/* An empty item in a comma list ("a,,b", ",a", "a,"), which strtok would skip. */
static int has_empty_item(const char *s) {
    size_t n = strlen(s);
    return n == 0 || s[0] == ',' || s[n - 1] == ',' || strstr(s, ",,") != NULL;
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

/* Values after a list option: the following arguments that are integers
 * (comma-separated lists allowed).  Returns the count, -1 on error. */
static int parse_list(const char *opt, int argc, char **argv, int *i, long lo, long hi, int *out, int max) {
    int n = 0;
    while (*i + 1 < argc) {
        const char *a = argv[*i + 1];
        char buf[256];
        snprintf(buf, sizeof buf, "%s", a);
        int all = !has_empty_item(a);
        for (char *t = strtok(buf, ","); t; t = strtok(NULL, ","))
            if (!is_int(t)) all = 0;
        if (!all || !*a) break;
        (*i)++;
        snprintf(buf, sizeof buf, "%s", a);
        for (char *t = strtok(buf, ","); t; t = strtok(NULL, ",")) {
            long v;
            if (cbvh_parse_long(t, lo, hi, &v)) {
                fprintf(stderr, "cbvh sweep: %s expects integers in %ld..%ld, got '%s'\n", opt, lo, hi, t);
                return -1;
            }
            if (n == max) {
                fprintf(stderr, "cbvh sweep: %s takes at most %d values\n", opt, max);
                return -1;
            }
            for (int k = 0; k < n; k++)
                if (out[k] == v) { /* the same setting twice would be traced and charted twice */
                    fprintf(stderr, "cbvh sweep: %s: %ld given twice\n", opt, v);
                    return -1;
                }
            out[n++] = (int)v;
        }
    }
    if (!n) {
        fprintf(stderr, "cbvh sweep: %s expects integers in %ld..%ld, got '%s'\n", opt, lo, hi,
                *i + 1 < argc ? argv[*i + 1] : "");
        return -1;
    }
    return n;
}

typedef struct {
    int is_float;
    int xf;               /* 1 + index into the other formats, 0 = none */
    char fmt[48];         /* a format name given on the command line, resolved after parsing */
    int bits, mant, min_scale; /* mant/min_scale < -1000: the first of the lists */
    int explicit_all;
} heat_spec;

/* A format name of --formats / --heatmap: "qbvh" or a tlist spec; the
 * canonical name goes to f.  0 or -1. */
static int parse_format(const char *t, cbvh_sweep_format *f, char *err, size_t errlen) {
    memset(f, 0, sizeof *f);
    if (strcmp(t, "qbvh") == 0) {
        f->format = CBVH_FORMAT_QBVH;
        snprintf(f->name, sizeof f->name, "qbvh");
        return 0;
    }
    if (cbvh_tlist_opts_parse(t, &f->tlist, err, errlen)) return -1;
    f->format = CBVH_FORMAT_TLIST;
    cbvh_tlist_opts_name(&f->tlist, f->name, sizeof f->name);
    return 0;
}

static int parse_heat(const char *s, heat_spec *h) {
    memset(h, 0, sizeof *h);
    if (strcmp(s, "float") == 0) {
        h->is_float = 1;
        return 0;
    }
    if (strcmp(s, "qbvh") == 0 || strncmp(s, "tlist", 5) == 0) {
        cbvh_sweep_format f;
        char e[160];
        if (parse_format(s, &f, e, sizeof e)) return -1;
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

typedef struct {
    int tty;
} prog_ctx;

static void progress(void *ctx, const char *label, int setting, int settings, int row, int rows) {
    (void)ctx;
    if (row % 8 && row != rows - 1) return;
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
                                                  "CPU time"};
static const char *metric_keys[SWEEP_NMETRICS] = {"box_per_ray", "tri_per_ray", "bytes_per_ray", "model_ns_per_ray",
                                                 "cpu_us_per_ray"};

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
                     uint64_t mem, uint64_t fmem, const cbvh_timing_params *tp, const char *same) {
    double p[SWEEP_NMETRICS], q[SWEEP_NMETRICS];
    cbvh_sweep_per_ray(s, tp, p);
    cbvh_sweep_per_ray(f, tp, q);
    printf("%-28s %-17s %8llu %8.2f %7.2f %8.1f %9.1f %7.2f |", setting, effect, (unsigned long long)s->rays,
           p[SWEEP_BOX], p[SWEEP_TRI], p[SWEEP_BYTES], p[SWEEP_MODEL_NS], p[SWEEP_CPU_US]);
    print_rel(cbvh_ratio(p[SWEEP_BOX], q[SWEEP_BOX]));
    print_rel(cbvh_ratio(p[SWEEP_TRI], q[SWEEP_TRI]));
    print_rel(cbvh_ratio(p[SWEEP_BYTES], q[SWEEP_BYTES]));
    print_rel(cbvh_ratio((double)mem, (double)fmem));
    print_rel(cbvh_ratio(p[SWEEP_MODEL_NS], q[SWEEP_MODEL_NS]));
    print_rel(cbvh_ratio(p[SWEEP_CPU_US], q[SWEEP_CPU_US]));
    printf("  %s\n", same);
}

static cJSON *json_costs(const cbvh_fx_stats *s, const cbvh_fx_stats *f, uint64_t mem, uint64_t fmem,
                         const cbvh_timing_params *tp) {
    double p[SWEEP_NMETRICS], q[SWEEP_NMETRICS];
    cbvh_sweep_per_ray(s, tp, p);
    cbvh_sweep_per_ray(f, tp, q);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "rays", (double)s->rays);
    cJSON_AddNumberToObject(o, "hits", (double)s->hits);
    cJSON_AddNumberToObject(o, "max_stack", s->st.max_stack);
    for (int m = 0; m < SWEEP_NMETRICS; m++) cJSON_AddNumberToObject(o, metric_keys[m], p[m]);
    cJSON *r = cJSON_AddObjectToObject(o, "relative_to_float");
    static const char *rk[SWEEP_NMETRICS] = {"box_tests", "tri_tests", "bytes", "model_time", "cpu_time"};
    for (int m = 0; m < SWEEP_NMETRICS; m++) json_rel(r, rk[m], cbvh_ratio(p[m], q[m]));
    json_rel(r, "node_memory", cbvh_ratio((double)mem, (double)fmem));
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

int cmd_sweep(int argc, char **argv) {
    const char *scene = NULL, *outdir = NULL;
    cbvh_sweep_opts o = {.bits_lo = 3, .bits_hi = 10, .corrupt_setting = -1};
    int json = 0, nheat = 0, heat_given = 0, mant_given = 0, ms_given = 0, formats_given = 0;
    long knee_pct = 10;
    heat_spec heat[MAX_HEAT];
    const char *corrupt = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--json") == 0)
            json = 1;
        else if (strcmp(a, "--bits") == 0) {
            const char *v = i + 1 < argc ? argv[++i] : "";
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
                fprintf(stderr, "cbvh sweep: --bits expects LO..HI or N within %d..%d (LO <= HI), got '%s'\n",
                        CBVH_N_MIN, CBVH_N_MAX, v);
                return 2;
            }
            o.bits_lo = (int)lo;
            o.bits_hi = (int)hi;
        } else if (strcmp(a, "--mant") == 0) {
            if (list_again(a, &mant_given)) return 2;
            if ((o.nmant = parse_list(a, argc, argv, &i, CBVH_MANT_MIN, CBVH_MANT_MAX, o.mant, CBVH_SWEEP_MAX_LIST)) < 0)
                return 2;
        } else if (strcmp(a, "--min-scale") == 0) {
            if (list_again(a, &ms_given)) return 2;
            if ((o.nmin_scale = parse_list(a, argc, argv, &i, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, o.min_scale, CBVH_SWEEP_MAX_LIST)) < 0)
                return 2;
        } else if (strcmp(a, "--spp") == 0) {
            long v;
            if (cbvh_parse_long(i + 1 < argc ? argv[i + 1] : NULL, 1, 1024, &v)) {
                fprintf(stderr, "cbvh sweep: --spp expects an integer in 1..1024, got '%s'\n",
                        i + 1 < argc ? argv[i + 1] : "");
                return 2;
            }
            i++;
            o.spp = (int)v;
        } else if (strcmp(a, "--knee") == 0) {
            if (cbvh_parse_long(i + 1 < argc ? argv[i + 1] : NULL, 0, 1000, &knee_pct)) {
                fprintf(stderr, "cbvh sweep: --knee expects a percentage in 0..1000, got '%s'\n",
                        i + 1 < argc ? argv[i + 1] : "");
                return 2;
            }
            i++;
        } else if (strcmp(a, "--out") == 0) {
            if (i + 1 >= argc || !argv[i + 1][0]) {
                fprintf(stderr, "cbvh sweep: --out expects a directory\n");
                return 2;
            }
            outdir = argv[++i];
        } else if (strcmp(a, "--heatmap") == 0) {
            if (list_again(a, &heat_given)) return 2;
            int n0 = nheat;
            while (i + 1 < argc && argv[i + 1][0] != '-' && (strcmp(argv[i + 1], "float") == 0 ||
                                                              strcmp(argv[i + 1], "qbvh") == 0 ||
                                                              strncmp(argv[i + 1], "tlist", 5) == 0 ||
                                                              (argv[i + 1][0] >= '0' && argv[i + 1][0] <= '9'))) {
                if (nheat == MAX_HEAT) {
                    fprintf(stderr, "cbvh sweep: --heatmap takes at most %d settings\n", MAX_HEAT);
                    return 2;
                }
                if (parse_heat(argv[i + 1], &heat[nheat])) {
                    fprintf(stderr, "cbvh sweep: --heatmap expects float, N, N:M:E (N in %d..%d) or a format, got '%s'\n",
                            CBVH_N_MIN, CBVH_N_MAX, argv[i + 1]);
                    return 2;
                }
                nheat++;
                i++;
            }
            if (nheat == n0) {
                fprintf(stderr, "cbvh sweep: --heatmap expects float, N, N:M:E (N in %d..%d) or a format, got '%s'\n",
                        CBVH_N_MIN, CBVH_N_MAX, i + 1 < argc ? argv[i + 1] : "");
                return 2;
            }
        } else if (strcmp(a, "--one-sided") == 0)
            o.one_sided = 1;
        else if (strcmp(a, "--formats") == 0) {
            if (list_again(a, &formats_given)) return 2;
            const char *v = i + 1 < argc ? argv[++i] : "";
            char buf[512], ferr[200] = "";
            size_t len = strlen(v);
            int cb = 0, bad = len >= sizeof buf || has_empty_item(v);
            if (!bad) memcpy(buf, v, len + 1);
            o.nextra = 0;
            for (char *t = strtok(buf, ","); t && !bad; t = strtok(NULL, ",")) {
                if (strcmp(t, "cbvh") == 0) {
                    cb = 1;
                    continue;
                }
                cbvh_sweep_format f;
                if (strcmp(t, "qbvh") != 0 && strncmp(t, "tlist", 5) != 0)
                    bad = 1;
                else if (parse_format(t, &f, ferr, sizeof ferr))
                    bad = 2;
                else if (o.nextra == CBVH_SWEEP_MAX_EXTRA) {
                    snprintf(ferr, sizeof ferr, "at most %d formats besides cbvh", CBVH_SWEEP_MAX_EXTRA);
                    bad = 2;
                } else {
                    for (int k = 0; k < o.nextra; k++)
                        if (strcmp(o.extra[k].name, f.name) == 0) {
                            snprintf(ferr, sizeof ferr, "format %s given twice", f.name);
                            bad = 2;
                        }
                    if (!bad) o.extra[o.nextra++] = f;
                }
            }
            if (bad == 2) {
                fprintf(stderr, "cbvh sweep: --formats: %s\n", ferr);
                return 2;
            }
            if (bad || !cb) {
                fprintf(stderr, "cbvh sweep: --formats expects cbvh[,qbvh][,tlist[:options]...], got '%s'\n", v);
                return 2;
            }
        } else if (strcmp(a, "--test-corrupt") == 0) {
            /* Test hook (docs/sweep.md): SETTING_INDEX:RAY_INDEX. */
            corrupt = i + 1 < argc ? argv[++i] : "";
            long si, ri;
            char buf[64];
            snprintf(buf, sizeof buf, "%s", corrupt);
            char *c = strchr(buf, ':');
            if (!c || (*c = 0, cbvh_parse_long(buf, 0, 100000, &si)) || cbvh_parse_long(c + 1, 0, 2000000000L, &ri)) {
                fprintf(stderr, "cbvh sweep: --test-corrupt expects SETTING:RAY, got '%s'\n", corrupt);
                return 2;
            }
            o.corrupt_setting = (int)si;
            o.corrupt_ray = (uint64_t)ri;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "cbvh sweep: unknown option '%s' (see cbvh sweep --help)\n", a);
            return 2;
        } else if (scene) {
            fprintf(stderr, "cbvh sweep: more than one scene ('%s', '%s')\n", scene, a);
            return 2;
        } else
            scene = a;
    }
    if (!scene) {
        fprintf(stderr, "cbvh sweep: no scene file given (see cbvh sweep --help)\n");
        return 2;
    }
    if (!o.nmant) o.mant[o.nmant++] = CBVH_MANT_MAX;
    if (!o.nmin_scale) o.min_scale[o.nmin_scale++] = CBVH_MIN_SCALE_DEFAULT;
    if (!heat_given) {
        heat[nheat++] = (heat_spec){.is_float = 1};
        static const int def[] = {3, 6, 10};
        for (int k = 0; k < 3; k++)
            if (def[k] >= o.bits_lo && def[k] <= o.bits_hi) heat[nheat++] = (heat_spec){.bits = def[k]};
        for (int k = 0; k < o.nextra && nheat < MAX_HEAT; k++) heat[nheat++] = (heat_spec){.xf = k + 1};
    }
    /* Every heat-map setting must be one the sweep traces. */
    for (int h = 0; h < nheat; h++) {
        heat_spec *s = &heat[h];
        if (s->is_float || s->xf) continue;
        if (s->fmt[0]) {
            for (int k = 0; k < o.nextra; k++)
                if (strcmp(o.extra[k].name, s->fmt) == 0) s->xf = k + 1;
            if (!s->xf) {
                fprintf(stderr, "cbvh sweep: --heatmap %s needs --formats cbvh,%s\n", s->fmt, s->fmt);
                return 2;
            }
            continue;
        }
        if (!s->explicit_all) {
            s->mant = o.mant[0];
            s->min_scale = o.min_scale[0];
        }
        int inm = 0, ine = 0;
        for (int k = 0; k < o.nmant; k++) inm |= o.mant[k] == s->mant;
        for (int k = 0; k < o.nmin_scale; k++) ine |= o.min_scale[k] == s->min_scale;
        if (s->bits < o.bits_lo || s->bits > o.bits_hi || !inm || !ine) {
            fprintf(stderr, "cbvh sweep: --heatmap %d:%d:%d is not a setting of this sweep\n", s->bits, s->mant,
                    s->min_scale);
            return 2;
        }
    }
    /* The same map twice (also "6" and "6:24:-30") would be drawn twice. */
    for (int h = 0; h < nheat; h++)
        for (int g = 0; g < h; g++) {
            const heat_spec *s = &heat[h], *t = &heat[g];
            if (s->is_float != t->is_float || s->xf != t->xf ||
                (!s->is_float && !s->xf &&
                 (s->bits != t->bits || s->mant != t->mant || s->min_scale != t->min_scale)))
                continue;
            if (s->is_float)
                fprintf(stderr, "cbvh sweep: --heatmap: float given twice\n");
            else if (s->xf)
                fprintf(stderr, "cbvh sweep: --heatmap: %s given twice\n", o.extra[s->xf - 1].name);
            else
                fprintf(stderr, "cbvh sweep: --heatmap: setting %d:%d:%d given twice\n", s->bits, s->mant,
                        s->min_scale);
            return 2;
        }
    char outbuf[1024];
    if (!outdir) {
        default_out(scene, outbuf, sizeof outbuf);
        outdir = outbuf;
    }
    cbvh_scene_desc d;
    char err[1024];
    if (cbvh_scene_file_open(scene, &d, err, sizeof err)) {
        fprintf(stderr, "cbvh sweep: %s\n", err);
        return 2;
    }
    int nb = o.bits_hi - o.bits_lo + 1;
    if (o.corrupt_setting >= nb * o.nmant * o.nmin_scale + o.nextra) {
        fprintf(stderr, "cbvh sweep: --test-corrupt setting %d: the sweep has %d settings\n", o.corrupt_setting,
                nb * o.nmant * o.nmin_scale + o.nextra);
        cbvh_scene_desc_free(&d);
        return 2;
    }
    if (ensure_dir(outdir) || check_writable(outdir)) {
        cbvh_scene_desc_free(&d);
        return 2;
    }
    int tty = isatty(2);
    if (tty) o.progress = progress;
    cbvh_timing_params tp;
    cbvh_fx_timing(&d, &tp);
    cbvh_sweep_result res;
    if (cbvh_sweep_run(&d, &o, &res, err, sizeof err)) {
        if (tty) fprintf(stderr, "\n");
        fprintf(stderr, "cbvh sweep: %s: %s\n", scene, err);
        cbvh_scene_desc_free(&d);
        return 2; /* the run could not be done: not a finding about hits */
    }
    if (tty) fprintf(stderr, "\r%70s\r", "");

    /* Relative totals per setting, for the knee and the chart. */
    double tol = (double)knee_pct / 100.0;
    int ncombo = o.nmant * o.nmin_scale;
    cbvh_fx_stats ftot = cbvh_fx_total(&res.ref.r);
    double fq[SWEEP_NMETRICS];
    cbvh_sweep_per_ray(&ftot, &tp, fq);
    double *relv = calloc((size_t)res.nrows * SWEEP_NMETRICS, sizeof *relv);
    int *bits = calloc((size_t)nb, sizeof *bits);
    if (!relv || !bits) cbvh_out_of_memory("sweep chart data");
    for (int b = 0; b < nb; b++) bits[b] = o.bits_lo + b;
    for (int i = 0; i < res.nrows; i++) {
        cbvh_fx_stats t = cbvh_fx_total(&res.rows[i].r);
        double p[SWEEP_NMETRICS];
        cbvh_sweep_per_ray(&t, &tp, p);
        for (int m = 0; m < SWEEP_NMETRICS; m++) relv[(size_t)m * res.nrows + i] = cbvh_ratio(p[m], fq[m]);
    }
    /* knee[c][m] for the four modelled metrics (CPU time is noisy: not a knee). */
    int knee[CBVH_SWEEP_MAX_LIST * CBVH_SWEEP_MAX_LIST][4];
    for (int c = 0; c < ncombo; c++)
        for (int m = 0; m < 4; m++) knee[c][m] = cbvh_sweep_knee(bits, &relv[(size_t)m * res.nrows + c * nb], nb, tol);

    /* Outputs: chart(s) and heat maps. */
    int status = res.all_same ? 0 : 1;
    char path[2048], title[1400];
    char written[16][2100];
    int nwritten = 0, nfailed = 0;
    char failed[1100] = ""; /* the first output file not written: one line at the end */
    double *x = calloc((size_t)nb, sizeof *x);
    if (!x) cbvh_out_of_memory("sweep chart axis");
    for (int b = 0; b < nb; b++) x[b] = bits[b];
    for (int c = 0; c < ncombo && nwritten < 8; c++) {
        const cbvh_sweep_setting *s = &res.rows[c * nb].s;
        if (ncombo == 1)
            snprintf(path, sizeof path, "%s/cost.svg", outdir);
        else
            snprintf(path, sizeof path, "%s/cost-M%d-E%d.svg", outdir, s->mant, s->min_scale);
        const char *mesh = strrchr(d.mesh_spec, '/');
        snprintf(title, sizeof title, "%s: cost relative to the float BVH (M=%d, min scale %d)",
                 mesh ? mesh + 1 : d.mesh_spec, s->mant, s->min_scale);
        /* Only the costs with a ratio (knee 0: the float BVH did none of it). */
        cbvh_svg_series ser[4];
        int nser = 0;
        for (int m = 0; m < 4; m++)
            if (knee[c][m]) ser[nser++] = (cbvh_svg_series){metric_names[m], &relv[(size_t)m * res.nrows + c * nb]};
        if (!nser) continue;
        if (cbvh_svg_chart(path, title, "coordinate bits N", "cost / float BVH", x, (size_t)nb, ser, (size_t)nser,
                           err, sizeof err)) {
            if (!nfailed++) snprintf(failed, sizeof failed, "%s", err);
        } else
            snprintf(written[nwritten++], sizeof written[0], "%s", path);
    }
    /* Heat maps on one colour scale: 0 .. the largest pixel of any chosen setting. */
    const cbvh_sweep_run_t *hr[MAX_HEAT];
    double vmax = 0;
    size_t npx = (size_t)res.width * (size_t)res.height;
    for (int h = 0; h < nheat; h++) {
        hr[h] = heat[h].xf ? &res.extra[heat[h].xf - 1] : &res.ref;
        if (!heat[h].is_float && !heat[h].xf)
            for (int i = 0; i < res.nrows; i++)
                if (res.rows[i].s.bits == heat[h].bits && res.rows[i].s.mant == heat[h].mant &&
                    res.rows[i].s.min_scale == heat[h].min_scale)
                    hr[h] = &res.rows[i];
        for (size_t p = 0; p < npx; p++)
            if (hr[h]->box_px[p] > vmax) vmax = hr[h]->box_px[p];
    }
    if (!(vmax > 0)) vmax = 1;
    double used_min = 0, used_max = vmax;
    for (int h = 0; h < nheat; h++) {
        if (heat[h].is_float)
            snprintf(path, sizeof path, "%s/heat-float.png", outdir);
        else if (heat[h].xf) {
            char fn[48];
            snprintf(fn, sizeof fn, "%s", o.extra[heat[h].xf - 1].name);
            for (char *p = fn; *p; p++)
                if (*p == ':') *p = '-';
            snprintf(path, sizeof path, "%s/heat-%s.png", outdir, fn);
        }
        else if (heat[h].explicit_all)
            snprintf(path, sizeof path, "%s/heat-N%d-M%d-E%d.png", outdir, heat[h].bits, heat[h].mant,
                     heat[h].min_scale);
        else
            snprintf(path, sizeof path, "%s/heat-N%d.png", outdir, heat[h].bits);
        if (cbvh_heatmap_png(path, hr[h]->box_px, (unsigned)res.width, (unsigned)res.height, 0, vmax, 0, &used_min,
                             &used_max, err, sizeof err)) {
            if (!nfailed++) snprintf(failed, sizeof failed, "%s", err);
        } else if (nwritten < 16)
            snprintf(written[nwritten++], sizeof written[0], "%s", path);
    }
    snprintf(path, sizeof path, "%s/render-float.png", outdir);
    if (cbvh_png_write(path, res.ref.image, (unsigned)res.width, (unsigned)res.height, 1, err, sizeof err)) {
        if (!nfailed++) snprintf(failed, sizeof failed, "%s", err);
    } else if (nwritten < 16)
        snprintf(written[nwritten++], sizeof written[0], "%s", path);

    int first_bad = -1;
    for (int i = 0; i < res.nrows; i++)
        if (!res.rows[i].same) {
            first_bad = i;
            break;
        }
    for (int k = 0; first_bad < 0 && k < res.nextra; k++)
        if (!res.extra[k].same) first_bad = res.nrows + k;
    static const char *knee_keys[4] = {"box_tests", "tri_tests", "bytes", "model_time"};
    if (nfailed) status = status ? status : 2; /* an output file not written */
    /* A file not written: no JSON (its "files" would pass for a complete run),
     * only the error line below, as trace and run print no JSON on an error. */
    if (json && !nfailed) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", scene);
        cJSON_AddStringToObject(root, "mesh", d.mesh_spec);
        cJSON_AddNumberToObject(root, "triangles", d.mesh.ntris);
        cJSON_AddNumberToObject(root, "width", res.width);
        cJSON_AddNumberToObject(root, "height", res.height);
        cJSON_AddNumberToObject(root, "spp", res.spp);
        cJSON_AddNumberToObject(root, "frames", res.frames);
        cJSON_AddNumberToObject(root, "rays", (double)res.ref_rays);
        cJSON *tj = cJSON_AddObjectToObject(root, "timing");
        cJSON_AddNumberToObject(tj, "box_cycles", tp.box_cycles);
        cJSON_AddNumberToObject(tj, "tri_cycles", tp.tri_cycles);
        cJSON_AddNumberToObject(tj, "fetch_latency", tp.fetch_latency);
        cJSON_AddNumberToObject(tj, "dram_bytes_per_cycle", tp.dram_bytes_per_cycle);
        cJSON_AddNumberToObject(tj, "clock_mhz", tp.clock_mhz);
        cJSON *fl = cJSON_AddObjectToObject(root, "float");
        cJSON_AddNumberToObject(fl, "node_bytes", (double)res.ref.r.node_bytes);
        cJSON *fe = cJSON_AddObjectToObject(fl, "effects");
        for (int e = 0; e < CBVH_FX_COUNT; e++)
            if (d.effect[e].enabled)
                cJSON_AddItemToObject(fe, cbvh_effect_name((cbvh_effect)e),
                                      json_costs(&res.ref.r.fx[e], &res.ref.r.fx[e], 1, 1, &tp));
        cJSON_AddItemToObject(fl, "total", json_costs(&ftot, &ftot, 1, 1, &tp));
        cJSON *rows = cJSON_AddArrayToObject(root, "settings");
        for (int i = 0; i < res.nrows; i++) {
            const cbvh_sweep_run_t *r = &res.rows[i];
            cJSON *row = cJSON_CreateObject();
            cJSON_AddNumberToObject(row, "bits", r->s.bits);
            cJSON_AddNumberToObject(row, "mant", r->s.mant);
            cJSON_AddNumberToObject(row, "min_scale", r->s.min_scale);
            cJSON_AddNumberToObject(row, "node_bytes", (double)r->r.node_bytes);
            cJSON_AddBoolToObject(row, "same_hits", r->same);
            if (!r->same) cJSON_AddStringToObject(row, "first_difference", r->why);
            cJSON *ef = cJSON_AddObjectToObject(row, "effects");
            for (int e = 0; e < CBVH_FX_COUNT; e++)
                if (d.effect[e].enabled)
                    cJSON_AddItemToObject(ef, cbvh_effect_name((cbvh_effect)e),
                                          json_costs(&r->r.fx[e], &res.ref.r.fx[e], r->r.node_bytes,
                                                     res.ref.r.node_bytes, &tp));
            cbvh_fx_stats t = cbvh_fx_total(&r->r);
            cJSON_AddItemToObject(row, "total", json_costs(&t, &ftot, r->r.node_bytes, res.ref.r.node_bytes, &tp));
            cJSON_AddItemToArray(rows, row);
        }
        cJSON *fj = res.nextra ? cJSON_AddArrayToObject(root, "formats") : NULL;
        for (int k = 0; k < res.nextra; k++) {
            const cbvh_sweep_run_t *r = &res.extra[k];
            cJSON *qj = cJSON_CreateObject();
            cJSON_AddItemToArray(fj, qj);
            cJSON_AddStringToObject(qj, "format", o.extra[k].name);
            cJSON_AddNumberToObject(qj, "mant", r->s.mant);
            cJSON_AddNumberToObject(qj, "node_bytes", (double)r->r.node_bytes);
            cJSON_AddNumberToObject(qj, "qbvh_stack", (double)r->r.units.qbvh_stack);
            cJSON_AddNumberToObject(qj, "ray_sphere", (double)r->r.units.ray_sphere);
            cJSON_AddBoolToObject(qj, "same_hits", r->same);
            if (!r->same) cJSON_AddStringToObject(qj, "first_difference", r->why);
            cJSON *ef = cJSON_AddObjectToObject(qj, "effects");
            for (int e = 0; e < CBVH_FX_COUNT; e++)
                if (d.effect[e].enabled)
                    cJSON_AddItemToObject(ef, cbvh_effect_name((cbvh_effect)e),
                                          json_costs(&r->r.fx[e], &res.ref.r.fx[e], r->r.node_bytes,
                                                     res.ref.r.node_bytes, &tp));
            cbvh_fx_stats t = cbvh_fx_total(&r->r);
            cJSON_AddItemToObject(qj, "total", json_costs(&t, &ftot, r->r.node_bytes, res.ref.r.node_bytes, &tp));
        }
        cJSON *kn = cJSON_AddArrayToObject(root, "knee");
        for (int c = 0; c < ncombo; c++) {
            cJSON *k = cJSON_CreateObject();
            cJSON_AddNumberToObject(k, "mant", res.rows[c * nb].s.mant);
            cJSON_AddNumberToObject(k, "min_scale", res.rows[c * nb].s.min_scale);
            cJSON_AddNumberToObject(k, "tolerance", tol);
            cJSON_AddNumberToObject(k, "reference_bits", o.bits_hi);
            for (int m = 0; m < 4; m++)
                if (knee[c][m])
                    cJSON_AddNumberToObject(k, knee_keys[m], knee[c][m]);
                else
                    cJSON_AddNullToObject(k, knee_keys[m]); /* no ratio: the float BVH did none */
            cJSON_AddItemToArray(kn, k);
        }
        cJSON_AddBoolToObject(root, "same_hits", res.all_same);
        cJSON_AddNumberToObject(root, "heatmap_max_box_tests", used_max);
        cJSON *wr = cJSON_AddArrayToObject(root, "files");
        for (int k = 0; k < nwritten; k++) cJSON_AddItemToArray(wr, cJSON_CreateString(written[k]));
        char *txt = cJSON_PrintUnformatted(root);
        if (!txt) cbvh_out_of_memory("sweep JSON");
        cbvh_json_fputs_utf8(txt, stdout); /* file names may hold bytes that are not UTF-8 */
        putchar('\n');
        free(txt);
        cJSON_Delete(root);
    } else if (!json) {
        printf("scene %s: %s, %u triangles, %dx%d, %d spp, %d frame%s; %llu rays per setting\n", scene, d.mesh_spec,
               d.mesh.ntris, res.width, res.height, res.spp, res.frames, res.frames > 1 ? "s" : "",
               (unsigned long long)res.ref_rays);
        printf("timing model: %g cycle/box, %g cycle/tri, %g cycles fetch latency, %g B/cycle DRAM, %g MHz "
               "(docs/timing_model.md)\n\n",
               tp.box_cycles, tp.tri_cycles, tp.fetch_latency, tp.dram_bytes_per_cycle, tp.clock_mhz);
        printf("%-28s %-17s %8s %8s %7s %8s %9s %7s | %7s %7s %7s %7s %7s %7s  %s\n", "setting", "effect", "rays",
               "box/ray", "tri/ray", "B/ray", "model ns", "CPU us", "box", "tri", "bytes", "memory", "model", "CPU",
               "hits");
        printf("%-28s %-17s %8s %8s %7s %8s %9s %7s | %55s\n", "", "", "", "", "", "", "", "",
               "relative to the float BVH ----------------------------");
        char name[48];
        for (int i = -1; i < res.nrows + res.nextra; i++) {
            const cbvh_sweep_run_t *r = i < 0 ? &res.ref : i >= res.nrows ? &res.extra[i - res.nrows] : &res.rows[i];
            if (i < 0)
                snprintf(name, sizeof name, "float");
            else if (i >= res.nrows && o.extra[i - res.nrows].format == CBVH_FORMAT_QBVH)
                snprintf(name, sizeof name, "qbvh M=%d", r->s.mant);
            else if (i >= res.nrows)
                snprintf(name, sizeof name, "%s", o.extra[i - res.nrows].name);
            else
                snprintf(name, sizeof name, "N=%d M=%d E=%d", r->s.bits, r->s.mant, r->s.min_scale);
            const char *same = i < 0 ? "reference" : r->same ? "same" : "DIFFERENT";
            for (int e = 0; e < CBVH_FX_COUNT; e++)
                if (d.effect[e].enabled)
                    text_row(name, cbvh_effect_name((cbvh_effect)e), &r->r.fx[e], &res.ref.r.fx[e], r->r.node_bytes,
                             res.ref.r.node_bytes, &tp, same);
            cbvh_fx_stats t = cbvh_fx_total(&r->r);
            text_row(name, "total", &t, &ftot, r->r.node_bytes, res.ref.r.node_bytes, &tp, same);
        }
        printf("\nnode memory: float BVH %llu B", (unsigned long long)res.ref.r.node_bytes);
        for (int b = 0; b < nb; b++) printf(", N=%d %llu B", res.rows[b].s.bits, (unsigned long long)res.rows[b].r.node_bytes);
        for (int k = 0; k < res.nextra; k++)
            printf(", %s %llu B", o.extra[k].name, (unsigned long long)res.extra[k].r.node_bytes);
        printf("\n");
        printf("knee = smallest N from which every finer N costs at most %ld%% more than N=%d (totals over effects):\n",
               knee_pct, o.bits_hi);
        int no_knee = 0;
        for (int c = 0; c < ncombo; c++) {
            printf("  M=%d E=%d:", res.rows[c * nb].s.mant, res.rows[c * nb].s.min_scale);
            for (int m = 0; m < 4; m++) {
                if (knee[c][m])
                    printf("%s %s N=%d", m ? "," : "", metric_names[m], knee[c][m]);
                else
                    printf("%s %s -", m ? "," : "", metric_names[m]);
                no_knee |= !knee[c][m];
            }
            printf("\n");
        }
        if (no_knee) printf("  (-: the float BVH did none of it, so there is no ratio and no knee)\n");
        for (int c = 0; c < ncombo; c++)
            for (int b = 0; b < nb; b++)
                if (bits[b] == 6 && res.rows[c * nb].s.mant == CBVH_MANT_MAX) {
                    printf("paper (Viitanen et al., CBVH at N=6): box tests x1.08, triangle tests x1.13; here (M=%d "
                           "E=%d): box tests",
                           res.rows[c * nb].s.mant, res.rows[c * nb].s.min_scale);
                    print_x(relv[(size_t)SWEEP_BOX * res.nrows + c * nb + b]);
                    printf(", triangle tests");
                    print_x(relv[(size_t)SWEEP_TRI * res.nrows + c * nb + b]);
                    printf("\n");
                }
        if (res.all_same)
            printf("hits: all %d settings%s%s return the float BVH's hits on all %llu rays (same triangle and t bits; no "
                   "false misses) and render the same %dx%d image\n",
                   res.nrows, res.nextra == 1 && o.extra[0].format == CBVH_FORMAT_QBVH ? " and the QBVH"
                              : res.nextra                                            ? " and the other formats"
                                                                                      : "",
                   o.one_sided ? " (one-sided)" : "", (unsigned long long)res.ref_rays, res.width, res.height);
        else {
            for (int i = 0; i < res.nrows; i++)
                if (!res.rows[i].same)
                    printf("hits: N=%d M=%d E=%d DIFFERENT from the float BVH: %s\n", res.rows[i].s.bits,
                           res.rows[i].s.mant, res.rows[i].s.min_scale, res.rows[i].why);
            for (int k = 0; k < res.nextra; k++)
                if (!res.extra[k].same)
                    printf("hits: %s DIFFERENT from the float BVH: %s\n", o.extra[k].name, res.extra[k].why);
        }
        printf("heat maps: box tests per primary-ray pixel, colour scale 0..%.1f for all\n", used_max);
        for (int k = 0; k < nwritten; k++) printf("wrote %s\n", written[k]);
    }
    if (first_bad >= res.nrows) {
        const cbvh_sweep_run_t *r = &res.extra[first_bad - res.nrows];
        if (o.extra[first_bad - res.nrows].format == CBVH_FORMAT_QBVH)
            fprintf(stderr, "cbvh sweep: qbvh M=%d differs from the float BVH: %s\n", r->s.mant, r->why);
        else
            fprintf(stderr, "cbvh sweep: %s differs from the float BVH: %s\n", o.extra[first_bad - res.nrows].name,
                    r->why);
    } else if (first_bad >= 0) {
        const cbvh_sweep_run_t *r = &res.rows[first_bad];
        fprintf(stderr, "cbvh sweep: setting N=%d M=%d E=%d differs from the float BVH: %s\n", r->s.bits, r->s.mant,
                r->s.min_scale, r->why);
    }
    if (nfailed)
        fprintf(stderr, "cbvh sweep: %s%s\n", failed,
                nfailed > 1 ? " (and more output files not written)" : "");
    free(x);
    free(bits);
    free(relv);
    cbvh_sweep_free(&res);
    cbvh_scene_desc_free(&d);
    return status;
}
