/* PNG output for the studies (cbvh sweep: per-pixel heat maps, rendered images):
 * 8-bit grey or RGB through libpng, written to a temporary file and renamed,
 * so a failed write never leaves a half-written image.  Every failure is a
 * one-line message in err and -1. */
#ifndef CBVH_HOST_IMAGE_PNG_H
#define CBVH_HOST_IMAGE_PNG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* pix: h rows of w pixels, channels = 1 (grey) or 3 (RGB), row-major, no
 * padding.  w, h in 1 .. 65535. */
int cbvh_png_write(const char *path, const uint8_t *pix, unsigned w, unsigned h, int channels, char *err,
                   size_t errlen);

/* The same PNG on an open stream (standard output, a pipe), flushed but not
 * closed; no temporary file, so a failed write may leave part of it there. */
int cbvh_png_write_stream(FILE *f, const uint8_t *pix, unsigned w, unsigned h, int channels, char *err,
                          size_t errlen);

/* The heat-map colour map: t in [0, 1] (clamped; NaN -> 0) to RGB, dark blue
 * -> purple -> orange -> pale yellow, monotone in luminance. */
void cbvh_colormap(double t, uint8_t rgb[3]);

/* The diverging colour map of difference heat maps: t in [0, 1] (clamped;
 * NaN -> 0.5) to RGB, blue (0) -> white (0.5) -> red (1). */
void cbvh_colormap_diverging(double t, uint8_t rgb[3]);

/* How a heat map is drawn. */
typedef struct {
    const char *title;  /* a line above the map (printable ASCII; other bytes drawn as '?'); NULL: none */
    const char *label;  /* a line under the colour bar: what a colour counts; NULL: none */
    double vmin, vmax;  /* the value range of the colours; vmin >= vmax: the data's own range */
    int diverging;      /* 1: the diverging map, the range made symmetric around 0 (max |v|) */
    unsigned min_width; /* the map is scaled up by a whole factor, without smoothing, to at least this
                           many pixels wide (0: 512) */
} cbvh_heatmap_style;

/* Where things went in a heat map. */
typedef struct {
    double vmin, vmax;      /* the range used */
    unsigned scale;         /* pixels per value, each way */
    unsigned width, height; /* the image */
    unsigned map_x, map_y;  /* the map's top-left corner (its size: w x h times scale) */
    unsigned bar_y, bar_h;  /* the colour bar: rows bar_y .. bar_y + bar_h - 1, columns map_x .. map_x + w*scale - 1 */
} cbvh_heatmap_info;

/* Heat map of a scalar per pixel (e.g. box tests per pixel) in a PNG: a
 * white frame with the title, the map scaled up (st->min_width), under it a
 * colour bar from vmin (left) to vmax (right) with five tick marks and
 * their values, and the label.  The range is also stored as tEXt chunks
 * "legend_min" / "legend_max", the title as "Title".  Non-finite values are
 * an error.  info may be NULL. */
int cbvh_heatmap_png(const char *path, const double *val, unsigned w, unsigned h, const cbvh_heatmap_style *st,
                     cbvh_heatmap_info *info, char *err, size_t errlen);

#endif
