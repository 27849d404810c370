/* An outside program built against an installed libcbvh (tests/install): only
 * the installed headers, linked shared or static, run with the installed
 * golden vectors.  Usage: consumer VECTORS_DIR.  Exit 0 when
 *   1. the axis compressor, the axis decoder (both encodings) and the ray-box
 *      unit, called through their own functions, reproduce every line of
 *      their N = 6 vector files, and every vector file of the MANIFEST passes
 *      through the word-level unit table (cbvh/unit_table.h);
 *   2. on random children inside random nodes, compress -> store -> decode
 *      gives back the compressor's fields, and the decoded box encloses the
 *      child (docs/datapath.md §7, §12);
 *   3. a ray from outside a box through its centre hits it with
 *      t_near <= 1 <= t_far, and the reversed ray misses (docs/traversal.md §3).
 * Any failure prints one line and exits 1. */
#include <cbvh/datapath.h>
#include <cbvh/fp32.h>
#include <cbvh/traversal_units.h>
#include <cbvh/unit_table.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void fail(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fputs("consumer: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    exit(1);
}

/* ---- vector files (docs/vectors.md) --------------------------------------- */
typedef struct {
    char unit[64], fields[512];
    cbvh_unit_config cfg;
    FILE *f;
    long line;
} vecfile;

