/* Host tool that makes the RP2040 image's pieces (no downloaded tool):
 *
 *   rp2040_image boot2 IN.bin OUT.bin
 *       pads boot2's code (at most 252 bytes) with zeros and appends the
 *       CRC-32 the boot ROM checks (RP2040 datasheet 2.8.1.3.1: polynomial
 *       0x04C11DB7, no reflection, initial 0xFFFFFFFF, no final XOR,
 *       little-endian), 256 bytes in all;
 *   rp2040_image bitstream IN.bin OUT.bin
 *       prefixes an iCE40 bitstream with the 16-byte header the firmware
 *       checks (board.h: "CBVB", length, CRC-32 IEEE of the bytes, 0);
 *   rp2040_image uf2 OUT.uf2 ADDR FILE [ADDR FILE ...]
 *       writes the files at those flash addresses as UF2 (Microsoft's USB
 *       Flashing Format: 512-byte blocks of 256 payload bytes, family ID
 *       0xE48BFF56 = RP2040), for drag-and-drop onto the boot ROM's drive.
 *
 * Bad input: one line on stderr, exit 2 (usage) or 1 (files). */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BOOT2_CODE 252u
#define UF2_PAYLOAD 256u
#define UF2_FAMILY_RP2040 0xE48BFF56u
#define FLASH_BASE 0x10000000u
#define FLASH_END 0x11000000u /* 16 MiB window */

static const char *me = "rp2040_image";

static void put32(uint8_t *p, uint32_t v) {
    for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}

static uint8_t *slurp(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "%s: cannot open %s: %s\n", me, path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    uint8_t *buf = malloc(cap);
    for (;;) {
        if (!buf) break;
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap) break;
        uint8_t *b = realloc(buf, cap *= 2);
        if (!b) free(buf);
        buf = b;
    }
    int err = ferror(f);
    fclose(f);
    if (!buf || err) {
        fprintf(stderr, "%s: cannot read %s\n", me, path);
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

static int spill(const char *path, const uint8_t *p, size_t n) {
    FILE *f = fopen(path, "wb");
    int ok = f != NULL;
    if (f) {
        ok = fwrite(p, 1, n, f) == n;
        ok = fclose(f) == 0 && ok;
    }
    if (!ok) fprintf(stderr, "%s: cannot write %s: %s\n", me, path, strerror(errno));
    return !ok;
}

static uint32_t crc32_boot2(const uint8_t *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= (uint32_t)p[i] << 24;
        for (int b = 0; b < 8; b++) c = c & 0x80000000u ? c << 1 ^ 0x04C11DB7u : c << 1;
    }
    return c;
}

static uint32_t crc32_ieee(const uint8_t *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int b = 0; b < 8; b++) c = c & 1u ? c >> 1 ^ 0xEDB88320u : c >> 1;
    }
    return ~c;
}

static int cmd_boot2(const char *in, const char *out) {
    size_t n;
    uint8_t *code = slurp(in, &n);
    if (!code) return 1;
    if (n > BOOT2_CODE) {
        fprintf(stderr, "%s: %s: boot2 is %zu bytes, at most %u fit before the CRC\n", me, in, n, BOOT2_CODE);
        free(code);
        return 1;
    }
    uint8_t img[BOOT2_CODE + 4] = {0};
    memcpy(img, code, n);
    free(code);
    put32(img + BOOT2_CODE, crc32_boot2(img, BOOT2_CODE));
    return spill(out, img, sizeof img);
}

static int cmd_bitstream(const char *in, const char *out) {
    size_t n;
    uint8_t *bits = slurp(in, &n);
    if (!bits) return 1;
    if (n == 0 || n > 1024u * 1024u - 16u) {
        fprintf(stderr, "%s: %s: a bitstream of %zu bytes does not fit the 1 MiB region\n", me, in, n);
        free(bits);
        return 1;
    }
    uint8_t *img = malloc(n + 16);
    if (!img) {
        free(bits);
        return 1;
    }
    put32(img, 0x42564243u); /* "CBVB" */
    put32(img + 4, (uint32_t)n);
    put32(img + 8, crc32_ieee(bits, n));
    put32(img + 12, 0);
    memcpy(img + 16, bits, n);
    free(bits);
    int rc = spill(out, img, n + 16);
    free(img);
    return rc;
}

