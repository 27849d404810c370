/* Word-level adapters from the unit table to the units (docs/vectors.md lists
 * the fields of each unit in this order). */
#include "cbvh/unit_table.h"

#include <string.h>

#include "cbvh/traversal_units.h"
#include "cbvh/qbvh_stack.h"
#include "cbvh/ray_box_incr.h"

static void add(cbvh_field *f, int *n, const char *name, int digits) {
    f[*n].name = name;
    f[*n].hex_digits = digits;
    (*n)++;
}

#define F32 8
#define SCALE 2
#define CODE 3
#define STATUS 2

/* ---- scale_estimate ---- */
static void estimate_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    add(l->in, &l->n_in, "lb", F32);
    add(l->in, &l->n_in, "ub", F32);
    add(l->out, &l->n_out, "scale", SCALE);
    add(l->out, &l->n_out, "status", STATUS);
}
static void estimate_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    int e;
    uint32_t st = cbvh_scale_estimate(&cfg->params, in[0], in[1], &e);
    out[0] = cbvh_scale_to_word(e);
    out[1] = st;
}

/* ---- shared axis-code output ---- */
static void code_layout(cbvh_layout *l) {
    add(l->out, &l->n_out, "lb_mod", CODE);
    add(l->out, &l->n_out, "ub_mod", CODE);
    add(l->out, &l->n_out, "child_scale", SCALE);
    add(l->out, &l->n_out, "clb", F32);
    add(l->out, &l->n_out, "cub", F32);
}
static void code_words(const cbvh_axis_code *c, uint32_t *out) {
    out[0] = c->lb_mod;
    out[1] = c->ub_mod;
    out[2] = cbvh_scale_to_word(c->child_scale);
    out[3] = c->clb;
    out[4] = c->cub;
}

/* ---- axis_compress ---- */
static void compress_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    add(l->in, &l->n_in, "lb", F32);
    add(l->in, &l->n_in, "ub", F32);
    add(l->in, &l->n_in, "scale", SCALE);
    add(l->in, &l->n_in, "node_clb", F32);
    code_layout(l);
    add(l->out, &l->n_out, "status", STATUS);
}
static void compress_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    cbvh_axis_code c;
    uint32_t st = cbvh_axis_compress(&cfg->params, in[0], in[1], cbvh_scale_from_word(in[2]), in[3], &c);
    code_words(&c, out);
    out[5] = st;
}

/* ---- axis_decode ---- */
static void ctx_layout(cbvh_layout *l, const char *const names[4]) {
    add(l->in, &l->n_in, names[0], SCALE);
    add(l->in, &l->n_in, names[1], SCALE);
    add(l->in, &l->n_in, names[2], CODE);
    add(l->in, &l->n_in, names[3], F32);
}
static cbvh_axis_ctx ctx_words(const uint32_t *in) {
    cbvh_axis_ctx c = {cbvh_scale_from_word(in[0]), cbvh_scale_from_word(in[1]), in[2], in[3]};
    return c;
}
static const char *const ctx_names[4] = {"parent_scale", "scale", "node_lb_mod", "node_clb"};
static void decode_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    ctx_layout(l, ctx_names);
    add(l->in, &l->n_in, "lb_code", CODE);
    add(l->in, &l->n_in, "ub_code", CODE);
    code_layout(l);
    add(l->out, &l->n_out, "status", STATUS);
}
static void decode_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    cbvh_axis_code c;
    cbvh_axis_ctx ctx = ctx_words(in);
    uint32_t st = cbvh_axis_decode(&cfg->params, cfg->enc, &ctx, in[4], in[5], &c);
    code_words(&c, out);
    out[5] = st;
}

