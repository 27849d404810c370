/* `cbvh vectors check`: verify a vector directory's MANIFEST, run every
 * vector on a backend (board or model), report (docs/vectors.md, "Checking").
 * Used by cmd_vectors.c and by `cbvh run`. */
#ifndef CBVH_HOST_VECTORS_CHECK_H
#define CBVH_HOST_VECTORS_CHECK_H

#include <stddef.h>
#include <stdio.h>

/* Exit statuses. */
enum { CBVH_CHECK_PASS = 0, CBVH_CHECK_MISMATCH = 1, CBVH_CHECK_BAD_INPUT = 2 };

#define CBVH_CHECK_BATCH 1024 /* vectors per backend call, so a board can stream */

typedef struct {
    size_t files, passed, failed;
    double seconds;            /* wall time of parsing + running + comparing */
    double vectors_per_second; /* (passed + failed) / seconds */
    char backend[160];         /* label of the backend used */
} cbvh_check_summary;

typedef struct {
    const char *backend; /* "auto", "model", "usb", "hid" (NULL = auto) */
    int max_errors;      /* mismatches printed in full (default 20; 0 = none) */
    int json;            /* one JSON object on out instead of text */
    int quiet;           /* text mode: no per-file lines */
    FILE *out;           /* report (NULL = stdout) */
    FILE *log;           /* one-line notes and errors (NULL = stderr) */
    size_t batch;        /* vectors per backend call (0 = CBVH_CHECK_BATCH) */
    size_t sample;       /* at most this many vectors per file, evenly spread (0 = all): for slow backends */
    cbvh_check_summary *summary; /* optional: filled on return */
    const char *who;     /* prefix of error lines (NULL = "cbvh vectors check") */
} cbvh_check_opts;

/* Checks directories (MANIFEST verified first, then every listed .vec file)
 * and single files (hash verified when a MANIFEST sits next to the file).
 * Returns CBVH_CHECK_PASS, CBVH_CHECK_MISMATCH or CBVH_CHECK_BAD_INPUT; every
 * bad input is reported as one line on log. */
int cbvh_vectors_check(const char *const *paths, int npaths, const cbvh_check_opts *opts);

#endif
