/* Accuracy vs time: the float reference and every CBVH setting on the same
 * rays, with a ray-by-ray identity check (docs/sweep.md). */
#include "trace/sweep.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/oom.h"


/* What the float reference returned for one ray. */
typedef struct {
    uint32_t prim, t;
    uint8_t fx, mode, hit;
} ray_rec;

typedef struct {
    const cbvh_scene_desc *d;
    const cbvh_sweep_opts *o;
    const cbvh_tri *tris0; /* frame 0, for shading */
    cbvh_sweep_run_t *run;
    int setting; /* index into rows; -1 = the reference */
    int nsettings;
    const char *label;
    ray_rec *rec; /* reference: recorded; setting: compared against */
    uint64_t nrec, caprec;
    uint64_t n;     /* rays seen in this run */
    double *shade;  /* width*height accumulated shade (frame 0) */
    int spp;
    int rep; /* 0: the traced pass; k: the k-th timed repetition */
} sweep_ctx;

static void *xcalloc(size_t n, size_t sz) {
    void *p = calloc(n ? n : 1, sz);
    if (!p) cbvh_out_of_memory("sweep tables");
    return p;
}

/* Grey level of a primary hit: facing ratio of the geometric normal. */
static double shade_hit(const cbvh_tri *tr, const cbvh_ray *r) {
    float e1[3], e2[3], n[3], dir[3];
    for (int a = 0; a < 3; a++) {
        e1[a] = tr->v[1][a] - tr->v[0][a];
        e2[a] = tr->v[2][a] - tr->v[0][a];
        memcpy(&dir[a], &r->d[a], sizeof(float));
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double nn = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    double dd = sqrt((double)dir[0] * dir[0] + (double)dir[1] * dir[1] + (double)dir[2] * dir[2]);
    double c = nn > 0 && dd > 0 ? fabs((double)n[0] * dir[0] + (double)n[1] * dir[1] + (double)n[2] * dir[2]) / (nn * dd)
                                : 0;
    return 40.0 + 215.0 * c;
}

static void on_ray(void *vctx, const cbvh_fx_ray *fr) {
    sweep_ctx *c = vctx;
    cbvh_sweep_run_t *run = c->run;
    uint64_t i = c->n++;
    cbvh_trav_hit h = *fr->hit;
    if (c->setting >= 0 && c->setting == c->o->corrupt_setting && i == c->o->corrupt_ray) {
        if (!(fr->mode & CBVH_TRAV_ANY) && h.hit)
            h.t ^= 1; /* one ulp off */
        else
            h.hit = !h.hit;
    }
    int w = c->d->camera.width;
    if (fr->effect == CBVH_FX_PRIMARY && fr->frame == 0) {
        size_t p = (size_t)fr->py * (size_t)w + (size_t)fr->px;
        run->box_px[p] += (double)fr->st->box_tests / c->spp;
        run->tri_px[p] += (double)fr->st->tri_tests / c->spp;
        if (h.hit) c->shade[p] += shade_hit(&c->tris0[h.prim], &fr->ray) / c->spp;
    }
    if (c->setting < 0) {
        if (c->nrec == c->caprec) {
            c->caprec = c->caprec ? 2 * c->caprec : 4096;
            c->rec = realloc(c->rec, c->caprec * sizeof *c->rec);
            if (!c->rec) cbvh_out_of_memory("sweep reference records");
        }
        c->rec[c->nrec++] = (ray_rec){h.prim, h.t, (uint8_t)fr->effect, (uint8_t)fr->mode, (uint8_t)(h.hit != 0)};
        return;
    }
    if (!run->same) return; /* report the first difference only */
    const char *fx = cbvh_effect_name(fr->effect);
    char what[120] = "";
    if (i >= c->nrec)
        snprintf(what, sizeof what, "an extra ray the float BVH never traced");
    else {
        const ray_rec *r = &c->rec[i];
        int hit = h.hit != 0;
        if (r->fx != fr->effect || r->mode != fr->mode)
            snprintf(what, sizeof what, "a different ray (%s instead of %s)", fx, cbvh_effect_name((cbvh_effect)r->fx));
        else if (r->hit && !hit)
            snprintf(what, sizeof what, "a false miss (float BVH hits triangle %u)", r->prim);
        else if (!r->hit && hit)
            snprintf(what, sizeof what, "a false hit on triangle %u (float BVH misses)", h.prim);
        else if (hit && !(fr->mode & CBVH_TRAV_ANY) && (r->prim != h.prim || r->t != h.t))
            snprintf(what, sizeof what, "triangle %u t=0x%08x, float BVH triangle %u t=0x%08x", h.prim, h.t, r->prim,
                     r->t);
    }
    if (what[0]) {
        run->same = 0;
        run->bad_ray = i;
        run->bad_px = fr->px;
        run->bad_py = fr->py;
        run->bad_frame = fr->frame;
        run->bad_fx = fr->effect;
        snprintf(run->why, sizeof run->why, "ray %llu (%s, pixel %d,%d, frame %d): %s", (unsigned long long)i, fx,
                 fr->px, fr->py, fr->frame, what);
    }
}

static void on_progress(void *vctx, int frame, int frames, int row, int rows) {
    sweep_ctx *c = vctx;
    (void)frame;
    (void)frames;
    if (c->o->progress) c->o->progress(c->o->ctx, c->label, c->setting + 1, c->nsettings, row, rows, c->rep);
}

static int run_one(sweep_ctx *c, cbvh_sweep_run_t *run, const char *format, char *err, size_t errlen) {
    size_t npx = (size_t)c->d->camera.width * (size_t)c->d->camera.height;
    run->box_px = xcalloc(npx, sizeof *run->box_px);
    run->tri_px = xcalloc(npx, sizeof *run->tri_px);
    run->image = xcalloc(npx, 1);
    c->shade = xcalloc(npx, sizeof *c->shade);
    c->run = run;
    c->n = 0;
    run->same = 1;
    cbvh_fx_opts fo = {.format = format,
                       .params = {run->s.bits ? run->s.bits : CBVH_N_DEFAULT, run->s.min_scale},
                       .mant = run->s.mant,
                       .spp = c->o->spp,
                       .on_ray = on_ray,
                       .progress = on_progress,
                       .ctx = c};
    fo.one_sided = c->o->one_sided;
    fo.cache_kb = c->o->cache_kb;
    fo.ncaches = c->o->ncaches;
    fo.cache_ways = c->o->cache_ways;
    fo.box_unit = run->s.box_unit; /* only a format that takes a box unit reads it: the CBVH */
    fo.texp = c->o->texp;
    int rc = cbvh_fx_run(c->d, &fo, &run->r, err, errlen);
    for (size_t p = 0; p < npx; p++) {
        double v = floor(c->shade[p] + 0.5);
        run->image[p] = (uint8_t)(v > 255 ? 255 : v);
    }
    free(c->shade);
    c->shade = NULL;
    return rc;
}

/* The CPU-time column: every configuration traced `reps` more times without
 * the caches or the observer, the configurations in turn within each
 * repetition (so a drift of the machine's speed hits them alike). */
static int timed_reps(sweep_ctx *c, cbvh_sweep_result *res, char *err, size_t errlen) {
    const cbvh_sweep_opts *o = c->o;
    int total = res->nrows + res->nextra;
    for (int k = 1; k <= o->reps; k++)
        for (int i = -1; i < total; i++) {
            cbvh_sweep_run_t *run = i < 0 ? &res->ref : i < res->nrows ? &res->rows[i] : &res->extra[i - res->nrows];
            const char *fmt = i < 0 ? "float" : i < res->nrows ? "cbvh" : o->extra[i - res->nrows].name;
            c->setting = i;
            c->rep = k;
            c->label = fmt;
            cbvh_fx_opts fo = {.format = fmt,
                               .params = {run->s.bits ? run->s.bits : CBVH_N_DEFAULT, run->s.min_scale},
                               .mant = run->s.mant,
                               .spp = o->spp,
                               .progress = on_progress,
                               .ctx = c,
                               .one_sided = o->one_sided,
                               .box_unit = run->s.box_unit,
                               .texp = o->texp};
            cbvh_fx_result rep;
            if (cbvh_fx_run(c->d, &fo, &rep, err, errlen)) return -1;
            if (cbvh_fx_add_rep(&run->r, &rep)) {
                snprintf(err, errlen, "repetition %d of %s traced other rays or hits than its first pass", k, fmt);
                return -1;
            }
        }
    c->rep = 0;
    return 0;
}

/* After a run: the same number of rays as the reference and the same image. */
static void check_totals(const sweep_ctx *c, cbvh_sweep_run_t *run, cbvh_sweep_result *res) {
    if (run->same && c->n != c->nrec) {
        run->same = 0;
        run->bad_ray = c->n;
        snprintf(run->why, sizeof run->why, "traced %llu rays, the float BVH %llu", (unsigned long long)c->n,
                 (unsigned long long)c->nrec);
    }
    /* The rendered image, pixel by pixel (implied by the ray check; checked anyway). */
    size_t npx = (size_t)res->width * (size_t)res->height;
    for (size_t p = 0; run->same && p < npx; p++)
        if (run->image[p] != res->ref.image[p]) {
            run->same = 0;
            run->bad_px = (int)(p % (size_t)res->width);
            run->bad_py = (int)(p / (size_t)res->width);
            run->bad_fx = CBVH_FX_PRIMARY;
            snprintf(run->why, sizeof run->why, "image pixel %d,%d: grey %u, float BVH %u", run->bad_px, run->bad_py,
                     run->image[p], res->ref.image[p]);
        }
    if (!run->same) res->all_same = 0;
}

int cbvh_sweep_run(const cbvh_scene_desc *d, const cbvh_sweep_opts *o, cbvh_sweep_result *res, char *err,
                   size_t errlen) {
    memset(res, 0, sizeof *res);
    if (o->nextra < 0 || o->nextra > CBVH_SWEEP_MAX_EXTRA) {
        snprintf(err, errlen, "at most %d other formats", CBVH_SWEEP_MAX_EXTRA);
        return -1;
    }
    if (o->bits_lo < CBVH_N_MIN || o->bits_hi > CBVH_N_MAX || o->bits_lo > o->bits_hi) {
        snprintf(err, errlen, "--bits range %d..%d not within %d..%d", o->bits_lo, o->bits_hi, CBVH_N_MIN, CBVH_N_MAX);
        return -1;
    }
    if (o->nmant < 1 || o->nmin_scale < 1 || o->nmant > CBVH_SWEEP_MAX_LIST || o->nmin_scale > CBVH_SWEEP_MAX_LIST) {
        snprintf(err, errlen, "need 1..%d values of --mant and of --min-scale", CBVH_SWEEP_MAX_LIST);
        return -1;
    }
    for (int i = 0; i < o->nmant; i++)
        if (o->mant[i] < CBVH_MANT_MIN || o->mant[i] > CBVH_MANT_MAX) {
            snprintf(err, errlen, "--mant %d out of range %d..%d", o->mant[i], CBVH_MANT_MIN, CBVH_MANT_MAX);
            return -1;
        }
    for (int i = 0; i < o->nmin_scale; i++)
        if (o->min_scale[i] < CBVH_SCALE_FLOOR || o->min_scale[i] > CBVH_SCALE_CEIL) {
            snprintf(err, errlen, "--min-scale %d out of range %d..%d", o->min_scale[i], CBVH_SCALE_FLOOR,
                     CBVH_SCALE_CEIL);
            return -1;
        }
    int units[CBVH_BOX_UNITS] = {CBVH_FORMAT_BOX_EXACT}, nu = o->nbox_unit ? o->nbox_unit : 1; /* none given: exact */
    if (nu < 0 || nu > CBVH_BOX_UNITS) {
        snprintf(err, errlen, "at most %d box units", CBVH_BOX_UNITS);
        return -1;
    }
    for (int i = 0; i < o->nbox_unit; i++) {
        int twice = 0;
        for (int j = 0; j < i; j++) twice |= units[j] == o->box_unit[i];
        units[i] = o->box_unit[i];
        if (twice || units[i] < 0 || units[i] >= CBVH_BOX_UNITS) {
            snprintf(err, errlen, "box unit %d given twice or unknown", units[i]);
            return -1;
        }
    }
    int nb = o->bits_hi - o->bits_lo + 1;
    res->nrows = nb * o->nmant * o->nmin_scale * nu;
    res->rows = xcalloc((size_t)res->nrows, sizeof *res->rows);
    res->width = d->camera.width;
    res->height = d->camera.height;
    res->spp = o->spp > 0 ? o->spp : d->camera.spp;
    res->frames = cbvh_scene_desc_frames(d);
    int k = 0;
    for (int u = 0; u < nu; u++)
        for (int m = 0; m < o->nmant; m++)
            for (int e = 0; e < o->nmin_scale; e++)
                for (int b = o->bits_lo; b <= o->bits_hi; b++)
                    res->rows[k++].s = (cbvh_sweep_setting){b, o->mant[m], o->min_scale[e], units[u]};

    cbvh_tri *tris0 = xcalloc(d->mesh.ntris, sizeof *tris0);
    cbvh_scene_desc_frame(d, 0, tris0);
    sweep_ctx c = {.d = d, .o = o, .tris0 = tris0, .setting = -1, .nsettings = res->nrows + o->nextra, .label = "float",
                   .spp = res->spp};
    int rc = -1;
    res->ref.s = (cbvh_sweep_setting){0, CBVH_MANT_MAX, o->min_scale[0], 0};
    if (run_one(&c, &res->ref, "float", err, errlen)) goto out;
    res->ref_rays = c.nrec;
    if (o->corrupt_setting >= 0 && o->corrupt_ray >= c.nrec) { /* a fault that never fires would pass */
        snprintf(err, errlen, "--test-corrupt %d:%llu: no ray %llu, the sweep traces rays 0..%llu", o->corrupt_setting,
                 (unsigned long long)o->corrupt_ray, (unsigned long long)o->corrupt_ray,
                 (unsigned long long)c.nrec - 1);
        goto out;
    }
    res->all_same = 1;
    char label[72]; /* a format name (47 chars) and " M=" with its value fit */
    for (int i = 0; i < res->nrows; i++) {
        cbvh_sweep_run_t *run = &res->rows[i];
        snprintf(label, sizeof label, "N=%d M=%d E=%d%s%s", run->s.bits, run->s.mant, run->s.min_scale,
                 nu > 1 ? " " : "", nu > 1 ? cbvh_box_units[run->s.box_unit].name : "");
        c.setting = i;
        c.label = label;
        if (run_one(&c, run, "cbvh", err, errlen)) goto out;
        check_totals(&c, run, res);
    }
    for (int k = 0; k < o->nextra; k++) {
        const cbvh_sweep_format *f = &o->extra[k];
        cbvh_sweep_run_t *run = &res->extra[k];
        res->nextra = k + 1;
        run->s = (cbvh_sweep_setting){0, o->mant[0], o->min_scale[0], 0};
        cbvh_sweep_format_label(f, run->s.mant, label, sizeof label);
        c.setting = res->nrows + k;
        c.label = label;
        if (run_one(&c, run, f->name, err, errlen)) goto out;
        check_totals(&c, run, res);
    }
    if (timed_reps(&c, res, err, errlen)) goto out;
    rc = 0;
out:
    free(c.rec);
    free(tris0);
    if (rc) cbvh_sweep_free(res);
    return rc;
}

void cbvh_sweep_free(cbvh_sweep_result *res) {
    free(res->ref.box_px);
    free(res->ref.tri_px);
    free(res->ref.image);
    for (int i = 0; res->rows && i < res->nrows; i++) {
        free(res->rows[i].box_px);
        free(res->rows[i].tri_px);
        free(res->rows[i].image);
    }
    free(res->rows);
    for (int k = 0; k < res->nextra; k++) {
        free(res->extra[k].box_px);
        free(res->extra[k].tri_px);
        free(res->extra[k].image);
    }
    memset(res, 0, sizeof *res);
}

void cbvh_sweep_per_ray(const cbvh_fx_stats *s, const cbvh_machine *mc, double out[SWEEP_NMETRICS]) {
    cbvh_ray_metrics m;
    cbvh_ray_metrics_of(s, mc, &m);
    out[SWEEP_BOX] = m.box;
    out[SWEEP_TRI] = m.tri;
    out[SWEEP_BYTES] = m.bytes;
    out[SWEEP_MODEL_NS] = m.model_ns;
    out[SWEEP_CPU_US] = m.cpu_us;
    out[SWEEP_ENERGY] = m.energy_nj;
}

void cbvh_pareto_front(const double (*cost)[3], int n, int *front) {
    for (int i = 0; i < n; i++) {
        const double *a = cost[i];
        front[i] = !isnan(a[0]) && !isnan(a[1]) && !isnan(a[2]);
        for (int j = 0; j < n && front[i]; j++) {
            const double *b = cost[j];
            if (j == i || isnan(b[0]) || isnan(b[1]) || isnan(b[2])) continue;
            int le = b[0] <= a[0] && b[1] <= a[1] && b[2] <= a[2];
            int lt = b[0] < a[0] || b[1] < a[1] || b[2] < a[2];
            if (le && lt) front[i] = 0;
        }
    }
}

int cbvh_argmin(const double *v, int n) {
    int k = -1;
    for (int i = 0; i < n; i++)
        if (isfinite(v[i]) && (k < 0 || v[i] < v[k])) k = i;
    return k;
}

const cbvh_format *cbvh_sweep_format_find(const char *spec) {
    const cbvh_format *f = cbvh_format_find(spec);
    return f && !(f->flags & (CBVH_FORMAT_REFERENCE | CBVH_FORMAT_USES_N)) ? f : NULL;
}

int cbvh_sweep_format_parse(const char *spec, cbvh_sweep_format *f, char *err, size_t errlen) {
    memset(f, 0, sizeof *f);
    if (!cbvh_sweep_format_find(spec)) {
        char syntax[200];
        cbvh_sweep_formats_syntax(syntax, sizeof syntax);
        snprintf(err, errlen, "format '%s': expected one of %s", spec, syntax);
        return -1;
    }
    return cbvh_format_parse(spec, &f->ops, f->name, sizeof f->name, err, errlen);
}

void cbvh_sweep_formats_syntax(char *out, size_t n) {
    size_t nf, used = (size_t)snprintf(out, n, "cbvh");
    const cbvh_format *const *fmts = cbvh_formats(&nf);
    for (size_t i = 0; i < nf && used < n; i++)
        if (cbvh_sweep_format_find(fmts[i]->name))
            used += (size_t)snprintf(out + used, n - used, "[,%s%s]", fmts[i]->name,
                                     fmts[i]->flags & CBVH_FORMAT_OPTIONS ? "[:options]..." : "");
}

void cbvh_sweep_format_label(const cbvh_sweep_format *f, int mant, char *out, size_t n) {
    if (f->ops->flags & CBVH_FORMAT_USES_MANT)
        snprintf(out, n, "%s M=%d", f->name, mant);
    else
        snprintf(out, n, "%s", f->name);
}

const char *cbvh_sweep_others(const cbvh_sweep_format *extra, int nextra, char *buf, size_t n) {
    if (nextra == 1 && !(extra[0].ops->flags & CBVH_FORMAT_OPTIONS))
        snprintf(buf, n, " and the %s", extra[0].ops->title);
    else
        snprintf(buf, n, "%s", nextra ? " and the other formats" : "");
    return buf;
}

int cbvh_sweep_knee(const int *bits, const double *rel, int n, double tol) {
    for (int i = 0; i < n; i++)
        if (!isfinite(rel[i])) return 0; /* the float BVH did none: no ratios, no knee */
    double limit = (1 + tol) * rel[n - 1];
    int k = n - 1;
    while (k > 0 && rel[k - 1] <= limit) k--;
    return bits[k];
}
