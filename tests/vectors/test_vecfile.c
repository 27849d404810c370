/* The vector-file reader, the MANIFEST and `vectors check` against bad input:
 * every corruption gives its specific error and a one-line "file:line:"
 * message, and nothing crashes (this test also runs under ASan+UBSan). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "vectors/manifest.h"
#include "vectors/vecfile.h"
#include "vectors/vecgen.h"
#include "vectors/vectors_check.h"

#ifndef FIXTURES
#error FIXTURES must point at tests/vectors/fixtures
#endif

static char err[1024];

static cbvh_vec_status load_fixture(const char *name, cbvh_vecfile *vf) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", FIXTURES, name);
    return cbvh_vecfile_load(path, vf, err, sizeof err);
}

/* Asserts the status and that the message contains every given piece. */
static void expect(const char *fixture, cbvh_vec_status want, const char *piece1, const char *piece2) {
    cbvh_vecfile vf;
    cbvh_vec_status st = load_fixture(fixture, &vf);
    if (st != want || !strstr(err, piece1) || (piece2 && !strstr(err, piece2)))
        fail_msg("%s: got status %d (%s) message '%s'; want %d (%s) with '%s'%s%s", fixture, st,
                 cbvh_vec_status_name(st), err, want, cbvh_vec_status_name(want), piece1, piece2 ? " and " : "",
                 piece2 ? piece2 : "");
    assert_null(strchr(err, '\n')); /* one line */
    assert_null(vf.in);
    assert_int_equal(vf.count, 0);
}

static void test_good(void **state) {
    (void)state;
    cbvh_vecfile vf;
    assert_int_equal(load_fixture("good.vec", &vf), CBVH_VEC_OK);
    assert_string_equal(vf.unit->name, "scale_estimate");
    assert_int_equal(vf.cfg.params.quant_bits, 4);
    assert_int_equal(vf.cfg.params.min_scale, -30);
    assert_int_equal(vf.level, 1);
    assert_true(vf.seed == CBVH_VECGEN_DEFAULT_SEED);
    assert_int_equal(vf.count, 3);
    assert_int_equal(vf.first_line, 12);
    assert_int_equal(vf.in[2 * 2 + 1], 0x00000001);  /* vector 2, ub */
    assert_int_equal(vf.in[1 * 2 + 0], 0x80000000);  /* vector 1, lb = -0 */
    assert_int_equal(vf.out[0], 0xE2);               /* scale -30 */
    cbvh_vecfile_free(&vf);
}

static void test_truncated(void **state) {
    (void)state;
    expect("truncated.vec", CBVH_VEC_E_COUNT, "truncated.vec:14: ", "no newline");
}
static void test_short_count(void **state) {
    (void)state;
    expect("short_count.vec", CBVH_VEC_E_COUNT, "short_count.vec:15: ", "after 3 vectors but the header's count is 5");
}
static void test_bad_hex(void **state) {
    (void)state;
    expect("bad_hex.vec", CBVH_VEC_E_HEX, "bad_hex.vec:13: ", "bad hex digit 'G' in field lb");
}
static void test_lower_hex(void **state) {
    (void)state;
    expect("lower_hex.vec", CBVH_VEC_E_HEX, "lower_hex.vec:13: ", "bad hex digit 'a' in field ub");
}
static void test_wrong_width(void **state) {
    (void)state;
    expect("wrong_width.vec", CBVH_VEC_E_WIDTH, "wrong_width.vec:14: ", "field ub has 7 hex digits, expected 8");
}
static void test_field_count(void **state) {
    (void)state;
    expect("field_count.vec", CBVH_VEC_E_FIELD_COUNT, "field_count.vec:12: ", "5 fields, expected 4");
}
static void test_unknown_unit(void **state) {
    (void)state;
    expect("unknown_unit.vec", CBVH_VEC_E_UNIT, "unknown_unit.vec:2: ", "unknown unit 'scale_estimator'");
}
static void test_missing_key(void **state) {
    (void)state;
    expect("missing_key.vec", CBVH_VEC_E_HEADER, "missing_key.vec:10: ", "missing header key 'min_scale'");
}
static void test_bad_header(void **state) {
    (void)state;
    expect("bad_header.vec", CBVH_VEC_E_HEADER, "bad_header.vec:6: ", "malformed header line 'level 1'");
}
static void test_version(void **state) {
    (void)state;
    expect("version.vec", CBVH_VEC_E_VERSION, "version.vec:3: ", "unsupported format version '2'");
}
static void test_bad_param(void **state) {
    (void)state;
    expect("bad_param.vec", CBVH_VEC_E_PARAM, "bad_param.vec:4: ", "quant_bits 11 out of range [3, 10]");
}
static void test_fields(void **state) {
    (void)state;
    expect("fields.vec", CBVH_VEC_E_FIELDS, "fields.vec:9: ", "found 'status', expected 'scale'");
}
static void test_empty(void **state) {
    (void)state;
    expect("empty.vec", CBVH_VEC_E_EMPTY, "empty.vec: empty file", NULL);
}
static void test_garbage(void **state) {
    (void)state;
    expect("garbage.vec", CBVH_VEC_E_MAGIC, "garbage.vec:1: not a cbvh vector file", NULL);
}
static void test_missing_file(void **state) {
    (void)state;
    expect("no-such-file.vec", CBVH_VEC_E_IO, "no-such-file.vec: cannot open", NULL);
}

