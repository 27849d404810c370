/* The C model through DPI-C for Verilator testbenches (cbvh_dpi.h;
 * docs/gateware.md, "DPI-C scoreboard").  Generic over the unit table: a
 * unit is found by name, its words are the table's; only the stimulus may be
 * the unit's own.  Every input word holds only what its field can (the
 * field's hex digits), as in a vector file and at the unit's ports. */
#include "cbvh_dpi.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/ray_box_incr.h"
#include "cbvh/unit_table.h"
#include "gen_inputs.h" /* tests/board: the generic mix per field */
#include "rbi_chain.h"  /* tests/common: chains of boxes and random inputs of unit 10 */

#define MAX_HANDLES 8
#define MAX_PINS 8

typedef struct {
    const cbvh_unit *unit;
    cbvh_unit_config cfg;
    cbvh_layout lay;
    uint64_t rng;
    int npins, pin_field[MAX_PINS];
    uint32_t pin_value[MAX_PINS];
    /* ray_box_incr: the chain being walked and its second child, not yet given out */
    rbi_chain chain;
    int chain_live, child_left, chain_kind;
    uint32_t child_words[CBVH_DPI_WORDS];
} handle;

static handle handles[MAX_HANDLES];
static int nhandles;

static handle *get(int h) {
    if (h < 0 || h >= nhandles) {
        fprintf(stderr, "cbvh_dpi: bad handle %d\n", h);
        exit(2);
    }
    return &handles[h];
}

static int pin_of(const handle *x, const char *name, uint32_t *v) {
    for (int i = 0; i < x->npins; i++)
        if (strcmp(x->lay.in[x->pin_field[i]].name, name) == 0) {
            *v = x->pin_value[i];
            return 1;
        }
    return 0;
}

int cbvh_dpi_open(const char *unit, int quant_bits, int min_scale, int modulo, const char *pins, int seed) {
    if (nhandles == MAX_HANDLES) {
        fprintf(stderr, "cbvh_dpi: more than %d units open\n", MAX_HANDLES);
        return -1;
    }
    handle *x = &handles[nhandles];
    memset(x, 0, sizeof *x);
    x->unit = cbvh_unit_find(unit);
    if (!x->unit) {
        fprintf(stderr, "cbvh_dpi: no unit '%s' in the unit table\n", unit);
        return -1;
    }
    x->cfg.params.quant_bits = quant_bits;
    x->cfg.params.min_scale = min_scale;
    x->cfg.enc = modulo ? CBVH_ENC_MODULO : CBVH_ENC_RELATIVE;
    if (cbvh_params_check(&x->cfg.params)) {
        fprintf(stderr, "cbvh_dpi: %s: bad design point N %d, min scale %d\n", unit, quant_bits, min_scale);
        return -1;
    }
    x->unit->layout(&x->cfg, &x->lay);
    x->rng = 0x9E3779B97F4A7C15u ^ (uint64_t)(uint32_t)seed * 0x100000001B3u;
    for (const char *p = pins ? pins : ""; *p;) { /* name=value[,name=value...] */
        char name[64];
        long value;
        int used = 0;
        if (sscanf(p, "%63[^=,]=%li%n", name, &value, &used) != 2) {
            fprintf(stderr, "cbvh_dpi: bad pin list '%s' (name=value,...)\n", pins);
            return -1;
        }
        int f = -1;
        for (int i = 0; i < x->lay.n_in; i++)
            if (strcmp(x->lay.in[i].name, name) == 0) f = i;
        if (f < 0 || x->npins == MAX_PINS) {
            fprintf(stderr, "cbvh_dpi: %s has no input field '%s'\n", unit, name);
            return -1;
        }
        x->pin_field[x->npins] = f;
        x->pin_value[x->npins++] = (uint32_t)value;
        p += used;
        if (*p == ',') p++;
    }
    return nhandles++;
}

