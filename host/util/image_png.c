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

void cbvh_colormap_diverging(double t, uint8_t rgb[3]) {
    static const double lo[3] = {33, 102, 172}, hi[3] = {178, 24, 43}; /* blue, red */
    if (isnan(t)) t = 0.5;
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    const double *end = t < 0.5 ? lo : hi;
    double f = t < 0.5 ? 1 - 2 * t : 2 * t - 1; /* 0 at white, 1 at the end */
    for (int c = 0; c < 3; c++) rgb[c] = (uint8_t)(255 + (end[c] - 255) * f + 0.5);
}

/* A 5x7 pixel font for the heat maps' text, printable ASCII from ' ': seven
 * rows per glyph, top first, bit 4 the leftmost column (drawn for this kit). */
static const uint8_t font5x7[95][7] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04}, {0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00},
    {0x0A, 0x1F, 0x0A, 0x0A, 0x1F, 0x0A, 0x00}, {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F}, {0x19, 0x1A, 0x04, 0x04, 0x08, 0x17, 0x07},
    {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F}, {0x04, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00}, {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02},
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}, {0x00, 0x15, 0x0E, 0x1F, 0x0E, 0x15, 0x00}, {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00},
    {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}, {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}, {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C},
    {0x01, 0x02, 0x02, 0x04, 0x08, 0x08, 0x10}, {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}, {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02},
    {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}, {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}, {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00},
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08}, {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}, {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00},
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}, {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}, {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F},
    {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}, {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}, {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E},
    {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}, {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}, {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10},
    {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}, {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}, {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E},
    {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}, {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}, {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F},
    {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}, {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}, {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E},
    {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}, {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}, {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11},
    {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}, {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}, {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E},
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}, {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}, {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11},
    {0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}, {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E},
    {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F}, {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}, {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F},
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}, {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F}, {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F},
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E}, {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}, {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F},
    {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}, {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}, {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E},
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}, {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}, {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0C},
    {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}, {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11},
    {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}, {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}, {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10},
    {0x00, 0x00, 0x0D, 0x13, 0x0F, 0x01, 0x01}, {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}, {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E},
    {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}, {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}, {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04},
    {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A}, {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}, {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E},
    {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F}, {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F},
    {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F}, {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F},
};

#define TEXT_SCALE 2                   /* pixels per font pixel */
#define CHAR_W (6 * TEXT_SCALE)        /* 5 columns and a space */
#define CHAR_H (9 * TEXT_SCALE)        /* 7 rows and two of space */

typedef struct {
    uint8_t *pix;
    unsigned w, h;
} canvas;

static void put(const canvas *c, long x, long y, const uint8_t rgb[3]) {
    if (x >= 0 && y >= 0 && (unsigned long)x < c->w && (unsigned long)y < c->h)
        memcpy(c->pix + ((size_t)y * c->w + (size_t)x) * 3, rgb, 3);
}

/* s in black from (x, y) (top-left), cut at the canvas' right edge. */
static void text(const canvas *c, long x, long y, const char *s) {
    static const uint8_t ink[3] = {0, 0, 0};
    for (; *s; s++, x += CHAR_W) {
        unsigned ch = (unsigned char)*s;
        const uint8_t *g = font5x7[(ch >= 32 && ch < 127 ? ch : '?') - 32];
        for (int r = 0; r < 7; r++)
            for (int k = 0; k < 5; k++)
                if (g[r] >> (4 - k) & 1)
                    for (int dy = 0; dy < TEXT_SCALE; dy++)
                        for (int dx = 0; dx < TEXT_SCALE; dx++)
                            put(c, x + k * TEXT_SCALE + dx, y + r * TEXT_SCALE + dy, ink);
    }
}

/* How many lines s takes when wrapped at spaces to `cols` characters (a word
 * longer than a line is cut); with c, draws them from (x, y). */
static int wrapped(const canvas *c, long x, long y, const char *s, size_t cols) {
    int lines = 0;
    char buf[512];
    if (cols < 1) cols = 1;
    if (cols >= sizeof buf) cols = sizeof buf - 1;
    while (*s) {
        size_t n = strlen(s), take = n;
        if (n > cols) {
            take = cols;
            while (take > 0 && s[take] != ' ') take--;
            if (take == 0) take = cols;
        }
        memcpy(buf, s, take);
        buf[take] = 0;
        if (c) text(c, x, y + (long)lines * CHAR_H, buf);
        lines++;
        s += take;
        while (*s == ' ') s++;
    }
    return lines;
}

