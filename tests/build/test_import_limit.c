/* The importer's time limit (cbvh_scene_import_limit_ms): 5 s + 1 s per MB
 * of the file and of the files a glTF references.  A 600-byte .gltf whose
 * buffer is a 300 MB .bin got 5 s and was killed while assimp still read the
 * .bin.  The big files here are sparse (ftruncate): nothing is imported from
 * them. */
#define _GNU_SOURCE
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

#include "scene/scene_load.h"

#define BIG 300000000LL /* the sparse .bin: 300 s of limit */

static char dir[64];

static const char *at(const char *name) {
    static char path[2][512];
    static int k;
    k ^= 1;
    snprintf(path[k], sizeof path[k], "%s/%s", dir, name);
    return path[k];
}

static long long write_file(const char *name, const void *data, size_t len) {
    FILE *f = fopen(at(name), "wb");
    assert_non_null(f);
    if (len) assert_int_equal(fwrite(data, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
    return (long long)len;
}

static long long write_text(const char *name, const char *text) { return write_file(name, text, strlen(text)); }

static void sparse_file(const char *name, long long size) {
    FILE *f = fopen(at(name), "wb");
    assert_non_null(f);
    assert_int_equal(ftruncate(fileno(f), (off_t)size), 0);
    assert_int_equal(fclose(f), 0);
}

static long long limit_for(long long bytes) { return 5000 + bytes / 1000; }

static int setup(void **st) {
    (void)st;
    snprintf(dir, sizeof dir, "/tmp/cbvh_limit_XXXXXX");
    if (!mkdtemp(dir)) return -1;
    sparse_file("big.bin", BIG);
    sparse_file("big two.bin", BIG / 2);
    return 0;
}

static int teardown(void **st) {
    (void)st;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* A valid one-triangle glTF 2 whose buffer is the file `bin`. */
static long long gltf_with_buffer(const char *name, const char *bin) {
    char text[1024];
    snprintf(text, sizeof text,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]}]}",
             bin);
    return write_text(name, text);
}

/* The defect: the .bin's size counts, not only the .gltf's. */
static void test_gltf_separate_bin(void **st) {
    (void)st;
    long long n = gltf_with_buffer("scene.gltf", "big.bin");
    assert_int_equal(cbvh_scene_import_limit_ms(at("scene.gltf")), limit_for(n + BIG));
    /* the same relative to the working directory (no folder in the name) */
    char cwd[1024];
    assert_non_null(getcwd(cwd, sizeof cwd));
    assert_int_equal(chdir(dir), 0);
    assert_int_equal(cbvh_scene_import_limit_ms("scene.gltf"), limit_for(n + BIG));
    assert_int_equal(chdir(cwd), 0);
}

