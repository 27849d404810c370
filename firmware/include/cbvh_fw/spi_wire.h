/* The bytes of one register-map transaction on the FPGA's SPI bus
 * (docs/protocol.md, "Datapath register map"): command byte (0x80 read,
 * 0x00 write), the 16-bit word address big-endian, then 4 data bytes
 * little-endian; a read has one turnaround byte before its data.  Shared by
 * the RP2040 port (PL022 master) and the sim port's gateware bridge, so the
 * simulated RTL sees exactly the bytes the board would. */
#ifndef CBVH_FW_SPI_WIRE_H
#define CBVH_FW_SPI_WIRE_H

#include <stdint.h>

#define CBVH_SPI_CMD_READ 0x80u
#define CBVH_SPI_CMD_WRITE 0x00u
#define CBVH_SPI_READ_BYTES 8u  /* cmd, addr hi, addr lo, turnaround, 4 data */
#define CBVH_SPI_WRITE_BYTES 7u /* cmd, addr hi, addr lo, 4 data */
#define CBVH_SPI_READ_DATA 4u   /* index of the first data byte of a read */

/* addr is a byte address; the bus carries addr / 4. */
static inline void cbvh_spi_read_bytes(uint32_t addr, uint8_t out[CBVH_SPI_READ_BYTES]) {
    out[0] = CBVH_SPI_CMD_READ;
    out[1] = (uint8_t)(addr >> 10);
    out[2] = (uint8_t)(addr >> 2);
    for (unsigned i = 3; i < CBVH_SPI_READ_BYTES; i++) out[i] = 0;
}

static inline void cbvh_spi_write_bytes(uint32_t addr, uint32_t value, uint8_t out[CBVH_SPI_WRITE_BYTES]) {
    out[0] = CBVH_SPI_CMD_WRITE;
    out[1] = (uint8_t)(addr >> 10);
    out[2] = (uint8_t)(addr >> 2);
    for (unsigned i = 0; i < 4; i++) out[3 + i] = (uint8_t)(value >> (8 * i));
}

/* The register value in the bytes the FPGA answered during a read. */
static inline uint32_t cbvh_spi_read_value(const uint8_t in[CBVH_SPI_READ_BYTES]) {
    uint32_t v = 0;
    for (unsigned i = 0; i < 4; i++) v |= (uint32_t)in[CBVH_SPI_READ_DATA + i] << (8 * i);
    return v;
}

#endif
