/* Socket transport to the virtual board (`cbvh board-sim`): the board
 * protocol over a Unix or TCP stream socket.  Spec: "sim:unix:PATH",
 * "sim:tcp:HOST:PORT" or "sim:PATH". */
#include <errno.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "link/board_link.h"
#include "link/sim_addr.h"

typedef struct {
    cbvh_link link; /* first: see board_link.h */
    int fd;
    char addr[256];
    cbvh_link_fault *faults;
    cbvh_link_fault env_faults;
} sim_state;

static int sock_write(void *ctx, const uint8_t *buf, size_t n, char *err, size_t errlen) {
    sim_state *s = ctx;
    if (s->fd < 0 || cbvh_link_fault_send(s->faults, s->fd, buf, n) != 0) {
        snprintf(err, errlen, "connection to the virtual board at %s lost", s->addr);
        if (s->fd >= 0) close(s->fd);
        s->fd = -1;
        return -1;
    }
    return 0;
}

static long sock_read(void *ctx, uint8_t *buf, size_t cap, int timeout_ms, char *err, size_t errlen) {
    sim_state *s = ctx;
    if (s->fd < 0) return -1;
    struct pollfd p = {s->fd, POLLIN, 0};
    int r = poll(&p, 1, timeout_ms);
    if (r < 0) return errno == EINTR ? 0 : -1;
    if (r == 0) return 0;
    ssize_t n = recv(s->fd, buf, cap, 0);
    if (n > 0) return (long)n;
    if (n < 0 && errno == EINTR) return 0;
    snprintf(err, errlen, "virtual board at %s closed the connection", s->addr);
    close(s->fd);
    s->fd = -1;
    return -1;
}

static int sock_reopen(void *ctx, char *err, size_t errlen) {
    sim_state *s = ctx;
    if (s->fd >= 0) close(s->fd);
    s->fd = cbvh_sim_connect(s->addr, err, errlen);
    return s->fd < 0 ? -1 : 0;
}

/* The board closed the connection (it lets a host go that sent nothing for
 * its --host-idle-ms): the next request reconnects first. */
static int sock_hung_up(void *ctx) {
    sim_state *s = ctx;
    if (s->fd < 0) return 1;
    struct pollfd p = {s->fd, POLLRDHUP, 0};
    return poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR));
}

/* A wrong address is reported as such, not as "no board (start one with
 * ...)" with a hint that would fail the same way. */
static int sim_check_arg(const char *arg, char *err, size_t errlen) {
    if (!arg || !*arg) {
        snprintf(err, errlen, "sim backend needs an address: sim:unix:PATH or sim:tcp:HOST:PORT");
        return CBVH_BACKEND_BAD_INPUT;
    }
    return cbvh_sim_addr_check(arg, err, errlen) ? CBVH_BACKEND_BAD_INPUT : 0;
}

static int sim_open(cbvh_backend *b, const char *arg, char *err, size_t errlen) {
    int bad = sim_check_arg(arg, err, errlen);
    if (bad) return bad;
    sim_state *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return CBVH_BACKEND_ERROR;
    }
    cbvh_link_io io = {s, sock_write, sock_read, sock_reopen, sock_hung_up};
    cbvh_link_init(&s->link, &io);
    if (cbvh_link_env_options(&s->link, err, errlen)) {
        free(s);
        return CBVH_BACKEND_BAD_INPUT;
    }
    snprintf(s->addr, sizeof s->addr, "%s", arg);
    const char *fs = getenv("CBVH_LINK_FAULTS");
    if (fs && *fs) {
        char why[160];
        if (cbvh_link_fault_parse(&s->env_faults, fs, why, sizeof why)) {
            snprintf(err, errlen, "CBVH_LINK_FAULTS: %s", why);
            free(s);
            return CBVH_BACKEND_BAD_INPUT;
        }
        s->faults = &s->env_faults;
    }
    char why[200];
    s->fd = cbvh_sim_connect(s->addr, why, sizeof why);
    if (s->fd < 0) {
        int bad_addr = s->fd == CBVH_SIM_BAD_ADDR; /* e.g. a host name that does not resolve */
        if (bad_addr)
            snprintf(err, errlen, "bad board address: %s", why);
        else
            snprintf(err, errlen, "no virtual board: %s (start one with `cbvh board-sim --listen %s`)", why, s->addr);
        free(s);
        return bad_addr ? CBVH_BACKEND_BAD_INPUT : CBVH_BACKEND_NONE;
    }
    cbvh_link_flush(&s->link, 5);
    if (cbvh_link_identify(&s->link, why, sizeof why)) {
        snprintf(err, errlen, "virtual board at %s: %s", s->addr, why);
        if (s->fd >= 0) close(s->fd);
        free(s);
        return CBVH_BACKEND_ERROR;
    }
    const cbvh_identity *id = &s->link.ident;
    snprintf(b->label, sizeof b->label, "sim %.100s (%s fw %u.%u.%u, datapath v%u)", s->addr, id->board_name, id->fw_major,
             id->fw_minor, id->fw_patch, (unsigned)id->datapath_version);
    b->state = s;
    return CBVH_BACKEND_OK;
}