/* Only regular files are read: /dev/zero would be read until memory runs
 * out, a FIFO would block. */
static void test_not_regular(void **state) {
    (void)state;
    char fifo[64], fifo_want[128];
    snprintf(fifo, sizeof fifo, "/tmp/cbvh_test_fifo_%ld.vec", (long)getpid());
    snprintf(fifo_want, sizeof fifo_want, "%s: not a regular file", fifo);
    remove(fifo);
    int have_fifo = mkfifo(fifo, 0600) == 0;
    alarm(20); /* a FIFO opened for reading would block: fail rather than hang */
    const char *paths[] = {"/dev/zero", FIXTURES, fifo};
    const char *want[] = {"/dev/zero: not a regular file", FIXTURES ": not a regular file (a directory)", fifo_want};
    for (int i = 0; i < 3; i++) {
        if ((i == 0 && access(paths[i], R_OK) != 0) || (i == 2 && !have_fifo)) continue;
        cbvh_vecfile vf;
        cbvh_vec_status st = cbvh_vecfile_load(paths[i], &vf, err, sizeof err);
        if (st != CBVH_VEC_E_IO || strcmp(err, want[i]) != 0) fail_msg("%s: status %d, message '%s'", paths[i], st, err);
        assert_null(vf.in);
    }
    alarm(0);
    if (have_fifo) remove(fifo);
}

/* In-memory variants of a real generated file. */
static char *gen_text(const char *unit, int bits, size_t *len) {
    cbvh_vecgen_spec s = {cbvh_unit_find(unit), {{bits, -30}, CBVH_ENC_MODULO}, 1, 42};
    cbvh_vecfile vf;
    assert_int_equal(cbvh_vecgen_generate(&s, &vf), 0);
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    assert_non_null(f);
    assert_int_equal(cbvh_vecfile_write(f, &vf), 0);
    fclose(f);
    cbvh_vecfile_free(&vf);
    return buf;
}

static cbvh_vec_status parse(const char *buf, size_t len) {
    cbvh_vecfile vf;
    cbvh_vec_status st = cbvh_vecfile_parse(buf, len, "mem", &vf, err, sizeof err);
    cbvh_vecfile_free(&vf);
    return st;
}

/* Every proper prefix of a file is rejected (never a crash, never accepted). */
static void test_every_truncation(void **state) {
    (void)state;
    size_t len;
    char *text = gen_text("nodepair_decode", 7, &len);
    assert_int_equal(parse(text, len), CBVH_VEC_OK);
    /* Copy each prefix into an exact-size heap block so ASan sees overreads. */
    size_t step = len > 20000 ? 13 : 1;
    for (size_t n = 0; n < len; n += (n < 2000 ? 1 : step)) {
        char *p = malloc(n ? n : 1);
        memcpy(p, text, n);
        cbvh_vec_status st = parse(p, n);
        free(p);
        if (st == CBVH_VEC_OK) fail_msg("prefix of %zu/%zu bytes was accepted", n, len);
    }
    free(text);
}

/* Random byte flips and garbage: the reader never crashes; a flip inside a
 * vector line is always caught (upper-case hex has no spare characters). */
static void test_random_damage(void **state) {
    (void)state;
    size_t len;
    char *text = gen_text("axis_decode", 5, &len);
    uint64_t x = 0x1234567;
    size_t header = (size_t)(strstr(text, "---\n") - text) + 4;
    for (int i = 0; i < 3000; i++) {
        char *p = malloc(len);
        memcpy(p, text, len);
        x = x * 6364136223846793005u + 1442695040888963407u;
        size_t at = (size_t)(x >> 33) % len;
        char was = p[at];
        char now = (char)(x >> 20);
        p[at] = now;
        cbvh_vec_status st = parse(p, len);
        /* Replacing a hex digit by another hex digit stays a valid file. */
        int still_hex = ((was >= '0' && was <= '9') || (was >= 'A' && was <= 'F')) &&
                        ((now >= '0' && now <= '9') || (now >= 'A' && now <= 'F'));
        if (at >= header && was != now && !still_hex && st == CBVH_VEC_OK)
            fail_msg("flip at %zu (%02x -> %02x) accepted", at, (unsigned char)was, (unsigned char)now);
        free(p);
    }
    for (int i = 0; i < 200; i++) {
        size_t n = (size_t)(i * 37 % 600);
        char *p = malloc(n ? n : 1);
        for (size_t k = 0; k < n; k++) {
            x = x * 6364136223846793005u + 1442695040888963407u;
            p[k] = (char)(x >> 40);
        }
        if (n > 22 && i % 2) memcpy(p, CBVH_VEC_MAGIC "\n", 22); /* garbage after a valid first line */
        assert_int_not_equal(parse(p, n), CBVH_VEC_OK);
        free(p);
    }
    free(text);
}

