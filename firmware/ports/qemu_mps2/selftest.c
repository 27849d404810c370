/* Firmware-core self-test on an emulated Cortex-M3 (also built for the host:
 * the reply digests of both must match, tests/board via firmware/cross.cmake) (qemu -M mps2-an385, with
 * semihosting for output and exit code).  The core is built for ARM exactly as
 * for the RP2040; its FPGA is the bit-exact model compiled for ARM too.
 * Checks: every unit's RUN replies equal the model's direct evaluation, and
 * malformed frames get error replies while the core keeps answering.  Given a
 * vector directory (argument 1; read through semihosting on qemu), it also
 * runs every golden vector file listed in its MANIFEST through the core and
 * compares the replies with the files' expected outputs: the model built for
 * a 32-bit target without unsigned __int128 (so every exact path is the
 * portable one) must reproduce the committed vectors bit for bit. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh_fw/fw.h"
#include "cbvh_sim.h"

static cbvh_regmap_model regs;
static cbvh_fw fw;
static uint8_t last[CBVH_FRAME_MAX];
static size_t last_len;
static int replies;

static void capture(void *ctx, const uint8_t *frame, size_t len) {
    (void)ctx;
    memcpy(last, frame, len);
    last_len = len;
    replies++;
}
static const cbvh_fw_hal hal = {&regs, cbvh_regmap_model_read, cbvh_regmap_model_write, capture, "qemu-mps2"};

static uint32_t rng = 2463534242u;
static uint32_t next(void) {
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

static uint8_t req[CBVH_FRAME_MAX];
static uint32_t digest = 2166136261u; /* FNV-1a over every reply word: equal on ARM and on the host */
static uint32_t in[1024 * 4], want[1024 * 4]; /* a batch's input words and expected outputs */

/* Sends count vectors (words: count * n_in input words) as one RUN frame in
 * USB-sized chunks; 0 and the decoded reply in *f when exactly one good reply
 * came back. */
static int run_frame(const cbvh_unit *u, const cbvh_unit_config *cfg, const cbvh_layout *lay, const uint32_t *words,
                     unsigned count, uint16_t seq, cbvh_frame *f) {
    uint8_t *p = req + CBVH_FRAME_HDR;
    memset(p, 0, 12);
    p[0] = u->id;
    p[1] = (uint8_t)cfg->params.quant_bits;
    cbvh_put16(p + 2, (uint16_t)(int16_t)cfg->params.min_scale);
    p[4] = (uint8_t)(cfg->enc == CBVH_ENC_RELATIVE);
    p[5] = (uint8_t)lay->n_in;
    p[6] = (uint8_t)lay->n_out;
    cbvh_put16(p + 8, (uint16_t)count);
    for (unsigned i = 0; i < count * (unsigned)lay->n_in; i++) cbvh_put32(p + 12 + 4 * i, words[i]);
    size_t n = cbvh_frame_seal(req, CBVH_CMD_RUN, 0, seq, (uint16_t)(12 + 4 * count * (unsigned)lay->n_in));
    replies = 0;
    for (size_t off = 0; off < n; off += 64) cbvh_fw_rx(&fw, req + off, n - off < 64 ? n - off : 64);
    return replies != 1 || cbvh_frame_decode(last, last_len, f) != CBVH_E_OK || f->status != CBVH_E_OK ||
           f->seq != seq;
}