/* s centred on x, kept inside the canvas. */
static void text_centred(const canvas *c, long x, long y, const char *s) {
    long len = (long)strlen(s) * CHAR_W, x0 = x - len / 2;
    if (x0 + len > (long)c->w) x0 = (long)c->w - len;
    if (x0 < 0) x0 = 0;
    text(c, x0, y, s);
}

int cbvh_heatmap_png(const char *path, const double *val, unsigned w, unsigned h, const cbvh_heatmap_style *st,
                     cbvh_heatmap_info *info, char *err, size_t errlen) {
    static const cbvh_heatmap_style plain = {NULL, NULL, 0, 0, 0, 0};
    if (!st) st = &plain;
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
    if (st->vmin < st->vmax) {
        lo = st->vmin;
        hi = st->vmax;
    }
    if (st->diverging) { /* symmetric around 0, so white is 0 */
        double m = fabs(lo) > fabs(hi) ? fabs(lo) : fabs(hi);
        lo = -m;
        hi = m;
    }
    unsigned minw = st->min_width ? st->min_width : 512, scale = (minw + w - 1) / w;
    if (scale < 1) scale = 1;
    /* The frame: a margin, the title, the map, the colour bar, its ticks and values, the label. */
    unsigned pad = 16, mw = w * scale, mh = h * scale;
    size_t cols = mw / CHAR_W;
    unsigned title_h = st->title ? (unsigned)wrapped(NULL, 0, 0, st->title, cols) * CHAR_H + 8 : 0, bar_h = 18,
             tick_h = 6, label_h = st->label ? (unsigned)wrapped(NULL, 0, 0, st->label, cols) * CHAR_H + 4 : 0;
    unsigned long W = (unsigned long)mw + 2 * pad,
                  H = (unsigned long)pad + title_h + mh + 10 + bar_h + tick_h + 2 + CHAR_H + label_h + pad;
    if (W > 65535 || H > 65535 || (unsigned long)w * scale > 65535) {
        snprintf(err, errlen, "heat map: %s: image too large (%lux%lu)", path ? path : "", W, H);
        return -1;
    }
    canvas c = {malloc(W * H * 3), (unsigned)W, (unsigned)H};
    if (!c.pix) {
        snprintf(err, errlen, "heat map: out of memory");
        return -1;
    }
    memset(c.pix, 255, W * H * 3);
    void (*cmap)(double, uint8_t *) = st->diverging ? cbvh_colormap_diverging : cbvh_colormap;
    double span = hi > lo ? hi - lo : 1;
    unsigned mx = pad, my = pad + title_h;
    for (unsigned y = 0; y < h; y++)
        for (unsigned x = 0; x < w; x++) {
            uint8_t rgb[3];
            cmap((val[(size_t)y * w + x] - lo) / span, rgb);
            for (unsigned dy = 0; dy < scale; dy++)
                for (unsigned dx = 0; dx < scale; dx++) put(&c, mx + x * scale + dx, my + y * scale + dy, rgb);
        }
    if (st->title) wrapped(&c, pad, pad, st->title, cols);
    unsigned by = my + mh + 10;
    static const uint8_t ink[3] = {0, 0, 0};
    for (unsigned x = 0; x < mw; x++) {
        uint8_t rgb[3];
        cmap(mw > 1 ? (double)x / (mw - 1) : 1.0, rgb);
        for (unsigned y = by; y < by + bar_h; y++) put(&c, mx + x, y, rgb);
    }
    for (int k = 0; k <= 4; k++) { /* five ticks: 0, 1/4, ... 1 of the range */
        unsigned x = mx + (unsigned)((double)(mw - 1) * k / 4.0 + 0.5);
        for (unsigned y = by + bar_h; y < by + bar_h + tick_h; y++) put(&c, x, y, ink);
        char num[32];
        double v = lo + (hi - lo) * k / 4.0;
        snprintf(num, sizeof num, "%.4g", fabs(v) < 1e-12 * (fabs(lo) + fabs(hi)) ? 0.0 : v);
        text_centred(&c, x, by + bar_h + tick_h + 2, num);
    }
    if (st->label) wrapped(&c, pad, by + bar_h + tick_h + 2 + CHAR_H + 4, st->label, cols);
    char smin[32], smax[32];
    snprintf(smin, sizeof smin, "%.17g", lo);
    snprintf(smax, sizeof smax, "%.17g", hi);
    png_note notes[3] = {{"legend_min", smin}, {"legend_max", smax}, {"Title", st->title ? st->title : ""}};
    int rc = write_png(path, c.pix, c.w, c.h, 3, notes, st->title ? 3 : 2, err, errlen);
    free(c.pix);
    if (rc == 0 && info) {
        *info = (cbvh_heatmap_info){lo, hi, scale, c.w, c.h, mx, my, by, bar_h};
    }
    return rc;
}
