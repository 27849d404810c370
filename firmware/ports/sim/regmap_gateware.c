/* The FPGA register map as simulated RTL: each register access becomes the
 * SPI transaction the RP2040 port would clock out (cbvh_fw/spi_wire.h), sent
 * to an Icarus simulation of the board top (gateware/tb/tb_board_link.v) on
 * its stdin; the simulation answers with the MISO bytes on its stdout as one
 * line "@ b0 b1 ...".  Other lines it prints go to stderr.  The simulation
 * runs for the bridge's lifetime, as an FPGA stays configured. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cbvh_fw/spi_wire.h"
#include "cbvh_sim.h"

/* A ray-box test with its STATUS polls is a few hundred microseconds of
 * simulated time; a reply this late means the simulation hangs. */
#define REPLY_TIMEOUT_MS 30000
/* How often a wait for the simulation looks at the stop flag (SIGINT/SIGTERM). */
#define STOP_CHECK_MS 50

struct cbvh_gateware {
    pid_t pid;
    int to_sim, from_sim;
    char buf[4096];
    size_t have;
    char err[256];
    uint32_t unit_sel;
    int broken_unit;
    uint64_t transactions;
    volatile int *stop; /* non-zero: abandon the transaction in progress */
    int abandoned;      /* a transaction was cut short: the simulation is in an unknown state */
};

static void fail(cbvh_gateware *g, const char *fmt, ...) {
    if (g->err[0]) return; /* the first failure is the one to report */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g->err, sizeof g->err, fmt, ap);
    va_end(ap);
}

const char *cbvh_gateware_error(const cbvh_gateware *g) { return g->err[0] ? g->err : NULL; }

/* An Icarus program is a vvp script ("#! /usr/bin/vvp"), run by vvp -n (a
 * signal then finishes it instead of opening its prompt); anything else, e.g.
 * a Verilator --binary build, runs as it is. */
static int is_vvp_script(const char *program) {
    char head[64] = {0};
    FILE *pf = fopen(program, "r");
    if (pf) {
        if (!fgets(head, sizeof head, pf)) head[0] = 0;
        fclose(pf);
    }
    return strncmp(head, "#!", 2) == 0 && strstr(head, "vvp") != NULL;
}

int cbvh_gateware_check(const char *program, char *err, size_t errlen) {
    struct stat st;
    if (access(program, R_OK) != 0 || stat(program, &st) != 0) {
        snprintf(err, errlen, "cannot read '%s': %s (build it with gateware/scripts/build-board-sim)", program,
                 strerror(errno));
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "'%s' is not a file (build one with gateware/scripts/build-board-sim)", program);
        return -1;
    }
    if (!is_vvp_script(program) && access(program, X_OK) != 0) {
        snprintf(err, errlen, "'%s' is neither a vvp script nor executable (build one with "
                              "gateware/scripts/build-board-sim)", program);
        return -1;
    }
    return 0;
}