static int parse_addr(const char *s, uint32_t *a) {
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 0);
    if (errno || end == s || *end || v < FLASH_BASE || v >= FLASH_END || v % UF2_PAYLOAD) return -1;
    *a = (uint32_t)v;
    return 0;
}

static int cmd_uf2(const char *out, int argc, char **argv) {
    if (argc < 2 || argc % 2) {
        fprintf(stderr, "%s uf2: expected OUT.uf2 followed by ADDR FILE pairs\n", me);
        return 2;
    }
    int nfiles = argc / 2;
    uint8_t **data = calloc((size_t)nfiles, sizeof *data);
    size_t *len = calloc((size_t)nfiles, sizeof *len);
    uint32_t *addr = calloc((size_t)nfiles, sizeof *addr);
    int rc = 1;
    uint32_t blocks = 0;
    FILE *f = NULL;
    if (!data || !len || !addr) goto done;
    for (int i = 0; i < nfiles; i++) {
        if (parse_addr(argv[2 * i], &addr[i])) {
            fprintf(stderr, "%s uf2: bad flash address '%s' (expected 0x10000000..0x10FFFF00, 256-byte aligned)\n",
                    me, argv[2 * i]);
            rc = 2;
            goto done;
        }
        if (!(data[i] = slurp(argv[2 * i + 1], &len[i]))) goto done;
        if (len[i] > FLASH_END - addr[i]) {
            fprintf(stderr, "%s uf2: %s does not fit in flash at 0x%08x\n", me, argv[2 * i + 1], (unsigned)addr[i]);
            goto done;
        }
        for (int j = 0; j < i; j++)
            if (addr[i] < addr[j] + len[j] && addr[j] < addr[i] + len[i]) {
                fprintf(stderr, "%s uf2: %s overlaps %s\n", me, argv[2 * i + 1], argv[2 * j + 1]);
                goto done;
            }
        blocks += (uint32_t)((len[i] + UF2_PAYLOAD - 1) / UF2_PAYLOAD);
    }
    if (!(f = fopen(out, "wb"))) {
        fprintf(stderr, "%s: cannot write %s: %s\n", me, out, strerror(errno));
        goto done;
    }
    uint32_t no = 0;
    for (int i = 0; i < nfiles; i++)
        for (size_t off = 0; off < len[i]; off += UF2_PAYLOAD, no++) {
            uint8_t b[512] = {0};
            put32(b + 0, 0x0A324655u);  /* magic start 0 "UF2\n" */
            put32(b + 4, 0x9E5D5157u);  /* magic start 1 */
            put32(b + 8, 0x00002000u);  /* flags: family ID present */
            put32(b + 12, addr[i] + (uint32_t)off);
            put32(b + 16, UF2_PAYLOAD);
            put32(b + 20, no);
            put32(b + 24, blocks);
            put32(b + 28, UF2_FAMILY_RP2040);
            size_t k = len[i] - off < UF2_PAYLOAD ? len[i] - off : UF2_PAYLOAD;
            memcpy(b + 32, data[i] + off, k);
            put32(b + 508, 0x0AB16F30u); /* magic end */
            if (fwrite(b, 1, sizeof b, f) != sizeof b) {
                fprintf(stderr, "%s: cannot write %s: %s\n", me, out, strerror(errno));
                goto done;
            }
        }
    if (fclose(f) != 0) {
        f = NULL;
        fprintf(stderr, "%s: cannot write %s: %s\n", me, out, strerror(errno));
        goto done;
    }
    f = NULL;
    rc = 0;
done:
    if (f) fclose(f);
    for (int i = 0; data && i < nfiles; i++) free(data[i]);
    free(data);
    free(len);
    free(addr);
    return rc;
}

int main(int argc, char **argv) {
    if (argc == 4 && !strcmp(argv[1], "boot2")) return cmd_boot2(argv[2], argv[3]);
    if (argc == 4 && !strcmp(argv[1], "bitstream")) return cmd_bitstream(argv[2], argv[3]);
    if (argc >= 3 && !strcmp(argv[1], "uf2")) return cmd_uf2(argv[2], argc - 3, argv + 3);
    fprintf(stderr, "usage: %s boot2 IN OUT | bitstream IN OUT | uf2 OUT.uf2 ADDR FILE [ADDR FILE ...]\n", me);
    return 2;
}