/* Writer and reader agree: write -> parse gives the same words. */
static void test_roundtrip(void **state) {
    (void)state;
    for (int u = 0; u < cbvh_unit_count; u++) {
        cbvh_vecgen_spec s = {cbvh_units[u], {{8, -30}, CBVH_ENC_RELATIVE}, 1, 7};
        cbvh_vecfile a, b;
        assert_int_equal(cbvh_vecgen_generate(&s, &a), 0);
        char *buf = NULL;
        size_t len;
        FILE *f = open_memstream(&buf, &len);
        assert_int_equal(cbvh_vecfile_write(f, &a), 0);
        fclose(f);
        assert_int_equal(cbvh_vecfile_parse(buf, len, "rt", &b, err, sizeof err), CBVH_VEC_OK);
        assert_int_equal(a.count, b.count);
        assert_int_equal(b.cfg.enc, cbvh_units[u]->uses_encoding ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO);
        assert_memory_equal(a.in, b.in, a.count * (size_t)a.layout.n_in * 4);
        assert_memory_equal(a.out, b.out, a.count * (size_t)a.layout.n_out * 4);
        free(buf);
        cbvh_vecfile_free(&a);
        cbvh_vecfile_free(&b);
    }
}

/* Header strictness that the fixtures do not cover. */
static void test_header_rules(void **state) {
    (void)state;
    size_t len;
    char *text = gen_text("axis_compress", 6, &len);
    struct {
        const char *from, *to;
        cbvh_vec_status st;
        const char *msg;
    } cases[] = {
        {"level: 1\n", "level: 1\nlevel: 1\n", CBVH_VEC_E_HEADER, "duplicate header key 'level'"},
        {"level: 1\n", "level: 1\ncolour: red\n", CBVH_VEC_E_HEADER, "unknown header key 'colour'"},
        {"level: 1\n", "level: 3\n", CBVH_VEC_E_PARAM, "level 3 out of range"},
        {"min_scale: -30\n", "min_scale: -127\n", CBVH_VEC_E_PARAM, "min_scale -127 out of range"},
        {"min_scale: -30\n", "min_scale: x\n", CBVH_VEC_E_HEADER, "not a decimal integer"},
        {"seed: 0x", "seed: 0y", CBVH_VEC_E_HEADER, "seed '0y"},
        {"level: 1\n", "level: 1\nencoding: modulo\n", CBVH_VEC_E_HEADER, "takes no 'encoding'"},
        {"---\n", "--\n", CBVH_VEC_E_HEADER, "malformed header line '--'"},
        {"node_clb ->", "node_clb", CBVH_VEC_E_FIELDS, "found 'lb_mod', expected '->'"},
        {" status\n", "\n", CBVH_VEC_E_FIELDS, "fields header ends early: expected 'status'"},
        {" status\n", " status extra\n", CBVH_VEC_E_FIELDS, "extra names"},
        {"# cbvh golden vectors", "# cbvh golden vector", CBVH_VEC_E_MAGIC, "not a cbvh vector file"},
        {"unit: axis_compress", "unit: axis_compress\r", CBVH_VEC_E_UNIT, "unknown unit 'axis_compress\\x0D'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *at = strstr(text, cases[i].from);
        assert_non_null(at);
        size_t pre = (size_t)(at - text), fl = strlen(cases[i].from), tl = strlen(cases[i].to);
        size_t n = len - fl + tl;
        char *p = malloc(n);
        memcpy(p, text, pre);
        memcpy(p + pre, cases[i].to, tl);
        memcpy(p + pre + tl, at + fl, len - pre - fl);
        cbvh_vec_status st = parse(p, n);
        if (st != cases[i].st || !strstr(err, cases[i].msg))
            fail_msg("case %zu: status %d '%s', want %d with '%s'", i, st, err, cases[i].st, cases[i].msg);
        free(p);
    }
    /* A vector beyond the count (appended); an empty line and a stray space
     * (inserted as the first vector line). */
    const char *extra[] = {"00000000 00000000 E2 000 000 E2 00000000 00000000 00\n", "\n", " \n"};
    const char *want[] = {"more vectors than the header's count", "mem:12: empty line", "mem:12: 2 fields, expected 10"};
    size_t body = (size_t)(strstr(text, "---\n") - text) + 4;
    for (int i = 0; i < 3; i++) {
        size_t xl = strlen(extra[i]), at = i == 0 ? len : body;
        char *p = malloc(len + xl);
        memcpy(p, text, at);
        memcpy(p + at, extra[i], xl);
        memcpy(p + at + xl, text + at, len - at);
        assert_int_not_equal(parse(p, len + xl), CBVH_VEC_OK);
        if (!strstr(err, want[i])) fail_msg("extra %d: '%s'", i, err);
        free(p);
    }
    free(text);
}

/* text with the value of header key replaced (the whole line). */
static char *with_header(const char *text, size_t len, const char *key, const char *value, size_t *n) {
    char k[64];
    snprintf(k, sizeof k, "\n%s: ", key);
    const char *at = strstr(text, k);
    assert_non_null(at);
    at += strlen(k);
    const char *eol = strchr(at, '\n');
    size_t pre = (size_t)(at - text), vl = strlen(value);
    *n = len - (size_t)(eol - at) + vl;
    char *p = malloc(*n);
    memcpy(p, text, pre);
    memcpy(p + pre, value, vl);
    memcpy(p + pre + vl, eol, len - (size_t)(eol - text));
    return p;
}

/* Header integers have one spelling; count >= 1; no generator newer than this
 * tool; the level agrees with the file name; over-long numbers are out of
 * range, not "not a decimal integer". */
static void test_header_values(void **state) {
    (void)state;
    size_t len;
    char *text = gen_text("axis_compress", 6, &len); /* count is line 10 */
    struct {
        const char *key, *value, *name;
        cbvh_vec_status st;
        const char *msg; /* NULL: accepted */
    } cases[] = {
        {"count", "0", "mem", CBVH_VEC_E_PARAM, "mem:10: count 0 out of range [1, 100000000]"},
        {"count", "99999999999", "mem", CBVH_VEC_E_PARAM, "mem:10: count 99999999999 out of range [1, 100000000]"},
        {"count", "1234567890123456789012", "mem", CBVH_VEC_E_PARAM,
         "mem:10: count 1234567890123456789012 out of range"},
        {"count", "02028", "mem", CBVH_VEC_E_HEADER, "mem:10: count: '02028' is not written canonically"},
        {"count", "+2028", "mem", CBVH_VEC_E_HEADER, "mem:10: count: '+2028' is not written canonically"},
        {"count", "-", "mem", CBVH_VEC_E_HEADER, "mem:10: count: '-' is not a decimal integer"},
        {"format", "01", "mem", CBVH_VEC_E_VERSION, "mem:3: format: '01' is not written canonically"},
        {"format", "+1", "mem", CBVH_VEC_E_VERSION, "mem:3: format: '+1' is not written canonically"},
        {"quant_bits", "06", "mem", CBVH_VEC_E_HEADER, "mem:4: quant_bits: '06' is not written canonically"},
        {"min_scale", "-030", "mem", CBVH_VEC_E_HEADER, "mem:5: min_scale: '-030' is not written canonically"},
        {"min_scale", "-0", "mem", CBVH_VEC_E_HEADER, "mem:5: min_scale: '-0' is not written canonically"},
        {"level", "01", "mem", CBVH_VEC_E_HEADER, "mem:6: level: '01' is not written canonically"},
        {"generator", "99", "mem", CBVH_VEC_E_VERSION, "mem:8: generator 99 is newer than this tool's"},
        {"generator", "007", "mem", CBVH_VEC_E_HEADER, "mem:8: generator: '007' is not written canonically"},
        {"level", "2", "mem", CBVH_VEC_E_PARAM, "mem:6: level 2 but the file name does not end in '-L2.vec'"},
        {"level", "2", "d/x.vec", CBVH_VEC_E_PARAM, "d/x.vec:6: level 2 but the file name does not end in '-L2.vec'"},
        {"level", "1", "d/x-L2.vec", CBVH_VEC_E_PARAM, "d/x-L2.vec:6: level 1 but the file name ends in '-L2.vec'"},
        {"level", "2", "d/x-L2.vec", CBVH_VEC_OK, NULL},
        {"min_scale", "0", "mem", CBVH_VEC_OK, NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        size_t n;
        char *p = with_header(text, len, cases[i].key, cases[i].value, &n);
        cbvh_vecfile vf;
        cbvh_vec_status st = cbvh_vecfile_parse(p, n, cases[i].name, &vf, err, sizeof err);
        cbvh_vecfile_free(&vf);
        if (st != cases[i].st || (cases[i].msg && strncmp(err, cases[i].msg, strlen(cases[i].msg)) != 0))
            fail_msg("%s: %s: status %d '%s', want %d with '%s'", cases[i].key, cases[i].value, st, err, cases[i].st,
                     cases[i].msg ? cases[i].msg : "");
        assert_null(strchr(err, '\n'));
        free(p);
    }
    free(text);
}

/* A file cut off right after its first line's text is truncated, not foreign;
 * a CRLF first line says so. */
static void test_first_line_messages(void **state) {
    (void)state;
    const char *magic = CBVH_VEC_MAGIC;
    assert_int_equal(parse(magic, strlen(magic)), CBVH_VEC_E_HEADER);
    assert_string_equal(err, "mem:1: first line '# cbvh golden vectors' is not terminated (file truncated?)");
    assert_int_equal(parse(magic, 6), CBVH_VEC_E_HEADER);
    assert_non_null(strstr(err, "mem:1: first line '# cbvh' is not terminated"));
    const char crlf[] = CBVH_VEC_MAGIC "\r\nunit: ray_box\r\n";
    assert_int_equal(parse(crlf, sizeof crlf - 1), CBVH_VEC_E_MAGIC);
    assert_non_null(strstr(err, "mem:1: first line ends in CR (Windows line endings)"));
    const char other[] = "# cbvh golden vectorz";
    assert_int_equal(parse(other, sizeof other - 1), CBVH_VEC_E_MAGIC);
    assert_non_null(strstr(err, "not a cbvh vector file"));
}

/* ---- MANIFEST and check on a scratch directory ---------------------------- */

static char dir[256];

static void write_bytes(const char *name, const char *buf, size_t len) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(buf, 1, len, f), len);
    fclose(f);
}