static void vec_open(vecfile *v, const char *dir, const char *name) {
    char path[1024], buf[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    memset(v, 0, sizeof *v);
    if (!(v->f = fopen(path, "r"))) fail("%s: cannot open", path);
    v->cfg.enc = CBVH_ENC_MODULO;
    while (fgets(buf, sizeof buf, v->f)) {
        v->line++;
        buf[strcspn(buf, "\n")] = '\0';
        if (!strcmp(buf, "---")) return;
        char *val = strstr(buf, ": ");
        if (!val) continue;
        *val = '\0';
        val += 2;
        if (!strcmp(buf, "unit")) snprintf(v->unit, sizeof v->unit, "%s", val);
        if (!strcmp(buf, "fields")) snprintf(v->fields, sizeof v->fields, "%s", val);
        if (!strcmp(buf, "quant_bits")) v->cfg.params.quant_bits = atoi(val);
        if (!strcmp(buf, "min_scale")) v->cfg.params.min_scale = atoi(val);
        if (!strcmp(buf, "encoding") && cbvh_encoding_parse(val, &v->cfg.enc) != 0) fail("%s: encoding %s", name, val);
    }
    fail("%s: no '---' after the header", name);
}

/* The next vector: n_in inputs then n_out expected outputs; 0 at the end. */
static int vec_next(vecfile *v, int n_in, uint32_t *in, int n_out, uint32_t *out) {
    char buf[2048];
    if (!fgets(buf, sizeof buf, v->f)) return 0;
    v->line++;
    char *p = buf;
    for (int i = 0; i < n_in + n_out; i++) {
        char *end;
        unsigned long w = strtoul(p, &end, 16);
        if (end == p) fail("%s line %ld: %d fields, expected %d", v->unit, v->line, i, n_in + n_out);
        if (i < n_in) in[i] = (uint32_t)w;
        else out[i - n_in] = (uint32_t)w;
        p = end;
    }
    return 1;
}

static void expect_fields(const vecfile *v, const char *fields) {
    if (strcmp(v->fields, fields)) fail("%s: fields '%s', this program knows '%s'", v->unit, v->fields, fields);
}

static void check_word(const vecfile *v, const char *what, uint32_t got, uint32_t want) {
    if (got != want) fail("%s line %ld: %s = %08X, the vector says %08X", v->unit, v->line, what, got, want);
}

/* The six outputs both axis units share: the code and the status. */
static void check_code(const vecfile *v, const cbvh_axis_code *c, uint32_t st, const uint32_t out[6]) {
    check_word(v, "lb_mod", c->lb_mod, out[0]);
    check_word(v, "ub_mod", c->ub_mod, out[1]);
    check_word(v, "child_scale", cbvh_scale_to_word(c->child_scale), out[2]);
    check_word(v, "clb", c->clb, out[3]);
    check_word(v, "cub", c->cub, out[4]);
    check_word(v, "status", st, out[5]);
}

static long check_compress(const char *dir) {
    vecfile v;
    vec_open(&v, dir, "axis_compress-N6-ms-30.vec");
    expect_fields(&v, "lb ub scale node_clb -> lb_mod ub_mod child_scale clb cub status");
    uint32_t in[4], out[6];
    long n = 0;
    for (; vec_next(&v, 4, in, 6, out); n++) {
        cbvh_axis_code c;
        memset(&c, 0, sizeof c);
        uint32_t st = cbvh_axis_compress(&v.cfg.params, in[0], in[1], cbvh_scale_from_word(in[2]), in[3], &c);
        check_code(&v, &c, st, out);
    }
    fclose(v.f);
    return n;
}

static long check_decode(const char *dir, const char *file) {
    vecfile v;
    vec_open(&v, dir, file);
    expect_fields(&v, "parent_scale scale node_lb_mod node_clb lb_code ub_code -> lb_mod ub_mod child_scale clb cub status");
    uint32_t in[6], out[6];
    long n = 0;
    for (; vec_next(&v, 6, in, 6, out); n++) {
        cbvh_axis_ctx ctx = {cbvh_scale_from_word(in[0]), cbvh_scale_from_word(in[1]), in[2], in[3]};
        cbvh_axis_code c;
        memset(&c, 0, sizeof c);
        uint32_t st = cbvh_axis_decode(&v.cfg.params, v.cfg.enc, &ctx, in[4], in[5], &c);
        check_code(&v, &c, st, out);
    }
    fclose(v.f);
    return n;
}

static long check_ray_box(const char *dir) {
    vecfile v;
    vec_open(&v, dir, "ray_box-N6-ms-30.vec");
    expect_fields(&v, "ox oy oz dx dy dz tmin tmax mant x_u x_scale x_r x_s y_u y_scale y_r y_s z_u z_scale z_r z_s "
                      "-> hit t_near t_far status");
    uint32_t in[21], out[4];
    long n = 0;
    for (; vec_next(&v, 21, in, 4, out); n++) {
        cbvh_ray ray = {{in[0], in[1], in[2]}, {in[3], in[4], in[5]}, in[6], in[7]};
        cbvh_grid_axis ax[3];
        for (int a = 0; a < 3; a++)
            ax[a] = (cbvh_grid_axis){in[9 + 4 * a], cbvh_scale_from_word(in[10 + 4 * a]), in[11 + 4 * a],
                                     in[12 + 4 * a]};
        cbvh_box_result r;
        memset(&r, 0, sizeof r);
        uint32_t st = cbvh_ray_box(&ray, (int)in[8], ax, &r);
        check_word(&v, "hit", (uint32_t)r.hit, out[0]);
        check_word(&v, "t_near", r.t_near, out[1]);
        check_word(&v, "t_far", r.t_far, out[2]);
        check_word(&v, "status", st, out[3]);
    }
    fclose(v.f);
    return n;
}

/* Every file of the MANIFEST through the unit table. */
static long check_manifest(const char *dir, int *files) {
    char path[1024], line[1024];
    snprintf(path, sizeof path, "%s/MANIFEST", dir);
    FILE *m = fopen(path, "r");
    if (!m) fail("%s: cannot open", path);
    long n = 0;
    *files = 0;
    while (fgets(line, sizeof line, m)) {
        char name[512];
        if (sscanf(line, "%*64s %511s", name) != 1) continue;
        vecfile v;
        vec_open(&v, dir, name);
        const cbvh_unit *u = cbvh_unit_find(v.unit);
        if (!u) fail("%s: unit '%s' not in the library's unit table", name, v.unit);
        cbvh_layout lay;
        u->layout(&v.cfg, &lay);
        uint32_t in[CBVH_MAX_FIELDS], want[CBVH_MAX_FIELDS], got[CBVH_MAX_FIELDS];
        while (vec_next(&v, lay.n_in, in, lay.n_out, want)) {
            memset(got, 0, sizeof got);
            u->eval(&v.cfg, in, got);
            for (int i = 0; i < lay.n_out; i++) check_word(&v, lay.out[i].name, got[i], want[i]);
            n++;
        }
        fclose(v.f);
        ++*files;
    }
    fclose(m);
    return n;
}

/* ---- properties ------------------------------------------------------------ */
static uint64_t rng = 0x9E3779B97F4A7C15u;
static double uniform(void) { /* [0, 1) */
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static int f32_le(cbvh_f32 a, cbvh_f32 b) { return cbvh_f32_cmp(a, b) <= 0; }

static long check_roundtrip(void) {
    long n = 0;
    for (int quant_bits = CBVH_N_MIN; quant_bits <= CBVH_N_MAX; quant_bits++) {
        cbvh_params p = {quant_bits, CBVH_MIN_SCALE_DEFAULT};
        for (int node = 0; node < 300; node++) {
            float lo = (float)((uniform() - 0.5) * 2000.0), hi = lo + (float)(uniform() * 100.0);
            cbvh_axis_ctx ctx;
            uint32_t st = cbvh_axis_root_ctx(&p, cbvh_f32_of(lo), cbvh_f32_of(hi), &ctx);
            if (st) fail("root [%g, %g] N=%d: status %u", lo, hi, quant_bits, st);
            for (int child = 0; child < 20; child++) {
                float a = lo + (float)uniform() * (hi - lo), b = lo + (float)uniform() * (hi - lo);
                float clo = a < b ? a : b, chi = a < b ? b : a;
                cbvh_axis_code code;
                st = cbvh_axis_compress(&p, cbvh_f32_of(clo), cbvh_f32_of(chi), ctx.scale, ctx.clb, &code);
                if (st) fail("compress [%g, %g] in [%g, %g] N=%d: status %u", clo, chi, lo, hi, quant_bits, st);
                if (!f32_le(code.clb, cbvh_f32_of(clo)) || !f32_le(cbvh_f32_of(chi), code.cub))
                    fail("compress [%g, %g] N=%d: decoded [%g, %g] does not enclose it", clo, chi, quant_bits,
                         cbvh_float_of(code.clb), cbvh_float_of(code.cub));
                for (int enc = CBVH_ENC_MODULO; enc <= CBVH_ENC_RELATIVE; enc++) {
                    uint32_t lbc, ubc;
                    cbvh_axis_code back;
                    cbvh_axis_store_codes(&p, (cbvh_encoding)enc, &ctx, &code, &lbc, &ubc);
                    st = cbvh_axis_decode(&p, (cbvh_encoding)enc, &ctx, lbc, ubc, &back);
                    if (st || back.lb_mod != code.lb_mod || back.ub_mod != code.ub_mod ||
                        back.child_scale != code.child_scale || back.clb != code.clb || back.cub != code.cub)
                        fail("[%g, %g] N=%d %s: decode(compress) differs from compress (status %u)", clo, chi,
                             quant_bits, cbvh_encoding_name((cbvh_encoding)enc), st);
                    n++;
                }
            }
        }
    }
    return n;
}

static long check_ray_box_centre(void) {
    long n = 0;
    for (int i = 0; i < 2000; i++) {
        float c[3], half[3], o[3];
        cbvh_f32 lo[3], hi[3];
        cbvh_ray ray, back;
        for (int a = 0; a < 3; a++) {
            c[a] = (float)((uniform() - 0.5) * 200.0);
            half[a] = (float)(0.5 + uniform() * 10.0);
            lo[a] = cbvh_f32_of(c[a] - half[a]);
            hi[a] = cbvh_f32_of(c[a] + half[a]);
        }
        /* an origin outside the box: 3 to 10 half-widths from the centre on one axis */
        int axis = (int)(uniform() * 3.0);
        for (int a = 0; a < 3; a++) o[a] = c[a] + (float)((uniform() - 0.5) * 2.0) * half[a];
        o[axis] = c[axis] + (uniform() < 0.5 ? -1.0f : 1.0f) * half[axis] * (float)(3.0 + uniform() * 7.0);
        for (int a = 0; a < 3; a++) {
            ray.o[a] = back.o[a] = cbvh_f32_of(o[a]);
            ray.d[a] = cbvh_f32_of(c[a] - o[a]); /* o + 1 * d is the centre, up to rounding */
            back.d[a] = cbvh_f32_of(o[a] - c[a]);
        }
        ray.tmin = back.tmin = cbvh_f32_of(0.0f);
        ray.tmax = back.tmax = CBVH_F32_POS_INF;
        for (int mant = CBVH_MANT_MIN; mant <= CBVH_MANT_MAX; mant += 7) {
            cbvh_box_result r;
            uint32_t st = cbvh_ray_box_float(&ray, mant, lo, hi, &r);
            if (st || !r.hit || !f32_le(r.t_near, cbvh_f32_of(1.0f)) || !f32_le(cbvh_f32_of(1.0f), r.t_far))
                fail("ray %d M=%d through the box centre: status %u hit %d t [%g, %g]", i, mant, st, r.hit,
                     cbvh_float_of(r.t_near), cbvh_float_of(r.t_far));
            st = cbvh_ray_box_float(&back, mant, lo, hi, &r);
            if (st || r.hit) fail("ray %d M=%d away from the box: status %u hit %d", i, mant, st, r.hit);
            n += 2;
        }
    }
    return n;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: consumer VECTORS_DIR\n");
        return 2;
    }
    long comp = check_compress(argv[1]);
    long dec = check_decode(argv[1], "axis_decode-N6-ms-30-modulo.vec") +
               check_decode(argv[1], "axis_decode-N6-ms-30-relative.vec");
    long box = check_ray_box(argv[1]);
    int files;
    long all = check_manifest(argv[1], &files);
    long rt = check_roundtrip(), centre = check_ray_box_centre();
    printf("consumer: vectors: %ld axis_compress, %ld axis_decode, %ld ray_box through the units' functions; "
           "%ld in %d files through the unit table\n",
           comp, dec, box, all, files);
    printf("consumer: %ld compress/decode round trips enclose their child; %ld ray-box centre/away checks\n", rt,
           centre);
    return 0;
}
