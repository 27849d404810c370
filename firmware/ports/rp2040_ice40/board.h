/* The board: tinyVision.ai pico-ice (RP2040 + iCE40UP5K).  Pins from the
 * board's public pin definitions (pico-ice-sdk include/boards/pico_ice.h and
 * rtl/pico_ice.pcf; docs/board.md cites them): the FPGA's configuration port
 * on SPI1, its CRESET_B/CDONE and clock on GPIO 27/26/24, and four FPGA pins
 * (27, 25, 21, 19) wired to RP2040 GPIO 0-3, which are SPI0's RX, CSn, SCK
 * and TX: the register-map bus (gateware/board/board.pcf). */
#ifndef CBVH_BOARD_H
#define CBVH_BOARD_H

/* Register-map bus: SPI0 (FPGA pins 27, 25, 21, 19; gateware/board/board.pcf). */
#define BOARD_PIN_SPI_RX 0  /* FPGA pin 27 -> MCU (CIPO) */
#define BOARD_PIN_SPI_CS 1  /* FPGA pin 25, driven by SIO, active low */
#define BOARD_PIN_SPI_SCK 2 /* FPGA pin 21 */
#define BOARD_PIN_SPI_TX 3  /* FPGA pin 19, MCU -> FPGA (COPI) */

/* FPGA configuration port: SPI1 to the iCE40's SPI_SO/SS/SCK/SI (pins 14,
 * 16, 15, 17), shared with the FPGA's own flash (whose CS is the same SS net). */
#define BOARD_PIN_CFG_RX 8   /* iCE40 SPI_SO */
#define BOARD_PIN_CFG_SS 9   /* iCE40 SPI_SS, driven by SIO */
#define BOARD_PIN_CFG_SCK 10 /* iCE40 SPI_SCK */
#define BOARD_PIN_CFG_TX 11  /* iCE40 SPI_SI */
#define BOARD_PIN_FPGA_CLK 24    /* clk_gpout2 -> iCE40 pin 35 (IOT_46b_G0) */
#define BOARD_PIN_FPGA_CDONE 26  /* input */
#define BOARD_PIN_FPGA_CRESET 27 /* CRESET_B, active low */

/* LEDs (RGB, shared with the FPGA): not driven by this firmware. */
#define BOARD_PIN_LED_R 13
#define BOARD_PIN_LED_G 12
#define BOARD_PIN_LED_B 15

/* Clocks: XOSC 12 MHz; PLL_SYS 12 MHz / 1 * 125 / (6 * 2) = 125 MHz; PLL_USB
 * 12 MHz / 1 * 100 / (5 * 5) = 48 MHz; clk_peri = clk_sys; the FPGA's clock
 * = XOSC on clk_gpout2 (12 MHz, what the gateware's timing is built for). */
#define BOARD_XOSC_HZ 12000000u
#define BOARD_SYS_HZ 125000000u

/* Register-map SPI: SCK = clk_peri / (CPSDVSR * (1 + SCR)) = 125 MHz / (2 * 42)
 * = 1.488 MHz.  The gateware's SPI slave oversamples (gateware/board/
 * spi_slave.v): SCK at most 1/8 of the FPGA's 12 MHz clock, 1.5 MHz. */
#define BOARD_SPI_CPSDVSR 2u
#define BOARD_SPI_SCR 41u
/* CS high between transactions and CS low before the first SCK edge: at least
 * 4 FPGA clocks (0.33 us) each, for the slave's synchronisers; 2 us here. */
#define BOARD_SPI_CS_GAP_US 2u

/* FPGA configuration SPI (iCE40 sysCONFIG slave mode, Lattice TN1248): SCK
 * 125 MHz / (2 * 3) = 20.8 MHz (the iCE40 takes 1-25 MHz); mode 3 (CPOL=1,
 * CPHA=1: the iCE40 samples SI on the rising edge, SCK idles high). */
#define BOARD_CFG_CPSDVSR 2u
#define BOARD_CFG_SCR 2u
#define BOARD_CFG_CRESET_LOW_US 2u   /* CRESET_B low pulse, >= 200 ns */
#define BOARD_CFG_WAIT_US 1300u      /* after CRESET_B high, >= 1200 us for the UP5K to clear its CRAM */
#define BOARD_CFG_TRAIL_BYTES 13u     /* >= 100 SCK cycles after the last bitstream byte (104) */
#define BOARD_CFG_CDONE_WAIT_US 1000u /* then CDONE must be high within this */
#define BOARD_CFG_USER_IO_BYTES 7u    /* then >= 49 more SCK cycles (56) start the user I/O */

/* Where the bitstream is: a named flash region, 1 MiB into the RP2040's flash
 * (pico-ice: 4 MiB), with a 16-byte header (tools/rp2040_image.c, bitstream):
 * u32 magic "CBVB", u32 length, u32 CRC-32 (IEEE, as the frame's) of the
 * bitstream bytes, u32 0; then the bytes as icepack wrote them. */
#define BOARD_BITSTREAM_ADDR 0x10100000u
#define BOARD_BITSTREAM_MAGIC 0x42564243u /* "CBVB" little-endian */
#define BOARD_BITSTREAM_HDR 16u
#define BOARD_BITSTREAM_MAX (1024u * 1024u - BOARD_BITSTREAM_HDR)

#define BOARD_RX_IDLE_US 20000u /* firmware inter-byte timeout (docs/protocol.md) */
#define BOARD_TX_STALL_US 250000u /* an IN packet the host has not taken for this long: reply dropped */

#endif