static void sim_close(cbvh_backend *b) {
    sim_state *s = b->state;
    if (!s) return;
    if (s->fd >= 0) close(s->fd);
    free(s);
    b->state = NULL;
}

static int sim_run(cbvh_backend *b, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in,
                   uint32_t *out, size_t count, char *err, size_t errlen) {
    sim_state *s = b->state;
    if (!s) {
        snprintf(err, errlen, "sim backend not open");
        return CBVH_BACKEND_ERROR;
    }
    return cbvh_link_run(&s->link, unit, cfg, in, out, count, err, errlen) ? CBVH_BACKEND_ERROR : CBVH_BACKEND_OK;
}

/* The board at arg, as `--backend sim:ARG` would open it. */
static int sim_list(const char *arg, FILE *out) {
    if (!arg || !*arg) {
        cbvh_backend_list_line(out, &cbvh_backend_sim,
                               "not probed (give --sim ADDR or CBVH_SIM_ADDR; start one with `cbvh board-sim`)");
        return 0;
    }
    cbvh_backend b;
    memset(&b, 0, sizeof b);
    b.ops = &cbvh_backend_sim;
    char err[300];
    if (sim_open(&b, arg, err, sizeof err) != CBVH_BACKEND_OK) {
        cbvh_backend_list_line(out, &cbvh_backend_sim, "none (%s)", err);
        return 0;
    }
    const cbvh_identity *id = &((sim_state *)b.state)->link.ident;
    cbvh_backend_list_line(out, &cbvh_backend_sim, "%s, units 0x%08x, max payload %u", b.label, (unsigned)id->units,
                           id->max_payload);
    sim_close(&b);
    return 1;
}

const cbvh_backend_ops cbvh_backend_sim = {"sim", sim_check_arg, sim_open, sim_close, sim_run, sim_list};

void cbvh_sim_set_faults(cbvh_backend *b, cbvh_link_fault *f) {
    if (b->ops == &cbvh_backend_sim && b->state) ((sim_state *)b->state)->faults = f;
}

cbvh_link *cbvh_backend_link(cbvh_backend *b) {
    if (!b->ops || !b->state) return NULL;
    if (b->ops == &cbvh_backend_sim || b->ops == &cbvh_backend_usb || b->ops == &cbvh_backend_hid)
        return (cbvh_link *)b->state;
    return NULL;
}

void cbvh_link_stats_line(const cbvh_link_stats *s, char *buf, size_t n) {
    snprintf(buf, n,
             "requests %llu, attempts %llu, ok %llu, retries %llu, timeouts %llu, crc %llu, sync %llu, stale %llu, "
             "board-reported %llu, link breaks %llu, reopens %llu, failures %llu",
             (unsigned long long)s->requests, (unsigned long long)s->attempts, (unsigned long long)s->replies_ok,
             (unsigned long long)s->retries, (unsigned long long)s->timeouts, (unsigned long long)s->crc_errors,
             (unsigned long long)s->sync_errors, (unsigned long long)s->stale_replies,
             (unsigned long long)s->link_errors_reported, (unsigned long long)s->link_breaks,
             (unsigned long long)s->reopens, (unsigned long long)s->failures);
}
