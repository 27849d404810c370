/* Subcommands of the cbvh tool: one file each (cmd_<name>.c).  Each takes
 * argc/argv starting at its own name, handles --help, and returns the process
 * exit status. */
#ifndef CBVH_HOST_COMMANDS_H
#define CBVH_HOST_COMMANDS_H

#include <math.h>
#include <stdio.h>

int cmd_vectors(int argc, char **argv); /* cmd_vectors.c: gen | check */
int cmd_run(int argc, char **argv);     /* cmd_run.c: the main job */

int cmd_devices(int argc, char **argv);   /* cmd_devices.c: boards per backend */
int cmd_board_sim(int argc, char **argv); /* cmd_board_sim.c: the virtual board */
int cmd_study(int argc, char **argv);     /* cmd_study.c: backtracking/memory-traffic study (issue 3) */
int cmd_trace(int argc, char **argv);     /* cmd_trace.c: trace the effects a scene file calls for (issue 4) */
int cmd_sweep(int argc, char **argv);     /* cmd_sweep.c: accuracy vs time over N x M x min scale (issue 4) */

/* getopt_long reported an unknown option or a missing value (call with
 * opterr = 0): one line naming it, instead of getopt's own message (which
 * names the subcommand as if it were the program) and the whole usage. */
int cbvh_bad_option(const char *cmd, char **argv, int optind_now); /* main.c; returns 2 */

/* A cost a relative to the float BVH's b.  Where the float BVH did none
 * (b = 0): NaN when neither did (0/0 is no ratio, not 1), infinity when only
 * a did some.  run, trace and sweep print and chart ratios through this. */
static inline double cbvh_ratio(double a, double b) { return b > 0 ? a / b : a > 0 ? INFINITY : NAN; }

/* A ratio column: " x1.234" (prec decimals), else "-" (NaN) or "x inf"
 * right-aligned to the same width. */
static inline void cbvh_print_x(double r, int prec) {
    if (isfinite(r))
        printf(" x%.*f", prec, r);
    else
        printf(" %*s", prec + 3, isnan(r) ? "-" : "x inf");
}

/* JSON must be UTF-8, but file names are bytes: a byte that does not belong
 * to a well-formed UTF-8 sequence (RFC 3629: no overlong forms, surrogates or
 * code points past U+10FFFF) is written as \u00XX, the character of the same
 * value (the byte read as Latin-1), so the name stays recognisable. */

/* Length (1..4) of the well-formed UTF-8 sequence starting at s, 0 if none. */
static inline int cbvh_utf8_len(const unsigned char *s) {
    unsigned c = s[0];
    if (c < 0x80) return 1;
    int n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    if (!n) return 0;
    /* the second byte's range excludes overlong forms, surrogates and > U+10FFFF */
    unsigned lo = c == 0xE0 ? 0xA0 : c == 0xF0 ? 0x90 : 0x80, hi = c == 0xED ? 0x9F : c == 0xF4 ? 0x8F : 0xBF;
    if (s[1] < lo || s[1] > hi) return 0;
    for (int i = 2; i < n; i++)
        if ((s[i] & 0xC0) != 0x80) return 0;
    return n;
}

/* Writes JSON text (cJSON_Print output: it escapes quotes and control bytes
 * but passes other bytes through unchecked) with every byte outside
 * well-formed UTF-8 as \u00XX.  Such bytes can only sit inside strings. */
static inline void cbvh_json_fputs_utf8(const char *s, FILE *f) {
    const unsigned char *p = (const unsigned char *)s;
    while (*p) {
        int n = cbvh_utf8_len(p);
        if (n)
            fwrite(p, 1, (size_t)n, f);
        else
            fprintf(f, "\\u%04x", *p);
        p += n ? n : 1;
    }
}

/* Prints a --json document to stdout (indented if pretty, else on one line)
 * through cbvh_json_fputs_utf8, then a newline, and deletes it; out of
 * memory is reported as `what` (cbvh/oom.h).  cli/json_print.c. */
struct cJSON;
void cbvh_json_print(struct cJSON *root, int pretty, const char *what);

/* A JSON string literal of s: quotes, backslashes and control bytes escaped,
 * bytes outside well-formed UTF-8 as \u00XX. */
static inline void cbvh_json_str(const char *s, FILE *f) {
    const unsigned char *p = (const unsigned char *)s;
    fputc('"', f);
    while (*p) {
        int n = cbvh_utf8_len(p);
        if (*p == '"' || *p == '\\')
            fprintf(f, "\\%c", *p);
        else if (*p < 0x20 || !n)
            fprintf(f, "\\u%04x", *p);
        else
            fwrite(p, 1, (size_t)n, f);
        p += n ? n : 1;
    }
    fputc('"', f);
}

#endif
