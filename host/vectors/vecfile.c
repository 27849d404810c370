/* Golden vector files: strict reader and writer (docs/vectors.md). */
#include "vectors/vecfile.h"
#include "vectors/vecgen.h" /* CBVH_VECGEN_VERSION: newer generators are refused */

#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *const status_names[] = {
    "ok",          "cannot read file", "empty file",         "not a vector file", "bad header",
    "unknown unit", "unsupported format version", "parameter out of range", "fields mismatch", "bad hex",
    "wrong field width", "wrong field count", "count mismatch", "out of memory",
};

const char *cbvh_vec_status_name(cbvh_vec_status st) {
    return (unsigned)st < sizeof status_names / sizeof status_names[0] ? status_names[st] : "?";
}

/* ---- small helpers --------------------------------------------------------- */

typedef struct {
    const char *name;
    char *err;
    size_t errlen;
} ctx_t;

static cbvh_vec_status fail(const ctx_t *c, cbvh_vec_status st, size_t line, const char *fmt, ...) {
    char msg[384];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (c->errlen) {
        if (line)
            snprintf(c->err, c->errlen, "%s:%zu: %s", c->name, line, msg);
        else
            snprintf(c->err, c->errlen, "%s: %s", c->name, msg);
    }
    return st;
}

/* Printable rendering of at most max bytes of s (control/non-ASCII as \xNN). */
static void show(const char *s, size_t n, char *dst, size_t dstlen) {
    size_t o = 0, max = 40;
    for (size_t i = 0; i < n && i < max && o + 5 < dstlen; i++) {
        unsigned char ch = (unsigned char)s[i];
        if (ch >= 0x20 && ch < 0x7F)
            dst[o++] = (char)ch;
        else
            o += (size_t)snprintf(dst + o, dstlen - o, "\\x%02X", ch);
    }
    if (n > max && o + 4 < dstlen) {
        memcpy(dst + o, "...", 3);
        o += 3;
    }
    dst[o < dstlen ? o : dstlen - 1] = '\0';
}

static int hexval(char ch) {
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
}

/* Strict canonical decimal integer: optional '-', digits, nothing else; no
 * leading zeros, no '+', no "-0", so that each value has one spelling.
 * 0, INT_BAD (not an integer), INT_NONCANON, or INT_BIG (more than 18 digits). */
enum { INT_BAD = -1, INT_NONCANON = -2, INT_BIG = -3 };
static int parse_int(const char *s, size_t n, long long *v) {
    size_t i = 0;
    int neg = 0;
    if (i < n && (s[i] == '-' || s[i] == '+')) {
        neg = s[i] == '-';
        i++;
    }
    if (i == n) return INT_BAD;
    for (size_t k = i; k < n; k++)
        if (s[k] < '0' || s[k] > '9') return INT_BAD;
    if (s[0] == '+' || (s[i] == '0' && (n - i > 1 || neg))) return INT_NONCANON;
    if (n - i > 18) return INT_BIG;
    long long x = 0;
    for (; i < n; i++) x = x * 10 + (s[i] - '0');
    *v = neg ? -x : x;
    return 0;
}

/* "0x" + 1..16 upper-case hex digits. */
static int parse_hex64(const char *s, size_t n, uint64_t *v) {
    if (n < 3 || n > 18 || s[0] != '0' || s[1] != 'x') return -1;
    uint64_t x = 0;
    for (size_t i = 2; i < n; i++) {
        int d = hexval(s[i]);
        if (d < 0) return -1;
        x = x << 4 | (uint64_t)d;
    }
    *v = x;
    return 0;
}

/* ---- header ---------------------------------------------------------------- */

enum { K_UNIT, K_FORMAT, K_QUANT_BITS, K_MIN_SCALE, K_ENCODING, K_LEVEL, K_SEED, K_GENERATOR, K_FIELDS, K_COUNT, K_N };
static const char *const key_names[K_N] = {"unit",  "format", "quant_bits", "min_scale", "encoding",
                                           "level", "seed",   "generator",  "fields",    "count"};

typedef struct {
    const char *v;
    size_t n, line;
} hval;