static int check_unit(const cbvh_unit *u, int n_bits, int enc, unsigned count, uint16_t seq) {
    cbvh_unit_config cfg = {{n_bits, -30}, enc ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO};
    cbvh_layout lay;
    u->layout(&cfg, &lay);
    for (unsigned i = 0; i < count * (unsigned)lay.n_in; i++) {
        uint32_t w = next();
        int d = lay.in[i % (unsigned)lay.n_in].hex_digits;
        if (d == 2) w = cbvh_scale_to_word((int)(w % 60) - 30);
        else if (d == 3) w &= (1u << n_bits) - 1u;
        else if (d == 1) w &= 3u;
        else if ((w & 3u) != 0) w = 0x3F000000u + (w & 0x00FFFFFFu); /* mostly 0.5..2 */
        in[i] = w;
    }
    /* Contexts with parent_scale < scale are kept out, so that the runs reach
     * the datapath rather than the reject (BAD_SCALE; the relative node-pair
     * encoder once shifted by a negative amount there, before it checked the
     * context first). */
    for (unsigned v = 0; v < count; v++)
        for (int f = 0; f + 1 < lay.n_in; f++) {
            uint32_t *w = in + v * (unsigned)lay.n_in;
            const char *nm = lay.in[f].name;
            size_t l = strlen(nm);
            if (l >= 12 && strcmp(nm + l - 12, "parent_scale") == 0 &&
                cbvh_scale_from_word(w[f]) < cbvh_scale_from_word(w[f + 1])) {
                uint32_t t = w[f];
                w[f] = w[f + 1];
                w[f + 1] = t;
            }
        }
    for (unsigned v = 0; v < count; v++) u->eval(&cfg, in + v * (unsigned)lay.n_in, want + v * (unsigned)lay.n_out);
    cbvh_frame f;
    if (run_frame(u, &cfg, &lay, in, count, seq, &f)) {
        printf("FAIL %s: no good reply (replies %d, status %d)\n", u->name, replies, last_len > 3 ? last[3] : -1);
        return 1;
    }
    for (unsigned i = 0; i < count * (unsigned)lay.n_out; i++) {
        for (int b = 0; b < 4; b++) digest = (digest ^ f.payload[4 + 4 * i + b]) * 16777619u;
        if (cbvh_get32(f.payload + 4 + 4 * i) != want[i]) {
            printf("FAIL %s N=%d: word %u differs\n", u->name, n_bits, i);
            return 1;
        }
    }
    return 0;
}

/* ---- golden vectors ---------------------------------------------------------- */

/* Sends count vectors of one file (in, want) as one RUN frame; returns mismatching vectors. */
static unsigned golden_batch(const cbvh_unit *u, const cbvh_unit_config *cfg, const cbvh_layout *lay,
                             unsigned count, uint16_t seq, const char *file, unsigned first) {
    cbvh_frame f;
    if (run_frame(u, cfg, lay, in, count, seq, &f)) {
        printf("FAIL %s: no good reply to a batch of %u\n", file, count);
        return count;
    }
    unsigned bad = 0;
    for (unsigned v = 0; v < count; v++)
        for (int k = 0; k < lay->n_out; k++)
            if (cbvh_get32(f.payload + 4 + 4 * (v * (unsigned)lay->n_out + (unsigned)k)) !=
                want[v * (unsigned)lay->n_out + (unsigned)k]) {
                if (bad++ < 3) printf("FAIL %s: vector %u, output %s differs\n", file, first + v, lay->out[k].name);
                break;
            }
    return bad;
}

/* One vector file: header keys, then after "---" one vector per line. */
static int golden_file(const char *path, const char *name, unsigned *nvec, unsigned *nbad, uint16_t *seq) {
    FILE *f = fopen(path, "r");
    if (!f) {
        printf("FAIL %s: cannot open\n", path);
        return 1;
    }
    static char line[1024];
    char unit[64] = "";
    cbvh_unit_config cfg = {{6, -30}, CBVH_ENC_MODULO};
    int body = 0, bad_line = 0;
    const cbvh_unit *u = NULL;
    cbvh_layout lay;
    unsigned batch = 0, in_batch = 0, index = 0;
    while (fgets(line, sizeof line, f)) {
        if (!body) {
            if (sscanf(line, "unit: %63s", unit) == 1) continue;
            if (sscanf(line, "quant_bits: %d", &cfg.params.quant_bits) == 1) continue;
            if (sscanf(line, "min_scale: %d", &cfg.params.min_scale) == 1) continue;
            if (strncmp(line, "encoding: relative", 18) == 0) cfg.enc = CBVH_ENC_RELATIVE;
            if (strncmp(line, "---", 3) == 0) {
                body = 1;
                u = cbvh_unit_find(unit);
                if (!u) break;
                u->layout(&cfg, &lay);
                unsigned words = (unsigned)(lay.n_in > lay.n_out ? lay.n_in : lay.n_out);
                batch = (CBVH_FRAME_MAX_PAYLOAD - 12) / (4 * words);
                if (batch > sizeof in / sizeof in[0] / words) batch = (unsigned)(sizeof in / sizeof in[0]) / words;
            }
            continue;
        }
        char *s = line, *e;
        for (int k = 0; k < lay.n_in + lay.n_out; k++, s = e) {
            unsigned long w = strtoul(s, &e, 16);
            if (e == s) bad_line = 1;
            if (k < lay.n_in) in[in_batch * (unsigned)lay.n_in + (unsigned)k] = (uint32_t)w;
            else want[in_batch * (unsigned)lay.n_out + (unsigned)(k - lay.n_in)] = (uint32_t)w;
        }
        if (bad_line) break;
        if (++in_batch == batch) {
            *nbad += golden_batch(u, &cfg, &lay, in_batch, (*seq)++, name, index);
            index += in_batch;
            in_batch = 0;
        }
    }
    fclose(f);
    if (!u || bad_line) {
        printf("FAIL %s: %s\n", name, u ? "malformed vector line" : "no known unit");
        return 1;
    }
    if (in_batch) *nbad += golden_batch(u, &cfg, &lay, in_batch, (*seq)++, name, index);
    *nvec += index + in_batch;
    return 0;
}