/* The scan does not get in the way of a real import of a .gltf + .bin. */
static void test_gltf_separate_bin_imports(void **st) {
    (void)st;
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    long long nbin = write_file("tri.bin", pos, sizeof pos);
    long long n = gltf_with_buffer("tri.gltf", "tri.bin");
    assert_int_equal(cbvh_scene_import_limit_ms(at("tri.gltf")), limit_for(n + nbin));
    cbvh_scene s;
    char err[512];
    if (cbvh_scene_import(at("tri.gltf"), &s, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(s.ntris, 1);
    assert_float_equal(s.tris[0].v[1][0], 1.0f, 0.0f);
    cbvh_scene_free(&s);
}

/* data: URIs are in the file already; a missing file, another scheme or a
 * folder adds nothing. */
static void test_not_counted(void **st) {
    (void)st;
    long long n = gltf_with_buffer("data.gltf", "data:application/octet-stream;base64,AAAA");
    assert_int_equal(cbvh_scene_import_limit_ms(at("data.gltf")), limit_for(n));
    n = gltf_with_buffer("missing.gltf", "no-such.bin");
    assert_int_equal(cbvh_scene_import_limit_ms(at("missing.gltf")), limit_for(n));
    n = gltf_with_buffer("http.gltf", "http://example.com/big.bin");
    assert_int_equal(cbvh_scene_import_limit_ms(at("http.gltf")), limit_for(n));
    n = gltf_with_buffer("folder.gltf", ".");
    assert_int_equal(cbvh_scene_import_limit_ms(at("folder.gltf")), limit_for(n));
    /* not a glTF: its own size only, even if the text looks like one */
    n = gltf_with_buffer("scene.obj", "big.bin");
    assert_int_equal(cbvh_scene_import_limit_ms(at("scene.obj")), limit_for(n));
    assert_int_equal(cbvh_scene_import_limit_ms(at("nothing-here.gltf")), 5000);
}

/* Images count too; a file named twice counts once (a hostile file must
 * not stretch the limit at will); glTF 1 keys its lists by id; URIs may be
 * JSON-escaped or percent-encoded. */
static void test_images_duplicates_escapes(void **st) {
    (void)st;
    long long n = write_text("many.gltf", "{\"asset\":{\"version\":\"2.0\"},"
                                          "\"buffers\":[{\"uri\":\"big.bin\"},{\"uri\":\"./big.bin\"}],"
                                          "\"images\":[{\"uri\":\"b\\u0069g%20two.bin\"},{\"uri\":\"big.bin\"}]}");
    assert_int_equal(cbvh_scene_import_limit_ms(at("many.gltf")), limit_for(n + BIG + BIG / 2));
    n = write_text("v1.gltf", "{\"asset\":{\"version\":\"1.0\"},\"buffers\":{\"b0\":{\"uri\":\"big two.bin\"}}}");
    assert_int_equal(cbvh_scene_import_limit_ms(at("v1.gltf")), limit_for(n + BIG / 2));
    /* "uri" elsewhere (a mesh's extras, a nested buffer field) is not a buffer */
    n = write_text("other.gltf", "{\"meshes\":[{\"uri\":\"big.bin\"}],"
                                 "\"buffers\":[{\"extras\":{\"uri\":\"big.bin\"}}]}");
    assert_int_equal(cbvh_scene_import_limit_ms(at("other.gltf")), limit_for(n));
}

/* GLB: the JSON chunk after the 20-byte header. */
static void test_glb(void **st) {
    (void)st;
    const char *json = "{\"buffers\":[{\"byteLength\":36,\"uri\":\"big.bin\"}]}  ";
    uint32_t jlen = (uint32_t)strlen(json), total = 20 + jlen;
    unsigned char glb[256];
    memcpy(glb, "glTF", 4);
    const uint32_t words[4] = {2, total, jlen, 0x4E4F534Au /* "JSON" */};
    for (int w = 0; w < 4; w++)
        for (int b = 0; b < 4; b++) glb[4 + 4 * w + b] = (unsigned char)(words[w] >> (8 * b));
    memcpy(glb + 20, json, jlen);
    long long n = write_file("scene.glb", glb, total);
    assert_int_equal(cbvh_scene_import_limit_ms(at("scene.glb")), limit_for(n + BIG));
    /* the chunk length bounds the JSON: cut short, the URI is not read */
    glb[12] = 20;
    glb[13] = glb[14] = glb[15] = 0;
    n = write_file("short.glb", glb, total);
    assert_int_equal(cbvh_scene_import_limit_ms(at("short.glb")), limit_for(n));
}

/* JSON that does not parse (cut short, deep nesting, bad escapes, binary
 * junk) counts the file's own size only: assimp's parser rejects it before
 * it reads any buffer.  A NUL would cut a URI short: nothing is counted. */
static void test_malformed(void **st) {
    (void)st;
    long long n = write_text("cut.gltf", "{\"buffers\":[{\"uri\":\"big.bin\"},{\"uri\":\"big two");
    assert_int_equal(cbvh_scene_import_limit_ms(at("cut.gltf")), limit_for(n));
    n = write_text("esc.gltf", "{\"buffers\":[{\"uri\":\"big\\q.bin\"}]}");
    assert_int_equal(cbvh_scene_import_limit_ms(at("esc.gltf")), limit_for(n));
    n = write_text("nul.gltf", "{\"buffers\":[{\"uri\":\"big.bin\\u0000x\"}]}");
    assert_int_equal(cbvh_scene_import_limit_ms(at("nul.gltf")), limit_for(n));
    n = write_file("rawnul.gltf", "{\"buffers\":[{\"uri\":\"big.bin\0x\"}]}", 33);
    assert_int_equal(cbvh_scene_import_limit_ms(at("rawnul.gltf")), limit_for(n));
    char deep[4096] = "{\"buffers\":";
    for (int i = 0; i < 1000; i++) strcat(deep, "[");
    n = write_text("deep.gltf", deep);
    assert_int_equal(cbvh_scene_import_limit_ms(at("deep.gltf")), limit_for(n));
    unsigned char junk[4096];
    uint32_t x = 2463534242u;
    for (size_t i = 0; i < sizeof junk; i++) x ^= x << 13, x ^= x >> 17, x ^= x << 5, junk[i] = (unsigned char)x;
    n = write_file("junk.gltf", junk, sizeof junk);
    assert_int_equal(cbvh_scene_import_limit_ms(at("junk.gltf")), limit_for(n));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gltf_separate_bin),
        cmocka_unit_test(test_gltf_separate_bin_imports),
        cmocka_unit_test(test_not_counted),
        cmocka_unit_test(test_images_duplicates_escapes),
        cmocka_unit_test(test_glb),
        cmocka_unit_test(test_malformed),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
