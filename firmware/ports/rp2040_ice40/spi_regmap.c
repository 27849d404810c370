/* The FPGA register map over SPI0 (PL022, mode 0, 8-bit frames), one
 * transaction per register access with CS low around it; the bytes are
 * cbvh_fw/spi_wire.h's. */
#include "board.h"
#include "cbvh_fw/spi_wire.h"
#include "port.h"
#include "rp2040_regs.h"

static uint8_t xfer(uint8_t out) {
    while (!(SSPSR & SSPSR_TNF)) {}
    SSPDR = out;
    while (!(SSPSR & SSPSR_RNE)) {}
    return (uint8_t)SSPDR;
}

static void wait_us(uint32_t us) {
    uint32_t t0 = TIMER_TIMERAWL;
    while (TIMER_TIMERAWL - t0 <= us) {}
}

static void cs(int active) {
    while (SSPSR & SSPSR_BSY) {}
    if (active) SIO_GPIO_OUT_CLR = 1u << BOARD_PIN_SPI_CS;
    else SIO_GPIO_OUT_SET = 1u << BOARD_PIN_SPI_CS;
    wait_us(BOARD_SPI_CS_GAP_US);
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

static void transaction(const uint8_t *out, uint8_t *in, unsigned n) {
    cs(1);
    for (unsigned i = 0; i < n; i++) in[i] = xfer(out[i]);
    cs(0);
}

uint32_t board_reg_read(void *ctx, uint32_t addr) {
    (void)ctx;
    uint8_t out[CBVH_SPI_READ_BYTES], in[CBVH_SPI_READ_BYTES];
    cbvh_spi_read_bytes(addr, out);
    transaction(out, in, CBVH_SPI_READ_BYTES);
    return cbvh_spi_read_value(in);
}

void board_reg_write(void *ctx, uint32_t addr, uint32_t value) {
    (void)ctx;
    uint8_t out[CBVH_SPI_WRITE_BYTES], in[CBVH_SPI_WRITE_BYTES];
    cbvh_spi_write_bytes(addr, value, out);
    transaction(out, in, CBVH_SPI_WRITE_BYTES);
}