static void make_dir_with(const char *unit, int bits, const char *name) {
    snprintf(dir, sizeof dir, "/tmp/cbvh-vectest-XXXXXX");
    assert_non_null(mkdtemp(dir));
    size_t len;
    char *text = gen_text(unit, bits, &len);
    write_bytes(name, text, len);
    char hex[65];
    assert_int_equal(cbvh_sha256_hex(text, len, hex), 0);
    cbvh_manifest m = {0};
    assert_int_equal(cbvh_manifest_set(&m, name, hex), 0);
    assert_int_equal(cbvh_manifest_save(dir, &m, err, sizeof err), 0);
    cbvh_manifest_free(&m);
    free(text);
}

static void remove_dir(void) {
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static int run_check_path(const char *path, const char *backend, char **out, char **log);

/* Runs check on dir; returns the status; out/log captured. */
static int run_check(const char *backend, char **out, char **log) { return run_check_path(dir, backend, out, log); }

/* check of path on the model: status want, log_has (if not NULL) in its log,
 * log_lacks (if not NULL) not. */
static void check_should(const char *path, int want, const char *log_has, const char *log_lacks) {
    char *out, *log;
    assert_int_equal(run_check_path(path, "model", &out, &log), want);
    if (log_has && !strstr(log, log_has)) fail_msg("'%s' not in: %s", log_has, log);
    if (log_lacks && strstr(log, log_lacks)) fail_msg("'%s' in: %s", log_lacks, log);
    if (want == CBVH_CHECK_PASS) assert_non_null(strstr(out, " passed, 0 failed"));
    free(out);
    free(log);
}

static int run_check_path(const char *path, const char *backend, char **out, char **log) {
    size_t ol, ll;
    FILE *fo = open_memstream(out, &ol), *fl = open_memstream(log, &ll);
    cbvh_check_opts o;
    memset(&o, 0, sizeof o);
    o.backend = backend;
    o.max_errors = 20;
    o.out = fo;
    o.log = fl;
    const char *paths[1] = {path};
    int rc = cbvh_vectors_check(paths, 1, &o);
    fclose(fo);
    fclose(fl);
    return rc;
}

static void test_sha256_known(void **state) {
    (void)state;
    char hex[65];
    assert_int_equal(cbvh_sha256_hex("abc", 3, hex), 0);
    assert_string_equal(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

static void test_manifest_ok_then_tampered(void **state) {
    (void)state;
    make_dir_with("scale_estimate", 4, "a.vec");
    char *out, *log;
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_PASS);
    assert_non_null(strstr(out, "a.vec: "));
    assert_non_null(strstr(out, " passed, 0 failed"));
    free(out);
    free(log);
    /* Tamper the hash: first digit changed. */
    char path[512];
    snprintf(path, sizeof path, "%s/MANIFEST", dir);
    FILE *f = fopen(path, "r+b");
    int c = fgetc(f);
    fseek(f, 0, SEEK_SET);
    fputc(c == '0' ? '1' : '0', f);
    fclose(f);
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_BAD_INPUT);
    assert_non_null(strstr(log, "a.vec: SHA-256 mismatch"));
    assert_null(strstr(out, "passed")); /* nothing ran */
    free(out);
    free(log);
    remove_dir();
}

static void test_manifest_missing_and_unlisted(void **state) {
    (void)state;
    char *out, *log;
    make_dir_with("axis_compress", 3, "b.vec");
    write_bytes("extra.vec", "x", 1); /* not listed */
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_BAD_INPUT);
    assert_non_null(strstr(log, "extra.vec: vector file not listed in MANIFEST"));
    free(out);
    free(log);
    char path[512];
    snprintf(path, sizeof path, "%s/extra.vec", dir);
    remove(path);
    snprintf(path, sizeof path, "%s/b.vec", dir);
    remove(path); /* listed but missing */
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_BAD_INPUT);
    assert_non_null(strstr(log, "b.vec: cannot open"));
    assert_non_null(strstr(log, "(listed in MANIFEST)"));
    free(out);
    free(log);
    snprintf(path, sizeof path, "%s/MANIFEST", dir);
    remove(path); /* no manifest at all */
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_BAD_INPUT);
    assert_non_null(strstr(log, "MANIFEST: missing"));
    free(out);
    free(log);
    write_bytes("MANIFEST", "deadbeef  b.vec\n", 16); /* malformed */
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_BAD_INPUT);
    assert_non_null(strstr(log, "MANIFEST:1: malformed line"));
    free(out);
    free(log);
    remove_dir();
}

