/* A small SVG line-chart writer for the accuracy-vs-cost studies (cbvh sweep:
 * x = coordinate bits N, y = cost relative to the float BVH, one series per
 * quantity or effect).  Axes with ticks and labels, a legend, one polyline
 * with point markers per series.  Written to a temporary file and renamed.
 * Every failure is a one-line message in err and -1. */
#ifndef CBVH_HOST_CHART_SVG_H
#define CBVH_HOST_CHART_SVG_H

#include <stddef.h>

typedef struct {
    const char *name; /* legend text (escaped for XML) */
    const double *y;  /* npts values, finite */
} cbvh_svg_series;

/* x: npts strictly increasing finite values (npts >= 1); 1 .. 12 series.
 * The y axis spans [min(0, ymin), ymax] rounded out to "nice" ticks. */
int cbvh_svg_chart(const char *path, const char *title, const char *xlabel, const char *ylabel, const double *x,
                   size_t npts, const cbvh_svg_series *series, size_t nseries, char *err, size_t errlen);

#endif