/* Every file of DIR/MANIFEST ("<sha256>  <name>" lines). */
static int golden_dir(const char *dir) {
    static char path[512], mline[512];
    snprintf(path, sizeof path, "%s/MANIFEST", dir);
    FILE *m = fopen(path, "r");
    if (!m) {
        printf("FAIL %s: cannot open\n", path);
        return 1;
    }
    unsigned files = 0, nvec = 0, nbad = 0;
    int fails = 0;
    uint16_t seq = 1000;
    while (fgets(mline, sizeof mline, m)) {
        char name[256];
        if (sscanf(mline, "%*64s %255s", name) != 1) continue;
        snprintf(path, sizeof path, "%s/%s", dir, name);
        fails += golden_file(path, name, &nvec, &nbad, &seq);
        files++;
    }
    fclose(m);
    printf("golden vectors: %u files, %u vectors, %u failures\n", files, nvec, nbad);
    return fails || nbad || files == 0;
}

int main(int argc, char **argv) {
    int fails = 0, runs = 0;
    cbvh_regmap_model_init(&regs);
    cbvh_fw_init(&fw, &hal);
    uint16_t seq = 1;
    static const int ns[] = {3, 6, 7, 10};
    for (int u = 0; u < cbvh_unit_count; u++)
        for (int a = 0; a < 4; a++)
            for (int enc = 0; enc < 2; enc++, runs++) fails += check_unit(cbvh_units[u], ns[a], enc, 24, seq++);
    /* malformed frames: bad CRC, unknown command, truncated + idle */
    size_t n = cbvh_frame_seal(req, CBVH_CMD_IDENTIFY, 0, 500, 0);
    req[n - 1] ^= 0x40;
    replies = 0;
    cbvh_fw_rx(&fw, req, n);
    if (replies != 1 || last[3] != CBVH_E_CRC) fails++, printf("FAIL: bad CRC not reported\n");
    n = cbvh_frame_seal(req, 0x66, 0, 501, 0);
    replies = 0;
    cbvh_fw_rx(&fw, req, n);
    if (replies != 1 || last[3] != CBVH_E_COMMAND) fails++, printf("FAIL: unknown command not reported\n");
    n = cbvh_frame_seal(req, CBVH_CMD_LOOPBACK, 0, 502, 0);
    replies = 0;
    cbvh_fw_rx(&fw, req, n - 3);
    cbvh_fw_rx_idle(&fw);
    if (replies != 1 || last[3] != CBVH_E_TIMEOUT) fails++, printf("FAIL: truncated frame not reported\n");
    n = cbvh_frame_seal(req, CBVH_CMD_IDENTIFY, 0, 503, 0);
    replies = 0;
    cbvh_fw_rx(&fw, req, n);
    if (replies != 1 || last[3] != CBVH_E_OK) fails++, printf("FAIL: core stopped answering\n");
    printf("cbvh firmware self-test: %d unit runs, %u vectors, %d failures, reply digest %08lx\n", runs,
           (unsigned)fw.n.vectors, fails, (unsigned long)digest);
    if (argc > 1) fails += golden_dir(argv[1]);
    return fails ? 1 : 0;
}
