/* Vectors per second through the three ways of running the datapath units,
 * measured in one run on the same inputs:
 *   model     the in-process bit-exact model (the baseline)
 *   firmware  the firmware core in-process: frames built, parsed, dispatched,
 *             the register map driven word by word (model-backed), replies
 *             parsed and validated; no I/O
 *   socket    the virtual board (sim port) on a unix socket, on a thread
 * and, for the same vector sizes, the link ceilings of USB 2.0 full-speed HID
 * (64-byte reports, 1 ms interval, 63 data bytes each), high-speed bulk, and
 * the SPI register-map traffic of the RP2040 port: at 24 MHz (an SPI slave
 * clocked by SCK) and as built (the gateware's oversampling slave: SCK at
 * most 1.5 MHz, 2 us at each CS edge; docs/gateware.md, "Timing").
 * The model's rate is the baseline of the "x model" columns: the link paths
 * cost about a microsecond per vector whatever the unit, so the ratio falls
 * as the model gets faster (docs/results.md, "Board link").
 * Usage: bench_board [--quick] [--help]; an unknown option exits 2. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cbvh_sim.h"
#include "link/board_link.h"
#include "link/sim_addr.h"
#include "gen_inputs.h"

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- in-process firmware link ---- */
typedef struct {
    cbvh_regmap_model regs;
    cbvh_fw fw;
    cbvh_fw_hal hal;
    uint8_t out[2 * CBVH_FRAME_MAX];
    size_t out_len, out_pos;
} inproc;

static void ip_send(void *ctx, const uint8_t *frame, size_t len) {
    inproc *ip = (inproc *)((char *)ctx - offsetof(inproc, regs));
    if (ip->out_len + len <= sizeof ip->out) {
        memcpy(ip->out + ip->out_len, frame, len);
        ip->out_len += len;
    }
}
static int ip_write(void *ctx, const uint8_t *buf, size_t n, char *err, size_t errlen) {
    (void)err, (void)errlen;
    inproc *ip = ctx;
    ip->out_len = ip->out_pos = 0;
    cbvh_fw_rx(&ip->fw, buf, n);
    return 0;
}
static long ip_read(void *ctx, uint8_t *buf, size_t cap, int timeout_ms, char *err, size_t errlen) {
    (void)timeout_ms, (void)err, (void)errlen;
    inproc *ip = ctx;
    size_t k = ip->out_len - ip->out_pos;
    if (k > cap) k = cap;
    memcpy(buf, ip->out + ip->out_pos, k);
    ip->out_pos += k;
    return (long)k;
}

/* ---- socket board on a thread ---- */
typedef struct {
    int fd;
    volatile int stop;
    pthread_t th;
} board_thread;
static void *board_main(void *arg) {
    board_thread *b = arg;
    cbvh_sim_board_opts o = {b->fd, &b->stop, 20, NULL, 0, 0, NULL, 0};
    cbvh_sim_board_serve(&o);
    return NULL;
}

/* Bytes on the link per vector and per frame for a unit shape. */
static void link_bytes(int n_in, int n_out, double *req_per_vec, double *rep_per_vec) {
    size_t batch = cbvh_link_max_batch(n_in, n_out);
    double frame = CBVH_FRAME_HDR + CBVH_FRAME_CRC;
    *req_per_vec = 4.0 * n_in + (frame + 12) / (double)batch;
    *rep_per_vec = 4.0 * n_out + (frame + 4) / (double)batch;
}

#define USAGE "usage: bench_board [--quick] [--help]"