static cbvh_vec_status check_fields(const ctx_t *c, const hval *h, const cbvh_layout *lay, const char *unit) {
    const char *s = h->v, *end = h->v + h->n;
    int total = lay->n_in + lay->n_out + 1; /* +1 for the "->" separator */
    for (int i = 0; i < total; i++) {
        const char *want = i < lay->n_in ? lay->in[i].name : i == lay->n_in ? "->" : lay->out[i - lay->n_in - 1].name;
        const char *tok = s;
        while (s < end && *s != ' ') s++;
        size_t tn = (size_t)(s - tok);
        if (tn == 0 && tok == end)
            return fail(c, CBVH_VEC_E_FIELDS, h->line, "fields header ends early: expected '%s' (unit %s)", want, unit);
        if (tn != strlen(want) || memcmp(tok, want, tn) != 0) {
            char shown[200];
            show(tok, tn, shown, sizeof shown);
            return fail(c, CBVH_VEC_E_FIELDS, h->line, "fields header does not match unit %s: found '%s', expected '%s'",
                        unit, shown, want);
        }
        if (s < end) s++;
        else if (i + 1 < total) {
            const char *next = i + 1 < lay->n_in ? lay->in[i + 1].name : i + 1 == lay->n_in ? "->" : lay->out[i - lay->n_in].name;
            return fail(c, CBVH_VEC_E_FIELDS, h->line, "fields header ends early: expected '%s' (unit %s)", next, unit);
        }
    }
    if (s != end || (h->n && end[-1] == ' '))
        return fail(c, CBVH_VEC_E_FIELDS, h->line, "fields header has extra names after '%s' (unit %s)",
                    lay->out[lay->n_out - 1].name, unit);
    return CBVH_VEC_OK;
}

static cbvh_vec_status need_int(const ctx_t *c, const hval *h, const char *key, long lo, long hi, long *v) {
    long long x = 0;
    int rc = parse_int(h->v, h->n, &x);
    char shown[200];
    show(h->v, h->n, shown, sizeof shown);
    if (rc == INT_BAD) return fail(c, CBVH_VEC_E_HEADER, h->line, "%s: '%s' is not a decimal integer", key, shown);
    if (rc == INT_NONCANON)
        return fail(c, CBVH_VEC_E_HEADER, h->line,
                    "%s: '%s' is not written canonically (no '+', leading zeros or '-0')", key, shown);
    if (rc == INT_BIG || x < lo || x > hi)
        return fail(c, CBVH_VEC_E_PARAM, h->line, "%s %s out of range [%ld, %ld]", key, shown, lo, hi);
    *v = (long)x;
    return CBVH_VEC_OK;
}

/* ---- vectors ------------------------------------------------------------- */

typedef struct {
    uint32_t *in, *out;
    size_t n, cap;
} store;

static int store_grow(store *s, const cbvh_layout *lay) {
    size_t cap = s->cap ? s->cap * 2 : 256;
    uint32_t *in = realloc(s->in, cap * (size_t)(lay->n_in ? lay->n_in : 1) * sizeof *in);
    if (!in) return -1;
    s->in = in;
    uint32_t *out = realloc(s->out, cap * (size_t)(lay->n_out ? lay->n_out : 1) * sizeof *out);
    if (!out) return -1;
    s->out = out;
    s->cap = cap;
    return 0;
}

static cbvh_vec_status parse_vector(const ctx_t *c, const char *s, size_t n, size_t line, const cbvh_layout *lay,
                                    uint32_t *in, uint32_t *out) {
    int nf = lay->n_in + lay->n_out;
    if (n == 0) return fail(c, CBVH_VEC_E_FIELD_COUNT, line, "empty line, expected %d fields", nf);
    int tokens = 1;
    for (size_t i = 0; i < n; i++) tokens += s[i] == ' ';
    if (tokens != nf)
        return fail(c, CBVH_VEC_E_FIELD_COUNT, line, "%d fields, expected %d (%d inputs + %d outputs)", tokens, nf,
                    lay->n_in, lay->n_out);
    size_t pos = 0;
    for (int f = 0; f < nf; f++) {
        const cbvh_field *fd = f < lay->n_in ? &lay->in[f] : &lay->out[f - lay->n_in];
        size_t start = pos;
        uint32_t v = 0;
        while (pos < n && s[pos] != ' ') {
            int d = hexval(s[pos]);
            if (d < 0) {
                char shown[16];
                show(s + pos, 1, shown, sizeof shown);
                return fail(c, CBVH_VEC_E_HEX, line, "bad hex digit '%s' in field %s (column %zu; upper-case hex only)",
                            shown, fd->name, pos + 1);
            }
            v = v << 4 | (uint32_t)d;
            pos++;
        }
        size_t w = pos - start;
        if (w == 0) return fail(c, CBVH_VEC_E_FIELD_COUNT, line, "empty field %s (stray space at column %zu)", fd->name, pos + 1);
        if (w != (size_t)fd->hex_digits)
            return fail(c, CBVH_VEC_E_WIDTH, line, "field %s has %zu hex digits, expected %d", fd->name, w,
                        fd->hex_digits);
        if (f < lay->n_in)
            in[f] = v;
        else
            out[f - lay->n_in] = v;
        pos++; /* the separating space */
    }
    return CBVH_VEC_OK;
}

