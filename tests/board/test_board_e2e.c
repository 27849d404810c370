/* End to end: start `cbvh board-sim` on a fresh unix socket, run every unit
 * through --backend sim:ADDR and through the model on the same generated
 * inputs, require identical words, stop the board and check it cleaned up.
 * Usage: test_board_e2e PATH/TO/cbvh [vectors-per-config] */

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "link/backend.h"
#include "link/board_link.h"
#include "gen_inputs.h"

static pid_t board = -1;
static char dir[256] = "", sock_path[300] = "";

static void cleanup(void) {
    if (board > 0) {
        kill(board, SIGTERM);
        waitpid(board, NULL, 0);
        board = -1;
    }
    if (sock_path[0]) unlink(sock_path);
    if (dir[0]) rmdir(dir);
}

#define FAIL(...)                                                                                                      \
    do {                                                                                                               \
        fprintf(stderr, "FAIL: " __VA_ARGS__);                                                                         \
        fprintf(stderr, "\n");                                                                                         \
        cleanup();                                                                                                     \
        return 1;                                                                                                      \
    } while (0)

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s PATH/TO/cbvh [vectors-per-config]\n", argv[0]);
        return 2;
    }
    size_t per = argc > 2 ? (size_t)atol(argv[2]) : 2000;
    snprintf(dir, sizeof dir, "%s/cbvh-e2e-XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(dir)) {
        dir[0] = 0;
        FAIL("mkdtemp: %s", strerror(errno));
    }
    snprintf(sock_path, sizeof sock_path, "%s/board.sock", dir);
    char addr[320], spec[330];
    snprintf(addr, sizeof addr, "unix:%s", sock_path);
    snprintf(spec, sizeof spec, "sim:%s", addr);
    board = fork();
    if (board == 0) {
        prctl(PR_SET_PDEATHSIG, SIGTERM); /* no orphaned board if this test dies */
        int devnull = open("/dev/null", O_WRONLY);
        if (devnull >= 0) dup2(devnull, 1);
        execl(argv[1], argv[1], "board-sim", "--listen", addr, (char *)NULL);
        _exit(127);
    }
    cbvh_backend sim, model;
    char err[512];
    int opened = -1;
    for (int i = 0; i < 250 && opened != 0; i++) { /* up to 5 s for the board to come up */
        struct timespec ts = {0, 20000000L};
        nanosleep(&ts, NULL);
        if (access(sock_path, F_OK) == 0) opened = cbvh_backend_open(spec, &sim, NULL, err, sizeof err);
    }
    if (opened != 0) FAIL("could not open %s: %s", spec, err);
    if (cbvh_backend_open("model", &model, NULL, err, sizeof err)) FAIL("model: %s", err);
    printf("board: %s\n", sim.label);

    static const int ns[] = {3, 6, 7, 10};
    static const int mins[] = {-30, -126, 0};
    size_t total = 0;
    uint64_t rng = 12345;
    for (int u = 0; u < cbvh_unit_count; u++) {
        const cbvh_unit *unit = cbvh_units[u];
        for (size_t a = 0; a < sizeof ns / sizeof ns[0]; a++)
            for (size_t m = 0; m < sizeof mins / sizeof mins[0]; m++)
                for (int enc = 0; enc < (unit->uses_encoding ? 2 : 1); enc++) {
                    cbvh_unit_config cfg = {{ns[a], mins[m]}, enc ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO};
                    cbvh_layout lay;
                    unit->layout(&cfg, &lay);
                    uint32_t *in = malloc(per * (size_t)lay.n_in * 4);
                    uint32_t *o1 = malloc(per * (size_t)lay.n_out * 4), *o2 = malloc(per * (size_t)lay.n_out * 4);
                    if (!in || !o1 || !o2) FAIL("out of memory");
                    cbvh_gen_inputs(&rng, &cfg, &lay, in, per);
                    memset(o2, 0xA5, per * (size_t)lay.n_out * 4);
                    if (model.ops->run(&model, unit, &cfg, in, o1, per, err, sizeof err)) FAIL("model: %s", err);
                    if (sim.ops->run(&sim, unit, &cfg, in, o2, per, err, sizeof err)) FAIL("sim: %s", err);
                    for (size_t i = 0; i < per * (size_t)lay.n_out; i++)
                        if (o1[i] != o2[i])
                            FAIL("%s N=%d min=%d enc=%d vector %zu field %s: model %08x board %08x", unit->name,
                                 ns[a], mins[m], enc, i / (size_t)lay.n_out, lay.out[i % (size_t)lay.n_out].name,
                                 o1[i], o2[i]);
                    total += per;
                    free(in), free(o1), free(o2);
                }
    }
    cbvh_link *l = cbvh_backend_link(&sim);
    char line[512];
    cbvh_link_stats_line(&l->st, line, sizeof line);
    printf("%zu vectors identical on sim and model; link: %s\n", total, line);
    if (l->st.retries || l->st.failures) FAIL("clean link needed retries");
    cbvh_backend_close(&sim);
    cbvh_backend_close(&model);

    kill(board, SIGTERM);
    int status = 0;
    waitpid(board, &status, 0);
    board = -1;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) FAIL("board-sim did not exit cleanly (status %d)", status);
    if (access(sock_path, F_OK) == 0) FAIL("board-sim left its socket behind");
    sock_path[0] = 0;
    cleanup();
    return 0;
}
