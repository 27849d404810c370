/* libFuzzer: the host's reply path.  The input plays the board: its bytes are
 * what the host reads back after sending a RUN (then an IDENTIFY).  Whatever
 * arrives, the host must either return validated results or an error, and
 * never write outputs it did not get. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "link/protocol.h"

typedef struct {
    const uint8_t *p;
    size_t n;
} feed;

static int f_write(void *ctx, const uint8_t *buf, size_t n, char *err, size_t errlen) {
    (void)ctx, (void)buf, (void)n, (void)err, (void)errlen;
    return 0;
}
static long f_read(void *ctx, uint8_t *buf, size_t cap, int timeout_ms, char *err, size_t errlen) {
    (void)timeout_ms, (void)err, (void)errlen;
    feed *f = ctx;
    if (f->n == 0) return -1; /* board gone: no waiting */
    size_t k = 1 + f->p[0] % 97; /* chunking from the data itself */
    if (k > f->n) k = f->n;
    if (k > cap) k = cap;
    memcpy(buf, f->p, k);
    f->p += k;
    f->n -= k;
    return (long)k;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static cbvh_link l;
    feed f = {data, size};
    cbvh_link_io io = {&f, f_write, f_read, NULL, NULL};
    cbvh_link_init(&l, &io);
    l.seq = 0; /* so inputs can answer seq 1, 2 */
    l.max_retries = 1;
    l.timeout_ms = 1;
    const cbvh_unit *u = cbvh_unit_find("scale_estimate");
    cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
    uint32_t in[6] = {0, 0x3f800000u, 0xbf800000u, 0x40000000u, 0, 0}, out[6];
    memset(out, 0xEE, sizeof out);
    char err[256];
    if (cbvh_link_run(&l, u, &cfg, in, out, 3, err, sizeof err) != 0) {
        for (int i = 0; i < 6; i++)
            if (out[i] != 0xEEEEEEEEu) abort(); /* failed run must not leave partial results */
        if (!err[0]) abort();
    }
    cbvh_link_identify(&l, err, sizeof err);
    /* The one-shot decoder and the payload parsers on the raw input too. */
    cbvh_frame fr;
    if (cbvh_frame_decode(data, size, &fr) == CBVH_E_OK) {
        cbvh_identity id;
        cbvh_identity_parse(fr.payload, fr.len, &id);
        cbvh_run_reply_check(fr.payload, fr.len, 1, 3, 2);
    }
    return 0;
}
