/* Strict decimal integers for options and environment variables: the whole
 * string, an optional sign then digits (no blanks, no trailing text, no
 * overflow), within [lo, hi].  atoi took "5x" as 5; strtol alone skips
 * leading blanks and accepts an empty string as 0. */
#ifndef CBVH_HOST_PARSE_INT_H
#define CBVH_HOST_PARSE_INT_H

#include <errno.h>
#include <stdlib.h>

/* 0 with *out set, or -1 (s may be NULL: a missing value). */
static inline int cbvh_parse_long(const char *s, long lo, long hi, long *out) {
    if (!s) return -1;
    const char *digits = s + (*s == '-' || *s == '+');
    if (*digits < '0' || *digits > '9') return -1;
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (*end || errno || v < lo || v > hi) return -1;
    *out = v;
    return 0;
}

#endif