/* Line cursor over the buffer: s/n is the current line without its '\n',
 * complete says whether it ended with one. */
typedef struct {
    const char *buf;
    size_t len, pos, line;
    const char *s;
    size_t n;
    int complete;
} lines;

static int next_line(lines *L) {
    if (L->pos >= L->len) return 0;
    L->s = L->buf + L->pos;
    L->line++;
    size_t rest = L->len - L->pos;
    const char *nl = memchr(L->s, '\n', rest);
    L->complete = nl != NULL;
    L->n = nl ? (size_t)(nl - L->s) : rest;
    L->pos += L->n + (size_t)L->complete;
    return 1;
}

cbvh_vec_status cbvh_vecfile_parse(const char *buf, size_t len, const char *name, cbvh_vecfile *vf, char *err,
                                   size_t errlen) {
    ctx_t c = {name ? name : "<buffer>", err, errlen};
    memset(vf, 0, sizeof *vf);
    if (errlen) err[0] = '\0';
    if (len == 0) return fail(&c, CBVH_VEC_E_EMPTY, 0, "empty file");

    lines L = {buf, len, 0, 0, NULL, 0, 0};
    next_line(&L);
    size_t mn = strlen(CBVH_VEC_MAGIC);
    if (!L.complete || L.n != mn || memcmp(L.s, CBVH_VEC_MAGIC, L.n) != 0) {
        char shown[200];
        show(L.s, L.n, shown, sizeof shown);
        /* A cut-off file or Windows line endings, not a foreign file. */
        if (!L.complete && L.n <= mn && memcmp(L.s, CBVH_VEC_MAGIC, L.n) == 0)
            return fail(&c, CBVH_VEC_E_HEADER, 1, "first line '%s' is not terminated (file truncated?)", shown);
        if (L.n == mn + 1 && memcmp(L.s, CBVH_VEC_MAGIC, mn) == 0 && L.s[mn] == '\r')
            return fail(&c, CBVH_VEC_E_MAGIC, 1,
                        "first line ends in CR (Windows line endings); vector files use \\n only");
        return fail(&c, CBVH_VEC_E_MAGIC, 1, "not a cbvh vector file: first line is '%s', expected '%s'", shown,
                    CBVH_VEC_MAGIC);
    }

    hval h[K_N];
    memset(h, 0, sizeof h);
    int have[K_N] = {0};
    size_t unknown_line = 0;
    char unknown[200] = "";
    int ended = 0;
    while (next_line(&L)) {
        if (!L.complete)
            return fail(&c, CBVH_VEC_E_HEADER, L.line, "header line has no newline (truncated file?)");
        if (L.n == 3 && memcmp(L.s, "---", 3) == 0) {
            ended = 1;
            break;
        }
        const char *s = L.s;
        size_t n = L.n;
        const char *colon = memchr(s, ':', n);
        if (!colon || (size_t)(colon - s) + 2 > n || colon[1] != ' ' || colon == s) {
            char shown[200];
            show(L.s, L.n, shown, sizeof shown);
            return fail(&c, CBVH_VEC_E_HEADER, L.line, "malformed header line '%s' (expected 'key: value' or '---')",
                        shown);
        }
        size_t kn = (size_t)(colon - s);
        const char *v = colon + 2;
        size_t vn = n - kn - 2;
        int k = -1;
        for (int i = 0; i < K_N; i++)
            if (strlen(key_names[i]) == kn && memcmp(key_names[i], s, kn) == 0) k = i;
        if (k < 0) {
            if (!unknown_line) {
                unknown_line = L.line;
                show(s, kn, unknown, sizeof unknown);
            }
            continue;
        }
        if (have[k]) return fail(&c, CBVH_VEC_E_HEADER, L.line, "duplicate header key '%s'", key_names[k]);
        if (vn == 0 || v[0] == ' ' || v[vn - 1] == ' ')
            return fail(&c, CBVH_VEC_E_HEADER, L.line, "header key '%s' has an empty or space-padded value", key_names[k]);
        have[k] = 1;
        h[k].v = v;
        h[k].n = vn;
        h[k].line = L.line;
    }
    if (!ended) return fail(&c, CBVH_VEC_E_HEADER, L.line + 1, "no '---' line ending the header (truncated file?)");
    size_t sep_line = L.line;

    /* The version decides what the rest means, so it is checked first. */
    long v;
    cbvh_vec_status st;
    if (!have[K_FORMAT]) return fail(&c, CBVH_VEC_E_HEADER, sep_line, "missing header key 'format'");
    long long fmt = 0;
    int frc = parse_int(h[K_FORMAT].v, h[K_FORMAT].n, &fmt);
    if (frc != 0 || fmt != CBVH_VEC_FORMAT) {
        char shown[200];
        show(h[K_FORMAT].v, h[K_FORMAT].n, shown, sizeof shown);
        if (frc == INT_NONCANON)
            return fail(&c, CBVH_VEC_E_VERSION, h[K_FORMAT].line,
                        "format: '%s' is not written canonically (no '+', leading zeros or '-0')", shown);
        return fail(&c, CBVH_VEC_E_VERSION, h[K_FORMAT].line, "unsupported format version '%s' (this reader supports %d)",
                    shown, CBVH_VEC_FORMAT);
    }
    if (unknown_line) return fail(&c, CBVH_VEC_E_HEADER, unknown_line, "unknown header key '%s'", unknown);
    if (!have[K_UNIT]) return fail(&c, CBVH_VEC_E_HEADER, sep_line, "missing header key 'unit'");
    char unit_name[64];
    if (h[K_UNIT].n >= sizeof unit_name) {
        char shown[200];
        show(h[K_UNIT].v, h[K_UNIT].n, shown, sizeof shown);
        return fail(&c, CBVH_VEC_E_UNIT, h[K_UNIT].line, "unknown unit '%s'", shown);
    }
    memcpy(unit_name, h[K_UNIT].v, h[K_UNIT].n);
    unit_name[h[K_UNIT].n] = '\0';
    const cbvh_unit *unit = memchr(unit_name, '\0', h[K_UNIT].n) ? NULL : cbvh_unit_find(unit_name);
    if (!unit) {
        char shown[200];
        show(h[K_UNIT].v, h[K_UNIT].n, shown, sizeof shown);
        return fail(&c, CBVH_VEC_E_UNIT, h[K_UNIT].line, "unknown unit '%s'", shown);
    }
    static const int required[] = {K_QUANT_BITS, K_MIN_SCALE, K_LEVEL, K_SEED, K_GENERATOR, K_FIELDS, K_COUNT};
    for (size_t i = 0; i < sizeof required / sizeof required[0]; i++)
        if (!have[required[i]])
            return fail(&c, CBVH_VEC_E_HEADER, sep_line, "missing header key '%s'", key_names[required[i]]);

    cbvh_unit_config cfg = {{0, 0}, CBVH_ENC_MODULO};
    if ((st = need_int(&c, &h[K_QUANT_BITS], "quant_bits", CBVH_N_MIN, CBVH_N_MAX, &v))) return st;
    cfg.params.quant_bits = (int)v;
    if ((st = need_int(&c, &h[K_MIN_SCALE], "min_scale", CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL, &v))) return st;
    cfg.params.min_scale = (int)v;
    if (unit->uses_encoding) {
        if (!have[K_ENCODING])
            return fail(&c, CBVH_VEC_E_HEADER, sep_line, "missing header key 'encoding' (unit %s needs one)", unit->name);
        char enc[16];
        size_t en = h[K_ENCODING].n < sizeof enc - 1 ? h[K_ENCODING].n : sizeof enc - 1;
        memcpy(enc, h[K_ENCODING].v, en);
        enc[en] = '\0';
        if (h[K_ENCODING].n >= sizeof enc || strlen(enc) != en || cbvh_encoding_parse(enc, &cfg.enc) != 0) {
            char shown[200];
            show(h[K_ENCODING].v, h[K_ENCODING].n, shown, sizeof shown);
            return fail(&c, CBVH_VEC_E_PARAM, h[K_ENCODING].line, "encoding '%s' is not modulo or relative", shown);
        }
    } else if (have[K_ENCODING]) {
        return fail(&c, CBVH_VEC_E_HEADER, h[K_ENCODING].line, "unit %s takes no 'encoding' header key", unit->name);
    }
    long level, gen, count;
    if ((st = need_int(&c, &h[K_LEVEL], "level", 1, 2, &level))) return st;
    /* The spec names level-2 files *-L2.vec (docs/vectors.md, "Generator"):
     * a header that disagrees with its name was edited or renamed.  Buffers
     * without a name have nothing to agree with. */
    if (name) {
        const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
        size_t bn = strlen(base), sn = strlen("-L2.vec");
        int l2_name = bn >= sn && strcmp(base + bn - sn, "-L2.vec") == 0;
        if (level == 2 && !l2_name)
            return fail(&c, CBVH_VEC_E_PARAM, h[K_LEVEL].line, "level 2 but the file name does not end in '-L2.vec'");
        if (level == 1 && l2_name)
            return fail(&c, CBVH_VEC_E_PARAM, h[K_LEVEL].line, "level 1 but the file name ends in '-L2.vec' (level 2)");
    }
    if ((st = need_int(&c, &h[K_GENERATOR], "generator", 1, 999999, &gen))) return st;
    /* A newer generator may have changed what its vectors mean. */
    if (gen > CBVH_VECGEN_VERSION)
        return fail(&c, CBVH_VEC_E_VERSION, h[K_GENERATOR].line,
                    "generator %ld is newer than this tool's (%d): check it with a newer cbvh", gen,
                    CBVH_VECGEN_VERSION);
    uint64_t seed;
    if (parse_hex64(h[K_SEED].v, h[K_SEED].n, &seed) != 0) {
        char shown[200];
        show(h[K_SEED].v, h[K_SEED].n, shown, sizeof shown);
        return fail(&c, CBVH_VEC_E_HEADER, h[K_SEED].line, "seed '%s' is not 0x followed by 1-16 upper-case hex digits",
                    shown);
    }
    /* At least one vector: an empty file would pass while testing nothing. */
    if ((st = need_int(&c, &h[K_COUNT], "count", 1, (long)CBVH_VEC_MAX_COUNT, &count))) return st;

    cbvh_layout lay;
    unit->layout(&cfg, &lay);
    if ((st = check_fields(&c, &h[K_FIELDS], &lay, unit->name))) return st;

    store sto = {NULL, NULL, 0, 0};
    size_t first = sep_line + 1;
    while (next_line(&L)) {
        if (!L.complete) {
            free(sto.in);
            free(sto.out);
            return fail(&c, CBVH_VEC_E_COUNT, L.line, "last line has no newline (truncated file?)");
        }
        if (sto.n == (size_t)count) {
            free(sto.in);
            free(sto.out);
            return fail(&c, CBVH_VEC_E_COUNT, L.line, "more vectors than the header's count: %ld", count);
        }
        if (sto.n == sto.cap && store_grow(&sto, &lay) != 0) {
            free(sto.in);
            free(sto.out);
            return fail(&c, CBVH_VEC_E_NOMEM, L.line, "out of memory");
        }
        st = parse_vector(&c, L.s, L.n, L.line, &lay, sto.in + sto.n * (size_t)lay.n_in, sto.out + sto.n * (size_t)lay.n_out);
        if (st) {
            free(sto.in);
            free(sto.out);
            return st;
        }
        sto.n++;
    }
    if (sto.n != (size_t)count) {
        free(sto.in);
        free(sto.out);
        return fail(&c, CBVH_VEC_E_COUNT, L.line + 1, "file ends after %zu vectors but the header's count is %ld (truncated file?)",
                    sto.n, count);
    }
    vf->unit = unit;
    vf->cfg = cfg;
    vf->level = (int)level;
    vf->seed = seed;
    vf->generator = (unsigned)gen;
    vf->layout = lay;
    vf->count = sto.n;
    vf->first_line = first;
    vf->in = sto.in;
    vf->out = sto.out;
    return CBVH_VEC_OK;
}

