/* `cbvh board-sim` serves one host at a time (docs/protocol.md, "Virtual
 * board"); the board runs as its own process, as a user starts it.
 *   busy: while one host is connected (here one that connects and sends
 *     nothing), another is refused at once with "busy: another host is
 *     connected": the backend's open, `cbvh vectors check` (one line, exit 2)
 *     and `cbvh devices` say so well within one link timeout, not after nine
 *     attempts of "no reply"; once the first host goes, the next is served.
 *   idle: a host that sends nothing for --host-idle-ms is disconnected, so
 *     the board is free for the next one; a host that was only idle gets a
 *     new connection without noticing (even with no retries allowed), unless
 *     another host took the board meanwhile: then it is told so at once.
 *   never: with --host-idle-ms 0 a silent host stays connected.
 * Usage: test_link_busy PATH/TO/cbvh VECTOR-FILE */
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "gen_inputs.h"
#include "link/board_link.h"
#include "link/sim_addr.h"
#include "test_util.h"

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stderr, c, __VA_ARGS__)

static const char *busy = "busy: another host is connected";
static const char *cbvh, *vec_file;
static char dir[256], sock_path[300], addr[320], spec[330], out_path[300], err_path[300], board_out[300];

static long now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long)ts.tv_sec * 1000L + ts.tv_nsec / 1000000L;
}