/* A vector file that passes the manifest but is itself bad: exit 2. */
static void test_check_bad_vector_file(void **state) {
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/cbvh-vectest-XXXXXX");
    assert_non_null(mkdtemp(dir));
    char *buf;
    size_t len;
    char path[1024];
    snprintf(path, sizeof path, "%s/bad_hex.vec", FIXTURES);
    assert_int_equal(cbvh_read_file(path, &buf, &len, err, sizeof err), 0);
    write_bytes("bad_hex.vec", buf, len);
    char hex[65];
    cbvh_sha256_hex(buf, len, hex);
    free(buf);
    cbvh_manifest m = {0};
    cbvh_manifest_set(&m, "bad_hex.vec", hex);
    assert_int_equal(cbvh_manifest_save(dir, &m, err, sizeof err), 0);
    cbvh_manifest_free(&m);
    char *out, *log;
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_BAD_INPUT);
    assert_non_null(strstr(log, "bad_hex.vec:13: bad hex digit 'G'"));
    free(out);
    free(log);
    remove_dir();
}

/* One flipped expected value: exit 1, the mismatch shown with field names. */
static void test_check_mismatch(void **state) {
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/cbvh-vectest-XXXXXX");
    assert_non_null(mkdtemp(dir));
    size_t len;
    char *text = gen_text("axis_decode", 6, &len);
    /* Vector 5 (line 13 + 5 = 18): flip the last digit of its clb output (field 9 of 0..11). */
    char *line = strstr(text, "---\n") + 4;
    for (int i = 0; i < 5; i++) line = strchr(line, '\n') + 1;
    char *p = line;
    for (int f = 0; f < 9; f++) p = strchr(p, ' ') + 1;
    p[7] = p[7] == '0' ? '1' : '0';
    write_bytes("x.vec", text, len);
    char hex[65];
    cbvh_sha256_hex(text, len, hex);
    cbvh_manifest m = {0};
    cbvh_manifest_set(&m, "x.vec", hex);
    assert_int_equal(cbvh_manifest_save(dir, &m, err, sizeof err), 0);
    cbvh_manifest_free(&m);
    char *out, *log;
    assert_int_equal(run_check("model", &out, &log), CBVH_CHECK_MISMATCH);
    assert_non_null(strstr(out, "x.vec:18: axis_decode (N=6 min_scale=-30 modulo)"));
    assert_non_null(strstr(out, "inputs: parent_scale="));
    assert_non_null(strstr(out, " lb_code="));
    assert_non_null(strstr(out, " ub_code="));
    const char *clb = strstr(out, "  clb ");
    assert_non_null(clb);
    const char *eol = strchr(clb, '\n');
    assert_non_null(strstr(clb, "<-- differs"));
    assert_true(strstr(clb, "<-- differs") < eol);
    const char *cub = strstr(out, "  cub ");
    assert_true(strstr(cub, "<-- differs") == NULL || strstr(cub, "<-- differs") > strchr(cub, '\n'));
    assert_non_null(strstr(out, " passed, 1 failed\n"));
    assert_non_null(strstr(out, "total: 1 files, "));
    free(out);
    free(log);
    free(text);
    remove_dir();
}

