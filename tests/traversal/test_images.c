/* PNG / heat-map writer (host/util/image_png.c) and SVG chart writer
 * (host/util/chart_svg.c): PNG round trip through libpng's reader, heat-map
 * colours and legend, SVG well-formedness basics, bad input rejected with
 * nothing left behind. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "util/chart_svg.h"
#include "util/image_png.h"

static char dir[256];

static int setup(void **state) {
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/cbvh_test_images_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state) {
    (void)state;
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char p[512];
        while ((e = readdir(d)))
            if (e->d_name[0] != '.') {
                snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
                unlink(p);
            }
        closedir(d);
    }
    rmdir(dir);
    return 0;
}

static int files_in_dir(void) {
    int n = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (e->d_name[0] != '.') n++;
    if (d) closedir(d);
    return n;
}

/* Read a PNG with libpng's simplified API in the given format. */
static uint8_t *read_png(const char *path, unsigned *w, unsigned *h, png_uint_32 format) {
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) return NULL;
    img.format = format;
    uint8_t *buf = malloc(PNG_IMAGE_SIZE(img));
    if (!buf || !png_image_finish_read(&img, NULL, buf, 0, NULL)) {
        free(buf);
        png_image_free(&img);
        return NULL;
    }
    *w = img.width;
    *h = img.height;
    return buf;
}

static void png_round_trip(void **state) {
    (void)state;
    char p[300], err[256];
    unsigned W = 37, H = 21;
    uint8_t *rgb = malloc((size_t)W * H * 3), *grey = malloc((size_t)W * H);
    for (size_t i = 0; i < (size_t)W * H * 3; i++) rgb[i] = (uint8_t)(i * 7 + (i >> 5));
    for (size_t i = 0; i < (size_t)W * H; i++) grey[i] = (uint8_t)(i * 13);
    snprintf(p, sizeof p, "%s/rgb.png", dir);
    assert_int_equal(cbvh_png_write(p, rgb, W, H, 3, err, sizeof err), 0);
    unsigned w, h;
    uint8_t *back = read_png(p, &w, &h, PNG_FORMAT_RGB);
    assert_non_null(back);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    assert_memory_equal(back, rgb, (size_t)W * H * 3);
    free(back);
    snprintf(p, sizeof p, "%s/grey.png", dir);
    assert_int_equal(cbvh_png_write(p, grey, W, H, 1, err, sizeof err), 0);
    back = read_png(p, &w, &h, PNG_FORMAT_GRAY);
    assert_non_null(back);
    assert_memory_equal(back, grey, (size_t)W * H);
    free(back);
    assert_int_equal(files_in_dir(), 2); /* no temporary files left */
    free(rgb);
    free(grey);
}

static void png_bad_input(void **state) {
    (void)state;
    char p[300], err[256] = "";
    uint8_t px[12] = {0};
    snprintf(p, sizeof p, "%s/bad.png", dir);
    assert_int_equal(cbvh_png_write(p, px, 0, 2, 3, err, sizeof err), -1);
    assert_non_null(strstr(err, "size"));
    assert_int_equal(cbvh_png_write(p, px, 2, 2, 2, err, sizeof err), -1);
    assert_non_null(strstr(err, "channels"));
    snprintf(p, sizeof p, "%s/no/such/dir/x.png", dir);
    assert_int_equal(cbvh_png_write(p, px, 2, 2, 3, err, sizeof err), -1);
    assert_non_null(strstr(err, "cannot create"));
    assert_int_equal(files_in_dir(), 0);
}

/* A pixel of an RGB image. */
static const uint8_t *px(const uint8_t *img, unsigned w, unsigned x, unsigned y) { return img + ((size_t)y * w + x) * 3; }

/* Any black (text) pixel in rows y0 .. y1 - 1. */
static int has_ink(const uint8_t *img, unsigned w, unsigned y0, unsigned y1) {
    for (unsigned y = y0; y < y1; y++)
        for (unsigned x = 0; x < w; x++)
            if (!px(img, w, x, y)[0] && !px(img, w, x, y)[1] && !px(img, w, x, y)[2]) return 1;
    return 0;
}