cbvh_gateware *cbvh_gateware_start(const char *program, int broken_unit, char *err, size_t errlen) {
    int in_pipe[2], out_pipe[2];
    if (pipe2(in_pipe, O_CLOEXEC) != 0) {
        snprintf(err, errlen, "pipe: %s", strerror(errno));
        return NULL;
    }
    if (pipe2(out_pipe, O_CLOEXEC) != 0) {
        snprintf(err, errlen, "pipe: %s", strerror(errno));
        close(in_pipe[0]);
        close(in_pipe[1]);
        return NULL;
    }
    /* An exec failure is reported through this pipe: a closed, empty pipe
     * means vvp started. */
    int exec_pipe[2];
    if (pipe2(exec_pipe, O_CLOEXEC) != 0) {
        snprintf(err, errlen, "pipe: %s", strerror(errno));
        for (int i = 0; i < 2; i++) close(in_pipe[i]), close(out_pipe[i]);
        return NULL;
    }
    int is_vvp = is_vvp_script(program);
    pid_t pid = fork();
    if (pid == 0) {
        setpgid(0, 0); /* the terminal's Ctrl-C stops board-sim, which stops the simulation */
        dup2(in_pipe[0], 0);
        dup2(out_pipe[1], 1);
        if (is_vvp) execlp("vvp", "vvp", "-n", program, (char *)NULL);
        else execl(program, program, (char *)NULL);
        int e = errno;
        ssize_t w = write(exec_pipe[1], &e, sizeof e);
        (void)w;
        _exit(127);
    }
    close(in_pipe[0]);
    close(out_pipe[1]);
    close(exec_pipe[1]);
    int child_errno = 0;
    ssize_t got = pid > 0 ? read(exec_pipe[0], &child_errno, sizeof child_errno) : -1;
    close(exec_pipe[0]);
    if (pid < 0 || got != 0) {
        snprintf(err, errlen, "cannot run %s: %s", is_vvp ? "vvp (Icarus Verilog, apt-get install iverilog)" : program,
                 strerror(pid < 0 ? errno : child_errno));
        close(in_pipe[1]);
        close(out_pipe[0]);
        if (pid > 0) waitpid(pid, NULL, 0);
        return NULL;
    }
    cbvh_gateware *g = calloc(1, sizeof *g);
    if (!g) {
        snprintf(err, errlen, "out of memory");
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        close(in_pipe[1]);
        close(out_pipe[0]);
        return NULL;
    }
    g->pid = pid;
    g->to_sim = in_pipe[1];
    g->from_sim = out_pipe[0];
    g->broken_unit = broken_unit;
    return g;
}

static long long now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

/* The simulation closed its end of a pipe: report how it ended, waiting up to
 * 1 s for it to exit (else the pipe error says what happened). */
static void report_end(cbvh_gateware *g, const char *pipe_error) {
    int st = 0, reaped = 0;
    for (int i = 0; i < 100 && !reaped; i++) {
        reaped = waitpid(g->pid, &st, WNOHANG) == g->pid;
        if (!reaped) usleep(10000);
    }
    if (!reaped) {
        fail(g, "gateware simulation: %s", pipe_error);
        return;
    }
    g->pid = -1;
    if (WIFEXITED(st)) fail(g, "gateware simulation ended (exit status %d)", WEXITSTATUS(st));
    else fail(g, "gateware simulation killed by signal %d", WIFSIGNALED(st) ? WTERMSIG(st) : 0);
}

/* The next "@ ..." line from the simulation, into line (NUL-terminated). */
static int read_reply(cbvh_gateware *g, char *line, size_t cap) {
    long long deadline = now_ms() + REPLY_TIMEOUT_MS;
    for (;;) {
        char *nl = memchr(g->buf, '\n', g->have);
        while (nl) {
            size_t len = (size_t)(nl - g->buf);
            int is_reply = len > 0 && g->buf[0] == '@';
            if (is_reply && len < cap) {
                memcpy(line, g->buf, len);
                line[len] = 0;
            } else if (!is_reply) {
                fprintf(stderr, "gateware: %.*s\n", (int)len, g->buf);
            }
            memmove(g->buf, nl + 1, g->have - len - 1);
            g->have -= len + 1;
            if (is_reply) {
                if (len >= cap) {
                    fail(g, "gateware simulation: reply line too long");
                    return -1;
                }
                return 0;
            }
            nl = memchr(g->buf, '\n', g->have);
        }
        if (g->have == sizeof g->buf) {
            fail(g, "gateware simulation: output line too long");
            return -1;
        }
        if (g->stop && *g->stop) {
            g->abandoned = 1;
            fail(g, "stopped by a signal while waiting for the gateware simulation to answer an SPI transaction "
                    "(transaction abandoned)");
            return -1;
        }
        long long left = deadline - now_ms();
        if (left <= 0) {
            fail(g, "gateware simulation did not answer an SPI transaction within %d s", REPLY_TIMEOUT_MS / 1000);
            return -1;
        }
        struct pollfd p = {g->from_sim, POLLIN, 0};
        int pr = poll(&p, 1, (int)(left < STOP_CHECK_MS ? left : STOP_CHECK_MS));
        if (pr < 0 && errno == EINTR) continue;
        if (pr <= 0) continue;
        ssize_t n = read(g->from_sim, g->buf + g->have, sizeof g->buf - g->have);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            report_end(g, n < 0 ? strerror(errno) : "it closed its output");
            return -1;
        }
        g->have += (size_t)n;
    }
}

