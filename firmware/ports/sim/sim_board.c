/* The virtual board: the firmware core behind a socket (one connection at a
 * time), with the model-backed register map or the simulated gateware as its
 * FPGA. */
#define _GNU_SOURCE
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include "cbvh_sim.h"
#include "link/link_fault.h"

/* HAL send for the socket: a failed send or injected disconnect marks the
 * connection as gone; the serve loop then closes it. */
typedef struct {
    int fd;
    int broken;
    cbvh_link_fault *faults;
} sim_conn;

typedef struct {
    cbvh_regmap_model regs;
    cbvh_gateware *gateware;
    sim_conn conn;
} sim_board;

static uint32_t hal_read(void *ctx, uint32_t addr) {
    sim_board *b = ctx;
    return b->gateware ? cbvh_gateware_read(b->gateware, addr) : cbvh_regmap_model_read(&b->regs, addr);
}
static void hal_write(void *ctx, uint32_t addr, uint32_t v) {
    sim_board *b = ctx;
    if (b->gateware) cbvh_gateware_write(b->gateware, addr, v);
    else cbvh_regmap_model_write(&b->regs, addr, v);
}
static void hal_send(void *ctx, const uint8_t *frame, size_t len) {
    sim_conn *c = &((sim_board *)ctx)->conn;
    if (c->broken) return;
    if (cbvh_link_fault_send(c->faults, c->fd, frame, len) != 0) c->broken = 1;
}

int cbvh_sim_board_serve(const cbvh_sim_board_opts *o) {
    static const int poll_ms = 10;
    sim_board *board = calloc(1, sizeof *board);
    cbvh_fw *fw = calloc(1, sizeof *fw);
    if (!board || !fw) {
        free(board);
        free(fw);
        return -1;
    }
    cbvh_regmap_model_init(&board->regs);
    board->regs.broken_unit = o->broken_unit;
    board->gateware = o->gateware;
    if (o->gateware) cbvh_gateware_watch_stop(o->gateware, o->stop);
    cbvh_fw_hal hal = {board, hal_read, hal_write, hal_send, "cbvh-sim"};
    cbvh_fw_init(fw, &hal);
    int rc = 0;
    while (!*o->stop) {
        struct pollfd pl = {o->listen_fd, POLLIN, 0};
        int pr = poll(&pl, 1, poll_ms);
        if (pr < 0 && errno != EINTR) {
            rc = -1;
            break;
        }
        if (pr <= 0) continue;
        int fd = accept4(o->listen_fd, NULL, NULL, SOCK_CLOEXEC);
        if (fd < 0) continue;
        board->conn.fd = fd;
        board->conn.broken = 0;
        board->conn.faults = o->faults;
        /* A new connection is a new USB session: stale partial frames go. */
        cbvh_parser_init(&fw->rx);
        if (o->verbose) fprintf(stderr, "cbvh board-sim: host connected\n");
        int idle_ms = 0;
        while (!*o->stop && !board->conn.broken) {
            struct pollfd pc = {fd, POLLIN, 0};
            pr = poll(&pc, 1, poll_ms);
            if (pr < 0 && errno != EINTR) break;
            if (pr <= 0) {
                idle_ms += poll_ms;
                if (cbvh_fw_rx_partial(fw) && idle_ms >= o->rx_idle_ms) cbvh_fw_rx_idle(fw);
                continue;
            }
            uint8_t buf[8192];
            ssize_t n = recv(fd, buf, sizeof buf, 0);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            idle_ms = 0;
            cbvh_fw_rx(fw, buf, (size_t)n);
            if (board->gateware && cbvh_gateware_error(board->gateware)) {
                rc = -1;
                break;
            }
        }
        close(fd);
        if (o->verbose) fprintf(stderr, "cbvh board-sim: host disconnected\n");
        if (rc) break;
    }
    /* A stop that abandoned a gateware transaction (even the reset at start)
     * is a failure, not a clean stop. */
    if (board->gateware && cbvh_gateware_error(board->gateware)) rc = -1;
    free(board);
    free(fw);
    return rc;
}