static void heatmap(void **state) {
    (void)state;
    char p[300], err[256];
    unsigned W = 64, H = 48;
    double *v = malloc((size_t)W * H * sizeof *v);
    for (unsigned y = 0; y < H; y++)
        for (unsigned x = 0; x < W; x++) v[y * W + x] = 10 + x + 0.5 * y; /* min 10 at (0,0), max at (63,47) */
    snprintf(p, sizeof p, "%s/heat.png", dir);
    cbvh_heatmap_style st = {"N=6 M=24: box tests", "box tests per pixel", 0, 0, 0, 0};
    cbvh_heatmap_info in;
    assert_int_equal(cbvh_heatmap_png(p, v, W, H, &st, &in, err, sizeof err), 0);
    assert_true(in.vmin == 10 && in.vmax == 10 + 63 + 23.5);
    assert_int_equal(in.scale, 8); /* 64 x 8 = 512: the smallest whole factor to 512 pixels wide */
    unsigned w, h;
    uint8_t *img = read_png(p, &w, &h, PNG_FORMAT_RGB);
    assert_non_null(img);
    assert_int_equal(w, in.width);
    assert_int_equal(h, in.height);
    assert_true(w >= 512 && w == W * 8 + 2 * in.map_x);
    uint8_t c0[3], c1[3];
    cbvh_colormap(0, c0);
    cbvh_colormap(1, c1);
    /* Scaled without smoothing: the whole 8 x 8 block of value (0,0) is the min colour, of (63,47) the max. */
    for (unsigned dy = 0; dy < 8; dy++)
        for (unsigned dx = 0; dx < 8; dx++) {
            assert_memory_equal(px(img, w, in.map_x + dx, in.map_y + dy), c0, 3);
            assert_memory_equal(px(img, w, in.map_x + 63 * 8 + dx, in.map_y + 47 * 8 + dy), c1, 3);
        }
    /* The colour bar: min at its left end, max at its right, luminance growing along it. */
    unsigned bar = in.bar_y + in.bar_h / 2;
    assert_memory_equal(px(img, w, in.map_x, bar), c0, 3);
    assert_memory_equal(px(img, w, in.map_x + W * 8 - 1, bar), c1, 3);
    double prev = -1;
    for (unsigned x = in.map_x; x < in.map_x + W * 8; x++) {
        const uint8_t *q = px(img, w, x, bar);
        double lum = 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
        assert_true(lum >= prev - 0.5);
        prev = lum;
    }
    /* Text: the title above the map, the tick values and the label below the bar; white around. */
    assert_true(has_ink(img, w, 0, in.map_y));
    assert_true(has_ink(img, w, in.bar_y + in.bar_h, h));
    assert_false(has_ink(img, w, in.map_y, in.map_y + H * 8)); /* no text over the map */
    assert_true(px(img, w, 0, in.map_y)[0] == 255);              /* white frame */
    free(img);
    /* Without a title the map starts higher; a diverging map is symmetric around 0, white at 0. */
    cbvh_heatmap_style ds = {NULL, NULL, 0, 0, 1, 100};
    for (unsigned i = 0; i < W * H; i++) v[i] = i % 3 == 0 ? -2.0 : i % 3 == 1 ? 0.0 : 5.0;
    assert_int_equal(cbvh_heatmap_png(p, v, W, H, &ds, &in, err, sizeof err), 0);
    assert_true(in.vmin == -5 && in.vmax == 5);
    assert_int_equal(in.scale, 2);
    img = read_png(p, &w, &h, PNG_FORMAT_RGB);
    assert_non_null(img);
    uint8_t white[3] = {255, 255, 255}, red[3];
    cbvh_colormap_diverging(1, red);
    assert_memory_equal(px(img, w, in.map_x + 2, in.map_y), white, 3); /* v[1] = 0 */
    assert_memory_equal(px(img, w, in.map_x + 4, in.map_y), red, 3);   /* v[2] = 5 */
    free(img);
    v[5] = NAN;
    assert_int_equal(cbvh_heatmap_png(p, v, W, H, NULL, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, "not finite"));
    free(v);
}