int cbvh_dpi_n_in(int h) { return get(h)->lay.n_in; }
int cbvh_dpi_n_out(int h) { return get(h)->lay.n_out; }
const char *cbvh_dpi_field(int h, int out, int i) {
    const handle *x = get(h);
    if (i < 0 || i >= (out ? x->lay.n_out : x->lay.n_in)) return "?";
    return out ? x->lay.out[i].name : x->lay.in[i].name;
}

/* ---- unit 10's stimulus (docs/traversal.md §17) ---- */
static void incr_words(const handle *x, const cbvh_rbi_ray *ray, const cbvh_rbi_params *p, const cbvh_rbi_planes *par,
                       const cbvh_rbi_axis ch[3], uint32_t *in) {
    (void)x;
    in[0] = ray->rcp[0], in[1] = ray->rcp[1], in[2] = ray->rcp[2];
    in[3] = ray->tmin, in[4] = ray->tmax;
    in[5] = (uint32_t)p->mant, in[6] = (uint32_t)p->texp;
    for (int a = 0; a < 3; a++) {
        uint32_t *w = in + 7 + 5 * a;
        w[0] = par->t_lb[a], w[1] = par->t_ub[a], w[2] = cbvh_scale_to_word(ch[a].e), w[3] = ch[a].r, w[4] = ch[a].sp;
    }
}

/* 1/2 children along chains of boxes (every structured kind in turn), 3/8
 * random valid inputs, 1/8 the generic mix (mostly rejects). */
static int stim_ray_box_incr(handle *x, uint32_t *in) {
    uint32_t M = 0, X = 0;
    if (!pin_of(x, "mant", &M) || !pin_of(x, "texp", &X)) return 0; /* no design point: the generic mix */
    cbvh_rbi_params p = {x->cfg.params.quant_bits, (int)M, (int)X};
    if (cbvh_rbi_params_check(&p)) return 0;
    uint64_t k = tu_xorshift64(&x->rng) % 8;
    if (k == 0) return 0;
    if (k < 4) {
        cbvh_rbi_ray ray;
        cbvh_rbi_planes par;
        cbvh_rbi_axis ch[3];
        rbi_random_inputs(&x->rng, &p, &ray, &par, ch);
        incr_words(x, &ray, &p, &par, ch, in);
        return 1;
    }
    if (x->child_left) { /* the other child of the last step */
        memcpy(in, x->child_words, sizeof x->child_words);
        x->child_left = 0;
        return 1;
    }
    for (int tries = 0; tries < 100; tries++) {
        if (!x->chain_live) {
            x->chain_kind = (x->chain_kind + 1) % RBI_KINDS;
            if (rbi_chain_start(&x->chain, &p, &x->rng, x->chain_kind)) continue;
            x->chain_live = 1;
        }
        cbvh_rbi_planes par = x->chain.T;
        rbi_child ch[2];
        x->chain_live = rbi_chain_step(&x->chain, ch);
        incr_words(x, &x->chain.rr, &p, &par, ch[0].ax, in);
        incr_words(x, &x->chain.rr, &p, &par, ch[1].ax, x->child_words);
        x->child_left = 1;
        return 1;
    }
    return 0;
}

void cbvh_dpi_stimulus(int h, uint32_t *in) {
    handle *x = get(h);
    memset(in, 0, CBVH_DPI_WORDS * sizeof *in);
    int done = 0;
    if (strcmp(x->unit->name, "ray_box_incr") == 0) done = stim_ray_box_incr(x, in);
    if (!done) cbvh_gen_inputs(&x->rng, &x->cfg, &x->lay, in, 1);
    for (int i = 0; i < x->npins; i++) in[x->pin_field[i]] = x->pin_value[i];
    for (int i = 0; i < x->lay.n_in; i++) /* a word holds what its field can (as in a vector file) */
        if (x->lay.in[i].hex_digits < 8) in[i] &= (UINT32_C(1) << (4 * x->lay.in[i].hex_digits)) - 1u;
}

void cbvh_dpi_eval(int h, const uint32_t *in, uint32_t *out) {
    handle *x = get(h);
    memset(out, 0, CBVH_DPI_WORDS * sizeof *out);
    x->unit->eval(&x->cfg, in, out);
}
