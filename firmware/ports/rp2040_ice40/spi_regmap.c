/* The FPGA register map over SPI0 (PL022, mode 0, 8-bit frames).
 * Transaction: CS low, command byte (0x80 = read, 0x00 = write), 16-bit word
 * address big-endian, then 4 data bytes little-endian (for a read the FPGA
 * answers in those 4 byte slots after one turnaround byte), CS high. */
#include "board.h"
#include "port.h"
#include "rp2040_regs.h"

static uint8_t xfer(uint8_t out) {
    while (!(SSPSR & SSPSR_TNF)) {}
    SSPDR = out;
    while (!(SSPSR & SSPSR_RNE)) {}
    return (uint8_t)SSPDR;
}

static void cs(int active) {
    while (SSPSR & SSPSR_BSY) {}
    if (active) SIO_GPIO_OUT_CLR = 1u << BOARD_PIN_SPI_CS;
    else SIO_GPIO_OUT_SET = 1u << BOARD_PIN_SPI_CS;
}

void board_spi_init(void) {
    RESETS_RESET &= ~(RESET_SPI0 | RESET_IO_BANK0 | RESET_PADS_BANK0 | RESET_TIMER);
    while ((RESETS_DONE & (RESET_SPI0 | RESET_IO_BANK0 | RESET_PADS_BANK0 | RESET_TIMER)) !=
           (RESET_SPI0 | RESET_IO_BANK0 | RESET_PADS_BANK0 | RESET_TIMER)) {}
    CLK_PERI_CTRL = CLK_PERI_ENABLE; /* AUXSRC 0 = clk_sys */
    GPIO_CTRL(BOARD_PIN_SPI_RX) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_SPI_SCK) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_SPI_TX) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_SPI_CS) = GPIO_FUNC_SIO;
    SIO_GPIO_OUT_SET = 1u << BOARD_PIN_SPI_CS;
    SIO_GPIO_OE_SET = 1u << BOARD_PIN_SPI_CS;
    SSPCPSR = BOARD_SPI_PRESCALE;
    SSPCR0 = 7u; /* DSS = 8 bits, Motorola SPI mode 0, SCR 0 */
    SSPCR1 = 1u << 1; /* SSE */
}

uint32_t board_reg_read(void *ctx, uint32_t addr) {
    (void)ctx;
    cs(1);
    xfer(0x80);
    xfer((uint8_t)(addr >> 10));
    xfer((uint8_t)(addr >> 2));
    xfer(0); /* turnaround */
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v |= (uint32_t)xfer(0) << (8 * i);
    cs(0);
    return v;
}

void board_reg_write(void *ctx, uint32_t addr, uint32_t value) {
    (void)ctx;
    cs(1);
    xfer(0x00);
    xfer((uint8_t)(addr >> 10));
    xfer((uint8_t)(addr >> 2));
    for (int i = 0; i < 4; i++) xfer((uint8_t)(value >> (8 * i)));
    cs(0);
}