/* gen's journal (.MANIFEST.pending): a file renamed into place by a gen
 * killed before it rewrote MANIFEST is accepted with a note, a stale journal
 * changes nothing, a file matching neither fails, and settle lists it. */
static void test_manifest_journal(void **state) {
    (void)state;
    make_dir_with("scale_estimate", 4, "a.vec");
    size_t len;
    char *text = gen_text("scale_estimate", 5, &len), hex[65], old_hex[65];
    assert_int_equal(cbvh_sha256_hex(text, len, hex), 0);
    cbvh_manifest m;
    assert_int_equal(cbvh_manifest_load(dir, &m, err, sizeof err), 0);
    snprintf(old_hex, sizeof old_hex, "%s", m.e[0].sha256);
    cbvh_manifest_free(&m);
    const char *note = "was put in place by a `vectors gen` killed before it updated MANIFEST";
    char path[600];
    snprintf(path, sizeof path, "%s/a.vec", dir);

    /* Killed before the rename: the old file still matches MANIFEST. */
    assert_int_equal(cbvh_manifest_journal_write(dir, "a.vec", hex, err, sizeof err), 0);
    check_should(dir, CBVH_CHECK_PASS, NULL, note);

    /* Killed after the rename: the new file matches the journal only
     * (checked as a directory and as a single file). */
    write_bytes("a.vec", text, len);
    check_should(dir, CBVH_CHECK_PASS, "a.vec was put in place", NULL);
    check_should(path, CBVH_CHECK_PASS, note, NULL);

    /* Neither: one byte changed. */
    text[len - 2] = text[len - 2] == '0' ? '1' : '0';
    write_bytes("a.vec", text, len);
    check_should(dir, CBVH_CHECK_BAD_INPUT, "a.vec: SHA-256 mismatch: MANIFEST says", NULL);
    text[len - 2] = text[len - 2] == '0' ? '1' : '0';
    write_bytes("a.vec", text, len);

    /* Settling (the next gen, under the lock) lists it and drops the journal. */
    assert_int_equal(cbvh_manifest_load(dir, &m, err, sizeof err), 0);
    assert_int_equal(cbvh_manifest_settle(dir, &m, err, sizeof err), 0);
    cbvh_manifest_free(&m);
    assert_int_equal(cbvh_manifest_load(dir, &m, err, sizeof err), 0);
    assert_int_equal(m.n, 1);
    assert_string_equal(m.e[0].sha256, hex);
    assert_string_not_equal(m.e[0].sha256, old_hex);
    cbvh_manifest_free(&m);
    char jpath[600];
    snprintf(jpath, sizeof jpath, "%s/%s", dir, CBVH_MANIFEST_JOURNAL);
    assert_int_equal(access(jpath, F_OK), -1);
    check_should(dir, CBVH_CHECK_PASS, NULL, note);

    /* A new file the journal vouches for is not "unlisted"; absent, it is ignored. */
    write_bytes("c.vec", text, len);
    check_should(dir, CBVH_CHECK_BAD_INPUT, "c.vec: vector file not listed in MANIFEST", NULL);
    assert_int_equal(cbvh_manifest_journal_write(dir, "c.vec", hex, err, sizeof err), 0);
    check_should(dir, CBVH_CHECK_PASS, "c.vec was put in place", NULL);
    snprintf(path, sizeof path, "%s/c.vec", dir);
    remove(path);
    check_should(dir, CBVH_CHECK_PASS, NULL, note);

    /* A malformed journal is named. */
    write_bytes(CBVH_MANIFEST_JOURNAL, "deadbeef  a.vec\n", 16);
    check_should(dir, CBVH_CHECK_BAD_INPUT, ".MANIFEST.pending:1: malformed line", NULL);
    free(text);
    remove_dir();
}

