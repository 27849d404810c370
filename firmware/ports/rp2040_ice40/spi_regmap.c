/* The FPGA register map over SPI0 (PL022, mode 0, 8-bit frames), one
 * transaction per register access with CS low around it; the bytes are
 * cbvh_fw/spi_wire.h's.  Pins and SCK: board.h. */
#include "board.h"
#include "cbvh_fw/spi_wire.h"
#include "port.h"
#include "rp2040_regs.h"

static int fpga_live;

static uint8_t xfer(uint8_t out) {
    while (!(SSPSR(SPI0_BASE) & SSPSR_TNF)) {}
    SSPDR(SPI0_BASE) = out;
    while (!(SSPSR(SPI0_BASE) & SSPSR_RNE)) {}
    return (uint8_t)SSPDR(SPI0_BASE);
}

static void cs(int active) {
    while (SSPSR(SPI0_BASE) & SSPSR_BSY) {}
    if (active) SIO_GPIO_OUT_CLR = 1u << BOARD_PIN_SPI_CS;
    else SIO_GPIO_OUT_SET = 1u << BOARD_PIN_SPI_CS;
    board_wait_us(BOARD_SPI_CS_GAP_US);
}

void board_spi_init(int live) {
    fpga_live = live;
    board_unreset(RESET_SPI0);
    GPIO_CTRL(BOARD_PIN_SPI_RX) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_SPI_SCK) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_SPI_TX) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_SPI_CS) = GPIO_FUNC_SIO;
    SIO_GPIO_OUT_SET = 1u << BOARD_PIN_SPI_CS;
    SIO_GPIO_OE_SET = 1u << BOARD_PIN_SPI_CS;
    SSPCPSR(SPI0_BASE) = BOARD_SPI_CPSDVSR;
    SSPCR0(SPI0_BASE) = BOARD_SPI_SCR << 8 | 7u; /* SCR, Motorola SPI mode 0, 8 bits */
    SSPCR1(SPI0_BASE) = SSPCR1_SSE;
}

static void transaction(const uint8_t *out, uint8_t *in, unsigned n) {
    cs(1);
    for (unsigned i = 0; i < n; i++) in[i] = xfer(out[i]);
    cs(0);
}

uint32_t board_reg_read(void *ctx, uint32_t addr) {
    (void)ctx;
    if (!fpga_live) return 0;
    uint8_t out[CBVH_SPI_READ_BYTES], in[CBVH_SPI_READ_BYTES];
    cbvh_spi_read_bytes(addr, out);
    transaction(out, in, CBVH_SPI_READ_BYTES);
    return cbvh_spi_read_value(in);
}

void board_reg_write(void *ctx, uint32_t addr, uint32_t value) {
    (void)ctx;
    if (!fpga_live) return;
    uint8_t out[CBVH_SPI_WRITE_BYTES], in[CBVH_SPI_WRITE_BYTES];
    cbvh_spi_write_bytes(addr, value, out);
    transaction(out, in, CBVH_SPI_WRITE_BYTES);
}
