/* Golden vector generator: TestFloat-style structured corner cases (level 1)
 * plus random cases (level 2).  Integer-only: inputs are built as binary32
 * bit patterns, so the files are identical on every host.  Each unit's cases
 * are in its own file, host/vectors/gen/<unit>.c (gen/gen.h); this file
 * lists them and writes the files. */
#include "vectors/vecgen.h"

#include "vectors/gen/gen.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One entry per unit (defined in host/vectors/gen/<unit>.c). */
extern const vg_unit vg_scale_estimate, vg_axis_compress, vg_axis_decode, vg_nodepair_encode, vg_nodepair_decode,
    vg_ray_box, vg_ray_triangle, vg_qbvh_stack, vg_ray_sphere, vg_ray_box_incr;
static const vg_unit *const unit_gens[] = {
    &vg_scale_estimate, &vg_axis_compress, &vg_axis_decode, &vg_nodepair_encode, &vg_nodepair_decode,
    &vg_ray_box,        &vg_ray_triangle,  &vg_qbvh_stack,  &vg_ray_sphere,     &vg_ray_box_incr,
};

static const vg_unit *find_gen(const cbvh_unit *u) {
    for (size_t i = 0; i < sizeof unit_gens / sizeof unit_gens[0]; i++)
        if (strcmp(u->name, unit_gens[i]->unit) == 0) return unit_gens[i];
    return NULL;
}

static void stem(const cbvh_vecgen_spec *s, char *buf, size_t n) {
    if (s->unit->uses_encoding)
        snprintf(buf, n, "%s-N%d-ms%d-%s", s->unit->name, s->cfg.params.quant_bits, s->cfg.params.min_scale,
                 cbvh_encoding_name(s->cfg.enc));
    else
        snprintf(buf, n, "%s-N%d-ms%d", s->unit->name, s->cfg.params.quant_bits, s->cfg.params.min_scale);
}

void cbvh_vecgen_filename(const cbvh_vecgen_spec *s, char *buf, size_t n) {
    char st[128];
    stem(s, st, sizeof st);
    snprintf(buf, n, "%s%s.vec", st, s->level >= 2 ? "-L2" : "");
}

int cbvh_vecgen_generate(const cbvh_vecgen_spec *s, cbvh_vecfile *vf) {
    memset(vf, 0, sizeof *vf);
    gen_t g;
    memset(&g, 0, sizeof g);
    g.spec = s;
    s->unit->layout(&s->cfg, &g.lay);
    g.N = s->cfg.params.quant_bits;
    g.ms = s->cfg.params.min_scale;
    g.mask = (1u << g.N) - 1u;
    /* One stream per file: the seed mixed with the file's stem (FNV-1a), the
     * same for both levels so level 2 extends level 1. */
    char st[128];
    stem(s, st, sizeof st);
    uint64_t h = UINT64_C(0xCBF29CE484222325);
    for (const char *c = st; *c; c++) h = (h ^ (uint8_t)*c) * UINT64_C(0x100000001B3);
    rng_seed(&g.rng, s->seed ^ h);
    g.stream = s->seed ^ h;

    const vg_unit *ug = find_gen(s->unit);
    if (!ug) return -1;
    ug->gen(&g, ug->level1);
    rng_t ex; /* generator 2: the exact-path cases, from a stream of their own */
    rng_seed(&ex, g.stream ^ UINT64_C(0xE7AC7CA5E5000002));
    if (ug->exact) ug->exact(&g, &ex, ug->n_exact);
    if (ug->appended) ug->appended(&g);
    if (s->level >= 2) {
        g.random_only = 1;
        ug->gen(&g, g.n + CBVH_VECGEN_LEVEL2_RANDOM);
        if (ug->exact) ug->exact(&g, &ex, CBVH_VECGEN_LEVEL2_EXACT);
    }
    if (g.oom) {
        free(g.in);
        return -1;
    }
    uint32_t *out = malloc((g.n ? g.n : 1) * (size_t)g.lay.n_out * sizeof *out);
    if (!out) {
        free(g.in);
        return -1;
    }
    for (size_t i = 0; i < g.n; i++)
        s->unit->eval(&s->cfg, g.in + i * (size_t)g.lay.n_in, out + i * (size_t)g.lay.n_out);
    vf->unit = s->unit;
    vf->cfg = s->cfg;
    if (!s->unit->uses_encoding) vf->cfg.enc = CBVH_ENC_MODULO;
    vf->level = s->level;
    vf->seed = s->seed;
    vf->generator = CBVH_VECGEN_VERSION;
    vf->layout = g.lay;
    vf->count = g.n;
    vf->first_line = 0;
    vf->in = g.in;
    vf->out = out;
    return 0;
}

size_t cbvh_vecgen_specs(const cbvh_vecgen_select *sel, cbvh_vecgen_spec *out, size_t max) {
    size_t n = 0;
    for (int pass = 0; pass < 2; pass++) {
        /* pass 0: the N sweep; pass 1: the extra minimum scales (default set only) */
        if (pass == 1 && (sel->bits || sel->ms_given)) break;
        for (int u = 0; u < cbvh_unit_count; u++) {
            const cbvh_unit *unit = cbvh_units[u];
            const vg_unit *ug = find_gen(unit);
            if (!ug || (sel->unit && sel->unit != unit)) continue;
            if (pass == 1 && !ug->extra_min_scales) continue;
            static const int extra_ms[] = {CBVH_SCALE_FLOOR, -10};
            int nlo = sel->bits ? sel->bits : CBVH_N_MIN, nhi = sel->bits ? sel->bits : CBVH_N_MAX;
            if (pass == 1) nlo = nhi = CBVH_N_DEFAULT;
            if (!ug->per_n && !sel->bits) nlo = nhi = CBVH_N_DEFAULT;
            for (int bits = nlo; bits <= nhi; bits++)
                for (int m = 0; m < (pass == 1 ? 2 : 1); m++)
                    for (int e = 0; e < (unit->uses_encoding ? 2 : 1); e++) {
                        cbvh_encoding enc = e ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO;
                        if (unit->uses_encoding && sel->enc_given && enc != sel->enc) continue;
                        if (n < max) {
                            cbvh_vecgen_spec *s = &out[n];
                            s->unit = unit;
                            s->cfg.params.quant_bits = bits;
                            s->cfg.params.min_scale = pass == 1 ? extra_ms[m]
                                                      : sel->ms_given ? sel->min_scale
                                                                      : CBVH_MIN_SCALE_DEFAULT;
                            s->cfg.enc = enc;
                            s->level = sel->level;
                            s->seed = sel->seed;
                        }
                        n++;
                    }
        }
    }
    return n;
}
