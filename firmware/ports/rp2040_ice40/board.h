/* Pin-out of the target board: RP2040 + iCE40UP5K, FPGA on SPI0.  (An
 * assumption about a board of this kind, e.g. a pico-ice-style layout.) */
#ifndef CBVH_BOARD_H
#define CBVH_BOARD_H

#define BOARD_PIN_SPI_RX 16   /* FPGA -> MCU (CIPO) */
#define BOARD_PIN_SPI_CS 17   /* driven by SIO, active low */
#define BOARD_PIN_SPI_SCK 18
#define BOARD_PIN_SPI_TX 19   /* MCU -> FPGA (COPI) */
/* SCK = clk_peri / 8.  The gateware's SPI slave oversamples (gateware/board/
 * spi_slave.v): SCK at most 1/8 of the FPGA's 12 MHz clock, 1.5 MHz.  clk_peri
 * is clk_sys, still on the ring oscillator (this port sets up no PLL): at most
 * 12 MHz, so /8 stays within the limit. */
#define BOARD_SPI_PRESCALE 8
/* CS high between transactions and CS low before the first SCK edge: at least
 * 4 FPGA clocks (0.33 us) each, for the slave's synchronisers; 2 us here. */
#define BOARD_SPI_CS_GAP_US 2u

#define BOARD_RX_IDLE_US 20000u /* firmware inter-byte timeout (docs/protocol.md) */

#endif