int cbvh_read_file(const char *path, char **buf, size_t *len, char *err, size_t errlen) {
    *buf = NULL;
    *len = 0;
    /* Only regular files of bounded size, checked before opening: /dev/zero
     * or a huge file would be read until memory runs out, opening a FIFO
     * blocks, and a directory gets a clearer message than a read error. */
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "%s: not a regular file%s", path, S_ISDIR(st.st_mode) ? " (a directory)" : "");
        return -1;
    }
    if ((uint64_t)st.st_size > CBVH_READ_MAX_BYTES) {
        snprintf(err, errlen, "%s: %lld bytes, larger than the %llu this tool reads", path, (long long)st.st_size,
                 (unsigned long long)CBVH_READ_MAX_BYTES);
        return -1;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    size_t cap = 1 << 16, n = 0;
    char *b = malloc(cap);
    int oom = !b;
    while (!oom) {
        if (n == cap) {
            char *nb = realloc(b, cap * 2);
            if (!nb) {
                oom = 1;
                break;
            }
            b = nb;
            cap *= 2;
        }
        size_t got = fread(b + n, 1, cap - n, f);
        n += got;
        if (got == 0) break;
        if (n > CBVH_READ_MAX_BYTES) { /* the file grew while being read */
            oom = 1;
            break;
        }
    }
    int bad = oom || ferror(f);
    fclose(f);
    if (bad) {
        free(b);
        snprintf(err, errlen, "%s: read error", path);
        return -1;
    }
    *buf = b;
    *len = n;
    return 0;
}