/* ---- node pair ---- */
static const char *const axis_ctx_names[3][4] = {
    {"x_parent_scale", "x_scale", "x_node_lb_mod", "x_node_clb"},
    {"y_parent_scale", "y_scale", "y_node_lb_mod", "y_node_clb"},
    {"z_parent_scale", "z_scale", "z_node_lb_mod", "z_node_clb"},
};
static const char *const word_names[6] = {"word0", "word1", "word2", "word3", "word4", "word5"};
static const char *const child_box_names[2][6] = {
    {"c0_lo_x", "c0_hi_x", "c0_lo_y", "c0_hi_y", "c0_lo_z", "c0_hi_z"},
    {"c1_lo_x", "c1_hi_x", "c1_lo_y", "c1_hi_y", "c1_lo_z", "c1_hi_z"},
};
static const char *const child_out_names[2][17] = {
    {"c0_flags", "c0_ptr", "c0_x_lb_mod", "c0_x_ub_mod", "c0_x_child_scale", "c0_x_clb", "c0_x_cub", "c0_y_lb_mod",
     "c0_y_ub_mod", "c0_y_child_scale", "c0_y_clb", "c0_y_cub", "c0_z_lb_mod", "c0_z_ub_mod", "c0_z_child_scale",
     "c0_z_clb", "c0_z_cub"},
    {"c1_flags", "c1_ptr", "c1_x_lb_mod", "c1_x_ub_mod", "c1_x_child_scale", "c1_x_clb", "c1_x_cub", "c1_y_lb_mod",
     "c1_y_ub_mod", "c1_y_child_scale", "c1_y_clb", "c1_y_cub", "c1_z_lb_mod", "c1_z_ub_mod", "c1_z_child_scale",
     "c1_z_clb", "c1_z_cub"},
};

/* Words of a node pair: 4 to 6 for N = 3..10 (the configuration is checked
 * before any unit runs); bounded here so that the 24-byte buffers below are
 * visibly large enough (GCC -O3 warns otherwise). */
#define PAIR_WORDS_MAX 6
static int pair_words(const cbvh_unit_config *cfg) {
    int n = (int)cbvh_nodepair_bytes(cfg->params.quant_bits) / 4;
    return n > PAIR_WORDS_MAX ? PAIR_WORDS_MAX : n;
}

static void node_ctx_layout(cbvh_layout *l) {
    for (int a = 0; a < 3; a++) ctx_layout(l, axis_ctx_names[a]);
}
static cbvh_node_ctx node_ctx_words(const uint32_t *in) {
    cbvh_node_ctx c;
    for (int a = 0; a < 3; a++) c.axis[a] = ctx_words(in + 4 * a);
    return c;
}
static void words_from_bytes(const uint8_t *b, int n, uint32_t *w) {
    for (int i = 0; i < n; i++)
        w[i] = (uint32_t)b[4 * i] | (uint32_t)b[4 * i + 1] << 8 | (uint32_t)b[4 * i + 2] << 16 |
               (uint32_t)b[4 * i + 3] << 24;
}
static void bytes_from_words(const uint32_t *w, int n, uint8_t *b) {
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 4; j++) b[4 * i + j] = (uint8_t)(w[i] >> (8 * j));
}

static void encode_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    l->n_in = l->n_out = 0;
    node_ctx_layout(l);
    for (int c = 0; c < 2; c++) {
        for (int i = 0; i < 6; i++) add(l->in, &l->n_in, child_box_names[c][i], F32);
        add(l->in, &l->n_in, child_out_names[c][0], 1);
        add(l->in, &l->n_in, child_out_names[c][1], 8);
    }
    for (int i = 0; i < pair_words(cfg); i++) add(l->out, &l->n_out, word_names[i], 8);
    add(l->out, &l->n_out, "status", STATUS);
}
static void encode_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    cbvh_node_ctx ctx = node_ctx_words(in);
    cbvh_child_in ch[2];
    for (int c = 0; c < 2; c++) {
        const uint32_t *w = in + 12 + 8 * c;
        for (int a = 0; a < 3; a++) {
            ch[c].lo[a] = w[2 * a];
            ch[c].hi[a] = w[2 * a + 1];
        }
        ch[c].leaf = (int)(w[6] & 1u);
        ch[c].empty = (int)((w[6] >> 1) & 1u);
        ch[c].ptr = w[7];
    }
    uint8_t bytes[4 * PAIR_WORDS_MAX];
    cbvh_child_out o[2];
    uint32_t st = cbvh_nodepair_encode(&cfg->params, cfg->enc, &ctx, ch, bytes, o);
    int nw = pair_words(cfg);
    words_from_bytes(bytes, nw, out);
    out[nw] = st;
}

