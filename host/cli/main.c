/* cbvh: host tool of the low-precision ray-tracing accelerator kit. */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/oom.h"
#include "cli/commands.h"

typedef struct {
    const char *name;
    int (*fn)(int, char **);
    const char *summary;
} command;

static const command commands[] = {
    {"run", cmd_run, "the main job: check the golden vectors, then an accuracy-vs-time table"},
    {"vectors", cmd_vectors, "generate (gen) or check (check) golden test vectors"},
    {"devices", cmd_devices, "list boards per backend (usb, hid, sim) and why none"},
    {"board-sim", cmd_board_sim, "run the virtual board (firmware sim port) on a socket"},
    {"study", cmd_study, "backtracking, memory-traffic and min-scale study of streaming CBVH builds"},
    {"trace", cmd_trace, "trace the rays a scene file's effects call for; cost per effect and timing model"},
    {"sweep", cmd_sweep, "accuracy vs time: cost per precision setting vs the float BVH, same-hits proof, charts"},
};

static void usage(FILE *f) {
    fprintf(f, "usage: cbvh <command> [options]   (cbvh <command> --help for each)\n\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(f, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "\noptions:\n  %-10s %s\n  %-10s %s\n", "--help", "this list", "--version", "print the version");
}

int cbvh_bad_option(const char *cmd, char **argv, int optind_now) {
    const char *arg = optind_now > 0 ? argv[optind_now - 1] : "";
    fprintf(stderr, "%s: unknown option or missing value: '%s' (see %s --help)\n", cmd, arg, cmd);
    return 2;
}

int cbvh_unknown_option(const char *cmd, char **argv, int optind_now) {
    fprintf(stderr, "%s: unknown option '%s' (see %s --help)\n", cmd, optind_now > 0 ? argv[optind_now - 1] : "", cmd);
    return 2;
}

/* Results go to stdout, often redirected: a full disk or a closed pipe must
 * not pass as success with the table or JSON lost.  Exit 2 unless the command
 * already failed.  (SIGPIPE is ignored, so a closed pipe is a write error
 * here too, not a silent death; stdio keeps the unwritten bytes, so the
 * fclose retries them and errno names the cause.) */
static int finish_stdout(int rc) {
    errno = 0;
    int bad = ferror(stdout);
    if (fclose(stdout) != 0) bad = 1;
    if (bad) {
        fprintf(stderr, "cbvh: cannot write the output to standard output: %s\n",
                errno ? strerror(errno) : "write error");
        return rc ? rc : 2;
    }
    return rc;
}

/* Out of memory deep in a builder (cbvh/oom.h) is a resource failure like
 * any other: one line and exit status 2, not an abort.  exit, not _exit: the
 * results printed so far are flushed; files in progress are temp names that
 * are only renamed when complete, so nothing half-written looks finished. */
static void on_out_of_memory(const char *what) {
    fprintf(stderr, "cbvh: out of memory (%s)\n", what);
    exit(2);
}

int main(int argc, char **argv) {
    cbvh_set_oom_handler(on_out_of_memory);
    signal(SIGPIPE, SIG_IGN); /* a closed pipe: EPIPE, reported by finish_stdout */
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return finish_stdout(0);
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("cbvh %s\n", CBVH_VERSION);
        return finish_stdout(0);
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(argv[1], commands[i].name) == 0) return finish_stdout(commands[i].fn(argc - 1, argv + 1));
    fprintf(stderr, "cbvh: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return 2;
}
