/* SVG line charts (see chart_svg.h). */
#include "util/file_mode.h"
#include "util/chart_svg.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void put_escaped(FILE *f, const char *s) {
    for (; s && *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&apos;", f); break;
        default:
            if ((unsigned char)*s >= 0x20 || *s == '\t') fputc(*s, f); /* drop control characters (invalid XML) */
        }
    }
}

/* A "nice" tick step (1, 2 or 5 times a power of ten) for about n ticks. */
static double nice_step(double span, int n) {
    double raw = span / n, p = pow(10, floor(log10(raw))), m = raw / p;
    return (m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10) * p;
}

static const char *const colours[12] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
                                        "#e377c2", "#7f7f7f", "#bcbd22", "#17becf", "#000000", "#aec7e8"};

int cbvh_svg_chart(const char *path, const char *title, const char *xlabel, const char *ylabel, const double *x,
                   size_t npts, const cbvh_svg_series *series, size_t nseries, char *err, size_t errlen) {
    if (!path || !*path) {
        snprintf(err, errlen, "svg: empty output path");
        return -1;
    }
    if (!x || npts == 0 || !series || nseries == 0 || nseries > 12) {
        snprintf(err, errlen, "svg: %s: need >= 1 point and 1..12 series (got %zu, %zu)", path, npts, nseries);
        return -1;
    }
    double ymin = 0, ymax = -INFINITY;
    for (size_t i = 0; i < npts; i++) {
        if (!isfinite(x[i]) || (i && x[i] <= x[i - 1])) {
            snprintf(err, errlen, "svg: %s: x values must be finite and strictly increasing (point %zu)", path, i);
            return -1;
        }
    }
    for (size_t s = 0; s < nseries; s++) {
        if (!series[s].y) {
            snprintf(err, errlen, "svg: %s: series %zu has no values", path, s);
            return -1;
        }
        for (size_t i = 0; i < npts; i++) {
            double v = series[s].y[i];
            if (!isfinite(v)) {
                snprintf(err, errlen, "svg: %s: series %zu point %zu is not finite", path, s, i);
                return -1;
            }
            if (v < ymin) ymin = v;
            if (v > ymax) ymax = v;
        }
    }
    if (ymax <= ymin) ymax = ymin + 1;
    double ystep = nice_step(ymax - ymin, 6);
    ymin = floor(ymin / ystep) * ystep;
    ymax = ceil(ymax / ystep) * ystep;
    double xmin = x[0], xmax = npts > 1 ? x[npts - 1] : x[0] + 1;
    if (npts == 1) xmin -= 1;
    double xstep = nice_step(xmax - xmin, 8);
    if (xstep < 1 && floor(xmin) == xmin && floor(xmax) == xmax && xmax - xmin <= 16) xstep = 1; /* integer bits */

    const double W = 720, H = 440, L = 80, R = 200, T = 50, B = 60; /* plot area [L, W-R] x [T, H-B] */
    double pw = W - L - R, ph = H - T - B;
#define PX(v) (L + ((v) - xmin) / (xmax - xmin) * pw)
#define PY(v) (H - B - ((v) - ymin) / (ymax - ymin) * ph)

    size_t plen = strlen(path);
    char *tmp = malloc(plen + 16);
    if (!tmp) {
        snprintf(err, errlen, "svg: out of memory");
        return -1;
    }
    snprintf(tmp, plen + 16, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(tmp);
    if (fd < 0) {
        snprintf(err, errlen, "svg: cannot create %s: %s", tmp, strerror(errno));
        free(tmp);
        return -1;
    }
    cbvh_fd_default_mode(fd);
    FILE *f = fdopen(fd, "w");
    if (!f) {
        snprintf(err, errlen, "svg: cannot open %s: %s", tmp, strerror(errno));
        close(fd);
        unlink(tmp);
        free(tmp);
        return -1;
    }
    errno = 0; /* so a failed write below can be named (e.g. no space left) */
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" "
            "font-family=\"sans-serif\" font-size=\"12\">\n",
            W, H, W, H);
    fprintf(f, "<rect x=\"0\" y=\"0\" width=\"%.0f\" height=\"%.0f\" fill=\"white\"/>\n", W, H);
    fprintf(f, "<text x=\"%.1f\" y=\"28\" text-anchor=\"middle\" font-size=\"15\">", L + pw / 2);
    put_escaped(f, title);
    fprintf(f, "</text>\n<g stroke=\"#dddddd\" stroke-width=\"1\">\n");
    for (double v = ymin; v <= ymax + ystep * 1e-9; v += ystep)
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>\n", L, PY(v), L + pw, PY(v));
    fprintf(f, "</g>\n<g stroke=\"black\" stroke-width=\"1\">\n");
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>\n", L, H - B, L + pw, H - B);
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>\n", L, T, L, H - B);
    fprintf(f, "</g>\n<g text-anchor=\"middle\">\n");
    for (double v = ceil(xmin / xstep) * xstep; v <= xmax + xstep * 1e-9; v += xstep)
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/><text x=\"%.1f\" y=\"%.1f\">%g</text>\n",
                PX(v), H - B, PX(v), H - B + 5, PX(v), H - B + 19, v);
    fprintf(f, "</g>\n<g text-anchor=\"end\">\n");
    for (double v = ymin; v <= ymax + ystep * 1e-9; v += ystep)
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">%g</text>\n", L - 6, PY(v) + 4, fabs(v) < ystep * 1e-9 ? 0.0 : v);
    fprintf(f, "</g>\n<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">", L + pw / 2, H - 18);
    put_escaped(f, xlabel);
    fprintf(f, "</text>\n<text x=\"18\" y=\"%.1f\" text-anchor=\"middle\" transform=\"rotate(-90 18 %.1f)\">",
            T + ph / 2, T + ph / 2);
    put_escaped(f, ylabel);
    fprintf(f, "</text>\n");
    for (size_t s = 0; s < nseries; s++) {
        const char *c = colours[s];
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"", c);
        for (size_t i = 0; i < npts; i++) fprintf(f, "%s%.1f,%.1f", i ? " " : "", PX(x[i]), PY(series[s].y[i]));
        fprintf(f, "\"/>\n<g fill=\"%s\">", c);
        for (size_t i = 0; i < npts; i++)
            fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\"/>", PX(x[i]), PY(series[s].y[i]));
        double ly = T + 10 + 20 * (double)s;
        fprintf(f, "</g>\n<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" stroke-width=\"2\"/>",
                L + pw + 15, ly, L + pw + 40, ly, c);
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">", L + pw + 46, ly + 4);
        put_escaped(f, series[s].name);
        fprintf(f, "</text>\n");
    }
    fprintf(f, "</svg>\n");
#undef PX
#undef PY
    int werr = ferror(f);
    if (fclose(f) != 0) werr = 1;
    if (werr) { /* errno from the failed write or flush, e.g. no space left */
        snprintf(err, errlen, "svg: writing %s failed: %s", path, errno ? strerror(errno) : "I/O error");
        unlink(tmp);
        free(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "svg: cannot rename %s to %s: %s", tmp, path, strerror(errno));
        unlink(tmp);
        free(tmp);
        return -1;
    }
    free(tmp);
    return 0;
}
