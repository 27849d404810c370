/* The RTL cost table (trace/cost_table.h, docs/timing_model.md §2). */
#define _POSIX_C_SOURCE 200809L /* scandir */
#include "trace/cost_table.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "cbvh/oom.h"

/* A number field of o: its value, dflt when absent or null; -1 when present
 * and not a finite number >= 0. */
static int num(const cJSON *o, const char *key, double dflt, double *out) {
    const cJSON *v = o ? cJSON_GetObjectItemCaseSensitive(o, key) : NULL;
    if (!v || cJSON_IsNull(v)) {
        *out = dflt;
        return 0;
    }
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || v->valuedouble < 0) return -1;
    *out = v->valuedouble;
    return 0;
}

/* "N" / "M": an integer in lo..hi, or -1 (absent or null: every value). */
static int design_int(const cJSON *o, const char *key, int lo, int hi, int *out) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    *out = -1;
    if (!v || cJSON_IsNull(v)) return 0;
    if (!cJSON_IsNumber(v) || v->valuedouble != floor(v->valuedouble) || v->valuedouble < lo || v->valuedouble > hi)
        return -1;
    *out = (int)v->valuedouble;
    return 0;
}

static const cJSON *either(const cJSON *o, const char *a, const char *b) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, a);
    return cJSON_IsObject(v) ? v : cJSON_GetObjectItemCaseSensitive(o, b);
}

static int parse_point(const cJSON *p, const char *unit, cbvh_cost_row *r, char *what, size_t n) {
    memset(r, 0, sizeof *r);
    snprintf(r->unit, sizeof r->unit, "%s", unit);
    if (!cJSON_IsObject(p)) return snprintf(what, n, "not an object"), -1;
    if (design_int(p, "N", 1, 64, &r->n)) return snprintf(what, n, "N: expected an integer 1..64 or null"), -1;
    if (design_int(p, "M", 1, 64, &r->m)) return snprintf(what, n, "M: expected an integer 1..64 or null"), -1;
    const cJSON *area = either(p, "area", "unit_P6"), *tim = either(p, "timing", "placed"),
                *asic = cJSON_GetObjectItemCaseSensitive(p, "asic");
    if (!cJSON_IsObject(area)) return snprintf(what, n, "no \"area\" object"), -1;
    if (!cJSON_IsObject(tim)) return snprintf(what, n, "no \"timing\" object"), -1;
    static const char *const ak[] = {"lut4", "carry", "dff", "dsp"};
    double *ad[] = {&r->lut4, &r->carry, &r->dff, &r->dsp};
    for (int k = 0; k < 4; k++)
        if (num(area, ak[k], k ? NAN : -1, ad[k]) || (k == 0 && r->lut4 < 0))
            return snprintf(what, n, "area.%s: %s", ak[k], k ? "expected a number >= 0" : "required, a number >= 0"),
                   -1;
    if (num(tim, "latency", -1, &r->latency) || r->latency < 0)
        return snprintf(what, n, "timing.latency: required, a number >= 0"), -1;
    if (num(tim, "II", -1, &r->ii) || !(r->ii > 0))
        return snprintf(what, n, "timing.II: required, a number > 0"), -1;
    if (num(tim, "fmax_mhz", NAN, &r->fmax_mhz)) return snprintf(what, n, "timing.fmax_mhz: expected a number"), -1;
    if (cJSON_IsObject(asic) &&
        (num(asic, "multiplier_pp_bits", 0, &r->pp_bits) || num(asic, "adder_bits", 0, &r->adder_bits)))
        return snprintf(what, n, "asic: multiplier_pp_bits and adder_bits are numbers >= 0"), -1;
    return 0;
}

int cbvh_cost_table_add_json(cbvh_cost_table *t, const char *text, const char *name, char *err, size_t errlen) {
    cJSON *root = cJSON_Parse(text);
    if (!root) {
        snprintf(err, errlen, "cost table %s: not JSON", name);
        return -1;
    }
    int rc = -1;
    const cJSON *unit = cJSON_GetObjectItemCaseSensitive(root, "unit"),
                *pts = cJSON_GetObjectItemCaseSensitive(root, "design_points");
    if (!cJSON_IsString(unit) || !unit->valuestring[0] || strlen(unit->valuestring) >= CBVH_COST_UNIT_MAX) {
        snprintf(err, errlen, "cost table %s: \"unit\": expected a name of 1..%d characters", name,
                 CBVH_COST_UNIT_MAX - 1);
        goto out;
    }
    if (!cJSON_IsArray(pts) || cJSON_GetArraySize(pts) == 0) {
        snprintf(err, errlen, "cost table %s: \"design_points\": expected a non-empty array", name);
        goto out;
    }
    int k = 0, n = cJSON_GetArraySize(pts);
    cbvh_cost_row *rows = realloc(t->rows, (size_t)(t->nrows + n) * sizeof *rows);
    if (!rows) cbvh_out_of_memory("cost table");
    t->rows = rows;
    for (const cJSON *p = pts->child; p; p = p->next, k++) {
        char what[160];
        if (parse_point(p, unit->valuestring, &t->rows[t->nrows], what, sizeof what)) {
            snprintf(err, errlen, "cost table %s: design_points[%d]: %s", name, k, what);
            goto out;
        }
        t->nrows++;
    }
    rc = 0;
out:
    cJSON_Delete(root);
    return rc;
}

