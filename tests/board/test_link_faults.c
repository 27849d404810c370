/* Fault injection on the socket link to the virtual board.  The board runs on
 * a thread of this process; faults hit host requests (injector in the sim
 * transport) and board replies (injector in the sim port).  For every
 * scenario: outputs of every batch that reported success equal the model
 * word for word, every injected fault shows up as a detection (timeout, CRC,
 * sync, stale reply, board-reported link error, link break), batches that
 * could not be recovered are reported as errors.
 * Usage: test_link_faults [--markdown] [--quick] */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cbvh_sim.h"
#include "link/board_link.h"
#include "link/sim_addr.h"
#include "gen_inputs.h"

static char dir[256], sock_path[300], addr[320], spec[330];

typedef struct {
    int fd;
    volatile int stop;
    cbvh_link_fault reply_faults;
    pthread_t th;
} board_thread;

static void *board_main(void *arg) {
    board_thread *b = arg;
    cbvh_sim_board_opts o = {b->fd, &b->stop, 20, &b->reply_faults, 0, 0, NULL, 0};
    cbvh_sim_board_serve(&o);
    return NULL;
}

static int board_start(board_thread *b) {
    char err[256];
    unlink(sock_path);
    b->fd = cbvh_sim_listen(addr, err, sizeof err);
    if (b->fd < 0) {
        fprintf(stderr, "FAIL: %s\n", err);
        return -1;
    }
    b->stop = 0;
    return pthread_create(&b->th, NULL, board_main, b);
}

static void board_stop(board_thread *b) {
    b->stop = 1;
    pthread_join(b->th, NULL);
    close(b->fd);
    unlink(sock_path);
}

typedef struct {
    const char *name;
    double rate;
    uint64_t inj[CBVH_FAULT_KINDS];
    uint64_t frames;
    cbvh_link_stats st;
    size_t batches, batches_failed, vectors_ok, wrong;
} result;

/* Runs `batches` batches of `per` axis_compress vectors (several frames each). */
static int scenario(const char *name, int kind, double rate, int batches, size_t per, result *r) {
    memset(r, 0, sizeof *r);
    r->name = name;
    r->rate = rate;
    board_thread *b = calloc(1, sizeof *b);
    cbvh_link_fault host_faults;
    cbvh_link_fault_init(&host_faults, 0x1234 + (uint64_t)(rate * 1000) + (uint64_t)kind);
    cbvh_link_fault_init(&b->reply_faults, 0x9876 + (uint64_t)(rate * 1000) + (uint64_t)kind);
    b->reply_faults.delay_ms = host_faults.delay_ms = 90;
    for (int k = 0; k < CBVH_FAULT_KINDS; k++) {
        if (kind >= 0 && k != kind) continue;
        b->reply_faults.rate[k] = rate;
        /* A delayed request on a synchronous host is only a slower send: delays are injected on replies. */
        host_faults.rate[k] = k == CBVH_FAULT_DELAY ? 0 : rate;
    }
    if (board_start(b)) return -1;
    cbvh_backend sim, model;
    char err[512];
    /* Open on a clean link, then arm the faults. */
    cbvh_link_fault saved = b->reply_faults;
    memset(b->reply_faults.rate, 0, sizeof b->reply_faults.rate);
    if (cbvh_backend_open(spec, &sim, NULL, err, sizeof err) || cbvh_backend_open("model", &model, NULL, err, sizeof err)) {
        fprintf(stderr, "FAIL: open: %s\n", err);
        return -1;
    }
    cbvh_link *l = cbvh_backend_link(&sim);
    l->timeout_ms = 60;
    l->max_retries = 8;
    memset(&l->st, 0, sizeof l->st);
    memcpy(b->reply_faults.rate, saved.rate, sizeof saved.rate);
    cbvh_sim_set_faults(&sim, &host_faults);

    const cbvh_unit *u = cbvh_unit_find("axis_compress");
    cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
    cbvh_layout lay;
    u->layout(&cfg, &lay);
    uint32_t *in = malloc(per * (size_t)lay.n_in * 4), *want = malloc(per * 8 * 4), *got = malloc(per * 8 * 4);
    uint64_t rng = 777 + (uint64_t)kind;
    for (int i = 0; i < batches; i++) {
        cbvh_gen_inputs(&rng, &cfg, &lay, in, per);
        model.ops->run(&model, u, &cfg, in, want, per, err, sizeof err);
        memset(got, 0, per * (size_t)lay.n_out * 4);
        r->batches++;
        if (sim.ops->run(&sim, u, &cfg, in, got, per, err, sizeof err) != 0) {
            r->batches_failed++;
            if (!strstr(err, "not run")) {
                fprintf(stderr, "FAIL: unclear error: %s\n", err);
                return -1;
            }
            continue;
        }
        for (size_t v = 0; v < per; v++) {
            if (memcmp(got + v * (size_t)lay.n_out, want + v * (size_t)lay.n_out, (size_t)lay.n_out * 4)) r->wrong++;
            else r->vectors_ok++;
        }
    }
    /* Drain on a clean link: late duplicates and delayed replies get counted. */
    cbvh_sim_set_faults(&sim, NULL);
    memset(b->reply_faults.rate, 0, sizeof b->reply_faults.rate);
    l->timeout_ms = 300;
    usleep(150 * 1000);
    if (cbvh_link_identify(l, err, sizeof err)) {
        fprintf(stderr, "FAIL: link did not recover after the scenario: %s\n", err);
        return -1;
    }
    r->st = l->st;
    cbvh_backend_close(&sim);
    cbvh_backend_close(&model);
    board_stop(b);
    for (int k = 0; k < CBVH_FAULT_KINDS; k++) r->inj[k] = host_faults.injected[k] + b->reply_faults.injected[k];
    r->frames = host_faults.frames + b->reply_faults.frames;
    free(b), free(in), free(want), free(got);
    return 0;
}