cbvh_vec_status cbvh_vecfile_load(const char *path, cbvh_vecfile *vf, char *err, size_t errlen) {
    memset(vf, 0, sizeof *vf);
    char *buf;
    size_t len;
    if (cbvh_read_file(path, &buf, &len, err, errlen) != 0) return CBVH_VEC_E_IO;
    cbvh_vec_status st = cbvh_vecfile_parse(buf, len, path, vf, err, errlen);
    free(buf);
    return st;
}

void cbvh_vecfile_free(cbvh_vecfile *vf) {
    free(vf->in);
    free(vf->out);
    memset(vf, 0, sizeof *vf);
}

static int put_field(FILE *f, uint32_t v, int digits, int first) {
    if (digits < 8 && (v >> (4 * digits)) != 0) return -1;
    return fprintf(f, "%s%0*" PRIX32, first ? "" : " ", digits, v) < 0 ? -1 : 0;
}

int cbvh_vecfile_write(FILE *f, const cbvh_vecfile *vf) {
    const cbvh_layout *l = &vf->layout;
    fprintf(f, "%s\nunit: %s\nformat: %d\nquant_bits: %d\nmin_scale: %d\n", CBVH_VEC_MAGIC, vf->unit->name,
            CBVH_VEC_FORMAT, vf->cfg.params.quant_bits, vf->cfg.params.min_scale);
    if (vf->unit->uses_encoding) fprintf(f, "encoding: %s\n", cbvh_encoding_name(vf->cfg.enc));
    fprintf(f, "level: %d\nseed: 0x%016" PRIX64 "\ngenerator: %u\nfields:", vf->level, vf->seed, vf->generator);
    for (int i = 0; i < l->n_in; i++) fprintf(f, " %s", l->in[i].name);
    fprintf(f, " ->");
    for (int i = 0; i < l->n_out; i++) fprintf(f, " %s", l->out[i].name);
    fprintf(f, "\ncount: %zu\n---\n", vf->count);
    for (size_t v = 0; v < vf->count; v++) {
        const uint32_t *in = vf->in + v * (size_t)l->n_in, *out = vf->out + v * (size_t)l->n_out;
        for (int i = 0; i < l->n_in; i++)
            if (put_field(f, in[i], l->in[i].hex_digits, i == 0)) return -1;
        for (int i = 0; i < l->n_out; i++)
            if (put_field(f, out[i], l->out[i].hex_digits, l->n_in == 0 && i == 0)) return -1;
        if (fputc('\n', f) == EOF) return -1;
    }
    return ferror(f) ? -1 : 0;
}
