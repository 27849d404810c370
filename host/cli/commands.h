/* Subcommands of the cbvh tool: one file each (cmd_<name>.c).  Each takes
 * argc/argv starting at its own name, handles --help, and returns the process
 * exit status. */
#ifndef CBVH_HOST_COMMANDS_H
#define CBVH_HOST_COMMANDS_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cbvh/format.h"
#include "cbvh/ray_box_incr.h"
#include "util/json.h" /* the --json writer and its UTF-8 rule */

int cmd_vectors(int argc, char **argv); /* cmd_vectors.c: gen | check */
int cmd_run(int argc, char **argv);     /* cmd_run.c: the main job */

int cmd_devices(int argc, char **argv);   /* cmd_devices.c: boards per backend */
int cmd_board_sim(int argc, char **argv); /* cmd_board_sim.c: the virtual board */
int cmd_study(int argc, char **argv);     /* cmd_study.c: backtracking/memory-traffic study (docs/study.md) */
int cmd_trace(int argc, char **argv);     /* cmd_trace.c: trace the effects a scene file calls for (docs/scenes.md) */
int cmd_sweep(int argc, char **argv);     /* cmd_sweep.c: accuracy vs time over N x M x min scale (docs/sweep.md) */

/* getopt_long reported an unknown option or a missing value (call with
 * opterr = 0): one line naming it, instead of getopt's own message (which
 * names the subcommand as if it were the program) and the whole usage. */
int cbvh_bad_option(const char *cmd, char **argv, int optind_now); /* main.c; returns 2 */
/* The same for a command that names a missing value itself (getopt_long's
 * ':' with a leading ':' in the option string): "CMD: unknown option 'X'
 * (see CMD --help)". */
int cbvh_unknown_option(const char *cmd, char **argv, int optind_now); /* main.c; returns 2 */

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

/* --box-unit of trace and sweep: "exact", "incremental" or "incremental:X"
 * (X in 3..8) into *unit (CBVH_FORMAT_BOX_*) and *texp (X, 8 unless given);
 * 0, or -1 after a one-line message naming CMD. */
static inline int cbvh_parse_box_unit(const char *cmd, const char *v, int *unit, int *texp) {
    *texp = CBVH_RBI_TEXP_DEFAULT;
    if (v && strcmp(v, "exact") == 0) {
        *unit = CBVH_FORMAT_BOX_EXACT;
        return 0;
    }
    if (v && strncmp(v, "incremental", 11) == 0 &&
        (v[11] == 0 || (v[11] == ':' && v[12] >= '0' + CBVH_RBI_TEXP_MIN && v[12] <= '0' + CBVH_RBI_TEXP_MAX &&
                        v[13] == 0))) {
        *unit = CBVH_FORMAT_BOX_INCREMENTAL;
        if (v[11] == ':') *texp = v[12] - '0';
        return 0;
    }
    fprintf(stderr, "%s: --box-unit expects exact, incremental or incremental:X (X in %d..%d), got '%s'\n", cmd,
            CBVH_RBI_TEXP_MIN, CBVH_RBI_TEXP_MAX, v ? v : "");
    return -1;
}

#endif
