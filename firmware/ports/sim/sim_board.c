/* The virtual board: the firmware core behind a socket (one connection at a
 * time), with the model-backed register map or the simulated gateware as its
 * FPGA. */
#define _GNU_SOURCE
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <time.h>
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

enum { POLL_MS = 10 }; /* how often the timers are checked */

static long now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long)ts.tv_sec * 1000L + ts.tv_nsec / 1000000L;
}

/* Another host while one is served: told so at once (docs/protocol.md, error
 * code busy), then let go.  The refusal is out of band: no request is read
 * and the reply fault injector is not applied. */
static void refuse_busy(int listen_fd, int verbose) {
    int fd = accept4(listen_fd, NULL, NULL, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) return;
    uint8_t frame[CBVH_FRAME_HDR + CBVH_FRAME_CRC];
    cbvh_send_all(fd, frame, cbvh_frame_seal(frame, CBVH_REPLY, CBVH_E_BUSY, 0, 0));
    shutdown(fd, SHUT_WR);
    /* Read what the host has already sent: closing a socket with unread
     * bytes resets the connection, which may discard the refusal. */
    uint8_t sink[1024];
    for (int i = 0; i < 16 && recv(fd, sink, sizeof sink, 0) > 0; i++) {}
    close(fd);
    if (verbose) fprintf(stderr, "cbvh board-sim: another host refused (busy)\n");
}

/* Whether the host has closed its end (its last bytes may still be unread).
 * A host that reconnects closes before it connects again, so when its new
 * connection is pending this already says so: it is not "another host". */
static int host_gone(int fd) {
    struct pollfd p = {fd, POLLRDHUP, 0};
    return poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR));
}

/* Runs the firmware on one host's connection until it closes, breaks, stays
 * silent for host_idle_ms, or *stop.  0, or -1 when the gateware failed. */
static int serve_host(const cbvh_sim_board_opts *o, sim_board *board, cbvh_fw *fw) {
    int fd = board->conn.fd;
    long last = now_ms(); /* the last bytes from the host, once answered */
    while (!*o->stop && !board->conn.broken) {
        struct pollfd p[2] = {{fd, POLLIN, 0}, {o->listen_fd, POLLIN, 0}};
        int pr = poll(p, 2, POLL_MS);
        if (pr < 0 && errno != EINTR) break;
        if (pr > 0 && p[0].revents) { /* first: a host that has left frees the board for the next */
            uint8_t buf[8192];
            ssize_t n = recv(fd, buf, sizeof buf, 0);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            cbvh_fw_rx(fw, buf, (size_t)n);
            last = now_ms();
            if (board->gateware && cbvh_gateware_error(board->gateware)) return -1;
        }
        if (pr > 0 && (p[1].revents & POLLIN) && !host_gone(fd)) refuse_busy(o->listen_fd, o->verbose);
        long quiet = now_ms() - last;
        if (cbvh_fw_rx_partial(fw) && quiet >= o->rx_idle_ms) cbvh_fw_rx_idle(fw);
        if (o->host_idle_ms > 0 && quiet >= o->host_idle_ms) {
            if (o->verbose) fprintf(stderr, "cbvh board-sim: host sent nothing for %ld ms, let go\n", quiet);
            break;
        }
    }
    return 0;
}

int cbvh_sim_board_serve(const cbvh_sim_board_opts *o) {
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
    while (!*o->stop && !rc) {
        struct pollfd pl = {o->listen_fd, POLLIN, 0};
        int pr = poll(&pl, 1, POLL_MS);
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
        rc = serve_host(o, board, fw);
        close(fd);
        if (o->verbose) fprintf(stderr, "cbvh board-sim: host disconnected\n");
    }
    /* A stop that abandoned a gateware transaction (even the reset at start)
     * is a failure, not a clean stop. */
    if (board->gateware && cbvh_gateware_error(board->gateware)) rc = -1;
    free(board);
    free(fw);
    return rc;
}