static char *slurp(const char *p) {
    FILE *f = fopen(p, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)n + 1);
    size_t got = fread(b, 1, (size_t)n, f);
    b[got] = 0;
    fclose(f);
    return b;
}

/* Tags balanced (a stack of element names), attribute quotes closed, no raw
 * '&' except entities, no '<' inside text.  Returns the number of elements
 * named `count_name`, or -1 if malformed. */
static int check_xml(const char *s, const char *count_name) {
    char stack[64][32];
    int sp = 0, count = 0;
    const char *p = strstr(s, "<svg");
    if (!p || strncmp(s, "<?xml", 5) != 0) return -1;
    while (*p) {
        if (*p == '&') {
            const char *e = strchr(p, ';');
            if (!e || e - p > 6) return -1;
            p = e + 1;
            continue;
        }
        if (*p != '<') {
            if (*p == '>') return -1;
            p++;
            continue;
        }
        const char *end = p + 1;
        int inq = 0;
        while (*end && (inq || *end != '>')) {
            if (*end == '"') inq = !inq;
            if (inq && *end == '<') return -1;
            end++;
        }
        if (!*end) return -1;
        char name[32];
        int closing = p[1] == '/';
        const char *n = p + 1 + closing;
        size_t k = 0;
        while (n < end && *n != ' ' && *n != '/' && *n != '\n' && k < sizeof name - 1) name[k++] = *n++;
        name[k] = 0;
        int selfclose = end[-1] == '/';
        if (closing) {
            if (sp == 0 || strcmp(stack[sp - 1], name)) return -1;
            sp--;
        } else {
            if (!strcmp(name, count_name)) count++;
            if (!selfclose) {
                if (sp == 64) return -1;
                snprintf(stack[sp++], sizeof stack[0], "%s", name);
            }
        }
        p = end + 1;
    }
    return sp == 0 ? count : -1;
}

static void svg_chart(void **state) {
    (void)state;
    char p[300], err[256];
    double x[8] = {3, 4, 5, 6, 7, 8, 9, 10};
    double box[8] = {7.3, 2.1, 1.3, 1.06, 1.03, 1.01, 1.005, 1.004}, tri[8] = {40.6, 5, 1.9, 1.07, 1.04, 1.02, 1.01, 1.005};
    cbvh_svg_series s[2] = {{"box tests <x> & more", box}, {"triangle tests", tri}};
    snprintf(p, sizeof p, "%s/chart.svg", dir);
    assert_int_equal(cbvh_svg_chart(p, "Cost vs \"bits\"", "N (bits)", "relative cost", x, 8, s, 2, err, sizeof err),
                     0);
    char *b = slurp(p);
    assert_non_null(b);
    assert_int_equal(check_xml(b, "polyline"), 2);
    assert_int_equal(check_xml(b, "circle"), 16);
    assert_non_null(strstr(b, "box tests &lt;x&gt; &amp; more"));
    assert_non_null(strstr(b, "Cost vs &quot;bits&quot;"));
    assert_non_null(strstr(b, ">10</text>")); /* x tick label */
    assert_null(strstr(b, "nan"));
    free(b);
    /* bad input: non-increasing x, non-finite y, no series; nothing written */
    double xb[3] = {1, 1, 2}, yb[3] = {1, NAN, 2};
    cbvh_svg_series sb = {"s", yb};
    snprintf(p, sizeof p, "%s/bad.svg", dir);
    assert_int_equal(cbvh_svg_chart(p, "t", "x", "y", xb, 3, &sb, 1, err, sizeof err), -1);
    assert_non_null(strstr(err, "increasing"));
    assert_int_equal(cbvh_svg_chart(p, "t", "x", "y", x, 3, &sb, 1, err, sizeof err), -1);
    assert_non_null(strstr(err, "not finite"));
    assert_int_equal(cbvh_svg_chart(p, "t", "x", "y", x, 3, &sb, 0, err, sizeof err), -1);
    assert_null(fopen(p, "r"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(png_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(png_bad_input, setup, teardown),
        cmocka_unit_test_setup_teardown(heatmap, setup, teardown),
        cmocka_unit_test_setup_teardown(svg_chart, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
