/* PNG writer and heat maps (see image_png.h). */
#include "util/file_mode.h"
#include "util/image_png.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct {
    const char *key, *text;
} png_note;

/* libpng's own handlers print "libpng error: ..." / "libpng warning: ..." on
 * stderr, a second line beside ours: its error message is kept for ours
 * instead, and a warning (nothing that stops the write) is not printed. */
typedef struct {
    char msg[160];
} png_errors;

static void on_png_error(png_structp png, png_const_charp msg) {
    png_errors *e = png_get_error_ptr(png);
    snprintf(e->msg, sizeof e->msg, "%s", msg);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg) {
    (void)png;
    (void)msg;
}

/* Size and channels (path only for the message); 0 or -1. */
static int check_image(const char *path, const uint8_t *pix, unsigned w, unsigned h, int channels, char *err,
                       size_t errlen) {
    if (!pix || w == 0 || h == 0 || w > 65535 || h > 65535) {
        snprintf(err, errlen, "png: %s: bad image size %ux%u (1..65535 each)", path, w, h);
        return -1;
    }
    if (channels != 1 && channels != 3) {
        snprintf(err, errlen, "png: %s: %d channels (1 = grey, 3 = RGB)", path, channels);
        return -1;
    }
    return 0;
}

/* The PNG on f, flushed (not closed): 0, or -1 with the reason in why (the
 * system's for a failed write, e.g. no space left, else libpng's). */
