/* Writes the seed corpora for fuzz_fw_parser and fuzz_host_decode:
 *   cc -std=c11 -Ifirmware/include fuzz/make_seeds.c firmware/core/frame.c -o /tmp/make_seeds && /tmp/make_seeds fuzz/corpus
 * (fuzz/corpus/vecfile holds cut-down copies of files in vectors/.) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cbvh_fw/frame.h"
#include "cbvh_fw/payload.h"
static uint8_t buf[8192];
static size_t frame(uint8_t *at, uint8_t cmd, uint8_t st, uint16_t seq, const uint8_t *p, uint16_t n) {
    if (n) memcpy(at + CBVH_FRAME_HDR, p, n); /* p may be NULL when n == 0 */
    return cbvh_frame_seal(at, cmd, st, seq, n);
}
static void put(const char *path, const uint8_t *p, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(p, 1, n, f) != n || fclose(f) != 0) {
        perror(path);
        exit(1);
    }
}
int main(int argc, char **argv) {
    (void)argc;
    char path[512];
    uint8_t run[12 + 16] = {1, 6, 0xE2, 0xFF, 0, 2, 2, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x80, 0x3f, 0, 0, 0, 0xbf, 0, 0, 0, 0x40};
    /* fw_parser: chunk byte, then frames */
    size_t n = 0;
    buf[n++] = 63;
    n += frame(buf + n, CBVH_CMD_IDENTIFY, 0, 1, NULL, 0);
    n += frame(buf + n, CBVH_CMD_RUN, 0, 2, run, sizeof run);
    n += frame(buf + n, CBVH_CMD_LOOPBACK, 0, 3, (const uint8_t *)"ping", 4);
    n += frame(buf + n, CBVH_CMD_STATUS, 0, 4, NULL, 0);
    n += frame(buf + n, CBVH_CMD_RESET, 0, 5, NULL, 0);
    snprintf(path, sizeof path, "%s/fw_parser/all_commands", argv[1]); put(path, buf, n);
    n = 0; buf[n++] = 4;
    memcpy(buf + n, "junk", 4), n += 4;
    size_t s = n; n += frame(buf + n, CBVH_CMD_RUN, 0, 9, run, sizeof run); buf[s + 10] ^= 1;
    n += frame(buf + n, CBVH_CMD_IDENTIFY, 0, 10, NULL, 0) - 3;
    snprintf(path, sizeof path, "%s/fw_parser/garbage_crc_truncated", argv[1]); put(path, buf, n);
    /* host_decode: replies to RUN seq 1 (3 vectors, 2 words out) and IDENTIFY seq 2 */
    uint8_t rr[4 + 24] = {3, 0, 2, 1};
    for (int i = 0; i < 24; i++) rr[4 + i] = (uint8_t)i;
    uint8_t id[CBVH_IDENTITY_BYTES] = {1, 0, 1, 0, 1, 0, 0, 0, 0x3e, 0, 0, 0, 0, 0x10, 64, 0, 0x43, 0x42, 0x56, 0x48, 's', 'i', 'm'};
    n = 0;
    n += frame(buf + n, CBVH_CMD_RUN | CBVH_REPLY, 0, 1, rr, sizeof rr);
    n += frame(buf + n, CBVH_CMD_IDENTIFY | CBVH_REPLY, 0, 2, id, sizeof id);
    snprintf(path, sizeof path, "%s/host_decode/good_replies", argv[1]); put(path, buf, n);
    n = 0;
    n += frame(buf + n, CBVH_CMD_RUN | CBVH_REPLY, 0, 0, rr, sizeof rr); /* stale */
    n += frame(buf + n, CBVH_CMD_RUN | CBVH_REPLY, CBVH_E_CRC, 1, NULL, 0);
    n += frame(buf + n, CBVH_CMD_RUN | CBVH_REPLY, 0, 1, rr, sizeof rr);
    snprintf(path, sizeof path, "%s/host_decode/stale_then_error_then_good", argv[1]); put(path, buf, n);
    return 0;
}