/* A MANIFEST with CRLF line endings says so (it said "bad file name"). */
static void test_manifest_crlf(void **state) {
    (void)state;
    char text[200];
    snprintf(text, sizeof text, "%064d  a.vec\r\n", 0);
    cbvh_manifest m;
    assert_int_equal(cbvh_manifest_parse(text, strlen(text), "MANIFEST", &m, err, sizeof err), -1);
    assert_string_equal(err, "MANIFEST:1: line ends in CR (Windows line endings); MANIFEST lines end in \\n only");
    assert_int_equal(m.n, 0);
}

/* gen's temporary files (".NAME.tmp.PID") and nothing else. */
static void test_temp_names(void **state) {
    (void)state;
    assert_true(cbvh_manifest_is_temp(".ray_box-N6-ms-30.vec.tmp.4711"));
    assert_true(cbvh_manifest_is_temp(".MANIFEST.tmp.1"));
    const char *no[] = {"ray_box-N6-ms-30.vec", ".vec.tmp.", ".a.vec.tmp.", ".a.vec.tmp.12x",
                        "a.vec.tmp.1",          "..tmp.1",   "."};
    for (size_t i = 0; i < sizeof no / sizeof no[0]; i++)
        if (cbvh_manifest_is_temp(no[i])) fail_msg("'%s' taken for a temporary file", no[i]);
}

/* A stdio stream for o.log that rewrites dir/x.vec the moment the check
 * writes its first note (auto's "no board found", after the MANIFEST check and
 * before any vector runs): the rewritten bytes must not run unverified. */
static char rewrite_path[600];
static const char *rewrite_text;
static size_t rewrite_len;
static char *log_copy;
static size_t log_copy_len;

