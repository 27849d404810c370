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
    if (c->o->progress) c->o->progress(c->o->ctx, c->label, c->setting + 1, c->nsettings, row, rows);
}

static int run_one(sweep_ctx *c, cbvh_sweep_run_t *run, cbvh_accel_format fmt, const cbvh_tlist_opts *tl, char *err,
                   size_t errlen) {
    size_t npx = (size_t)c->d->camera.width * (size_t)c->d->camera.height;
    run->box_px = xcalloc(npx, sizeof *run->box_px);
    run->image = xcalloc(npx, 1);
    c->shade = xcalloc(npx, sizeof *c->shade);
    c->run = run;
    c->n = 0;
    run->same = 1;
    cbvh_fx_opts fo = {.format = fmt,
                       .params = {run->s.bits ? run->s.bits : CBVH_N_DEFAULT, run->s.min_scale},
                       .mant = run->s.mant,
                       .spp = c->o->spp,
                       .on_ray = on_ray,
                       .progress = on_progress,
                       .ctx = c};
    if (tl) fo.tlist = *tl;
    fo.one_sided = c->o->one_sided;
    int rc = cbvh_fx_run(c->d, &fo, &run->r, err, errlen);
    for (size_t p = 0; p < npx; p++) {
        double v = floor(c->shade[p] + 0.5);
        run->image[p] = (uint8_t)(v > 255 ? 255 : v);
    }
    free(c->shade);
    c->shade = NULL;
    return rc;
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
            snprintf(err, errlen, "--min-scale %d out of range %d..%d", o->min_scale[i], CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL);
            return -1;
        }
    int nb = o->bits_hi - o->bits_lo + 1;
    res->nrows = nb * o->nmant * o->nmin_scale;
    res->rows = xcalloc((size_t)res->nrows, sizeof *res->rows);
    res->width = d->camera.width;
    res->height = d->camera.height;
    res->spp = o->spp > 0 ? o->spp : d->camera.spp;
    res->frames = cbvh_scene_desc_frames(d);
    int k = 0;
    for (int m = 0; m < o->nmant; m++)
        for (int e = 0; e < o->nmin_scale; e++)
            for (int b = o->bits_lo; b <= o->bits_hi; b++)
                res->rows[k++].s = (cbvh_sweep_setting){b, o->mant[m], o->min_scale[e]};

    cbvh_tri *tris0 = xcalloc(d->mesh.ntris, sizeof *tris0);
    cbvh_scene_desc_frame(d, 0, tris0);
    sweep_ctx c = {.d = d, .o = o, .tris0 = tris0, .setting = -1, .nsettings = res->nrows + o->nextra, .label = "float",
                   .spp = res->spp};
    int rc = -1;
    res->ref.s = (cbvh_sweep_setting){0, CBVH_MANT_MAX, o->min_scale[0]};
    if (run_one(&c, &res->ref, CBVH_FORMAT_FLOAT, NULL, err, errlen)) goto out;
    res->ref_rays = c.nrec;
    res->all_same = 1;
    char label[72]; /* a format name (47 chars) and " M=" with its value fit */
    for (int i = 0; i < res->nrows; i++) {
        cbvh_sweep_run_t *run = &res->rows[i];
        snprintf(label, sizeof label, "N=%d M=%d E=%d", run->s.bits, run->s.mant, run->s.min_scale);
        c.setting = i;
        c.label = label;
        if (run_one(&c, run, CBVH_FORMAT_CBVH, NULL, err, errlen)) goto out;
        check_totals(&c, run, res);
    }
    for (int k = 0; k < o->nextra; k++) {
        const cbvh_sweep_format *f = &o->extra[k];
        cbvh_sweep_run_t *run = &res->extra[k];
        res->nextra = k + 1;
        run->s = (cbvh_sweep_setting){0, o->mant[0], o->min_scale[0]};
        if (f->format == CBVH_FORMAT_QBVH)
            snprintf(label, sizeof label, "%s M=%d", f->name, run->s.mant);
        else
            snprintf(label, sizeof label, "%s", f->name);
        c.setting = res->nrows + k;
        c.label = label;
        if (run_one(&c, run, f->format, &f->tlist, err, errlen)) goto out;
        check_totals(&c, run, res);
    }
    rc = 0;
out:
    free(c.rec);
    free(tris0);
    if (rc) cbvh_sweep_free(res);
    return rc;
}

void cbvh_sweep_free(cbvh_sweep_result *res) {
    free(res->ref.box_px);
    free(res->ref.image);
    for (int i = 0; res->rows && i < res->nrows; i++) {
        free(res->rows[i].box_px);
        free(res->rows[i].image);
    }
    free(res->rows);
    for (int k = 0; k < res->nextra; k++) {
        free(res->extra[k].box_px);
        free(res->extra[k].image);
    }
    memset(res, 0, sizeof *res);
}

void cbvh_sweep_per_ray(const cbvh_fx_stats *s, const cbvh_timing_params *tp, double out[SWEEP_NMETRICS]) {
    for (int i = 0; i < SWEEP_NMETRICS; i++) out[i] = 0;
    if (!s->rays) return;
    double n = (double)s->rays;
    out[SWEEP_BOX] = (double)s->st.box_tests / n;
    out[SWEEP_TRI] = (double)s->st.tri_tests / n;
    out[SWEEP_BYTES] = (double)s->st.bytes / n;
    cbvh_timing_work w = {s->st.box_tests, s->st.tri_tests, s->st.nodes, s->st.bytes};
    cbvh_timing_result tr;
    if (cbvh_timing_eval(tp, &w, &tr) == 0) out[SWEEP_MODEL_NS] = tr.seconds * 1e9 / n;
    out[SWEEP_CPU_US] = s->cpu_seconds * 1e6 / n;
}

int cbvh_sweep_knee(const int *bits, const double *rel, int n, double tol) {
    for (int i = 0; i < n; i++)
        if (!isfinite(rel[i])) return 0; /* the float BVH did none: no ratios, no knee */
    double limit = (1 + tol) * rel[n - 1];
    int k = n - 1;
    while (k > 0 && rel[k - 1] <= limit) k--;
    return bits[k];
}