/* One SPI transaction: out[0..n) clocked out, the MISO bytes into in. */
static int transaction(cbvh_gateware *g, const uint8_t *out, uint8_t *in, unsigned n) {
    if (g->err[0]) return -1;
    char req[64];
    int len = snprintf(req, sizeof req, "%u", n);
    for (unsigned i = 0; i < n; i++) len += snprintf(req + len, sizeof req - (size_t)len, " %02x", out[i]);
    req[len++] = '\n';
    for (int done = 0; done < len;) {
        ssize_t w = write(g->to_sim, req + done, (size_t)(len - done));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            char why[128];
            snprintf(why, sizeof why, "cannot send a transaction: %s", strerror(errno));
            report_end(g, why);
            return -1;
        }
        done += (int)w;
    }
    char line[128];
    if (read_reply(g, line, sizeof line)) return -1;
    const char *p = line + 1;
    for (unsigned i = 0; i < n; i++) {
        char *end;
        unsigned long b = strtoul(p, &end, 16);
        if (end == p || b > 0xFF) {
            fail(g, "gateware simulation: malformed reply '%s'", line);
            return -1;
        }
        in[i] = (uint8_t)b;
        p = end;
    }
    while (*p == ' ') p++;
    if (*p) {
        fail(g, "gateware simulation: malformed reply '%s'", line);
        return -1;
    }
    g->transactions++;
    return 0;
}

uint32_t cbvh_gateware_read(void *ctx, uint32_t addr) {
    cbvh_gateware *g = ctx;
    uint8_t out[CBVH_SPI_READ_BYTES], in[CBVH_SPI_READ_BYTES];
    cbvh_spi_read_bytes(addr, out);
    /* On a failed simulation every read says "busy, error", so the driver stops. */
    if (transaction(g, out, in, CBVH_SPI_READ_BYTES)) return CBVH_STAT_BUSY | CBVH_STAT_ERROR;
    uint32_t v = cbvh_spi_read_value(in);
    if (addr == CBVH_REG_OUT(0) && g->broken_unit && (int)g->unit_sel == g->broken_unit) v ^= 1u;
    return v;
}

void cbvh_gateware_write(void *ctx, uint32_t addr, uint32_t value) {
    cbvh_gateware *g = ctx;
    uint8_t out[CBVH_SPI_WRITE_BYTES], in[CBVH_SPI_WRITE_BYTES];
    cbvh_spi_write_bytes(addr, value, out);
    if (addr == CBVH_REG_UNIT_SEL) g->unit_sel = value;
    transaction(g, out, in, CBVH_SPI_WRITE_BYTES);
}

uint64_t cbvh_gateware_transactions(const cbvh_gateware *g) { return g->transactions; }

void cbvh_gateware_watch_stop(cbvh_gateware *g, volatile int *stop) { g->stop = stop; }

void cbvh_gateware_stop(cbvh_gateware *g) {
    if (!g) return;
    if (g->pid > 0) {
        /* "0" ends the testbench's loop; closing stdin does too. */
        ssize_t w = write(g->to_sim, "0\n", 2);
        (void)w;
    }
    close(g->to_sim);
    close(g->from_sim);
    if (g->pid > 0) {
        int st, reaped = 0;
        /* A simulation stuck in a transaction is not given its second. */
        for (int i = 0; i < 100 && !reaped && !g->abandoned; i++) {
            reaped = waitpid(g->pid, &st, WNOHANG) == g->pid;
            if (!reaped) usleep(10000);
        }
        if (!reaped) {
            kill(-g->pid, SIGKILL); /* its process group (setpgid above): a wrapper's children too */
            kill(g->pid, SIGKILL);
            waitpid(g->pid, &st, 0);
        }
    }
    free(g);
}