static int is_json(const struct dirent *e) {
    size_t n = strlen(e->d_name);
    return n > 5 && e->d_name[0] != '.' && strcmp(e->d_name + n - 5, ".json") == 0;
}

int cbvh_cost_table_load(const char *dir, cbvh_cost_table *t, char *err, size_t errlen) {
    memset(t, 0, sizeof *t);
    struct dirent **names;
    int n = scandir(dir, &names, is_json, alphasort);
    if (n < 0) {
        snprintf(err, errlen, "cost table %s: %s", dir, strerror(errno));
        return -1;
    }
    int rc = n ? 0 : -1;
    if (!n) snprintf(err, errlen, "cost table %s: no .json file", dir);
    for (int i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]->d_name);
        if (!rc) {
            FILE *f = fopen(path, "rb");
            char *text = NULL;
            long len = -1;
            if (f && fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
                text = malloc((size_t)len + 1);
                if (!text) cbvh_out_of_memory("cost table file");
                if (fread(text, 1, (size_t)len, f) != (size_t)len) len = -1;
                else text[len] = 0;
            }
            if (len < 0) {
                snprintf(err, errlen, "cost table %s: cannot read: %s", path, strerror(errno ? errno : EIO));
                rc = -1;
            } else
                rc = cbvh_cost_table_add_json(t, text, path, err, errlen);
            free(text);
            if (f) fclose(f);
        }
        free(names[i]);
    }
    free(names);
    if (rc) cbvh_cost_table_free(t);
    return rc;
}

void cbvh_cost_table_free(cbvh_cost_table *t) {
    free(t->rows);
    t->rows = NULL;
    t->nrows = 0;
}

static double lerp(double a, double b, double f) { return isnan(a) || isnan(b) ? NAN : a + (b - a) * f; }

int cbvh_cost_lookup(const cbvh_cost_table *t, const char *unit, int n, int m, cbvh_cost_row *out) {
    /* 1. which M */
    int want = -2, above = -1, top = -1;
    for (int i = 0; i < t->nrows; i++) {
        const cbvh_cost_row *r = &t->rows[i];
        if (strcmp(r->unit, unit)) continue;
        if (r->m == m) want = m;
        if (r->m == -1 && want != m) want = -1;
        if (r->m > m && (above < 0 || r->m < above)) above = r->m;
        if (r->m > top) top = r->m;
    }
    if (want == -2) want = above >= 0 ? above : top;
    /* 2. which N: exact (or every N), else the nearest below and above */
    const cbvh_cost_row *lo = NULL, *hi = NULL;
    for (int i = 0; i < t->nrows; i++) {
        const cbvh_cost_row *r = &t->rows[i];
        if (strcmp(r->unit, unit) || r->m != want) continue;
        if (r->n == n || r->n == -1) {
            *out = *r;
            return 0;
        }
        if (r->n < n && (!lo || r->n > lo->n)) lo = r;
        if (r->n > n && (!hi || r->n < hi->n)) hi = r;
    }
    if (!lo && !hi) return -1;
    if (!lo || !hi) {
        *out = lo ? *lo : *hi;
        return 0;
    }
    double f = (double)(n - lo->n) / (double)(hi->n - lo->n);
    *out = *lo;
    out->n = n;
    out->lut4 = lerp(lo->lut4, hi->lut4, f);
    out->carry = lerp(lo->carry, hi->carry, f);
    out->dff = lerp(lo->dff, hi->dff, f);
    out->dsp = lerp(lo->dsp, hi->dsp, f);
    out->latency = lerp(lo->latency, hi->latency, f);
    out->ii = lerp(lo->ii, hi->ii, f);
    out->fmax_mhz = lerp(lo->fmax_mhz, hi->fmax_mhz, f);
    out->pp_bits = lerp(lo->pp_bits, hi->pp_bits, f);
    out->adder_bits = lerp(lo->adder_bits, hi->adder_bits, f);
    return 0;
}