static ssize_t rewriting_log(void *cookie, const char *buf, size_t n) {
    (void)cookie;
    if (rewrite_text) {
        FILE *f = fopen(rewrite_path, "wb");
        if (f) {
            fwrite(rewrite_text, 1, rewrite_len, f);
            fclose(f);
        }
        rewrite_text = NULL;
    }
    char *nl = realloc(log_copy, log_copy_len + n + 1);
    if (!nl) return -1;
    log_copy = nl;
    memcpy(log_copy + log_copy_len, buf, n);
    log_copy_len += n;
    log_copy[log_copy_len] = '\0';
    return (ssize_t)n;
}

static void test_check_file_rewritten_after_verify(void **state) {
    (void)state;
    setenv("CBVH_USB_VID", "f0f0", 1); /* no such board: auto writes its note */
    setenv("CBVH_USB_PID", "0f0f", 1);
    size_t len;
    char *text = gen_text("scale_estimate", 5, &len);
    /* The same file with vector 0's status flipped: a mismatch if it ran. */
    char *evil = malloc(len);
    memcpy(evil, text, len);
    char *v0 = strstr(evil, "---\n") + 4;
    char *eol = strchr(v0, '\n');
    eol[-2] = eol[-2] == '4' ? '0' : '4';
    for (int single = 0; single < 2; single++) {
        make_dir_with("scale_estimate", 5, "x.vec");
        snprintf(rewrite_path, sizeof rewrite_path, "%s/x.vec", dir);
        rewrite_text = evil;
        rewrite_len = len;
        log_copy = NULL;
        log_copy_len = 0;
        cookie_io_functions_t io = {NULL, rewriting_log, NULL, NULL};
        FILE *logf = fopencookie(NULL, "w", io);
        assert_non_null(logf);
        setvbuf(logf, NULL, _IONBF, 0);
        char *out = NULL;
        size_t ol;
        FILE *fo = open_memstream(&out, &ol);
        cbvh_check_opts o;
        memset(&o, 0, sizeof o);
        o.backend = "auto";
        o.max_errors = 20;
        o.out = fo;
        o.log = logf;
        const char *paths[1] = {single ? rewrite_path : dir};
        int rc = cbvh_vectors_check(paths, 1, &o);
        fclose(fo);
        fclose(logf);
        assert_null(rewrite_text); /* the hook did run */
        if (rc != CBVH_CHECK_BAD_INPUT || !strstr(log_copy, "x.vec: SHA-256 mismatch: MANIFEST says "))
            fail_msg("%s: rewritten file: exit %d, log '%s', out '%s'", single ? "file" : "dir", rc, log_copy, out);
        assert_null(strstr(out, "passed"));
        free(out);
        free(log_copy);
        log_copy = NULL;
        remove_dir();
    }
    free(evil);
    free(text);
}

/* auto: no board here, so one line on the log and the model runs. */
static void test_auto_falls_back(void **state) {
    (void)state;
    setenv("CBVH_USB_VID", "f0f0", 1); /* an identity no real device has */
    setenv("CBVH_USB_PID", "0f0f", 1);
    make_dir_with("axis_decode", 4, "c.vec");
    char *out, *log;
    assert_int_equal(run_check("auto", &out, &log), CBVH_CHECK_PASS);
    assert_non_null(strstr(log, "no board found"));
    assert_non_null(strstr(log, "using the software model"));
    assert_int_equal(strchr(log, '\n') - log + 1, (long)strlen(log)); /* exactly one line */
    assert_non_null(strstr(out, "backend: model"));
    free(out);
    free(log);
    remove_dir();
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good),
        cmocka_unit_test(test_truncated),
        cmocka_unit_test(test_short_count),
        cmocka_unit_test(test_bad_hex),
        cmocka_unit_test(test_lower_hex),
        cmocka_unit_test(test_wrong_width),
        cmocka_unit_test(test_field_count),
        cmocka_unit_test(test_unknown_unit),
        cmocka_unit_test(test_missing_key),
        cmocka_unit_test(test_bad_header),
        cmocka_unit_test(test_version),
        cmocka_unit_test(test_bad_param),
        cmocka_unit_test(test_fields),
        cmocka_unit_test(test_empty),
        cmocka_unit_test(test_garbage),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_not_regular),
        cmocka_unit_test(test_every_truncation),
        cmocka_unit_test(test_random_damage),
        cmocka_unit_test(test_roundtrip),
        cmocka_unit_test(test_header_rules),
        cmocka_unit_test(test_header_values),
        cmocka_unit_test(test_first_line_messages),
        cmocka_unit_test(test_sha256_known),
        cmocka_unit_test(test_manifest_ok_then_tampered),
        cmocka_unit_test(test_manifest_missing_and_unlisted),
        cmocka_unit_test(test_check_bad_vector_file),
        cmocka_unit_test(test_check_mismatch),
        cmocka_unit_test(test_auto_falls_back),
        cmocka_unit_test(test_manifest_journal),
        cmocka_unit_test(test_manifest_crlf),
        cmocka_unit_test(test_temp_names),
        cmocka_unit_test(test_check_file_rewritten_after_verify),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
