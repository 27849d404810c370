/* Pin-out of the target board: RP2040 + iCE40UP5K, FPGA on SPI0.  (An
 * assumption about a board of this kind, e.g. a pico-ice-style layout.) */
#ifndef CBVH_BOARD_H
#define CBVH_BOARD_H

#define BOARD_PIN_SPI_RX 16   /* FPGA -> MCU (CIPO) */
#define BOARD_PIN_SPI_CS 17   /* driven by SIO, active low */
#define BOARD_PIN_SPI_SCK 18
#define BOARD_PIN_SPI_TX 19   /* MCU -> FPGA (COPI) */
#define BOARD_SPI_PRESCALE 2  /* clk_peri / 2 */

#define BOARD_RX_IDLE_US 20000u /* firmware inter-byte timeout (docs/protocol.md) */

#endif