static void decode_pair_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    l->n_in = l->n_out = 0;
    node_ctx_layout(l);
    for (int i = 0; i < pair_words(cfg); i++) add(l->in, &l->n_in, word_names[i], 8);
    for (int c = 0; c < 2; c++) {
        add(l->out, &l->n_out, child_out_names[c][0], 1);
        add(l->out, &l->n_out, child_out_names[c][1], 8);
        for (int a = 0; a < 3; a++) {
            static const int digits[5] = {CODE, CODE, SCALE, F32, F32};
            for (int i = 0; i < 5; i++) add(l->out, &l->n_out, child_out_names[c][2 + 5 * a + i], digits[i]);
        }
    }
    add(l->out, &l->n_out, "status", STATUS);
}
static void decode_pair_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    cbvh_node_ctx ctx = node_ctx_words(in);
    uint8_t bytes[4 * PAIR_WORDS_MAX];
    int nw = pair_words(cfg);
    bytes_from_words(in + 12, nw, bytes);
    cbvh_child_out o[2];
    uint32_t st = cbvh_nodepair_decode(&cfg->params, cfg->enc, &ctx, bytes, o);
    uint32_t *w = out;
    for (int c = 0; c < 2; c++) {
        *w++ = (uint32_t)o[c].leaf | (uint32_t)o[c].empty << 1;
        *w++ = o[c].ptr;
        for (int a = 0; a < 3; a++, w += 5) code_words(&o[c].axis[a], w);
    }
    *w = st;
}

/* ---- ray_box (docs/traversal.md §3) ---- */
static const char *const ray_names[8] = {"ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax"};
static const char *const grid_names[3][4] = {
    {"x_u", "x_scale", "x_r", "x_s"}, {"y_u", "y_scale", "y_r", "y_s"}, {"z_u", "z_scale", "z_r", "z_s"}};
static cbvh_ray ray_words(const uint32_t *in) {
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        r.o[a] = in[a];
        r.d[a] = in[3 + a];
    }
    r.tmin = in[6];
    r.tmax = in[7];
    return r;
}
static void ray_box_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    for (int i = 0; i < 8; i++) add(l->in, &l->n_in, ray_names[i], F32);
    add(l->in, &l->n_in, "mant", 2);
    for (int a = 0; a < 3; a++) {
        add(l->in, &l->n_in, grid_names[a][0], F32);
        add(l->in, &l->n_in, grid_names[a][1], SCALE);
        add(l->in, &l->n_in, grid_names[a][2], CODE);
        add(l->in, &l->n_in, grid_names[a][3], CODE);
    }
    add(l->out, &l->n_out, "hit", 1);
    add(l->out, &l->n_out, "t_near", F32);
    add(l->out, &l->n_out, "t_far", F32);
    add(l->out, &l->n_out, "status", STATUS);
}
static void ray_box_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    (void)cfg;
    cbvh_ray r = ray_words(in);
    cbvh_grid_axis g[3];
    for (int a = 0; a < 3; a++) {
        const uint32_t *w = in + 9 + 4 * a;
        g[a].u = w[0];
        g[a].e = cbvh_scale_from_word(w[1]);
        g[a].r = w[2];
        g[a].s = w[3];
    }
    cbvh_box_result res;
    uint32_t st = cbvh_ray_box(&r, (int)in[8], g, &res);
    out[0] = (uint32_t)res.hit;
    out[1] = res.t_near;
    out[2] = res.t_far;
    out[3] = st;
}

/* ---- ray_triangle (docs/traversal.md §4) ---- */
static const char *const vert_names[9] = {"v0x", "v0y", "v0z", "v1x", "v1y", "v1z", "v2x", "v2y", "v2z"};
static void ray_tri_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    for (int i = 0; i < 6; i++) add(l->in, &l->n_in, ray_names[i], F32);
    for (int i = 0; i < 9; i++) add(l->in, &l->n_in, vert_names[i], F32);
    add(l->out, &l->n_out, "hit", 1);
    add(l->out, &l->n_out, "t", F32);
    add(l->out, &l->n_out, "b1", F32);
    add(l->out, &l->n_out, "b2", F32);
    add(l->out, &l->n_out, "status", STATUS);
}
static void ray_tri_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    (void)cfg;
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        r.o[a] = in[a];
        r.d[a] = in[3 + a];
    }
    r.tmin = 0;
    r.tmax = CBVH_F32_POS_INF;
    cbvh_tri_result res;
    uint32_t st = cbvh_ray_triangle(&r, in + 6, in + 9, in + 12, &res);
    out[0] = (uint32_t)res.hit;
    out[1] = res.t;
    out[2] = res.b1;
    out[3] = res.b2;
    out[4] = st;
}

