/* RP2040 + iCE40UP5K port: what the port's files give each other. */
#ifndef CBVH_PORT_RP2040_H
#define CBVH_PORT_RP2040_H

#include <stddef.h>
#include <stdint.h>

#include "usbd.h"

/* clocks.c */
void board_clocks_init(void);
void board_unreset(uint32_t bits);
uint32_t board_time_us(void);
void board_wait_us(uint32_t us);

/* fpga_config.c: configures the FPGA from the bitstream region at boot. */
enum { BOARD_FPGA_OK = 0, BOARD_FPGA_NO_BITSTREAM = 1, BOARD_FPGA_CDONE_LOW = 2 };
int board_fpga_configure(void);
const uint8_t *board_bitstream(uint32_t *len); /* checked header, or NULL */

/* spi_regmap.c: the register map over SPI0; with live = 0 (no FPGA) reads
 * return 0 and writes go nowhere. */
void board_spi_init(int live);
uint32_t board_reg_read(void *ctx, uint32_t addr);
void board_reg_write(void *ctx, uint32_t addr, uint32_t value);

/* usb_rp2040.c */
void board_usb_init(usbd_dev *d, const usbd_class *cls);
void board_usb_poll(void *ctx);

#endif
