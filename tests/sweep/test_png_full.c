/* A PNG that cannot be written (a full disk: /dev/full) fails with one line
 * of ours and nothing else on stderr: libpng's own handlers printed
 * "libpng error: Write Error" first, a second line. */
#define _POSIX_C_SOURCE 200809L /* fileno, dup */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "util/image_png.h"

/* Runs the write with stderr going to a temporary file; returns what it got. */
static int write_capturing_stderr(FILE *f, const uint8_t *pix, unsigned w, unsigned h, char *err, size_t errlen,
                                  char *captured, size_t caplen) {
    FILE *cap = tmpfile();
    assert_non_null(cap);
    fflush(stderr);
    int saved = dup(2);
    assert_true(saved >= 0);
    assert_true(dup2(fileno(cap), 2) >= 0);
    int rc = cbvh_png_write_stream(f, pix, w, h, 3, err, errlen);
    fflush(stderr);
    assert_true(dup2(saved, 2) >= 0);
    close(saved);
    rewind(cap);
    size_t n = fread(captured, 1, caplen - 1, cap);
    captured[n] = 0;
    fclose(cap);
    return rc;
}

static void full_disk_one_line(void **st) {
    (void)st;
    FILE *full = fopen("/dev/full", "wb");
    if (!full) skip();
    /* noise, so that the compressed data overflows stdio's buffer and the
     * write fails inside libpng, not only at the final flush */
    enum { W = 256, H = 256 };
    uint8_t *pix = malloc((size_t)W * H * 3);
    assert_non_null(pix);
    uint32_t x = 2463534242u;
    for (size_t i = 0; i < (size_t)W * H * 3; i++) x ^= x << 13, x ^= x >> 17, x ^= x << 5, pix[i] = (uint8_t)x;
    char err[300] = "", captured[1024];
    int rc = write_capturing_stderr(full, pix, W, H, err, sizeof err, captured, sizeof captured);
    fclose(full);
    free(pix);
    assert_int_equal(rc, -1);
    assert_string_equal(err, "png: writing failed: No space left on device");
    if (captured[0]) fail_msg("printed on stderr besides the error: '%s'", captured);
}

/* A stream that takes the bytes: a readable PNG, nothing on stderr. */
static void stream_ok(void **st) {
    (void)st;
    FILE *f = tmpfile();
    assert_non_null(f);
    const uint8_t pix[2 * 2 * 3] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
    char err[300] = "", captured[1024];
    assert_int_equal(write_capturing_stderr(f, pix, 2, 2, err, sizeof err, captured, sizeof captured), 0);
    assert_string_equal(captured, "");
    unsigned char sig[8];
    rewind(f);
    assert_int_equal(fread(sig, 1, 8, f), 8);
    assert_memory_equal(sig, "\x89PNG\r\n\x1a\n", 8);
    fclose(f);
}

int main(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(full_disk_one_line), cmocka_unit_test(stream_ok)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