static void sleep_ms(long ms) {
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* Runs argv (argv[0] = cbvh) with stdout and stderr to files: exit status,
 * or -1 when it did not exit normally. */
static int run(const char *const *argv, long *took) {
    long t0 = now_ms();
    pid_t pid = fork();
    if (pid == 0) {
        int o = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0600), e = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (o < 0 || e < 0 || dup2(o, 1) < 0 || dup2(e, 2) < 0) _exit(127);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    int st = 0;
    waitpid(pid, &st, 0);
    *took = now_ms() - t0;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* The whole of a small output file. */
static const char *slurp(const char *path) {
    static char buf[4096];
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f) fclose(f);
    buf[n] = '\0';
    return buf;
}

static int count_lines(const char *s) {
    int n = 0;
    for (; *s; s++) n += *s == '\n';
    return n;
}

/* `cbvh board-sim --listen ADDR [extra]` in the background; its pid once it
 * says it listens (the socket file alone appears before listen()), or -1. */
static pid_t board_start(const char *extra_opt, const char *extra_val) {
    unlink(sock_path);
    unlink(board_out);
    pid_t pid = fork();
    if (pid == 0) {
        int o = open(board_out, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (o < 0 || dup2(o, 1) < 0) _exit(127);
        execl(cbvh, cbvh, "board-sim", "--listen", addr, extra_opt, extra_val, (char *)NULL);
        _exit(127);
    }
    for (int i = 0; i < 250; i++) {
        int status;
        if (strstr(slurp(board_out), "listening on")) return pid;
        if (waitpid(pid, &status, WNOHANG) == pid) {
            CHECK(0, "board-sim %s %s exited with %d before listening", extra_opt ? extra_opt : "",
                  extra_val ? extra_val : "", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
            return -1;
        }
        sleep_ms(20);
    }
    CHECK(0, "board-sim did not listen on %s within 5 s", sock_path);
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
    return -1;
}

static void board_stop(pid_t pid) {
    int st = 0;
    kill(pid, SIGTERM);
    waitpid(pid, &st, 0);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0, "board-sim stopped while idle should exit 0 (status %d)", st);
}

/* A host that connects and sends nothing. */
static int silent_host(void) {
    char err[256];
    int fd = cbvh_sim_connect(addr, err, sizeof err);
    CHECK(fd >= 0, "silent host: %s", err);
    sleep_ms(50); /* the board has taken it */
    return fd;
}

/* Whether the board has closed fd, waiting up to wait_ms. */
static int closed_by_board(int fd, int wait_ms) {
    struct pollfd p = {fd, POLLIN, 0};
    if (poll(&p, 1, wait_ms) <= 0) return 0;
    char c;
    return recv(fd, &c, 1, MSG_DONTWAIT) == 0;
}

/* A batch on the sim backend equals the model's. */
static uint32_t in[200 * 8], want[200 * 8], got[200 * 8];
static const cbvh_unit *unit;
static cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
static cbvh_layout lay;
enum { PER = 200 };

static int run_batch(cbvh_backend *b, char *err, size_t errlen) {
    memset(got, 0, sizeof got);
    int rc = b->ops->run(b, unit, &cfg, in, got, PER, err, errlen);
    CHECK(rc != 0 || memcmp(got, want, (size_t)PER * (size_t)lay.n_out * 4) == 0, "words differ from the model");
    return rc;
}

/* A second host is refused at once, however it asks. */
static void refused_cases(const char *when) {
    cbvh_backend b;
    char err[512] = "";
    long t0 = now_ms();
    int rc = cbvh_backend_open(spec, &b, NULL, err, sizeof err);
    long took = now_ms() - t0;
    CHECK(rc != 0 && strstr(err, busy) && !strchr(err, '\n') && took < 900,
          "%s: second host's open: rc %d after %ld ms (want busy within 900 ms): '%s'", when, rc, took, err);
    if (rc == 0) cbvh_backend_close(&b);
    printf("%s: open refused in %ld ms: %s\n", when, took, err);

    const char *check[] = {cbvh, "vectors", "check", "--backend", spec, vec_file, NULL};
    rc = run(check, &took);
    const char *e = slurp(err_path);
    CHECK(rc == 2 && count_lines(e) == 1 && strstr(e, busy) && took < 900,
          "%s: vectors check: exit %d after %ld ms (want 2 within 900 ms, one line with '%s'): %s", when, rc, took,
          busy, e);
    const char *devices[] = {cbvh, "devices", "--sim", addr, NULL};
    rc = run(devices, &took);
    const char *o = slurp(out_path);
    const char *sim = strstr(o, "sim:   none (");
    CHECK(rc == 0 && sim && strstr(sim, busy) && took < 900, "%s: devices: exit %d after %ld ms: %s", when, rc, took,
          o);
}

static void busy_cases(void) {
    pid_t board = board_start(NULL, NULL);
    if (board < 0) return;
    int quiet = silent_host();
    refused_cases("busy");
    /* the silent host leaves: the next host is served */
    close(quiet);
    cbvh_backend b;
    char err[512] = "";
    if (cbvh_backend_open(spec, &b, NULL, err, sizeof err) == 0) {
        CHECK(run_batch(&b, err, sizeof err) == 0, "after the first host left: %s", err);
        cbvh_backend_close(&b);
    } else {
        CHECK(0, "after the first host left, open failed: %s", err);
    }
    board_stop(board);
}

static void idle_cases(void) {
    pid_t board = board_start("--host-idle-ms", "600");
    if (board < 0) return;
    /* a silent host is let go after 600 ms */
    long t0 = now_ms();
    int quiet = silent_host();
    int closed = closed_by_board(quiet, 3000);
    long took = now_ms() - t0;
    CHECK(closed && took >= 550 && took < 2000, "silent host: closed %d after %ld ms (want after about 600 ms)", closed,
          took);
    close(quiet);
    printf("idle: a silent host was disconnected after %ld ms\n", took);

    cbvh_backend b;
    char err[512] = "";
    if (cbvh_backend_open(spec, &b, NULL, err, sizeof err) != 0) {
        CHECK(0, "the board should be free once the silent host is gone: %s", err);
        board_stop(board);
        return;
    }
    cbvh_link *l = cbvh_backend_link(&b);
    CHECK(run_batch(&b, err, sizeof err) == 0, "first batch: %s", err);
    /* only idle: reconnected without a retry */
    l->max_retries = 0;
    sleep_ms(900);
    uint64_t reopens = l->st.reopens;
    int rc = run_batch(&b, err, sizeof err);
    CHECK(rc == 0 && l->st.reopens == reopens + 1, "idle host's next batch: rc %d, reopens %llu -> %llu: %s", rc,
          (unsigned long long)reopens, (unsigned long long)l->st.reopens, err);
    /* idle, and another host took the board: told at once */
    sleep_ms(900);
    quiet = silent_host();
    l->max_retries = CBVH_LINK_RETRIES_DEFAULT;
    t0 = now_ms();
    rc = run_batch(&b, err, sizeof err);
    took = now_ms() - t0;
    CHECK(rc != 0 && strstr(err, busy) && strstr(err, "not run") && took < 900,
          "board taken while idle: rc %d after %ld ms (want busy within 900 ms): '%s'", rc, took, err);
    printf("idle: board taken meanwhile, told in %ld ms: %s\n", took, err);
    close(quiet);
    cbvh_backend_close(&b);
    board_stop(board);
}

static void never_cases(void) {
    pid_t board = board_start("--host-idle-ms", "0");
    if (board < 0) return;
    int quiet = silent_host();
    CHECK(!closed_by_board(quiet, 1200), "--host-idle-ms 0: a silent host was disconnected");
    refused_cases("never");
    close(quiet);
    board_stop(board);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: test_link_busy PATH/TO/cbvh VECTOR-FILE\n");
        return 2;
    }
    cbvh = argv[1];
    vec_file = argv[2];
    signal(SIGPIPE, SIG_IGN);
    unsetenv("CBVH_LINK_TIMEOUT_MS");
    unsetenv("CBVH_LINK_RETRIES");
    unsetenv("CBVH_LINK_FAULTS");
    snprintf(dir, sizeof dir, "%s/cbvh-busy-XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(sock_path, sizeof sock_path, "%s/b.sock", dir);
    snprintf(addr, sizeof addr, "unix:%s", sock_path);
    snprintf(spec, sizeof spec, "sim:%s", addr);
    snprintf(out_path, sizeof out_path, "%s/out", dir);
    snprintf(err_path, sizeof err_path, "%s/err", dir);
    snprintf(board_out, sizeof board_out, "%s/board.out", dir);

    unit = cbvh_unit_find("axis_compress");
    unit->layout(&cfg, &lay);
    uint64_t rng = 777;
    cbvh_gen_inputs(&rng, &cfg, &lay, in, PER);
    cbvh_backend model;
    char err[256];
    if (cbvh_backend_open("model", &model, NULL, err, sizeof err) || model.ops->run(&model, unit, &cfg, in, want, PER, err,
                                                                                     sizeof err)) {
        fprintf(stderr, "model: %s\n", err);
        return 1;
    }
    cbvh_backend_close(&model);

    busy_cases();
    idle_cases();
    never_cases();

    unlink(sock_path);
    unlink(out_path);
    unlink(err_path);
    unlink(board_out);
    rmdir(dir);
    if (fails) fprintf(stderr, "%d failures\n", fails);
    else printf("board-sim: a second host is refused at once, a silent one let go after --host-idle-ms\n");
    return fails ? 1 : 0;
}