static int png_stream(FILE *f, const uint8_t *pix, unsigned w, unsigned h, int channels, const png_note *notes,
                      int nnotes, char *why, size_t whylen) {
    png_errors perr = {""};
    errno = 0; /* so a failed write below can be named (e.g. no space left) */
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &perr, on_png_error, on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    volatile int ok = 0;
    if (png && info && !setjmp(png_jmpbuf(png))) {
        png_init_io(png, f);
        png_set_IHDR(png, info, w, h, 8, channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY,
                     PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_text txt[4];
        int nt = nnotes < 4 ? nnotes : 4;
        for (int i = 0; i < nt; i++) {
            memset(&txt[i], 0, sizeof txt[i]);
            txt[i].compression = PNG_TEXT_COMPRESSION_NONE;
            txt[i].key = (png_charp)notes[i].key;
            txt[i].text = (png_charp)notes[i].text;
        }
        if (nt) png_set_text(png, info, txt, nt);
        png_write_info(png, info);
        for (unsigned y = 0; y < h; y++) png_write_row(png, (png_const_bytep)(pix + (size_t)y * w * channels));
        png_write_end(png, NULL);
        ok = 1;
    }
    png_destroy_write_struct(png ? &png : NULL, info ? &info : NULL);
    int werr = fflush(f) != 0 || ferror(f);
    if (ok && !werr) return 0;
    snprintf(why, whylen, "%s", errno ? strerror(errno) : !ok && perr.msg[0] ? perr.msg : !ok ? "libpng error" : "I/O error");
    return -1;
}

static int write_png(const char *path, const uint8_t *pix, unsigned w, unsigned h, int channels,
                     const png_note *notes, int nnotes, char *err, size_t errlen) {
    if (!path || !*path) {
        snprintf(err, errlen, "png: empty output path");
        return -1;
    }
    if (check_image(path, pix, w, h, channels, err, errlen)) return -1;
    size_t plen = strlen(path);
    char *tmp = malloc(plen + 16);
    if (!tmp) {
        snprintf(err, errlen, "png: out of memory");
        return -1;
    }
    snprintf(tmp, plen + 16, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(tmp);
    if (fd < 0) {
        snprintf(err, errlen, "png: cannot create %s: %s", tmp, strerror(errno));
        free(tmp);
        return -1;
    }
    cbvh_fd_default_mode(fd);
    FILE *f = fdopen(fd, "wb");
    if (!f) {
        snprintf(err, errlen, "png: cannot open %s: %s", tmp, strerror(errno));
        close(fd);
        unlink(tmp);
        free(tmp);
        return -1;
    }
    char why[200];
    int bad = png_stream(f, pix, w, h, channels, notes, nnotes, why, sizeof why);
    if (fclose(f) != 0 && !bad) {
        snprintf(why, sizeof why, "%s", errno ? strerror(errno) : "I/O error");
        bad = 1;
    }
    if (bad) {
        snprintf(err, errlen, "png: writing %s failed: %s", path, why);
        unlink(tmp);
        free(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "png: cannot rename %s to %s: %s", tmp, path, strerror(errno));
        unlink(tmp);
        free(tmp);
        return -1;
    }
    free(tmp);
    return 0;
}

int cbvh_png_write_stream(FILE *f, const uint8_t *pix, unsigned w, unsigned h, int channels, char *err,
                          size_t errlen) {
    char why[200];
    if (check_image("(stream)", pix, w, h, channels, err, errlen)) return -1;
    if (png_stream(f, pix, w, h, channels, NULL, 0, why, sizeof why) == 0) return 0;
    snprintf(err, errlen, "png: writing failed: %s", why);
    return -1;
}

int cbvh_png_write(const char *path, const uint8_t *pix, unsigned w, unsigned h, int channels, char *err,
                   size_t errlen) {
    return write_png(path, pix, w, h, channels, NULL, 0, err, errlen);
}

void cbvh_colormap(double t, uint8_t rgb[3]) {
    /* control points (inferno-like), linear between them */
    static const double cp[6][3] = {{0, 0, 4},      {40, 11, 84},    {120, 28, 109},
                                    {188, 55, 84},  {249, 142, 9},   {252, 255, 164}};
    if (!(t > 0)) t = 0; /* also NaN */
    if (t > 1) t = 1;
    double x = t * 5;
    int i = (int)x;
    if (i > 4) i = 4;
    double f = x - i;
    for (int c = 0; c < 3; c++) {
        double v = cp[i][c] + (cp[i + 1][c] - cp[i][c]) * f;
        rgb[c] = (uint8_t)(v + 0.5);
    }
}

int cbvh_heatmap_png(const char *path, const double *val, unsigned w, unsigned h, double vmin, double vmax,
                     unsigned legend_h, double *used_min, double *used_max, char *err, size_t errlen) {
    if (!val || w == 0 || h == 0 || w > 65535 || h > 65535) {
        snprintf(err, errlen, "heat map: %s: bad image size %ux%u", path ? path : "", w, h);
        return -1;
    }
    size_t n = (size_t)w * h;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(val[i])) {
            snprintf(err, errlen, "heat map: %s: value %zu (x %zu, y %zu) is not finite", path ? path : "", i,
                     i % w, i / w);
            return -1;
        }
        if (val[i] < lo) lo = val[i];
        if (val[i] > hi) hi = val[i];
    }
    if (vmin < vmax) {
        lo = vmin;
        hi = vmax;
    }
    if (legend_h == 0) legend_h = h / 12 > 8 ? h / 12 : 8;
    unsigned gap = 4, H = h + gap + legend_h;
    if (H > 65535) {
        snprintf(err, errlen, "heat map: %s: image with legend is too tall (%u rows)", path ? path : "", H);
        return -1;
    }
    uint8_t *pix = calloc((size_t)w * H, 3);
    if (!pix) {
        snprintf(err, errlen, "heat map: out of memory");
        return -1;
    }
    double span = hi > lo ? hi - lo : 1;
    for (size_t i = 0; i < n; i++) cbvh_colormap((val[i] - lo) / span, pix + 3 * i);
    for (unsigned y = h; y < h + gap; y++) memset(pix + (size_t)y * w * 3, 255, (size_t)w * 3); /* white gap */
    for (unsigned x = 0; x < w; x++) {
        uint8_t c[3];
        cbvh_colormap(w > 1 ? (double)x / (w - 1) : 1.0, c);
        for (unsigned y = h + gap; y < H; y++) memcpy(pix + ((size_t)y * w + x) * 3, c, 3);
    }
    char smin[32], smax[32];
    snprintf(smin, sizeof smin, "%.17g", lo);
    snprintf(smax, sizeof smax, "%.17g", hi);
    png_note notes[2] = {{"legend_min", smin}, {"legend_max", smax}};
    int rc = write_png(path, pix, w, H, 3, notes, 2, err, errlen);
    free(pix);
    if (rc == 0) {
        if (used_min) *used_min = lo;
        if (used_max) *used_max = hi;
    }
    return rc;
}
