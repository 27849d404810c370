/* `cbvh vectors check`: MANIFEST first, then every vector on a backend. */
#include "vectors/vectors_check.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cbvh/oom.h"
#include "link/backend.h"
#include "util/json.h"
#include "vectors/manifest.h"
#include "vectors/vecfile.h"

/* ---- the work list ---------------------------------------------------------- */

/* Each file with the SHA-256 its MANIFEST gives ("" when there is none): the
 * bytes that run are hashed again from the same read that is parsed, so a
 * file rewritten after the manifest check cannot run unverified. */
typedef struct {
    char **path;
    char (*sha)[CBVH_SHA256_HEX_LEN + 1];
    size_t n, cap;
} list_t;

static int list_add(list_t *l, const char *p, const char *sha) {
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 128;
        char **np = realloc(l->path, cap * sizeof *np);
        if (!np) return -1;
        l->path = np;
        char(*ns)[CBVH_SHA256_HEX_LEN + 1] = realloc(l->sha, cap * sizeof *ns);
        if (!ns) return -1;
        l->sha = ns;
        l->cap = cap;
    }
    snprintf(l->sha[l->n], sizeof l->sha[l->n], "%s", sha ? sha : "");
    l->path[l->n] = strdup(p);
    return l->path[l->n] ? (int)(l->n++, 0) : -1;
}

static void list_free(list_t *l) {
    for (size_t i = 0; i < l->n; i++) free(l->path[i]);
    free(l->path);
    free(l->sha);
}

