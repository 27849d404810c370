/* The FPGA's register map for the RP2040 emulation harness (board_emu.mjs):
 * the sim port's model-backed register map (firmware/ports/sim/
 * regmap_model.c, the bit-exact model behind it) served over two named
 * pipes, so the harness can answer each SPI read synchronously.
 *
 *   board_emu_regmap REQ_FIFO RESP_FIFO
 *
 * Requests, 9 bytes: u8 op (0 write, 1 read, 2 power-on: a fresh register
 * map), u32 address, u32 value (little-endian); a read is answered with its
 * u32 value on RESP_FIFO.  Ends at end of input; a malformed request is one
 * line on stderr and exit 1. */
#include <stdio.h>
#include <stdlib.h>

#include "cbvh_sim.h"

static uint32_t get32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: board_emu_regmap REQ_FIFO RESP_FIFO\n");
        return 2;
    }
    FILE *req = fopen(argv[1], "rb");
    FILE *resp = req ? fopen(argv[2], "wb") : NULL;
    if (!req || !resp) {
        fprintf(stderr, "board_emu_regmap: cannot open %s\n", req ? argv[2] : argv[1]);
        return 1;
    }
    static cbvh_regmap_model m;
    cbvh_regmap_model_init(&m);
    unsigned char r[9];
    size_t n;
    while ((n = fread(r, 1, sizeof r, req)) == sizeof r) {
        uint32_t addr = get32(r + 1), value = get32(r + 5);
        if (r[0] == 0) {
            cbvh_regmap_model_write(&m, addr, value);
        } else if (r[0] == 1) {
            uint32_t v = cbvh_regmap_model_read(&m, addr);
            unsigned char o[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                                  (unsigned char)(v >> 24)};
            if (fwrite(o, 1, 4, resp) != 4 || fflush(resp) != 0) return 1;
        } else if (r[0] == 2) {
            cbvh_regmap_model_init(&m);
        } else {
            fprintf(stderr, "board_emu_regmap: unknown request %u\n", r[0]);
            return 1;
        }
    }
    if (n != 0) {
        fprintf(stderr, "board_emu_regmap: request cut short (%zu of 9 bytes)\n", n);
        return 1;
    }
    return 0;
}