/* ---- ray_sphere (docs/traversal.md §10) ---- */
static const char *const sphere_names[4] = {"cx", "cy", "cz", "r"};
static void ray_sphere_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    for (int i = 0; i < 8; i++) add(l->in, &l->n_in, ray_names[i], F32);
    for (int i = 0; i < 4; i++) add(l->in, &l->n_in, sphere_names[i], F32);
    add(l->out, &l->n_out, "hit", 1);
    add(l->out, &l->n_out, "status", STATUS);
}
static void ray_sphere_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    (void)cfg;
    cbvh_ray r = ray_words(in);
    int hit;
    uint32_t st = cbvh_ray_sphere(&r, in + 8, in[11], &hit);
    out[0] = (uint32_t)hit;
    out[1] = st;
}

/* ---- ray_box_incr (docs/traversal.md §17): one child of a node ---- */
static const char *const incr_in_names[3][5] = {{"x_t_lb", "x_t_ub", "x_scale", "x_r", "x_sp"},
                                                {"y_t_lb", "y_t_ub", "y_scale", "y_r", "y_sp"},
                                                {"z_t_lb", "z_t_ub", "z_scale", "z_r", "z_sp"}};
static const char *const incr_out_names[6] = {"x_c_lb", "x_c_ub", "y_c_lb", "y_c_ub", "z_c_lb", "z_c_ub"};
static void ray_box_incr_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    add(l->in, &l->n_in, "rcp_x", F32);
    add(l->in, &l->n_in, "rcp_y", F32);
    add(l->in, &l->n_in, "rcp_z", F32);
    add(l->in, &l->n_in, "tmin", F32);
    add(l->in, &l->n_in, "tmax", F32);
    add(l->in, &l->n_in, "mant", 2);
    add(l->in, &l->n_in, "texp", 2);
    for (int a = 0; a < 3; a++) {
        static const int digits[5] = {F32, F32, SCALE, CODE, CODE};
        for (int i = 0; i < 5; i++) add(l->in, &l->n_in, incr_in_names[a][i], digits[i]);
    }
    add(l->out, &l->n_out, "hit", 1);
    add(l->out, &l->n_out, "t_near", F32);
    add(l->out, &l->n_out, "t_far", F32);
    for (int i = 0; i < 6; i++) add(l->out, &l->n_out, incr_out_names[i], F32);
    add(l->out, &l->n_out, "status", STATUS);
}
static void ray_box_incr_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    cbvh_rbi_params p = {cfg->params.quant_bits, (int)in[5], (int)in[6]};
    cbvh_rbi_ray ray = {{in[0], in[1], in[2]}, in[3], in[4]};
    cbvh_rbi_planes par;
    cbvh_rbi_axis ch[3];
    for (int a = 0; a < 3; a++) {
        const uint32_t *w = in + 7 + 5 * a;
        par.t_lb[a] = w[0];
        par.t_ub[a] = w[1];
        ch[a].e = cbvh_scale_from_word(w[2]);
        ch[a].r = w[3];
        ch[a].sp = w[4];
    }
    cbvh_rbi_result res;
    uint32_t st = cbvh_ray_box_incr(&p, &ray, &par, ch, &res);
    out[0] = (uint32_t)res.hit;
    out[1] = res.t_near;
    out[2] = res.t_far;
    for (int a = 0; a < 3; a++) {
        out[3 + 2 * a] = res.planes.t_lb[a];
        out[4 + 2 * a] = res.planes.t_ub[a];
    }
    out[9] = st;
}