int main(int argc, char **argv) {
    int quick = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            printf(USAGE "\n"
                   "  Vectors per second of every unit (N = 6, modulo) through the bit-exact model,\n"
                   "  the firmware core in-process and the virtual board on a unix socket, each link\n"
                   "  path also as a ratio to the model; and the USB and SPI ceilings of the link for\n"
                   "  the same vector sizes (docs/results.md, \"Board link\").\n"
                   "  --quick  a tenth of the vectors per unit\n"
                   "  Exit status: 0 done, 1 a path failed or the outputs differ, 2 bad option.\n");
            return 0;
        }
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else {
            fprintf(stderr, "bench_board: unknown argument '%s' (" USAGE ")\n", argv[i]);
            return 2;
        }
    }
    char dir[256], sock[300], addr[320], spec[330], err[512];
    snprintf(dir, sizeof dir, "/tmp/cbvh-bench-XXXXXX");
    if (!mkdtemp(dir)) return 1;
    snprintf(sock, sizeof sock, "%s/board.sock", dir);
    snprintf(addr, sizeof addr, "unix:%s", sock);
    snprintf(spec, sizeof spec, "sim:%s", addr);
    board_thread *bt = calloc(1, sizeof *bt);
    if (!bt) {
        fprintf(stderr, "bench_board: out of memory\n");
        return 1;
    }
    bt->fd = cbvh_sim_listen(addr, err, sizeof err);
    if (bt->fd < 0) {
        fprintf(stderr, "bench_board: %s\n", err);
        free(bt);
        rmdir(dir);
        return 1;
    }
    pthread_create(&bt->th, NULL, board_main, bt);

    cbvh_backend model, sim;
    if (cbvh_backend_open("model", &model, NULL, err, sizeof err) || cbvh_backend_open(spec, &sim, NULL, err, sizeof err)) {
        fprintf(stderr, "bench_board: %s\n", err);
        return 1;
    }
    inproc *ip = calloc(1, sizeof *ip);
    cbvh_regmap_model_init(&ip->regs);
    ip->hal = (cbvh_fw_hal){&ip->regs, cbvh_regmap_model_read, cbvh_regmap_model_write, ip_send, "inproc"};
    cbvh_fw_init(&ip->fw, &ip->hal);
    static cbvh_link link;
    cbvh_link_io io = {ip, ip_write, ip_read, NULL, NULL};
    cbvh_link_init(&link, &io);

    printf("| unit (N=6) | words in/out | model vec/s | firmware in-process vec/s (x model) | socket board vec/s (x model) | "
           "FS HID ceiling vec/s | HS bulk ceiling vec/s | SPI 24 MHz regmap ceiling vec/s | "
           "SPI as built (1.5 MHz) ceiling vec/s |\n");
    printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    int fails = 0;
    for (int u = 0; u < cbvh_unit_count; u++) {
        const cbvh_unit *unit = cbvh_units[u];
        cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
        cbvh_layout lay;
        unit->layout(&cfg, &lay);
        size_t count = (size_t)(quick ? 20000 : 200000) / (size_t)(lay.n_in + lay.n_out) * 4;
        uint32_t *in = malloc(count * (size_t)lay.n_in * 4);
        uint32_t *o[3];
        for (int k = 0; k < 3; k++) o[k] = malloc(count * (size_t)lay.n_out * 4);
        uint64_t rng = 99;
        cbvh_gen_inputs(&rng, &cfg, &lay, in, count);
        double rate[3];
        for (int k = 0; k < 3; k++) {
            double best = 1e30;
            for (int rep = 0; rep < 3; rep++) { /* best of 3: the machine is shared */
                double t0 = now_s();
                int rc = k == 0 ? model.ops->run(&model, unit, &cfg, in, o[0], count, err, sizeof err)
                         : k == 1 ? cbvh_link_run(&link, unit, &cfg, in, o[1], count, err, sizeof err)
                                  : sim.ops->run(&sim, unit, &cfg, in, o[2], count, err, sizeof err);
                double t = now_s() - t0;
                if (rc) {
                    fprintf(stderr, "bench_board: %s\n", err);
                    return 1;
                }
                if (t < best) best = t;
            }
            rate[k] = (double)count / best;
        }
        if (memcmp(o[0], o[1], count * (size_t)lay.n_out * 4) || memcmp(o[0], o[2], count * (size_t)lay.n_out * 4)) {
            fprintf(stderr, "bench_board: %s: outputs differ between paths\n", unit->name);
            fails++;
        }
        double req, rep;
        link_bytes(lay.n_in, lay.n_out, &req, &rep);
        /* FS HID: IN and OUT interrupt endpoints, one 64-byte report per ms
         * each (63 data bytes after the length byte), streamed. */
        double hid = 63000.0 / (req > rep ? req : rep);
        /* HS bulk: 13 x 512-byte packets per 125 us microframe, both
         * directions share the bus. */
        double bulk = 13.0 * 512.0 * 8000.0 / (req + rep);
        /* SPI: write = 1 cmd + 2 addr + 4 data, read = + 1 turnaround; per
         * vector: n_in writes, CTRL write, >= 1 STATUS read, n_out reads. */
        double spi_bytes = 7.0 * (lay.n_in + 1) + 8.0 * (1 + lay.n_out);
        double spi = 24e6 / 8.0 / spi_bytes;
        /* As built: SCK = 12 MHz / 8 and 2 us at each of a transaction's two
         * CS edges (firmware/ports/rp2040_ice40/board.h). */
        double spi_txn = (double)(lay.n_in + 1) + (double)(lay.n_out + 1);
        double spi_built = 1.0 / (spi_bytes * 8.0 / 1.5e6 + spi_txn * 4e-6);
        printf("| %s | %d/%d | %.3g | %.3g (%.3f) | %.3g (%.3f) | %.3g | %.3g | %.3g | %.0f |\n", unit->name, lay.n_in,
               lay.n_out, rate[0], rate[1], rate[1] / rate[0], rate[2], rate[2] / rate[0], hid, bulk, spi, spi_built);
        free(in);
        for (int k = 0; k < 3; k++) free(o[k]);
    }
    cbvh_backend_close(&sim);
    cbvh_backend_close(&model);
    bt->stop = 1;
    pthread_join(bt->th, NULL);
    close(bt->fd);
    unlink(sock);
    rmdir(dir);
    free(ip);
    free(bt);
    return fails ? 1 : 0;
}