static uint64_t detections(const cbvh_link_stats *s) {
    return s->timeouts + s->crc_errors + s->sync_errors + s->other_parse_errors + s->link_errors_reported +
           s->link_breaks + s->stale_replies;
}

int main(int argc, char **argv) {
    int markdown = 0, quick = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--markdown") == 0) markdown = 1;
        else if (strcmp(argv[i], "--quick") == 0) quick = 1;
    }
    snprintf(dir, sizeof dir, "%s/cbvh-faults-XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(dir)) return 1;
    snprintf(sock_path, sizeof sock_path, "%s/board.sock", dir);
    snprintf(addr, sizeof addr, "unix:%s", sock_path);
    snprintf(spec, sizeof spec, "sim:%s", addr);

    const double rates_full[] = {0.01, 0.05, 0.2}, rates_quick[] = {0.05};
    const double *rates = quick ? rates_quick : rates_full;
    int nrates = quick ? 1 : 3;
    int batches = quick ? 6 : 12;
    size_t per = 1000; /* 6 RUN frames of <= 170 vectors per batch */
    int fails = 0;
    if (markdown) {
        printf("| faults (per frame, each direction) | frames sent | injected | detected | retries | batches failed (reported) | vectors verified | wrong |\n");
        printf("|---|---:|---|---|---:|---:|---:|---:|\n");
    }
    for (int kind = 0; kind <= CBVH_FAULT_KINDS; kind++) {
        for (int ri = 0; ri < nrates; ri++) {
            double rate = kind == CBVH_FAULT_KINDS ? rates[ri] / 2 : rates[ri];
            const char *name = kind == CBVH_FAULT_KINDS ? "all six mixed" : cbvh_fault_names[kind];
            result r;
            if (scenario(name, kind == CBVH_FAULT_KINDS ? -1 : kind, rate, batches, per, &r)) return 1;
            uint64_t injected = 0;
            for (int k = 0; k < CBVH_FAULT_KINDS; k++) injected += r.inj[k];
            uint64_t det = detections(&r.st);
            const cbvh_link_stats *s = &r.st;
            char inj[200] = "", dt[300];
            for (int k = 0; k < CBVH_FAULT_KINDS; k++)
                if (r.inj[k])
                    snprintf(inj + strlen(inj), sizeof inj - strlen(inj), "%s%s %llu", inj[0] ? ", " : "",
                             cbvh_fault_names[k], (unsigned long long)r.inj[k]);
            snprintf(dt, sizeof dt, "timeout %llu, crc %llu, sync %llu, other %llu, board-reported %llu, breaks %llu, stale %llu",
                     (unsigned long long)s->timeouts, (unsigned long long)s->crc_errors,
                     (unsigned long long)s->sync_errors, (unsigned long long)s->other_parse_errors,
                     (unsigned long long)s->link_errors_reported, (unsigned long long)s->link_breaks,
                     (unsigned long long)s->stale_replies);
            if (markdown)
                printf("| %s %.3g | %llu | %s | %s | %llu | %zu of %zu | %zu | %zu |\n", name, rate,
                       (unsigned long long)r.frames, inj[0] ? inj : "none", dt, (unsigned long long)s->retries,
                       r.batches_failed, r.batches, r.vectors_ok, r.wrong);
            else
                printf("%-14s rate %.3g: frames %llu, injected %llu (%s); detected %llu (%s); retries %llu; batches failed %zu/%zu; vectors ok %zu; wrong %zu\n",
                       name, rate, (unsigned long long)r.frames, (unsigned long long)injected, inj,
                       (unsigned long long)det, dt, (unsigned long long)s->retries, r.batches_failed, r.batches,
                       r.vectors_ok, r.wrong);
            /* What the link guarantees: no wrong answer, every vector accounted for. */
            if (r.wrong) fprintf(stderr, "FAIL: %s %.3g: %zu wrong vectors reported as answered\n", name, rate, r.wrong), fails++;
            if (r.vectors_ok + r.batches_failed * per != r.batches * per)
                fprintf(stderr, "FAIL: %s: vectors unaccounted for\n", name), fails++;
            /* A fault on a request and one on the board's (error) reply to it
             * can be caught by a single timeout: at most two faults per
             * exchange, so detections >= injected / 2; the single-kind
             * scenarios below pin the counts exactly where that cannot happen. */
            if (2 * det < injected) fprintf(stderr, "FAIL: %s %.3g: %llu faults but only %llu detections\n", name, rate,
                                        (unsigned long long)injected, (unsigned long long)det), fails++;
            if (kind == CBVH_FAULT_DROP && s->timeouts != injected)
                fprintf(stderr, "FAIL: drop: %llu drops vs %llu timeouts\n", (unsigned long long)injected,
                        (unsigned long long)s->timeouts), fails++;
            if (kind == CBVH_FAULT_DUP && s->stale_replies != injected)
                fprintf(stderr, "FAIL: dup: %llu duplicates vs %llu stale replies\n", (unsigned long long)injected,
                        (unsigned long long)s->stale_replies), fails++;
            if (kind == CBVH_FAULT_DISCONNECT && s->link_breaks != injected)
                fprintf(stderr, "FAIL: disconnect: %llu cuts vs %llu link breaks\n", (unsigned long long)injected,
                        (unsigned long long)s->link_breaks), fails++;
            if (kind < CBVH_FAULT_KINDS && rate <= 0.05 && r.batches_failed)
                fprintf(stderr, "FAIL: %s %.3g: retries should recover at this rate\n", name, rate), fails++;
            if (injected == 0 && rate >= 0.05) fprintf(stderr, "FAIL: %s: nothing injected\n", name), fails++;
        }
    }
    /* A dead link: every request dropped.  Must fail, clearly, with nothing claimed. */
    {
        board_thread *b = calloc(1, sizeof *b);
        cbvh_link_fault_init(&b->reply_faults, 5);
        if (board_start(b)) return 1;
        cbvh_backend sim;
        char err[512];
        if (cbvh_backend_open(spec, &sim, NULL, err, sizeof err)) return 1;
        cbvh_link *l = cbvh_backend_link(&sim);
        l->timeout_ms = 30;
        l->max_retries = 3;
        cbvh_link_fault all_drop;
        cbvh_link_fault_init(&all_drop, 9);
        all_drop.rate[CBVH_FAULT_DROP] = 1.0;
        cbvh_sim_set_faults(&sim, &all_drop);
        const cbvh_unit *u = cbvh_unit_find("scale_estimate");
        cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
        uint32_t in[2] = {0, 0x3f800000u}, out[2] = {0xDEADBEEF, 0xDEADBEEF};
        int rc = sim.ops->run(&sim, u, &cfg, in, out, 1, err, sizeof err);
        if (rc == 0 || out[0] != 0xDEADBEEF || !strstr(err, "no valid reply"))
            fprintf(stderr, "FAIL: a dead link must fail the run (rc %d, err '%s')\n", rc, err), fails++;
        else if (!markdown)
            printf("dead link: run failed as it must: %s\n", err);
        cbvh_backend_close(&sim);
        board_stop(b);
        free(b);
    }
    rmdir(dir);
    if (fails) fprintf(stderr, "%d failures\n", fails);
    return fails ? 1 : 0;
}
