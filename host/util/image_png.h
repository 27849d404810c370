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

/* Heat map of a scalar per pixel (e.g. box tests per pixel): values mapped
 * linearly from [vmin, vmax] to the colour map (vmin >= vmax: the data's own
 * range), then a legend strip under the image: a 4-pixel gap and a gradient
 * from vmin (left) to vmax (right), legend_h rows (0: max(8, h / 12)).  The
 * range used is stored as tEXt chunks "legend_min" / "legend_max" and
 * returned in *used_min / *used_max (may be NULL).  Non-finite values are an
 * error. */
int cbvh_heatmap_png(const char *path, const double *val, unsigned w, unsigned h, double vmin, double vmax,
                     unsigned legend_h, double *used_min, double *used_max, char *err, size_t errlen);

#endif