static int ends_with(const char *s, const char *suffix) {
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

/* A file vouched for by the journal of a killed gen, not yet by MANIFEST. */
static void note_journal(FILE *log, const char *dir, const cbvh_manifest *m) {
    if (m->from_journal)
        fprintf(log,
                "cbvh: note: %s/%s%s was put in place by a `vectors gen` killed before it updated MANIFEST; "
                "checked against the SHA-256 in %s/%s (the next gen there lists it)\n",
                dir, m->from_journal_name, m->from_journal > 1 ? " and others" : "", dir, CBVH_MANIFEST_JOURNAL);
}

/* A single file: verified against the MANIFEST next to it when there is one;
 * sha receives the listed SHA-256 ("" without a MANIFEST). */
static int verify_single(const char *path, FILE *log, char *sha, char *err, size_t errlen) {
    sha[0] = '\0';
    char dir[4096];
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    if (slash) {
        size_t n = (size_t)(slash - path);
        if (n >= sizeof dir) n = sizeof dir - 1;
        memcpy(dir, path, n);
        dir[n ? n : 1] = '\0';
        if (n == 0) dir[0] = '/';
    } else {
        strcpy(dir, ".");
    }
    cbvh_manifest m;
    int rc = cbvh_manifest_load_journaled(dir, &m, err, errlen);
    if (rc < 0) return -1;
    if (rc == 1) {
        fprintf(log, "cbvh: note: no MANIFEST next to %s; its SHA-256 is not verified\n", path);
        return 0;
    }
    const cbvh_manifest_entry *e = cbvh_manifest_find(&m, base);
    if (!e) {
        snprintf(err, errlen, "%.400s: not listed in %.400s/MANIFEST", path, dir);
        cbvh_manifest_free(&m);
        return -1;
    }
    char *buf;
    size_t len;
    if (cbvh_read_file(path, &buf, &len, err, errlen) != 0) {
        cbvh_manifest_free(&m);
        return -1;
    }
    int hrc = cbvh_sha256_check(path, buf, len, e->sha256, err, errlen);
    free(buf);
    if (hrc != 0) {
        cbvh_manifest_free(&m);
        return -1;
    }
    memcpy(sha, e->sha256, CBVH_SHA256_HEX_LEN + 1);
    note_journal(log, dir, &m);
    cbvh_manifest_free(&m);
    return 0;
}

static int collect(const char *const *paths, int npaths, FILE *log, list_t *files, char *err, size_t errlen) {
    for (int i = 0; i < npaths; i++) {
        struct stat st;
        if (stat(paths[i], &st) != 0) {
            snprintf(err, errlen, "%s: %s", paths[i], strerror(errno));
            return -1;
        }
        if (S_ISDIR(st.st_mode)) {
            char d[4096];
            snprintf(d, sizeof d, "%s", paths[i]);
            for (size_t k = strlen(d); k > 1 && d[k - 1] == '/'; k--) d[k - 1] = '\0'; /* "vectors/" -> "vectors" */
            cbvh_manifest m;
            if (cbvh_manifest_verify_dir(d, &m, err, errlen) != 0) return -1;
            note_journal(log, d, &m);
            /* Leftovers of a killed gen are not vector files: named, not run. */
            char first[4200];
            size_t temps = cbvh_manifest_find_temps(d, first, sizeof first);
            if (temps)
                fprintf(log,
                        "cbvh: note: ignoring %zu temporary file%s of an interrupted `vectors gen`, e.g. %s (delete %s)\n",
                        temps, temps > 1 ? "s" : "", first, temps > 1 ? "them" : "it");
            for (size_t k = 0; k < m.n; k++) {
                if (!ends_with(m.e[k].name, ".vec")) continue;
                char p[4096];
                snprintf(p, sizeof p, "%.3800s/%s", d, m.e[k].name);
                if (list_add(files, p, m.e[k].sha256) != 0) {
                    cbvh_manifest_free(&m);
                    snprintf(err, errlen, "out of memory");
                    return -1;
                }
            }
            cbvh_manifest_free(&m);
        } else {
            char sha[CBVH_SHA256_HEX_LEN + 1];
            if (verify_single(paths[i], log, sha, err, errlen) != 0) return -1;
            if (list_add(files, paths[i], sha) != 0) {
                snprintf(err, errlen, "out of memory");
                return -1;
            }
        }
    }
    if (files->n == 0) {
        snprintf(err, errlen, "no vector files to check");
        return -1;
    }
    return 0;
}

/* Reads path once, checks that buffer against sha (when given) and parses
 * the same buffer: what runs is exactly what was verified. */
static int load_verified(const char *path, const char *sha, cbvh_vecfile *vf, char *err, size_t errlen) {
    memset(vf, 0, sizeof *vf);
    char *buf;
    size_t len;
    if (cbvh_read_file(path, &buf, &len, err, errlen) != 0) return -1;
    if (sha[0] && cbvh_sha256_check(path, buf, len, sha, err, errlen) != 0) {
        free(buf);
        return -1;
    }
    cbvh_vec_status st = cbvh_vecfile_parse(buf, len, path, vf, err, errlen);
    free(buf);
    return st == CBVH_VEC_OK ? 0 : -1;
}

/* A failed backend call names vectors by their place in the batch (protocol.c:
 * "unit: vectors A..B not run: ..."); restate them as vectors of the file,
 * with their lines, as everywhere else.  pick maps run positions to file
 * vectors under --sample (NULL: the identity). */
static void locate_failure(const char *berr, const cbvh_vecfile *vf, size_t off, size_t cnt, const size_t *pick,
                           char *dst, size_t n) {
    const char *at = strstr(berr, "vectors ");
    size_t a = 0, b = 0;
    int len = 0;
    if (at && sscanf(at, "vectors %zu..%zu%n", &a, &b, &len) == 2 && len > 0 && a <= b && b < cnt) {
        size_t fa = pick ? pick[off + a] : off + a, fb = pick ? pick[off + b] : off + b;
        char what[200];
        if (pick)
            snprintf(what, sizeof what, "%zu sampled vectors among vectors %zu..%zu (lines %zu..%zu)", b - a + 1, fa,
                     fb, vf->first_line + fa, vf->first_line + fb);
        else
            snprintf(what, sizeof what, "vectors %zu..%zu (lines %zu..%zu)", fa, fb, vf->first_line + fa,
                     vf->first_line + fb);
        snprintf(dst, n, "%.*s%s%s", (int)(at - berr), berr, what, at + len);
        return;
    }
    /* Another message: say which batch it was. */
    size_t fa = pick ? pick[off] : off, fb = pick ? pick[off + cnt - 1] : off + cnt - 1;
    snprintf(dst, n, "%s (in the batch of vectors %zu..%zu, lines %zu..%zu)", berr, fa, fb, vf->first_line + fa,
             vf->first_line + fb);
}

/* ---- reporting -------------------------------------------------------------- */

static const char *const status_bit_names[] = {"NAN_INF",    "INVERTED", "BAD_SCALE", "BAD_PARAM",
                                               "BAD_CODE",   "BAD_FORMAT", "NO_FIT",   "OUTSIDE"};

/* Readable form of a field value: scales in decimal, status bits by name
 * (bit 7 is the compressor's OUTSIDE and the ray units' ZERO_DIR). */
static void annotate(const cbvh_unit *u, const char *name, uint32_t v, char *buf, size_t n) {
    int ray_unit = strncmp(u->name, "ray_", 4) == 0;
    buf[0] = '\0';
    if (ends_with(name, "scale")) {
        snprintf(buf, n, " (%d)", cbvh_scale_from_word(v));
    } else if (strcmp(name, "status") == 0 && v) {
        size_t o = (size_t)snprintf(buf, n, " (");
        for (int b = 0; b < 8 && o < n; b++)
            if (v >> b & 1u)
                o += (size_t)snprintf(buf + o, n - o, "%s%s", o > 2 ? "|" : "",
                                      b == 7 && ray_unit ? "ZERO_DIR" : status_bit_names[b]);
        if (o < n) snprintf(buf + o, n - o, ")");
    }
}

static void describe_cfg(const cbvh_vecfile *vf, char *buf, size_t n) {
    snprintf(buf, n, "N=%d min_scale=%d%s%s", vf->cfg.params.quant_bits, vf->cfg.params.min_scale,
             vf->unit->uses_encoding ? " " : "", vf->unit->uses_encoding ? cbvh_encoding_name(vf->cfg.enc) : "");
}

static void print_mismatch_text(FILE *f, const char *path, const cbvh_vecfile *vf, size_t i, const uint32_t *act) {
    const cbvh_layout *l = &vf->layout;
    const uint32_t *in = vf->in + i * (size_t)l->n_in, *exp = vf->out + i * (size_t)l->n_out;
    char cfg[96], note[128];
    describe_cfg(vf, cfg, sizeof cfg);
    fprintf(f, "MISMATCH %s:%zu: %s (%s)\n  inputs:", path, vf->first_line + i, vf->unit->name, cfg);
    for (int k = 0; k < l->n_in; k++) {
        annotate(vf->unit, l->in[k].name, in[k], note, sizeof note);
        fprintf(f, " %s=%0*" PRIX32 "%s", l->in[k].name, l->in[k].hex_digits, in[k], note);
    }
    fprintf(f, "\n");
    for (int k = 0; k < l->n_out; k++) {
        int d = l->out[k].hex_digits;
        char ne[128];
        annotate(vf->unit, l->out[k].name, exp[k], ne, sizeof ne);
        annotate(vf->unit, l->out[k].name, act[k], note, sizeof note);
        fprintf(f, "  %-18s expected %0*" PRIX32 "%s  actual %0*" PRIX32 "%s%s\n", l->out[k].name, d, exp[k], ne, d,
                act[k], note, exp[k] != act[k] ? "   <-- differs" : "");
    }
}

/* A field value as the vector files write it: hex, the field's digits. */
static void json_hex(cJSON *o, const char *key, int digits, uint32_t v) {
    char hex[16];
    snprintf(hex, sizeof hex, "%0*" PRIX32, digits, v);
    cJSON_AddStringToObject(o, key, hex);
}

static cJSON *json_mismatch(const char *path, const cbvh_vecfile *vf, size_t i, const uint32_t *act) {
    const cbvh_layout *l = &vf->layout;
    const uint32_t *in = vf->in + i * (size_t)l->n_in, *exp = vf->out + i * (size_t)l->n_out;
    cJSON *m = cJSON_CreateObject();
    cJSON_AddStringToObject(m, "file", path);
    cJSON_AddNumberToObject(m, "line", (double)(vf->first_line + i));
    cJSON_AddStringToObject(m, "unit", vf->unit->name);
    cJSON *ins = cJSON_AddObjectToObject(m, "inputs");
    for (int k = 0; k < l->n_in; k++) json_hex(ins, l->in[k].name, l->in[k].hex_digits, in[k]);
    cJSON *outs = cJSON_AddArrayToObject(m, "outputs");
    for (int k = 0; k < l->n_out; k++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "field", l->out[k].name);
        json_hex(o, "expected", l->out[k].hex_digits, exp[k]);
        json_hex(o, "actual", l->out[k].hex_digits, act[k]);
        cJSON_AddBoolToObject(o, "differs", exp[k] != act[k]);
        cJSON_AddItemToArray(outs, o);
    }
    return m;
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- the check ------------------------------------------------------------ */

int cbvh_vectors_check(const char *const *paths, int npaths, const cbvh_check_opts *opts) {
    cbvh_check_opts o = *opts;
    FILE *out = o.out ? o.out : stdout, *log = o.log ? o.log : stderr;
    const char *spec = o.backend ? o.backend : "auto";
    size_t batch = o.batch ? o.batch : CBVH_CHECK_BATCH;
    cbvh_check_summary sum;
    memset(&sum, 0, sizeof sum);
    char err[1024] = "";
    int rc = CBVH_CHECK_BAD_INPUT;
    list_t files = {NULL, NULL, 0, 0};
    cbvh_backend be;
    memset(&be, 0, sizeof be);
    int be_open = 0;
    uint32_t *act = NULL;
    size_t act_cap = 0;
    int printed = 0;
    double t0 = now();
    /* --json: one tree, printed once at the end (also after an error). */
    cJSON *root = o.json ? cJSON_CreateObject() : NULL, *jfiles = NULL;

    if (collect(paths, npaths, log, &files, err, sizeof err) != 0) goto done;
    char berr[512] = "";
    fflush(out); /* keep the fallback note after anything already printed */
    if (cbvh_backend_open(spec, &be, log, berr, sizeof berr) != 0) {
        snprintf(err, sizeof err, "backend '%.100s': %s", spec, berr);
        goto done;
    }
    be_open = 1;
    snprintf(sum.backend, sizeof sum.backend, "%s", be.label);
    if (o.json) {
        cJSON_AddStringToObject(root, "backend", be.label);
        jfiles = cJSON_AddArrayToObject(root, "files");
    } else {
        fprintf(out, "backend: %s\n", be.label);
    }
    t0 = now();
    for (size_t fi = 0; fi < files.n; fi++) {
        const char *path = files.path[fi];
        cbvh_vecfile vf;
        if (load_verified(path, files.sha[fi], &vf, err, sizeof err) != 0) goto done_json;
        const cbvh_layout *l = &vf.layout;
        size_t need = batch * (size_t)(l->n_out ? l->n_out : 1);
        if (need > act_cap) {
            uint32_t *na = realloc(act, need * sizeof *na);
            if (!na) {
                snprintf(err, sizeof err, "out of memory");
                cbvh_vecfile_free(&vf);
                goto done_json;
            }
            act = na;
            act_cap = need;
        }
        /* --sample: vectors k * count / m, k < m, copied together so that a
         * batch stays one contiguous run for the backend. */
        size_t m = vf.count, *pick = NULL;
        uint32_t *picked_in = NULL;
        if (o.sample && o.sample < vf.count) {
            m = o.sample;
            pick = malloc(m * sizeof *pick);
            picked_in = malloc(m * (size_t)l->n_in * sizeof *picked_in);
            if (!pick || !picked_in) {
                free(pick);
                free(picked_in);
                snprintf(err, sizeof err, "out of memory");
                cbvh_vecfile_free(&vf);
                goto done_json;
            }
            for (size_t k = 0; k < m; k++) {
                pick[k] = k * vf.count / m;
                memcpy(picked_in + k * (size_t)l->n_in, vf.in + pick[k] * (size_t)l->n_in,
                       (size_t)l->n_in * sizeof *picked_in);
            }
        }
        const uint32_t *run_in = picked_in ? picked_in : vf.in;
        size_t pass = 0, fail = 0;
        cJSON *jfile = NULL, *jmis = NULL; /* in the tree at once: an error below still shows the file */
        if (o.json) {
            jfile = cJSON_CreateObject();
            cJSON_AddItemToArray(jfiles, jfile);
            cJSON_AddStringToObject(jfile, "file", path);
            cJSON_AddStringToObject(jfile, "unit", vf.unit->name);
            jmis = cJSON_AddArrayToObject(jfile, "mismatches");
        }
        for (size_t off = 0; off < m; off += batch) {
            size_t cnt = m - off < batch ? m - off : batch;
            char berr[512] = "";
            memset(act, 0, cnt * (size_t)l->n_out * sizeof *act);
            if (be.ops->run(&be, vf.unit, &vf.cfg, run_in + off * (size_t)l->n_in, act, cnt, berr, sizeof berr) != 0) {
                char where[700];
                locate_failure(berr, &vf, off, cnt, pick, where, sizeof where);
                snprintf(err, sizeof err, "%s: backend %s failed: %s", path, be.label, where);
                free(pick);
                free(picked_in);
                cbvh_vecfile_free(&vf);
                goto done_json;
            }
            for (size_t i = 0; i < cnt; i++) {
                size_t v = pick ? pick[off + i] : off + i;
                const uint32_t *a = act + i * (size_t)l->n_out, *e = vf.out + v * (size_t)l->n_out;
                if (memcmp(a, e, (size_t)l->n_out * sizeof *a) == 0) {
                    pass++;
                    continue;
                }
                fail++;
                if (printed < o.max_errors && !o.json) print_mismatch_text(out, path, &vf, v, a);
                if (printed < o.max_errors && o.json) cJSON_AddItemToArray(jmis, json_mismatch(path, &vf, v, a));
                printed++;
            }
        }
        free(pick);
        free(picked_in);
        if (o.json) {
            cJSON_AddNumberToObject(jfile, "passed", (double)pass);
            cJSON_AddNumberToObject(jfile, "failed", (double)fail);
            cJSON_AddNumberToObject(jfile, "count", (double)vf.count);
        } else if (!o.quiet || fail) {
            fprintf(out, "%s: %zu passed, %zu failed", path, pass, fail);
            if (m < vf.count) fprintf(out, " (a sample of %zu of its %zu vectors)", m, vf.count);
            fprintf(out, "\n");
        }
        sum.files++;
        sum.passed += pass;
        sum.failed += fail;
        cbvh_vecfile_free(&vf);
    }
    rc = sum.failed ? CBVH_CHECK_MISMATCH : CBVH_CHECK_PASS;
    /* A check that ran nothing proves nothing (the reader refuses count 0;
     * this keeps it so whatever the input). */
    if (sum.passed + sum.failed == 0) {
        snprintf(err, sizeof err, "no vectors were run (%zu files)", sum.files);
        rc = CBVH_CHECK_BAD_INPUT;
    }
done_json:
    sum.seconds = now() - t0;
    sum.vectors_per_second = sum.seconds > 0 ? (double)(sum.passed + sum.failed) / sum.seconds : 0;
    if (o.json) {
        cJSON *t = cJSON_AddObjectToObject(root, "total");
        cJSON_AddNumberToObject(t, "files", (double)sum.files);
        cJSON_AddNumberToObject(t, "passed", (double)sum.passed);
        cJSON_AddNumberToObject(t, "failed", (double)sum.failed);
        cJSON_AddNumberToObject(t, "seconds", round(sum.seconds * 1e6) / 1e6); /* microseconds, as the text */
        cJSON_AddNumberToObject(t, "vectors_per_second", round(sum.vectors_per_second));
        cJSON_AddNumberToObject(root, "mismatches_shown", printed < o.max_errors ? printed : o.max_errors);
        cJSON_AddNumberToObject(root, "status", rc);
        if (rc == CBVH_CHECK_BAD_INPUT) cJSON_AddStringToObject(root, "error", err);
        cbvh_json_print(root, out);
    } else if (rc != CBVH_CHECK_BAD_INPUT) {
        if (printed > o.max_errors)
            fprintf(out, "(%d more mismatches not shown; --max-errors raises the limit)\n", printed - o.max_errors);
        fprintf(out, "total: %zu files, %zu passed, %zu failed (%zu vectors in %.3f s, %.0f vectors/s)\n", sum.files,
                sum.passed, sum.failed, sum.passed + sum.failed, sum.seconds, sum.vectors_per_second);
    }
    goto finish;
done:
    if (o.json) {
        cJSON_AddNumberToObject(root, "status", rc);
        cJSON_AddStringToObject(root, "error", err);
        cbvh_json_print(root, out);
    }
finish:
    cJSON_Delete(root);
    if (rc == CBVH_CHECK_BAD_INPUT) fprintf(log, "%s: %s\n", o.who ? o.who : "cbvh vectors check", err);
    if (be_open) cbvh_backend_close(&be);
    free(act);
    list_free(&files);
    if (o.summary) *o.summary = sum;
    return rc;
}
