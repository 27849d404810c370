/* Scenes, float builders and CBVH compressors (docs/study.md). */
#define _POSIX_C_SOURCE 200809L /* mkfifo */
#include <float.h>
#include <math.h>
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

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "test_util.h"
#include "scene/scene_load.h"

#ifndef CBVH_SCENES_DIR
#error "CBVH_SCENES_DIR must name the scenes folder"
#endif

static char errbuf[512];

/* ---- helpers ----------------------------------------------------------- */

static char *write_temp(const char *suffix, const void *data, size_t len) {
    static char path[256];
    snprintf(path, sizeof path, "/tmp/cbvh_test_%d_%s", (int)getpid(), suffix);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    if (len) assert_int_equal(fwrite(data, 1, len, f), len);
    fclose(f);
    return path;
}

static int import_text(const char *suffix, const char *text, cbvh_scene *s) {
    char *p = write_temp(suffix, text, strlen(text));
    int rc = cbvh_scene_import(p, s, errbuf, sizeof errbuf);
    remove(p);
    return rc;
}

static void load_bunny(cbvh_scene *s) {
    int rc = cbvh_scene_import(CBVH_SCENES_DIR "/bunny-small.obj", s, errbuf, sizeof errbuf);
    if (rc) fail_msg("%s", errbuf);
}

static uint32_t rng_state = 12345u;
static uint32_t rnd(void) { return tu_xorshift32(&rng_state); }
static float rndf(void) { return (float)(rnd() & 0xFFFFFF) / 16777216.0f; }

static void random_scene(cbvh_scene *s, uint32_t n, float spread, float size) {
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "random");
    s->tris = malloc(n * sizeof *s->tris);
    s->ntris = n;
    for (uint32_t i = 0; i < n; i++) {
        float c[3] = {spread * (rndf() - 0.5f), spread * (rndf() - 0.5f), spread * (rndf() - 0.5f)};
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) s->tris[i].v[v][a] = c[a] + size * (rndf() - 0.5f);
    }
}

/* An empty scene of n zeroed triangles, to be filled by the test. */
static void zero_scene(cbvh_scene *s, uint32_t n) {
    memset(s, 0, sizeof *s);
    s->ntris = n;
    s->tris = calloc(n, sizeof *s->tris);
    assert_non_null(s->tris);
}

static void no_error(int rc) {
    if (rc) fail_msg("%s", errbuf);
}

/* ---- import ------------------------------------------------------------ */

static void test_import_bunny(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    assert_int_equal(s.ntris, 3674);
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    for (int a = 0; a < 3; a++) assert_true(lo[a] < hi[a] && hi[a] - lo[a] < 100.0f);
    cbvh_scene_free(&s);
}

static void test_import_formats(void **st) {
    (void)st;
    cbvh_scene s;
    const char *off = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    no_error(import_text("a.off", off, &s));
    assert_int_equal(s.ntris, 2);
    assert_float_equal(s.tris[1].v[2][1], 1.0f, 0.0f);
    cbvh_scene_free(&s);
    const char *ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n2 0 0\n0 3 0\n3 0 1 2\n";
    no_error(import_text("a.ply", ply, &s));
    assert_int_equal(s.ntris, 1);
    assert_float_equal(s.tris[0].v[2][1], 3.0f, 0.0f);
    cbvh_scene_free(&s);
    const char *stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
                      "endfacet\nendsolid t\n";
    no_error(import_text("a.stl", stl, &s));
    assert_int_equal(s.ntris, 1);
    cbvh_scene_free(&s);
    /* A quad is triangulated. */
    no_error(import_text("q.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", &s));
    assert_int_equal(s.ntris, 2);
    cbvh_scene_free(&s);
}

static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
static void base64(const uint8_t *in, size_t n, char *out) {
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = b64[v >> 18 & 63];
        out[o++] = b64[v >> 12 & 63];
        out[o++] = i + 1 < n ? b64[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? b64[v & 63] : '=';
    }
    out[o] = 0;
}

/* glTF with one triangle, one morph target (+1 in z for every vertex), and a
 * weight animation 0 -> 1 over one second; node translated by +10 in x. */
static void test_import_gltf_morph(void **st) {
    (void)st;
    float buf[22] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* positions */
                     0, 0, 1, 0, 0, 1, 0, 0, 1, /* target deltas */
                     0, 1,                      /* times */
                     0, 1};                     /* weights */
    char enc[200], gltf[4096];
    base64((const uint8_t *)buf, sizeof buf, enc);
    snprintf(gltf, sizeof gltf,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"mesh\":0,\"translation\":[10,0,0]}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"targets\":[{\"POSITION\":1}]}],"
             "\"weights\":[0]}],"
             "\"buffers\":[{\"byteLength\":88,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,"
             "\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":8},{\"buffer\":0,\"byteOffset\":80,"
             "\"byteLength\":8}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],"
             "\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,1],"
             "\"max\":[0,0,1]},{\"bufferView\":2,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],"
             "\"max\":[1]},{\"bufferView\":3,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],"
             "\"animations\":[{\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}],"
             "\"samplers\":[{\"input\":2,\"output\":3,\"interpolation\":\"LINEAR\"}]}]}",
             enc);
    cbvh_scene s;
    no_error(import_text("m.gltf", gltf, &s));
    assert_int_equal(s.ntris, 1);
    assert_float_equal(s.tris[0].v[1][0], 11.0f, 0.0f); /* node transform applied */
    assert_int_equal(s.nmorph, 1);
    assert_true(s.nkeys >= 2);
    assert_float_equal(cbvh_scene_duration(&s), 1.0f, 1e-6f);
    cbvh_tri fr;
    cbvh_scene_frame(&s, 0.5f, &fr);
    assert_float_equal(fr.v[0][2], 0.5f, 1e-6f);
    cbvh_scene_frame(&s, 1.0f, &fr);
    assert_float_equal(fr.v[2][2], 1.0f, 1e-6f);
    assert_float_equal(fr.v[2][0], 10.0f, 1e-6f);
    cbvh_scene_free(&s);
}

/* Nested node transforms compose parent x child: a parent scaled by 2 and
 * rotated 90 degrees about z over a child translated by +1 in x puts the
 * child's vertex (1, 0, 0) at R S (v + t) = (0, 4, 0); the other order gives
 * (0, 3, 0) and no rotation (4, 0, 0). */