/* ---- qbvh_stack (docs/qbvh.md §2) ---- */
static void qstack_layout(const cbvh_unit_config *cfg, cbvh_layout *l) {
    (void)cfg;
    l->n_in = l->n_out = 0;
    add(l->in, &l->n_in, "op", 1); /* 0 = sort + push, 1 = pop */
    add(l->in, &l->n_in, "first", F32);
    add(l->in, &l->n_in, "hit_mask", 1);
    add(l->in, &l->n_in, "t0", F32);
    add(l->in, &l->n_in, "t1", F32);
    add(l->in, &l->n_in, "t2", F32);
    add(l->in, &l->n_in, "t3", F32);
    add(l->in, &l->n_in, "entry", 8);
    add(l->out, &l->n_out, "node", 8);
    add(l->out, &l->n_out, "next_entry", 8);
    add(l->out, &l->n_out, "write", 1);
    add(l->out, &l->n_out, "order", 2);
    add(l->out, &l->n_out, "nhit", 1);
    add(l->out, &l->n_out, "status", STATUS);
}
static void qstack_eval(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out) {
    (void)cfg;
    for (int i = 0; i < 6; i++) out[i] = 0;
    if (in[0] == 1) {
        int keep;
        out[5] = cbvh_qstack_pop(in[7], &out[0], &out[1], &keep);
        out[2] = (uint32_t)keep;
        return;
    }
    if (in[0] != 0) {
        out[5] = CBVH_ST_BAD_PARAM;
        return;
    }
    uint8_t order[4];
    int nhit;
    uint32_t st = cbvh_qstack_sort(in + 3, in[2], order, &nhit);
    uint32_t entry = 0;
    if (!st) st = cbvh_qstack_push(in[1], order, nhit, &entry);
    if (st) {
        out[5] = st;
        return;
    }
    out[0] = nhit ? in[1] + order[0] : 0;
    out[1] = entry;
    out[2] = nhit >= 2;
    out[3] = (uint32_t)order[0] | (uint32_t)order[1] << 2 | (uint32_t)order[2] << 4 | (uint32_t)order[3] << 6;
    out[4] = (uint32_t)nhit;
}

static const cbvh_unit unit_estimate = {"scale_estimate", 1, 0, estimate_layout, estimate_eval};
static const cbvh_unit unit_compress = {"axis_compress", 2, 0, compress_layout, compress_eval};
static const cbvh_unit unit_decode = {"axis_decode", 3, 1, decode_layout, decode_eval};
static const cbvh_unit unit_encode_pair = {"nodepair_encode", 4, 1, encode_layout, encode_eval};
static const cbvh_unit unit_decode_pair = {"nodepair_decode", 5, 1, decode_pair_layout, decode_pair_eval};
static const cbvh_unit unit_ray_box = {"ray_box", 6, 0, ray_box_layout, ray_box_eval};
static const cbvh_unit unit_ray_triangle = {"ray_triangle", 7, 0, ray_tri_layout, ray_tri_eval};
static const cbvh_unit unit_qbvh_stack = {"qbvh_stack", 8, 0, qstack_layout, qstack_eval};
static const cbvh_unit unit_ray_sphere = {"ray_sphere", 9, 0, ray_sphere_layout, ray_sphere_eval};
static const cbvh_unit unit_ray_box_incr = {"ray_box_incr", 10, 0, ray_box_incr_layout, ray_box_incr_eval};

const cbvh_unit *const cbvh_units[] = {&unit_estimate, &unit_compress, &unit_decode, &unit_encode_pair,
                                       &unit_decode_pair, &unit_ray_box, &unit_ray_triangle,
                                       &unit_qbvh_stack, &unit_ray_sphere, &unit_ray_box_incr};
const int cbvh_unit_count = (int)(sizeof cbvh_units / sizeof cbvh_units[0]);

const cbvh_unit *cbvh_unit_find(const char *name) {
    for (int i = 0; i < cbvh_unit_count; i++)
        if (strcmp(cbvh_units[i]->name, name) == 0) return cbvh_units[i];
    return NULL;
}

const cbvh_unit *cbvh_unit_by_id(int id) {
    for (int i = 0; i < cbvh_unit_count; i++)
        if (cbvh_units[i]->id == id) return cbvh_units[i];
    return NULL;
}

const char *cbvh_encoding_name(cbvh_encoding e) { return e == CBVH_ENC_RELATIVE ? "relative" : "modulo"; }

int cbvh_encoding_parse(const char *s, cbvh_encoding *e) {
    if (strcmp(s, "modulo") == 0) *e = CBVH_ENC_MODULO;
    else if (strcmp(s, "relative") == 0) *e = CBVH_ENC_RELATIVE;
    else return -1;
    return 0;
}
