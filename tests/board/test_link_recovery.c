/* What the host does when the board goes away or answers nonsense.
 *   reconnect: the virtual board (a thread of this process) is stopped like a
 *     crash (its socket file left behind) and restarted 0.9 s later while a
 *     batch runs: with the default timeout and retries the batch completes,
 *     every word equal to the model's.  A board that never comes back fails
 *     the batch with "not back within" in bounded time.
 *   replies: a scripted board (a fake transport) answers each request with
 *     garbage, a protocol-version-2 frame, half a frame, a bad CRC, stale
 *     frames or nothing; the error must say which, not only "no reply".
 * Usage: test_link_recovery */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cbvh_sim.h"
#include "link/board_link.h"
#include "link/sim_addr.h"
#include "gen_inputs.h"
#include "test_util.h"

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stderr, c, __VA_ARGS__)

static long now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long)ts.tv_sec * 1000L + ts.tv_nsec / 1000000L;
}

static void sleep_ms(long ms) {
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* ---- reconnect: the virtual board on a thread --------------------------- */

static char dir[256], sock_path[300], addr[320], spec[330];

typedef struct {
    int fd;
    volatile int stop;
    pthread_t th;
    long restart_after_ms; /* for restarter(): how long the board stays away */
    int restarted;
} board_thread;

static void *board_main(void *arg) {
    board_thread *b = arg;
    cbvh_sim_board_opts o = {b->fd, &b->stop, 20, NULL, 0, 0, NULL, 0};
    cbvh_sim_board_serve(&o);
    return NULL;
}

/* cbvh_sim_listen, not unlink + listen: a restart must get past the socket
 * file the "crashed" board left. */
static int board_start(board_thread *b) {
    char err[256];
    b->fd = cbvh_sim_listen(addr, err, sizeof err);
    if (b->fd < 0) {
        fprintf(stderr, "FAIL: board start: %s\n", err);
        return -1;
    }
    b->stop = 0;
    return pthread_create(&b->th, NULL, board_main, b);
}

/* Like a killed process: connections closed, socket file left in place. */
static void board_crash(board_thread *b) {
    b->stop = 1;
    pthread_join(b->th, NULL);
    close(b->fd);
}

static void *restarter(void *arg) {
    board_thread *b = arg;
    sleep_ms(b->restart_after_ms);
    b->restarted = board_start(b) == 0;
    return NULL;
}

static void reconnect_cases(void) {
    snprintf(dir, sizeof dir, "%s/cbvh-recover-XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(dir)) {
        CHECK(0, "mkdtemp");
        return;
    }
    snprintf(sock_path, sizeof sock_path, "%s/board.sock", dir);
    snprintf(addr, sizeof addr, "unix:%s", sock_path);
    snprintf(spec, sizeof spec, "sim:%s", addr);
    unsetenv("CBVH_LINK_TIMEOUT_MS");
    unsetenv("CBVH_LINK_RETRIES");

    board_thread b;
    memset(&b, 0, sizeof b);
    if (board_start(&b)) {
        fails++;
        return;
    }
    cbvh_backend sim, model;
    char err[512] = "";
    if (cbvh_backend_open(spec, &sim, NULL, err, sizeof err) || cbvh_backend_open("model", &model, NULL, err, sizeof err)) {
        CHECK(0, "open: %s", err);
        return;
    }
    cbvh_link *l = cbvh_backend_link(&sim);
    CHECK(l->timeout_ms == CBVH_LINK_TIMEOUT_MS_DEFAULT && l->max_retries == CBVH_LINK_RETRIES_DEFAULT,
          "defaults expected: %d ms, %d retries", l->timeout_ms, l->max_retries);

    const cbvh_unit *u = cbvh_unit_find("axis_compress");
    cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
    cbvh_layout lay;
    u->layout(&cfg, &lay);
    enum { PER = 600 }; /* several RUN frames */
    static uint32_t in[PER * 8], want[PER * 8], got[PER * 8];
    uint64_t rng = 4242;
    cbvh_gen_inputs(&rng, &cfg, &lay, in, PER);
    CHECK(model.ops->run(&model, u, &cfg, in, want, PER, err, sizeof err) == 0, "model: %s", err);

    /* 1. Gone for 0.9 s (a board reset, a USB re-enumeration), back while
     * the batch waits: the batch completes with the model's words. */
    board_crash(&b);
    struct stat st;
    CHECK(stat(sock_path, &st) == 0 && S_ISSOCK(st.st_mode), "the crashed board's socket file should be left behind");
    b.restart_after_ms = 900;
    pthread_t rt;
    pthread_create(&rt, NULL, restarter, &b);
    memset(got, 0, sizeof got);
    long t0 = now_ms();
    int rc = sim.ops->run(&sim, u, &cfg, in, got, PER, err, sizeof err);
    long took = now_ms() - t0;
    pthread_join(rt, NULL);
    CHECK(b.restarted, "the board did not restart over its stale socket file");
    CHECK(rc == 0, "a board away for 0.9 s must be waited for with the default settings: %s", err);
    CHECK(rc != 0 || memcmp(got, want, (size_t)PER * (size_t)lay.n_out * 4) == 0, "words differ from the model");
    CHECK(l->st.reopens >= 1, "no reopen counted (%llu)", (unsigned long long)l->st.reopens);
    CHECK(took >= 800, "the batch finished in %ld ms: the board was not really away", took);
    printf("reconnect: board away 0.9 s, batch of %d vectors completed in %ld ms (reopens %llu, retries %llu)\n",
           PER, took, (unsigned long long)l->st.reopens, (unsigned long long)l->st.retries);

    /* 2. Gone for good: a clear error after (1 + retries) attempts of at most
     * a timeout each, nothing claimed as run. */
    board_crash(&b);
    l->timeout_ms = 200;
    l->max_retries = 2;
    memset(got, 0xEE, sizeof got);
    t0 = now_ms();
    rc = sim.ops->run(&sim, u, &cfg, in, got, PER, err, sizeof err);
    took = now_ms() - t0;
    CHECK(rc != 0, "a board gone for good must fail the batch");
    CHECK(strstr(err, "vectors 0..") && strstr(err, "not run") && strstr(err, "after 3 attempts") &&
              strstr(err, "link lost and not back within 200 ms") && strstr(err, sock_path) && !strchr(err, '\n'),
          "unclear error: '%s'", err);
    /* The first attempt is spent on the write that finds the link broken;
     * each of the two retries waits up to 200 ms for the board. */
    CHECK(took >= 350 && took < 3000, "gave up after %ld ms (want about 2 x 200 ms)", took);
    CHECK(got[0] == 0xEEEEEEEEu, "output written although nothing was run");
    printf("gone for good: failed after %ld ms: %s\n", took, err);

    cbvh_backend_close(&sim);
    cbvh_backend_close(&model);
    unlink(sock_path);
    rmdir(dir);
}

/* ---- replies: a scripted board ------------------------------------------ */

typedef enum { R_NOTHING, R_GARBAGE, R_VERSION2, R_HALF, R_BAD_CRC, R_STALE, R_GOOD } reply_kind;

typedef struct {
    reply_kind kind;
    uint8_t out[CBVH_FRAME_MAX + 64];
    size_t out_len, out_pos;
} script_board;

/* An IDENTIFY reply to seq, sealed with version and CRC as given. */
static size_t identify_reply(uint8_t *buf, uint16_t seq, uint8_t version, int bad_crc) {
    memset(buf + CBVH_FRAME_HDR, 0, CBVH_IDENTITY_BYTES);
    buf[CBVH_FRAME_HDR] = CBVH_PROTO_VERSION;
    cbvh_put16(buf + CBVH_FRAME_HDR + 12, 4096);
    size_t n = cbvh_frame_seal(buf, CBVH_CMD_IDENTIFY | CBVH_REPLY, 0, seq, CBVH_IDENTITY_BYTES);
    if (version != CBVH_PROTO_VERSION) {
        buf[1] = version;
        cbvh_put32(buf + n - 4, cbvh_crc32(0, buf, n - 4));
    }
    if (bad_crc) buf[n - 1] ^= 0x5A;
    return n;
}

static int sb_write(void *ctx, const uint8_t *buf, size_t n, char *err, size_t errlen) {
    (void)err, (void)errlen;
    script_board *s = ctx;
    uint16_t seq = n >= 6 ? cbvh_get16(buf + 4) : 0;
    s->out_pos = 0;
    switch (s->kind) {
    case R_NOTHING: s->out_len = 0; break;
    case R_GARBAGE: /* no magic byte among them */
        for (size_t i = 0; i < 100; i++) s->out[i] = (uint8_t)(0x11 + 7 * i) == CBVH_FRAME_MAGIC ? 0 : (uint8_t)(0x11 + 7 * i);
        s->out_len = 100;
        break;
    case R_VERSION2: s->out_len = identify_reply(s->out, seq, 2, 0); break;
    case R_HALF: s->out_len = identify_reply(s->out, seq, CBVH_PROTO_VERSION, 0) / 2; break;
    case R_BAD_CRC: s->out_len = identify_reply(s->out, seq, CBVH_PROTO_VERSION, 1); break;
    case R_STALE: s->out_len = identify_reply(s->out, (uint16_t)(seq - 100), CBVH_PROTO_VERSION, 0); break;
    case R_GOOD: s->out_len = identify_reply(s->out, seq, CBVH_PROTO_VERSION, 0); break;
    }
    return 0;
}

static long sb_read(void *ctx, uint8_t *buf, size_t cap, int timeout_ms, char *err, size_t errlen) {
    (void)err, (void)errlen;
    script_board *s = ctx;
    if (s->out_pos >= s->out_len) { /* nothing more this attempt: wait, as a quiet link does */
        sleep_ms(timeout_ms < 5 ? timeout_ms : 5);
        return 0;
    }
    size_t k = s->out_len - s->out_pos;
    if (k > 7) k = 7; /* in pieces, as a byte stream arrives */
    if (k > cap) k = cap;
    memcpy(buf, s->out + s->out_pos, k);
    s->out_pos += k;
    return (long)k;
}

static void reply_case(reply_kind kind, const char *want, const char *must_not) {
    static cbvh_link l;
    script_board sb = {kind, {0}, 0, 0};
    cbvh_link_io io = {&sb, sb_write, sb_read, NULL, NULL};
    cbvh_link_init(&l, &io);
    l.timeout_ms = 40;
    l.max_retries = 1;
    char err[512] = "";
    int rc = cbvh_link_identify(&l, err, sizeof err);
    if (!want) {
        CHECK(rc == 0, "a good reply refused: %s", err);
        return;
    }
    CHECK(rc != 0 && strstr(err, "no valid reply to command 0x01") && strstr(err, "after 2 attempts") &&
              strstr(err, want) && !strchr(err, '\n') && !(must_not && strstr(err, must_not)),
          "kind %d: rc %d, '%s' (want '%s'%s%s)", (int)kind, rc, err, want, must_not ? ", without " : "",
          must_not ? must_not : "");
    printf("reply kind %d: %s\n", (int)kind, err);
}

static void reply_cases(void) {
    reply_case(R_GOOD, NULL, NULL);
    reply_case(R_NOTHING, "no reply within 40 ms", NULL);
    reply_case(R_GARBAGE, "100 bytes that are not a frame", "no reply within");
    reply_case(R_VERSION2, "reply from protocol version 2 (this host speaks version 1)", "no reply within");
    reply_case(R_HALF, "reply cut short: 26 of its 52 bytes arrived", "no reply within");
    reply_case(R_BAD_CRC, "reply damaged: bad CRC", "no reply within");
    reply_case(R_STALE, "only 1 stale frame", NULL);
}

int main(void) {
    reply_cases();
    reconnect_cases();
    if (fails) fprintf(stderr, "%d failures\n", fails);
    else printf("link recovery: reconnects within the timeout, gives up in bounded time, names what arrived\n");
    return fails ? 1 : 0;
}