static void test_import_gltf_nested_nodes(void **st) {
    (void)st;
    float buf[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    char enc[100], gltf[2048];
    base64((const uint8_t *)buf, sizeof buf, enc);
    snprintf(gltf, sizeof gltf,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"children\":[1],\"scale\":[2,2,2],\"rotation\":[0,0,0.70710678,0.70710678]},"
             "{\"mesh\":0,\"translation\":[1,0,0]}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]}]}",
             enc);
    cbvh_scene s;
    no_error(import_text("n.gltf", gltf, &s));
    assert_int_equal(s.ntris, 1);
    assert_float_equal(s.tris[0].v[0][0], 0.0f, 1e-5f); /* (0,0,0) + t -> (1,0,0) -> (2,0,0) -> (0,2,0) */
    assert_float_equal(s.tris[0].v[0][1], 2.0f, 1e-5f);
    assert_float_equal(s.tris[0].v[1][0], 0.0f, 1e-5f);
    assert_float_equal(s.tris[0].v[1][1], 4.0f, 1e-5f);
    assert_float_equal(s.tris[0].v[2][0], -2.0f, 1e-5f); /* (0,1,0) + t = (1,1,0) -> (2,2,0) -> (-2,2,0) */
    assert_float_equal(s.tris[0].v[2][1], 2.0f, 1e-5f);
    cbvh_scene_free(&s);
}

/* An import that assimp cannot finish: -1, no scene, a one-line error
 * containing one of the two messages (alt may be NULL), and the next import
 * works (the child process took the failure). */
static void expect_importer_failure(const char *path, const char *msg, const char *alt) {
    cbvh_scene s;
    errbuf[0] = 0;
    assert_int_equal(cbvh_scene_import(path, &s, errbuf, sizeof errbuf), -1);
    assert_null(s.tris);
    assert_null(strchr(errbuf, '\n'));
    if (!strstr(errbuf, msg) && !(alt && strstr(errbuf, alt))) fail_msg("unexpected error: %s", errbuf);
    load_bunny(&s);
    assert_int_equal(s.ntris, 3674);
    cbvh_scene_free(&s);
}

/* A glTF on which assimp 5.2's reader dereferences NULL (found by
 * fuzz_mesh_import): the import runs in a child process, so the crash is a
 * one-line error. */
static void test_import_assimp_crash(void **st) {
    (void)st;
    expect_importer_failure(CBVH_BUILD_FIXTURES "/assimp-crash.gltf", "the importer (assimp) crashed on it",
                            "ended without a result");
}

/* A file on which assimp 5.2's PLY reader (chosen by the "ply" magic, the
 * name says glTF) never returns (found by fuzz_mesh_import): the child is
 * killed at its time limit. */
static void test_import_assimp_hang(void **st) {
    (void)st;
    expect_importer_failure(CBVH_BUILD_FIXTURES "/assimp-hang.gltf", "the importer (assimp) did not finish within 5 s",
                            NULL);
}

static void expect_import_error(const char *suffix, const char *text, const char *needle) {
    cbvh_scene s;
    errbuf[0] = 0;
    assert_int_equal(import_text(suffix, text, &s), -1);
    assert_null(s.tris);
    assert_int_equal(s.ntris, 0);
    assert_null(strchr(errbuf, '\n'));
    if (needle && !strstr(errbuf, needle)) fail_msg("error '%s' lacks '%s'", errbuf, needle);
}

static void test_import_errors(void **st) {
    (void)st;
    expect_import_error("e.obj", "", "empty");
    expect_import_error("n.obj", "v 0 0 0\nv 1 0 0\n", NULL);
    expect_import_error("r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", NULL);
    expect_import_error("f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n", NULL);
    expect_import_error("i.off", "OFF\n3 1 0\n0 0 0\n1e999 0 0\n0 1 0\n3 0 1 2\n", NULL);
    expect_import_error("x.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "out of range");
    expect_import_error("m.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n", "out of range");
    expect_import_error("t.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", NULL);
    expect_import_error("r.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0\n2 0 0\n0 3 0\n3 0 1 5\n", "out of range");
    expect_import_error("g.ply", "ply\nformat ascii 1.0\nelement vertex 900\nend_header\n1 2\n", NULL);
    expect_import_error("b.gltf", "{\"asset\":{\"version\":\"2.0\"}, \"meshes\":[{]}", NULL);
    /* assimp throws mid-parse (and leaks inside itself: tests/lsan-assimp.supp) */
    expect_import_error("t.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\n", "cannot import");
    cbvh_scene s;
    assert_int_equal(cbvh_scene_import("/nonexistent/dir/x.obj", &s, errbuf, sizeof errbuf), -1);
    assert_non_null(strstr(errbuf, "cannot open"));
    assert_int_equal(cbvh_scene_open("proc:nosuch", &s, errbuf, sizeof errbuf), -1);
    assert_int_equal(cbvh_scene_open("proc:cloth:0", &s, errbuf, sizeof errbuf), -1);
}

/* The import of `path` fails with a one-line message starting with `want`
 * (printf format, %s = path) and leaves nothing loaded. */
static void expect_error_at(const char *path, const char *want_fmt) {
    char want[512];
    snprintf(want, sizeof want, want_fmt, path);
    cbvh_scene s;
    errbuf[0] = 0;
    assert_int_equal(cbvh_scene_import(path, &s, errbuf, sizeof errbuf), -1);
    assert_null(s.tris);
    assert_int_equal(s.ntris, 0);
    assert_null(strchr(errbuf, '\n'));
    if (strncmp(errbuf, want, strlen(want)) != 0) fail_msg("error '%s' does not start with '%s'", errbuf, want);
}

static void expect_error_prefix(const char *suffix, const void *data, size_t len, const char *want_fmt) {
    char *p = write_temp(suffix, data, len);
    expect_error_at(p, want_fmt);
    remove(p);
}

static void expect_text_error(const char *suffix, const char *text, const char *want_fmt) {
    expect_error_prefix(suffix, text, strlen(text), want_fmt);
}

/* An OBJ 'f' line without indices: assimp drops the face with only a log
 * message, so it is refused (as an OFF face of 0 vertices is); an undefined
 * material alone changes no triangle and is not an error. */
static void test_import_obj_empty_face(void **st) {
    (void)st;
    expect_text_error("bare.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nosuch\nf\nf 1 2 3\n",
                      "cannot import '%s': a face with no vertices (an 'f' line without indices)");
    expect_text_error("bare2.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf   \r\n",
                      "cannot import '%s': a face with no vertices");
    cbvh_scene s;
    assert_int_equal(import_text("mtl.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nosuch\nf 1 2 3\n", &s), 0);
    assert_int_equal(s.ntris, 1);
    cbvh_scene_free(&s);
}

#define PLY_ASCII_HEAD(nv, nf)                                                                                  \
    "ply\nformat ascii 1.0\nelement vertex " #nv "\nproperty float x\nproperty float y\nproperty float z\n"     \
    "element face " #nf "\nproperty list uchar int vertex_indices\nend_header\n"
#define QUAD_VERTS "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"

/* assimp trusts a PLY header's counts: the body is checked against them. */
static void test_import_ply_counts(void **st) {
    (void)st;
    /* one face fewer than declared: assimp invented a third triangle */
    expect_text_error("f.ply", PLY_ASCII_HEAD(4, 3) QUAD_VERTS "3 0 1 2\n3 0 2 3\n",
                      "'%s': the header declares 3 face records, the file has 2");
    /* one vertex fewer: assimp read the first face line as a vertex */
    expect_text_error("v.ply", PLY_ASCII_HEAD(5, 2) QUAD_VERTS "3 0 1 2\n3 0 2 3\n",
                      "'%s' line 14: vertex 4: more values than the header's 3 properties");
    expect_text_error("x.ply", PLY_ASCII_HEAD(4, 1) QUAD_VERTS "3 0 1 2\n0 0 1\n",
                      "'%s' line 15: more records than the header declares");
    expect_text_error("l.ply", PLY_ASCII_HEAD(4, 2) QUAD_VERTS "3 0 1\n3 0 2 3\n",
                      "'%s' line 14: face 0: list declares 3 values but has 2");
    expect_text_error("n.ply", PLY_ASCII_HEAD(4, 2) "0 0 0\n1 y 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
                      "'%s' line 11: vertex 1: 'y' is not a number");
    expect_text_error("i.ply", PLY_ASCII_HEAD(4, 2) QUAD_VERTS "3 0 1 2\n3 0 2 z\n",
                      "'%s' line 15: face 1: 'z' is not an integer");
    expect_text_error("r.ply", PLY_ASCII_HEAD(4, 2) QUAD_VERTS "3 0 1 2\n3 0 2 4\n",
                      "'%s' line 15: face 1: vertex index 4 out of range (4 vertices)");
    expect_text_error("h.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
                      "'%s': the PLY header has no end_header line");
    expect_text_error("c.ply", "ply\nformat ascii 1.0\nelement vertex -3\nproperty float x\nend_header\n",
                      "'%s' line 3: element 'vertex' count '-3' is not an integer in 0..4294967295");
    /* a strict header grammar: assimp's reader loops forever on some
     * malformed headers (found by fuzz_mesh_import: a garbled format line
     * and a property before any element) */
    expect_text_error("fm.ply", "ply\nformat ascii 2propeVty float y\nproperty float z\nend_header\n",
                      "'%s' line 2: expected the PLY format line");
    expect_text_error("fv.ply", "ply\nformat ascii 2.0\nelement vertex 0\nend_header\n",
                      "'%s' line 2: expected the PLY format line");
    expect_text_error("pb.ply", "ply\nformat ascii 1.0\nproperty float z\nend_header\n",
                      "'%s' line 3: a property before any element");
    expect_text_error("pt.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n0\n",
                      "'%s' line 4: expected 'property TYPE NAME'");
    expect_text_error("pl.ply", "ply\nformat ascii 1.0\nelement face 1\nproperty list float int v\nend_header\n",
                      "'%s' line 4: expected 'property TYPE NAME'");
    expect_text_error("uk.ply", "ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n",
                      "'%s' line 3: unknown PLY header line 'elemnt'");
    expect_text_error("ex.ply", "ply\nformat ascii 1.0\nelement vertex 1 2\nend_header\n",
                      "'%s' line 3: expected 'element NAME COUNT'");
    expect_text_error("mg.ply", "ply\xff\xff\nformat ascii\nOFF\n3 4 0\n", "'%s' line 1: not a PLY file");
    /* assimp reads these blank lines as records of zeros (and then dropped
     * a face): a second empty line, an empty line after "\r\n", spaces */
    expect_text_error("b2.ply", PLY_ASCII_HEAD(4, 2) QUAD_VERTS "\n\n3 0 1 2\n3 0 2 3\n",
                      "'%s' line 15: blank line where face 0 is expected (read as a record)");
    expect_text_error("bc.ply", PLY_ASCII_HEAD(4, 2) "0 0 0\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n\r\n3 0 1 2\r\n3 0 2 3\r\n",
                      "'%s' line 14: blank line where face 0 is expected (read as a record)");
    expect_text_error("bs.ply", PLY_ASCII_HEAD(4, 2) QUAD_VERTS "  \n3 0 1 2\n3 0 2 3\n",
                      "'%s' line 14: blank line where face 0 is expected (read as a record)");
    /* one empty line after a record, trailing empty lines, comments in the
     * header and extra elements with their own records are fine */
    cbvh_scene s;
    no_error(import_text("ok.ply",
                         "ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\nproperty float y\n"
                         "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                         "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n" QUAD_VERTS
                         "\n3 0 1 2\n3 0 2 3\n0 1\n\n\n",
                         &s));
    assert_int_equal(s.ntris, 2);
    cbvh_scene_free(&s);
}

/* A binary PLY: header + 4 vertices + the faces given (3 indices each). */
static size_t binary_ply(uint8_t *out, const char *endian, unsigned nv_declared, unsigned nf_declared, int nfaces) {
    int n = sprintf((char *)out,
                    "ply\nformat binary_%s_endian 1.0\nelement vertex %u\nproperty float x\nproperty float y\n"
                    "property float z\nelement face %u\nproperty list uchar int vertex_indices\nend_header\n",
                    endian, nv_declared, nf_declared);
    int big = endian[0] == 'b';
    const float v[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const int32_t f[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int i = 0; i < 12 + 3 * nfaces; i++) {
        if (i >= 12 && (i - 12) % 3 == 0) out[n++] = 3;
        uint32_t w;
        if (i < 12)
            memcpy(&w, &v[i], 4);
        else
            memcpy(&w, &f[(i - 12) / 3][(i - 12) % 3], 4);
        for (int b = 0; b < 4; b++) out[n++] = (uint8_t)(w >> (big ? 24 - 8 * b : 8 * b));
    }
    return (size_t)n;
}

static void test_import_ply_binary_size(void **st) {
    (void)st;
    uint8_t buf[512];
    cbvh_scene s;
    for (int e = 0; e < 2; e++) {
        const char *endian = e ? "big" : "little";
        size_t n = binary_ply(buf, endian, 4, 2, 2);
        char *p = write_temp("b.ply", buf, n);
        no_error(cbvh_scene_import(p, &s, errbuf, sizeof errbuf));
        remove(p);
        assert_int_equal(s.ntris, 2);
        assert_float_equal(s.tris[1].v[2][1], 1.0f, 0.0f);
        cbvh_scene_free(&s);
        /* 3 faces declared, 2 present: 48 + 3 x 13 bytes needed, 74 there */
        n = binary_ply(buf, endian, 4, 3, 2);
        expect_error_prefix("t.ply", buf, n,
                            "'%s': binary PLY too short: its header declares records needing at least 87 bytes, "
                            "the file has 74 after the header");
    }
    /* 4e9 vertices claimed by a tiny file: refused before assimp allocates
     * (it threw std::bad_alloc; under ASan the process aborted) */
    size_t n = binary_ply(buf, "little", 4000000000u, 2, 2);
    expect_error_prefix("g.ply", buf, n,
                        "'%s': binary PLY too short: its header declares records needing at least 48000000026 "
                        "bytes, the file has 74 after the header");
}

static void test_import_off_tokens(void **st) {
    (void)st;
    const char *head = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
    char text[256];
    snprintf(text, sizeof text, "%s3 0 1 x\n3 0 2 3\n", head);
    expect_text_error("x.off", text, "'%s' line 7: face 0: vertex index 'x' is not a number");
    snprintf(text, sizeof text, "%sx 0 1 2\n3 0 2 3\n", head);
    expect_text_error("k.off", text, "'%s' line 7: face 0: vertex count 'x' is not an integer");
    snprintf(text, sizeof text, "%s0\n3 0 1 2\n3 0 2 3\n", head);
    expect_text_error("z.off", text, "'%s' line 7: face 0 has 0 vertices (the OFF importer takes 1 to 9)");
    snprintf(text, sizeof text, "%s3 0 1 2\n# c\n3 0 2 3\n", head);
    expect_text_error("h.off", text, "'%s' line 8: a comment or blank line among the records (read as a record)");
    snprintf(text, sizeof text, "%s3 0 1\n3 0 2 3\n", head);
    expect_text_error("s.off", text, "'%s' line 7: face 0 declares 3 vertices but lists 2");
    snprintf(text, sizeof text, "%s3 0 1 2\n3 0 2 3\n0 0 1\n", head);
    expect_text_error("e.off", text, "'%s' line 9: more records than the header's 4 vertices and 2 faces");
    expect_text_error("v.off", "OFF\n4 2 0\n0 0 0\n1 x 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
                      "'%s' line 4: vertex 1: coordinate 'x' is not a number");
    expect_text_error("w.off", "OFF\n4 2 0\n0 0 0\n1 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
                      "'%s' line 4: vertex 1 has 2 coordinates, 3 needed");
    expect_text_error("t.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                      "'%s': the header declares 3 vertices and 2 faces, the file ends after 4");
    expect_text_error("c.off", "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                      "'%s' line 2: the OFF header needs vertex, face and edge counts");
    /* comments in the header and after a record, empty lines and a colour
     * after the indices are fine */
    cbvh_scene s;
    no_error(import_text("ok.off",
                         "# c\nOFF\n# c\n4 2 0\n# c\n0 0 0 # c\n1 0 0\n\n1 1 0\n0 1 0\n3 0 1 2 255 0 0\n\n"
                         "3 0 2 3 # c\n\n# c\n",
                         &s));
    assert_int_equal(s.ntris, 2);
    cbvh_scene_free(&s);
}

/* glTF: one primitive over 4 vertices with the given uint16 indices. */
static void gltf_indexed(char *out, size_t len, const uint16_t *idx, int nidx) {
    uint8_t buf[48 + 24] = {0};
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    memcpy(buf, pos, sizeof pos);
    memcpy(buf + 48, idx, (size_t)nidx * 2);
    char enc[200];
    base64(buf, 48 + (size_t)nidx * 2, enc);
    snprintf(out, len,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
             "\"buffers\":[{\"byteLength\":%d,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":%d}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5123,\"count\":%d,"
             "\"type\":\"SCALAR\"}]}",
             48 + nidx * 2, enc, nidx * 2, nidx);
}

/* assimp drops glTF faces with out-of-range indices (and a partial last
 * triangle) with only a log warning. */
static void test_import_gltf_dropped_faces(void **st) {
    (void)st;
    char gltf[2048];
    const uint16_t good[6] = {0, 1, 2, 0, 2, 3}, bad[6] = {0, 1, 2, 0, 1, 9}, partial[5] = {0, 1, 2, 0, 2};
    cbvh_scene s;
    gltf_indexed(gltf, sizeof gltf, good, 6);
    no_error(import_text("g.gltf", gltf, &s));
    assert_int_equal(s.ntris, 2);
    cbvh_scene_free(&s);
    gltf_indexed(gltf, sizeof gltf, bad, 6);
    expect_text_error("b.gltf", gltf,
                      "cannot import '%s': Some faces had out-of-range indices. Those faces were dropped.");
    gltf_indexed(gltf, sizeof gltf, partial, 5);
    expect_text_error("p.gltf", gltf,
                      "cannot import '%s': The number of vertices was not compatible with the TRIANGLES mode");
}

/* Only regular files: a directory, a device or a FIFO is named as such (a
 * FIFO used to block in open: the alarm fails the test instead of hanging). */
static void test_import_not_regular_file(void **st) {
    (void)st;
    char path[256];
    snprintf(path, sizeof path, "/tmp/cbvh_test_%d_dir.obj", (int)getpid());
    assert_int_equal(mkdir(path, 0700), 0);
    expect_error_at(path, "'%s' is a directory, not a mesh file");
    rmdir(path);
    expect_error_at("/dev/zero", "'%s' is not a regular file (a device, FIFO or socket), not a mesh file");
    snprintf(path, sizeof path, "/tmp/cbvh_test_%d_fifo.obj", (int)getpid());
    assert_int_equal(mkfifo(path, 0600), 0);
    alarm(20);
    expect_error_at(path, "'%s' is not a regular file (a device, FIFO or socket), not a mesh file");
    alarm(0);
    remove(path);
}

/* Procedural sizes outside a scene's range are errors (they were clamped,
 * so proc:far:2 gave the 16 triangles of proc:far:4). */
static void test_proc_size_range(void **st) {
    (void)st;
    static const struct {
        const char *spec, *err;
    } bad[] = {
        {"proc:far:2", "procedural scene 'far': size 2 out of range 4..4096 (sphere segments)"},
        {"proc:far:4097", "procedural scene 'far': size 4097 out of range 4..4096 (sphere segments)"},
        {"proc:cloth:20001", "procedural scene 'cloth': size 20001 out of range 1..20000 (grid cells per side)"},
        {"proc:wave:100000", "procedural scene 'wave': size 100000 out of range 1..20000 (grid cells per side)"},
        {"proc:instanced:201", "procedural scene 'instanced': size 201 out of range 1..200 (instances per side)"},
    };
    cbvh_scene s;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        errbuf[0] = 0;
        assert_int_equal(cbvh_scene_open(bad[i].spec, &s, errbuf, sizeof errbuf), -1);
        assert_null(s.tris);
        assert_int_equal(s.ntris, 0);
        assert_string_equal(errbuf, bad[i].err);
    }
    no_error(cbvh_scene_open("proc:far:4", &s, errbuf, sizeof errbuf));
    assert_int_equal(s.ntris, 16);
    cbvh_scene_free(&s);
    no_error(cbvh_scene_open("proc:far", &s, errbuf, sizeof errbuf));
    assert_int_equal(s.ntris, 2304);
    cbvh_scene_free(&s);
}

static void test_scene_validate(void **st) {
    (void)st;
    cbvh_scene s;
    random_scene(&s, 10, 1.0f, 0.1f);
    assert_int_equal(cbvh_scene_validate(&s, errbuf, sizeof errbuf), 0);
    s.tris[7].v[1][2] = INFINITY;
    assert_int_equal(cbvh_scene_validate(&s, errbuf, sizeof errbuf), -1);
    assert_non_null(strstr(errbuf, "triangle 7"));
    cbvh_bvh b;
    assert_int_equal(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf), -1);
    assert_int_equal(cbvh_build_sah(&s, 0, 0, &b, errbuf, sizeof errbuf), -1);
    s.tris[7].v[1][2] = 0.5f;
    /* Morph targets are validated too: one target, a copy of the base, is
     * fine; a NaN in it is named. */
    s.nmorph = 1;
    s.morph = malloc(s.ntris * sizeof *s.morph);
    assert_non_null(s.morph);
    memcpy(s.morph, s.tris, s.ntris * sizeof *s.morph);
    assert_int_equal(cbvh_scene_validate(&s, errbuf, sizeof errbuf), 0);
    s.morph[9].v[2][0] = NAN;
    assert_int_equal(cbvh_scene_validate(&s, errbuf, sizeof errbuf), -1);
    assert_non_null(strstr(errbuf, "morph target has a non-finite"));
    s.morph[9].v[2][0] = 0.0f;
    /* The SAH builder's parameters: 4..64 bins, 1..64 per leaf (0: default). */
    const int bad_params[][2] = {{3, 4}, {65, 4}, {16, 65}, {-1, 4}, {16, -1}};
    for (size_t i = 0; i < sizeof bad_params / sizeof bad_params[0]; i++) {
        assert_int_equal(cbvh_build_sah(&s, bad_params[i][0], bad_params[i][1], &b, errbuf, sizeof errbuf), -1);
        assert_non_null(strstr(errbuf, "bins must be 4..64"));
    }
    no_error(cbvh_build_sah(&s, 4, 64, &b, errbuf, sizeof errbuf));
    cbvh_bvh_free(&b);
    /* Primitive IDs are 31 bits: a count past that is refused before any
     * triangle is read. */
    s.ntris = 0x80000000u;
    assert_int_equal(cbvh_scene_validate(&s, errbuf, sizeof errbuf), -1);
    assert_non_null(strstr(errbuf, "IDs must fit in 31 bits"));
    s.ntris = 10;
    cbvh_scene_free(&s);
    random_scene(&s, 10, 1.0f, 0.1f);
    s.ntris = 0;
    assert_int_equal(cbvh_scene_validate(&s, errbuf, sizeof errbuf), -1);
    assert_non_null(strstr(errbuf, "no triangles"));
    cbvh_scene_free(&s);
}

/* ---- float builders ---------------------------------------------------- */

static void test_lbvh_valid(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
    uint32_t leaves, inner;
    cbvh_bvh_counts(&b, &leaves, &inner);
    assert_int_equal(leaves, inner + 1);
    assert_true(leaves > s.ntris / 2 && leaves <= s.ntris);
    /* Root box is the scene box. */
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    for (int a = 0; a < 3; a++) {
        assert_true(b.nodes[b.root].lo[a] == lo[a]);
        assert_true(b.nodes[b.root].hi[a] == hi[a]);
    }
    /* Corrupting a box makes the check fail (the check can fail). */
    b.nodes[b.nodes[b.root].child[0]].hi[1] += 1.0f;
    assert_int_equal(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf), -1);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

static void test_lbvh_equal_codes_share_leaf(void **st) {
    (void)st;
    cbvh_scene s;
    random_scene(&s, 64, 10.0f, 0.5f);
    /* Triangles 10..19 identical to 5: same centroid, same Morton code. */
    for (int i = 10; i < 20; i++) s.tris[i] = s.tris[5];
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
    int found = 0;
    for (uint32_t i = 0; i < b.nnodes; i++) {
        const cbvh_bvh_node *n = &b.nodes[i];
        if (!cbvh_bvh_is_leaf(n)) continue;
        int has5 = 0;
        for (uint32_t j = 0; j < n->count; j++) has5 |= b.prims[n->first + j] == 5;
        if (has5) {
            assert_true(n->count >= 11);
            for (uint32_t j = 0; j < n->count; j++) {
                uint32_t p = b.prims[n->first + j];
                assert_true(p == 5 || (p >= 10 && p < 20) || memcmp(&s.tris[p], &s.tris[5], sizeof s.tris[5]) != 0);
            }
            found = 1;
        }
    }
    assert_true(found);
    cbvh_bvh_free(&b);
    /* All identical: a single leaf is the root. */
    for (uint32_t i = 0; i < s.ntris; i++) s.tris[i] = s.tris[0];
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    assert_int_equal(b.nnodes, 1);
    assert_int_equal(b.nodes[b.root].count, 64);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* The Morton order is pinned (docs/study.md): triangles centred on grid cells
 * of a scene whose centre bounds are exactly [0, 1024]^3, so the cell is
 * floor(centre); the leaves, in node order, must list the triangles in the
 * order of x9 y9 z9 x8 ... z0 codes computed here bit by bit, equal codes in
 * one leaf (in triangle order: the sort is stable), distinct codes apart. */
static uint32_t morton_ref(const uint32_t k[3]) {
    uint32_t code = 0;
    for (int bit = 9; bit >= 0; bit--)
        for (int a = 0; a < 3; a++) code = code << 1 | (k[a] >> bit & 1u);
    return code;
}

static void test_lbvh_morton_order(void **st) {
    (void)st;
    enum { N = 3000 };
    cbvh_scene s;
    zero_scene(&s, N);
    uint32_t *code = malloc(N * sizeof *code);
    assert_non_null(code);
    for (uint32_t i = 0; i < N; i++) {
        uint32_t k[3];
        for (int a = 0; a < 3; a++) {
            /* Triangles 0 and 1 fix the centre bounds at 0 and 1024; every
             * eighth repeats its predecessor's cell (a shared leaf). */
            k[a] = i == 0 ? 0u : i == 1 ? 1023u : (i % 8 == 0) ? 0u : rnd() & 1023u;
        }
        if (i > 1 && i % 8 == 0) {
            s.tris[i] = s.tris[i - 1];
            code[i] = code[i - 1];
            continue;
        }
        float c[3];
        for (int a = 0; a < 3; a++) c[a] = i == 1 ? 1024.0f : i == 0 ? 0.0f : (float)k[a] + 0.5f;
        /* Box centre lo/2 + hi/2 = c exactly. */
        const float d = 0.25f;
        float v[3][3] = {{c[0] - d, c[1] - d, c[2] - d}, {c[0] + d, c[1] - d, c[2] + d}, {c[0], c[1] + d, c[2]}};
        memcpy(&s.tris[i], v, sizeof v);
        code[i] = morton_ref(k);
    }
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
    uint32_t leaves, inner, seen = 0, prev_code = 0, prev_prim = 0;
    cbvh_bvh_counts(&b, &leaves, &inner);
    for (uint32_t li = 0; li < leaves; li++) {
        const cbvh_bvh_node *n = &b.nodes[inner + li]; /* leaves follow the inner nodes */
        assert_true(cbvh_bvh_is_leaf(n));
        for (uint32_t j = 0; j < n->count; j++, seen++) {
            uint32_t p = b.prims[n->first + j];
            if (seen) {
                if (j == 0)
                    assert_true(code[p] > prev_code); /* a new leaf: a new, larger code */
                else {
                    assert_int_equal(code[p], prev_code); /* one code per leaf */
                    assert_true(p > prev_prim);           /* stable */
                }
            }
            prev_code = code[p];
            prev_prim = p;
        }
    }
    assert_int_equal(seen, N);
    cbvh_bvh_free(&b);
    free(code);
    cbvh_scene_free(&s);
}

static void test_sah_valid_and_better(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh sah, lb;
    no_error(cbvh_build_sah(&s, 16, 4, &sah, errbuf, sizeof errbuf));
    no_error(cbvh_bvh_check(&sah, &s, errbuf, sizeof errbuf));
    no_error(cbvh_build_lbvh(&s, &lb, errbuf, sizeof errbuf));
    double cs = cbvh_bvh_sah(&sah), cl = cbvh_bvh_sah(&lb);
    assert_true(cs > 1.0 && cl > 1.0);
    assert_true(cs < cl); /* SAH optimises the cost LBVH ignores */
    for (uint32_t i = 0; i < sah.nnodes; i++)
        if (cbvh_bvh_is_leaf(&sah.nodes[i])) assert_true(sah.nodes[i].count <= 4);
    /* 0, 0 means the documented defaults, 16 bins and 4 per leaf: the same
     * tree node for node (and 15 bins or 3 per leaf a different one, so the
     * comparison can fail). */
    cbvh_bvh dflt, other;
    no_error(cbvh_build_sah(&s, 0, 0, &dflt, errbuf, sizeof errbuf));
    assert_int_equal(dflt.nnodes, sah.nnodes);
    assert_memory_equal(dflt.nodes, sah.nodes, sah.nnodes * sizeof *sah.nodes);
    assert_memory_equal(dflt.prims, sah.prims, sah.nprims * sizeof *sah.prims);
    cbvh_bvh_free(&dflt);
    const int variants[2][2] = {{15, 4}, {16, 3}};
    for (int v = 0; v < 2; v++) {
        no_error(cbvh_build_sah(&s, variants[v][0], variants[v][1], &other, errbuf, sizeof errbuf));
        assert_true(other.nnodes != sah.nnodes || memcmp(other.nodes, sah.nodes, sah.nnodes * sizeof *sah.nodes) != 0);
        cbvh_bvh_free(&other);
    }
    cbvh_bvh_free(&sah);
    cbvh_bvh_free(&lb);
    cbvh_scene_free(&s);
}

/* Centroid extents binary32 cannot scale (build_sah.c, binner): x
 * centroids at -+3e38, whose extent overflows (bins / extent = 0), and at 0
 * and 2^-146, whose scale bins / extent overflows.  The builder once
 * converted the NaN or Inf products to int (undefined; found by
 * fuzz_cbvh_traverse, caught by the sanitize preset's float-cast-overflow).
 * Now those axes are binned in binary64: the tree is valid and the root
 * separates the two sides. */
static void test_sah_extreme_extents(void **st) {
    (void)st;
    const float side[2][2] = {{-3e38f, 3e38f}, {0.0f, 1.12103877e-44f}}; /* 8 * 2^-149 */
    for (int k = 0; k < 2; k++) {
        cbvh_scene s;
        zero_scene(&s, 16);
        for (uint32_t i = 0; i < 16; i++) /* segments along z, x on one side: only x splits */
            for (int v = 0; v < 3; v++) {
                s.tris[i].v[v][0] = side[k][i & 1];
                s.tris[i].v[v][2] = (float)v;
            }
        cbvh_bvh b;
        no_error(cbvh_build_sah(&s, 16, 1, &b, errbuf, sizeof errbuf));
        no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
        /* the centroids differ in x alone: the root splits there */
        const cbvh_bvh_node *r = &b.nodes[b.root];
        assert_false(cbvh_bvh_is_leaf(r));
        const cbvh_bvh_node *c0 = &b.nodes[r->child[0]], *c1 = &b.nodes[r->child[1]];
        assert_true(c0->hi[0] == side[k][0] && c1->lo[0] == side[k][1]);
        cbvh_bvh_free(&b);
        cbvh_scene_free(&s);
    }
}

static void test_sah_cost_formula(void **st) {
    (void)st;
    /* Two unit-cube-ish leaves side by side: root [0,2]x[0,1]x[0,1] area 10,
     * leaves area 6 each with 1 triangle: cost = 1 + 6/10 + 6/10 = 2.2. */
    cbvh_bvh_node n[3] = {{{0, 0, 0}, {2, 1, 1}, {1, 2}, 0, 0},
                          {{0, 0, 0}, {1, 1, 1}, {0, 0}, 0, 1},
                          {{1, 0, 0}, {2, 1, 1}, {0, 0}, 1, 1}};
    uint32_t prims[2] = {0, 1};
    cbvh_bvh b = {n, 3, 0, prims, 2};
    assert_float_equal(cbvh_bvh_sah(&b), 2.2, 1e-12);
}

/* ---- compressors ------------------------------------------------------- */

static cbvh_compress_opts opts(int n, int min_scale, cbvh_encoding enc, int treelet) {
    cbvh_compress_opts o = {{n, min_scale}, enc, treelet, 0};
    return o;
}

/* Top-down and bottom-up on one float BVH: both decode to enclosing boxes and
 * are bit-identical; treelets only move work on chip. */
static void check_both(cbvh_bvh *b, int n, int min_scale, cbvh_encoding enc) {
    cbvh_compress_opts o = opts(n, min_scale, enc, 1);
    cbvh_tree td, bu;
    cbvh_bu_stats stt;
    no_error(cbvh_compress_topdown(b, &o, &td, errbuf, sizeof errbuf));
    no_error(cbvh_tree_check(&td, b, errbuf, sizeof errbuf));
    no_error(cbvh_compress_bottomup(b, NULL, &o, &bu, &stt, errbuf, sizeof errbuf));
    no_error(cbvh_tree_check(&bu, b, errbuf, sizeof errbuf));
    long d = cbvh_tree_diff(&td, &bu);
    if (d != -1) fail_msg("N=%d min_scale=%d enc=%d: bottom-up differs from top-down at byte %ld", n, min_scale, enc, d);
    /* The diff can see every part: a header field (reported as byte 0), the
     * last pair byte, the last ID. */
    bu.root_ctx.axis[2].scale ^= 1;
    assert_int_equal(cbvh_tree_diff(&td, &bu), 0);
    bu.root_ctx.axis[2].scale ^= 1;
    const size_t last = (size_t)bu.npairs * bu.pair_bytes - 1;
    bu.pairs[last] ^= 0x80u;
    assert_int_equal(cbvh_tree_diff(&td, &bu), (long)last);
    bu.pairs[last] ^= 0x80u;
    bu.ids[bu.nids - 1] ^= 1u;
    assert_int_equal(cbvh_tree_diff(&td, &bu), (long)(last + 1 + 4 * ((size_t)bu.nids - 1)));
    bu.ids[bu.nids - 1] ^= 1u;
    assert_int_equal(cbvh_tree_diff(&td, &bu), -1);
    uint64_t hsum = 0;
    for (int i = 0; i < CBVH_BT_HIST; i++) hsum += stt.hist[i];
    assert_true(hsum == stt.reencodes);
    assert_true(stt.backtracks == stt.reencodes);
    assert_true(stt.encodes == td.npairs);
    uint64_t prev = stt.backtracks;
    for (int m = 2; m <= 4; m++) {
        cbvh_tree t2;
        cbvh_bu_stats s2;
        o.treelet_depth = m;
        no_error(cbvh_compress_bottomup(b, NULL, &o, &t2, &s2, errbuf, sizeof errbuf));
        assert_int_equal(cbvh_tree_diff(&td, &t2), -1);
        assert_true(s2.reencodes == stt.reencodes);
        uint64_t deep = 0;
        for (int i = m; i < CBVH_BT_HIST; i++) deep += stt.hist[i];
        assert_true(s2.backtracks == deep);
        assert_true(s2.backtracks <= prev);
        prev = s2.backtracks;
        cbvh_tree_free(&t2);
    }
    cbvh_tree_free(&td);
    cbvh_tree_free(&bu);
}

/* SAH of degenerate roots: a scene on a line (root area 0) is costed by half
 * perimeters, for the float BVH and its CBVH alike (decoded boxes enclose, so
 * the CBVH's cost is not lower); a scene in one point costs 0.  A CBVH the
 * cost walk cannot decode (root pair out of range; a reserved bit set) gives
 * -1, not a number. */
static void test_sah_degenerate(void **st) {
    (void)st;
    cbvh_scene s;
    zero_scene(&s, 16);
    for (int i = 0; i < 16; i++) /* slivers on the x axis: y = z = 0 */
        for (int v = 0; v < 3; v++) s.tris[i].v[v][0] = (float)(i * 3 + v) * 0.5f;
    cbvh_bvh b;
    no_error(cbvh_build_sah(&s, 0, 1, &b, errbuf, sizeof errbuf));
    no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
    double fb_sah = cbvh_bvh_sah(&b);
    /* by half perimeters: the root (1) plus every other node's length share */
    double want = 0.0, root_len = (double)b.nodes[b.root].hi[0] - b.nodes[b.root].lo[0];
    for (uint32_t i = 0; i < b.nnodes; i++) {
        const cbvh_bvh_node *n = &b.nodes[i];
        want += (cbvh_bvh_is_leaf(n) ? (double)n->count : 1.0) * ((double)n->hi[0] - n->lo[0]) / root_len;
    }
    assert_float_equal(fb_sah, want, 1e-12);
    assert_true(fb_sah > 1.0);
    cbvh_compress_opts o = opts(8, -30, CBVH_ENC_MODULO, 1); /* N = 8: its pairs have reserved bits */
    cbvh_tree t;
    no_error(cbvh_compress_topdown(&b, &o, &t, errbuf, sizeof errbuf));
    double tree_sah = cbvh_tree_sah(&t);
    assert_true(tree_sah >= fb_sah && tree_sah < 2.0 * fb_sah);
    const uint32_t rp = t.root_pair;
    t.root_pair = t.npairs;
    assert_true(cbvh_tree_sah(&t) == -1.0);
    t.root_pair = rp;
    const int nbits = cbvh_node_bits(8), ptr_end = 6 * 8 + 1 + cbvh_node_ptr_bits(8);
    assert_true(ptr_end < nbits); /* a reserved bit exists */
    uint8_t *pair = t.pairs + (size_t)rp * t.pair_bytes;
    pair[ptr_end / 8] ^= (uint8_t)(1u << (ptr_end % 8));
    assert_true(cbvh_tree_sah(&t) == -1.0);
    pair[ptr_end / 8] ^= (uint8_t)(1u << (ptr_end % 8));
    assert_true(cbvh_tree_sah(&t) == tree_sah);
    cbvh_tree_free(&t);
    cbvh_bvh_free(&b);
    /* the smallest trees (one, two and three pairs): the cost walk's stack
     * holds them (the sanitize preset sees any overrun) */
    for (uint32_t nt = 2; nt <= 4; nt++) {
        cbvh_scene small = s;
        small.ntris = nt;
        no_error(cbvh_build_sah(&small, 0, 1, &b, errbuf, sizeof errbuf));
        no_error(cbvh_compress_topdown(&b, &o, &t, errbuf, sizeof errbuf));
        assert_int_equal(t.npairs, nt - 1);
        double c = cbvh_tree_sah(&t);
        assert_true(c >= cbvh_bvh_sah(&b) && c < 2.0 * cbvh_bvh_sah(&b));
        cbvh_tree_free(&t);
        cbvh_bvh_free(&b);
    }
    /* every vertex in one point: no length to cost by */
    for (int i = 0; i < 16; i++) memset(&s.tris[i], 0, sizeof s.tris[i]);
    no_error(cbvh_build_sah(&s, 0, 1, &b, errbuf, sizeof errbuf));
    assert_true(cbvh_bvh_sah(&b) == 0.0);
    no_error(cbvh_compress_topdown(&b, &o, &t, errbuf, sizeof errbuf));
    assert_true(cbvh_tree_sah(&t) == 0.0);
    cbvh_tree_free(&t);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* A malformed float BVH (a box inverted, a NaN bound, a child far outside
 * its parent's grid) is refused by both compressors, each naming the pair
 * the encoder rejected with the unit's status, and leaves no tree behind. */
static void test_compress_malformed(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh b;
    no_error(cbvh_build_sah(&s, 0, 0, &b, errbuf, sizeof errbuf));
    const uint32_t c0 = b.nodes[b.root].child[0], g = b.nodes[c0].child[0];
    assert_false(cbvh_bvh_is_leaf(&b.nodes[c0]));
    const cbvh_bvh_node saved = b.nodes[g];
    /* NO_FIT implies OUTSIDE (0x80): a box wider than 2^N cells leaves the window */
    static const char *const status[3] = {"status 0x2)", "status 0x1)", "status 0xc0)"};
    for (int m = 0; m < 3; m++)
        for (int enc = 0; enc < 2; enc++) {
            b.nodes[g] = saved;
            if (m == 0) b.nodes[g].hi[0] = b.nodes[g].lo[0] - 0.01f; /* inverted: INVERTED */
            if (m == 1) b.nodes[g].lo[1] = NAN;                       /* NAN_INF */
            if (m == 2) b.nodes[g].hi[0] = b.nodes[c0].hi[0] + 100.0f; /* NO_FIT on its parent's grid */
            cbvh_compress_opts o = opts(6, -30, enc ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO, 4);
            cbvh_tree t;
            cbvh_bu_stats bs;
            memset(&t, 0x5A, sizeof t);
            assert_int_equal(cbvh_compress_topdown(&b, &o, &t, errbuf, sizeof errbuf), -1);
            assert_non_null(strstr(errbuf, "cbvh top-down: pair "));
            assert_non_null(strstr(errbuf, status[m]));
            assert_null(t.pairs);
            memset(&t, 0x5A, sizeof t);
            assert_int_equal(cbvh_compress_bottomup(&b, NULL, &o, &t, &bs, errbuf, sizeof errbuf), -1);
            assert_non_null(strstr(errbuf, "cbvh bottom-up: pair "));
            assert_non_null(strstr(errbuf, status[m]));
            assert_null(t.pairs);
        }
    b.nodes[g] = saved;
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

static void test_compress_bunny(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh lb, sah;
    no_error(cbvh_build_lbvh(&s, &lb, errbuf, sizeof errbuf));
    no_error(cbvh_build_sah(&s, 0, 0, &sah, errbuf, sizeof errbuf));
    const int ns[] = {3, 4, 6, 7, 10};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++)
        for (int e = 0; e < 2; e++) {
            check_both(&lb, ns[i], -30, (cbvh_encoding)e);
            check_both(&sah, ns[i], -126, (cbvh_encoding)e);
        }
    cbvh_bvh_free(&lb);
    cbvh_bvh_free(&sah);
    cbvh_scene_free(&s);
}

static void test_compress_hard_scenes(void **st) {
    (void)st;
    const char *specs[] = {"proc:cloth:48", "proc:far:16", "proc:wave:24"};
    for (size_t i = 0; i < 3; i++) {
        cbvh_scene s;
        no_error(cbvh_scene_open(specs[i], &s, errbuf, sizeof errbuf));
        cbvh_bvh b;
        no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
        no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
        for (int e = 0; e < 2; e++) {
            check_both(&b, 6, -126, (cbvh_encoding)e);
            check_both(&b, 6, -30, (cbvh_encoding)e);
            check_both(&b, 5, -10, (cbvh_encoding)e);
        }
        cbvh_bvh_free(&b);
        cbvh_scene_free(&s);
    }
    /* Huge and tiny coordinates mixed. */
    cbvh_scene s;
    random_scene(&s, 300, 1.0f, 0.01f);
    for (uint32_t i = 0; i < 20; i++)
        for (int v = 0; v < 3; v++) s.tris[i].v[v][i % 3] *= (i & 1) ? 1e30f : 1e-30f;
    cbvh_bvh b;
    no_error(cbvh_build_sah(&s, 0, 2, &b, errbuf, sizeof errbuf));
    for (int e = 0; e < 2; e++) check_both(&b, 6, -126, (cbvh_encoding)e);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* Coordinates up to +-FLT_MAX: decoded bounds reach -2^128 / +Inf. */
static void test_compress_huge_range(void **st) {
    (void)st;
    cbvh_scene s;
    random_scene(&s, 200, 1.0f, 0.2f);
    for (uint32_t i = 0; i < s.ntris; i++)
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) s.tris[i].v[v][a] *= 3.4e38f;
    s.tris[0].v[0][0] = -FLT_MAX;
    s.tris[1].v[1][1] = FLT_MAX;
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
    uint32_t leaves, inner;
    cbvh_bvh_counts(&b, &leaves, &inner);
    assert_true(leaves > 100); /* Morton codes did not collapse */
    for (int e = 0; e < 2; e++) check_both(&b, 6, -30, (cbvh_encoding)e);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

static void test_compress_single_leaf_root(void **st) {
    (void)st;
    cbvh_scene s;
    random_scene(&s, 3, 1.0f, 0.5f);
    s.tris[1] = s.tris[2] = s.tris[0];
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    assert_int_equal(b.nnodes, 1);
    check_both(&b, 6, -30, CBVH_ENC_MODULO);
    cbvh_tree t;
    cbvh_compress_opts o = opts(6, -30, CBVH_ENC_MODULO, 1);
    no_error(cbvh_compress_topdown(&b, &o, &t, errbuf, sizeof errbuf));
    assert_int_equal(t.npairs, 1);
    assert_int_equal(t.ids[2], b.prims[2] | CBVH_ID_LAST);
    assert_int_equal(t.ids[0] & CBVH_ID_LAST, 0);
    cbvh_tree_free(&t);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

static void test_check_detects_corruption(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    cbvh_compress_opts o = opts(6, -30, CBVH_ENC_MODULO, 1);
    cbvh_tree t;
    no_error(cbvh_compress_topdown(&b, &o, &t, errbuf, sizeof errbuf));
    /* A float box larger than what was compressed is no longer enclosed. */
    uint32_t c0 = b.nodes[b.root].child[0];
    float save = b.nodes[c0].hi[0];
    b.nodes[c0].hi[0] = save + 0.5f * (b.nodes[b.root].hi[0] - save) + 1e-3f;
    assert_int_equal(cbvh_tree_check(&t, &b, errbuf, sizeof errbuf), -1);
    assert_non_null(strstr(errbuf, "enclose"));
    b.nodes[c0].hi[0] = save;
    no_error(cbvh_tree_check(&t, &b, errbuf, sizeof errbuf));
    /* A flipped ID flag. */
    t.ids[0] ^= CBVH_ID_LAST;
    assert_int_equal(cbvh_tree_check(&t, &b, errbuf, sizeof errbuf), -1);
    t.ids[0] ^= CBVH_ID_LAST;
    /* Flipping a root-pair code bit changes or breaks the decoded tree. */
    int failures = 0;
    for (int bit = 0; bit < 36; bit++) {
        t.pairs[(size_t)t.root_pair * t.pair_bytes + (size_t)bit / 8] ^= (uint8_t)(1u << (bit % 8));
        failures += cbvh_tree_check(&t, &b, errbuf, sizeof errbuf) != 0;
        t.pairs[(size_t)t.root_pair * t.pair_bytes + (size_t)bit / 8] ^= (uint8_t)(1u << (bit % 8));
    }
    assert_true(failures > 0);
    no_error(cbvh_tree_check(&t, &b, errbuf, sizeof errbuf));
    /* The CBVH is smaller than the float BVH and its SAH cost is close. */
    assert_true(cbvh_tree_bytes(&t) < cbvh_bvh_bytes(&b));
    double q = cbvh_tree_sah(&t) / cbvh_bvh_sah(&b);
    assert_true(q >= 1.0 && q < 1.5);
    cbvh_tree_free(&t);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* The re-encoding rule behind bit-exactness: for a box quantized at scale a
 * and re-encoded at b >= a, [u, pred(v)] gives Eq. 1 of the original box,
 * while [u, v] (as printed) gains one upper cell exactly when v lies on the
 * 2^b grid. */
static void test_reencode_rule(void **st) {
    (void)st;
    cbvh_params p = {6, -126};
    int grew = 0;
    for (int i = 0; i < 200000; i++) {
        float lo = (rndf() - 0.5f) * 64.0f, hi = lo + rndf() * 8.0f;
        if (i % 7 == 0) hi = lo; /* flat */
        cbvh_f32 l = cbvh_f32_of(lo), h = cbvh_f32_of(hi);
        int a;
        assert_int_equal(cbvh_scale_estimate(&p, l, h, &a), 0);
        int b = a + (int)(rnd() % 12);
        cbvh_axis_code qa, want, got, naive;
        /* each box in its own window (node_clb = its lower bound, as a root) */
        assert_int_equal(cbvh_axis_compress(&p, l, h, a, l, &qa), 0);
        cbvh_axis_compress(&p, l, h, b, l, &want);
        cbvh_axis_compress(&p, qa.clb, cbvh_f32_next_down(qa.cub), b, qa.clb, &got);
        assert_int_equal(got.lb_mod, want.lb_mod);
        assert_int_equal(got.ub_mod, want.ub_mod);
        assert_int_equal(got.clb, want.clb);
        assert_int_equal(got.cub, want.cub);
        assert_int_equal(got.child_scale, want.child_scale);
        cbvh_axis_compress(&p, qa.clb, qa.cub, b, qa.clb, &naive);
        float v = cbvh_float_of(qa.cub);
        int on_grid = fmod((double)v, ldexp(1.0, b)) == 0.0;
        assert_int_equal(naive.ub_mod != want.ub_mod || naive.cub != want.cub, on_grid);
        grew += on_grid;
    }
    assert_true(grew > 1000);
}

static void test_naive_backtrack_differs(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    cbvh_compress_opts o = opts(6, -30, CBVH_ENC_RELATIVE, 1);
    cbvh_tree td, nv;
    cbvh_bu_stats stt;
    no_error(cbvh_compress_topdown(&b, &o, &td, errbuf, sizeof errbuf));
    o.naive_reencode = 1;
    no_error(cbvh_compress_bottomup(&b, NULL, &o, &nv, &stt, errbuf, sizeof errbuf));
    assert_true(stt.reencodes > 0);
    no_error(cbvh_tree_check(&nv, &b, errbuf, sizeof errbuf)); /* still encloses */
    assert_true(cbvh_tree_diff(&td, &nv) >= 0);               /* but not top-down's bits */
    assert_true(cbvh_tree_sah(&nv) >= cbvh_tree_sah(&td));
    cbvh_tree_free(&td);
    cbvh_tree_free(&nv);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* Naive re-encoding on the inputs that once broke it: boxes reaching
 * +-FLT_MAX, where a grown upper bound decodes as +Inf (2^128, no binary32
 * input) and children grown by earlier naive re-encodes stick out of a node
 * box that a fallback shrank again.  Before the repairs (docs/study.md) these
 * soups failed 56 % of naive builds with an error and left 9 undecodable
 * CBVHs.  Every build must now succeed, decode and enclose; the repairs must
 * have been needed (naive_nofit). */
static void test_naive_extremes_valid(void **st) {
    (void)st;
    uint64_t nofit = 0, builds = 0;
    rng_state = 987654321u;
    for (int i = 0; i < 120; i++) {
        cbvh_scene s;
        uint32_t n = 1 + rnd() % 160;
        zero_scene(&s, n);
        for (uint32_t t = 0; t < n; t++) {
            float c[3];
            for (int a = 0; a < 3; a++) c[a] = rndf() - 0.5f;
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) s.tris[t].v[v][a] = 2.0f * (c[a] + 0.05f * (rndf() - 0.5f)) * 3.2e38f;
        }
        s.tris[0].v[0][0] = -FLT_MAX;
        s.tris[0].v[1][1] = FLT_MAX;
        cbvh_bvh b;
        no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
        for (int q = 3; q <= 10; q++)
            for (int e = 0; e < 2; e++) {
                cbvh_compress_opts o = opts(q, -30, (cbvh_encoding)e, 1 + (int)(rnd() % 4));
                o.naive_reencode = 1;
                cbvh_tree t;
                cbvh_bu_stats stt;
                if (cbvh_compress_bottomup(&b, NULL, &o, &t, &stt, errbuf, sizeof errbuf))
                    fail_msg("soup %d N=%d enc=%d: %s", i, q, e, errbuf);
                if (cbvh_tree_check(&t, &b, errbuf, sizeof errbuf))
                    fail_msg("soup %d N=%d enc=%d: %s", i, q, e, errbuf);
                nofit += stt.naive_nofit;
                builds++;
                cbvh_tree_free(&t);
            }
        cbvh_bvh_free(&b);
        cbvh_scene_free(&s);
    }
    assert_int_equal(builds, 120 * 16);
    assert_true(nofit > builds);
}

static void test_modulo_fewer_backtracks(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    cbvh_bu_stats rel, mod;
    cbvh_tree t;
    cbvh_compress_opts o = opts(6, -30, CBVH_ENC_RELATIVE, 1);
    no_error(cbvh_compress_bottomup(&b, NULL, &o, &t, &rel, errbuf, sizeof errbuf));
    cbvh_tree_free(&t);
    o.enc = CBVH_ENC_MODULO;
    no_error(cbvh_compress_bottomup(&b, NULL, &o, &t, &mod, errbuf, sizeof errbuf));
    cbvh_tree_free(&t);
    assert_true(rel.backtracks > 0);
    assert_true(mod.backtracks < rel.backtracks);
    /* Cloth with the finest minimum scale backtracks far more than at 2^-30. */
    cbvh_scene c;
    no_error(cbvh_scene_open("proc:cloth:64", &c, errbuf, sizeof errbuf));
    cbvh_bvh cb;
    no_error(cbvh_build_lbvh(&c, &cb, errbuf, sizeof errbuf));
    cbvh_bu_stats fine, coarse;
    o = opts(6, -126, CBVH_ENC_MODULO, 1);
    no_error(cbvh_compress_bottomup(&cb, NULL, &o, &t, &fine, errbuf, sizeof errbuf));
    cbvh_tree_free(&t);
    o.params.min_scale = -30;
    no_error(cbvh_compress_bottomup(&cb, NULL, &o, &t, &coarse, errbuf, sizeof errbuf));
    cbvh_tree_free(&t);
    assert_true(fine.backtracks > 4 * coarse.backtracks + 10);
    cbvh_bvh_free(&cb);
    cbvh_scene_free(&c);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* A backtrack 70 levels deep (the histogram's last bin): a chain of inner
 * nodes j = 0..69, each the parent of a leaf spanning [-29.5, 33.5] 2^s in x
 * (s = -j) and of node j + 1.  With N = 6 each box fits 64 cells of its own
 * scale s, also when quantized on its parent's grid s + 1 ([-30, 34]), but
 * not on any coarser one ([-32, 36] on s + 2): so when a node's scale grows,
 * its child's grows too.  A top node with a leaf spanning [0, 2^20],
 * processed last, coarsens node 0's grid, and the change runs down the
 * whole chain. */
static void test_backtrack_deep_chain(void **st) {
    (void)st;
    enum { D = 70, N = 6 };
    cbvh_scene s;
    zero_scene(&s, D + 2);
    for (uint32_t j = 0; j <= D + 1; j++) {
        int sc = -(int)j;
        s.tris[j].v[0][0] = s.tris[j].v[2][0] = j <= D ? ldexpf(-29.5f, sc) : 0.0f;
        s.tris[j].v[1][0] = j <= D ? ldexpf(33.5f, sc) : 0x1p20f;
        s.tris[j].v[2][1] = 0x1p-100f;
    }
    /* nodes: 0 the top, 1 + j inner j, 1 + D the big leaf, 2 + D + j leaf j */
    cbvh_bvh b;
    memset(&b, 0, sizeof b);
    b.nnodes = 2 * D + 3;
    b.nodes = calloc(b.nnodes, sizeof *b.nodes);
    b.nprims = D + 2;
    b.prims = calloc(b.nprims, sizeof *b.prims);
    assert_non_null(b.nodes);
    assert_non_null(b.prims);
    for (uint32_t j = 0; j <= D + 1; j++) {
        cbvh_bvh_node *lf = &b.nodes[j <= D ? 2 + D + j : 1 + D];
        lf->first = j;
        lf->count = 1;
        b.prims[j] = j;
        cbvh_tri_bounds(&s.tris[j], lf->lo, lf->hi);
    }
    for (int j = D - 1; j >= -1; j--) { /* inner j (j = -1: the top), bottom-up */
        cbvh_bvh_node *n = &b.nodes[1 + j];
        n->child[0] = j >= 0 ? 2 + D + (uint32_t)j : 1 + D;
        n->child[1] = j + 1 < D ? 2 + (uint32_t)j : 2 + D + D;
        for (int a = 0; a < 3; a++) {
            const cbvh_bvh_node *l = &b.nodes[n->child[0]], *r = &b.nodes[n->child[1]];
            n->lo[a] = fminf(l->lo[a], r->lo[a]);
            n->hi[a] = fmaxf(l->hi[a], r->hi[a]);
        }
    }
    no_error(cbvh_bvh_check(&b, &s, errbuf, sizeof errbuf));
    cbvh_compress_opts o = opts(N, -126, CBVH_ENC_MODULO, 1);
    cbvh_tree td, bu;
    cbvh_bu_stats bs;
    no_error(cbvh_compress_topdown(&b, &o, &td, errbuf, sizeof errbuf));
    no_error(cbvh_compress_bottomup(&b, NULL, &o, &bu, &bs, errbuf, sizeof errbuf));
    no_error(cbvh_tree_check(&bu, &b, errbuf, sizeof errbuf));
    assert_int_equal(bu.npairs, td.npairs);
    assert_memory_equal(bu.pairs, td.pairs, (size_t)td.npairs * td.pair_bytes);
    assert_true(bs.hist[CBVH_BT_HIST - 1] >= D - CBVH_BT_HIST + 1); /* depths 64..70 */
    uint64_t sum = 0;
    for (int i = 0; i < CBVH_BT_HIST; i++) sum += bs.hist[i];
    assert_int_equal(sum, bs.reencodes);
    assert_int_equal(bs.naive_nofit, 0);
    cbvh_tree_free(&td);
    cbvh_tree_free(&bu);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* The procedural twist as its header states: about the vertical axis through
 * the box centre, by `amount` radians per scene height, so a vertex at the
 * bottom stays, one at the top turns by `amount` (here a quarter turn: (x, z)
 * -> (-z, x) about the centre), one halfway by half; y moves only with the
 * wave, whose amplitude is `wave` times the height. */
static void test_deform_twist(void **st) {
    (void)st;
    cbvh_scene s;
    zero_scene(&s, 1);
    const float v[3][3] = {{2, 1, 0}, {2, 5, 0}, {0, 3, 2}}; /* box [0,2]x[1,5]x[0,2], centre (1, _, 1) */
    memcpy(s.tris[0].v, v, sizeof v);
    const float q = 1.5707963f;
    cbvh_tri out;
    cbvh_scene_deform(&s, q, 0.0f, 0.0f, &out);
    assert_float_equal(out.v[0][0], 2.0, 1e-6); /* bottom: unchanged */
    assert_float_equal(out.v[0][2], 0.0, 1e-6);
    assert_float_equal(out.v[1][0], 2.0, 1e-6); /* top: (1, -1) from the centre turns to (1, 1) */
    assert_float_equal(out.v[1][2], 2.0, 1e-6);
    const double c = cos(q / 2), sn = sin(q / 2); /* halfway: (-1, 1) turns by q/2 */
    assert_float_equal(out.v[2][0], 1.0 + c * -1.0 - sn * 1.0, 1e-6);
    assert_float_equal(out.v[2][2], 1.0 + sn * -1.0 + c * 1.0, 1e-6);
    for (int k = 0; k < 3; k++) assert_float_equal(out.v[k][1], v[k][1], 0.0);
    /* the wave alone: y + wave * h * sin(2 pi (x - x0) / w + t) */
    cbvh_scene_deform(&s, 0.0f, 0.25f, 0.5f, &out);
    for (int k = 0; k < 3; k++) {
        assert_float_equal(out.v[k][0], v[k][0], 1e-6);
        assert_float_equal(out.v[k][1], v[k][1] + 0.25 * 4.0 * sin(6.2831853 * v[k][0] / 2.0 + 0.5), 1e-5);
    }
    cbvh_scene_free(&s);
}

/* ---- refit ------------------------------------------------------------- */

static void test_refit(void **st) {
    (void)st;
    cbvh_scene s;
    load_bunny(&s);
    cbvh_bvh b;
    no_error(cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf));
    cbvh_tri *moved = malloc(s.ntris * sizeof *moved);
    cbvh_scene_deform(&s, 0.8f, 0.05f, 0.3f, moved);
    cbvh_scene ms = s;
    ms.tris = moved;
    /* Refit-then-compress vs streaming refit: same bits, both enclosing. */
    cbvh_bvh r1 = b, r2 = b;
    r1.nodes = malloc(b.nnodes * sizeof *b.nodes);
    r2.nodes = malloc(b.nnodes * sizeof *b.nodes);
    memcpy(r1.nodes, b.nodes, b.nnodes * sizeof *b.nodes);
    memcpy(r2.nodes, b.nodes, b.nnodes * sizeof *b.nodes);
    cbvh_bvh_refit(&r1, moved);
    no_error(cbvh_bvh_check(&r1, &ms, errbuf, sizeof errbuf));
    assert_int_equal(cbvh_bvh_check(&b, &ms, errbuf, sizeof errbuf), -1); /* the old boxes no longer fit */
    for (int e = 0; e < 2; e++) {
        cbvh_compress_opts o = opts(6, -30, (cbvh_encoding)e, 2);
        cbvh_tree td, bu;
        cbvh_bu_stats stt;
        no_error(cbvh_compress_topdown(&r1, &o, &td, errbuf, sizeof errbuf));
        no_error(cbvh_compress_bottomup(&r2, moved, &o, &bu, &stt, errbuf, sizeof errbuf));
        assert_memory_equal(r1.nodes, r2.nodes, b.nnodes * sizeof *b.nodes);
        no_error(cbvh_tree_check(&bu, &r1, errbuf, sizeof errbuf));
        assert_int_equal(cbvh_tree_diff(&td, &bu), -1);
        cbvh_tree_free(&td);
        cbvh_tree_free(&bu);
    }
    free(r1.nodes);
    free(r2.nodes);
    free(moved);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_import_bunny),
        cmocka_unit_test(test_import_formats),
        cmocka_unit_test(test_import_gltf_morph),
        cmocka_unit_test(test_import_gltf_nested_nodes),
        cmocka_unit_test(test_import_errors),
        cmocka_unit_test(test_import_obj_empty_face),
        cmocka_unit_test(test_import_ply_counts),
        cmocka_unit_test(test_import_ply_binary_size),
        cmocka_unit_test(test_import_off_tokens),
        cmocka_unit_test(test_import_gltf_dropped_faces),
        cmocka_unit_test(test_import_not_regular_file),
        cmocka_unit_test(test_proc_size_range),
        cmocka_unit_test(test_scene_validate),
        cmocka_unit_test(test_lbvh_valid),
        cmocka_unit_test(test_lbvh_equal_codes_share_leaf),
        cmocka_unit_test(test_lbvh_morton_order),
        cmocka_unit_test(test_sah_valid_and_better),
        cmocka_unit_test(test_sah_cost_formula),
        cmocka_unit_test(test_sah_degenerate),
        cmocka_unit_test(test_sah_extreme_extents),
        cmocka_unit_test(test_compress_bunny),
        cmocka_unit_test(test_compress_malformed),
        cmocka_unit_test(test_compress_hard_scenes),
        cmocka_unit_test(test_compress_huge_range),
        cmocka_unit_test(test_compress_single_leaf_root),
        cmocka_unit_test(test_check_detects_corruption),
        cmocka_unit_test(test_reencode_rule),
        cmocka_unit_test(test_import_assimp_crash),
        cmocka_unit_test(test_import_assimp_hang),
        cmocka_unit_test(test_naive_backtrack_differs),
        cmocka_unit_test(test_naive_extremes_valid),
        cmocka_unit_test(test_modulo_fewer_backtracks),
        cmocka_unit_test(test_backtrack_deep_chain),
        cmocka_unit_test(test_deform_twist),
        cmocka_unit_test(test_refit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
