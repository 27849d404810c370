/* FPGA configuration at boot, iCE40 SPI-slave mode (Lattice TN1248, "iCE40
 * Programming and Configuration", SPI slave configuration): CRESET_B low with
 * SPI_SS low, CRESET_B high (the iCE40 samples SS: low = slave mode), wait
 * >= 1200 us while it clears its configuration memory, SS high for 8 dummy
 * clocks, SS low, the bitstream MSB first, SS high, >= 100 clocks, CDONE must
 * be high, then >= 49 more clocks to start the user I/O.  The bitstream is
 * read from its flash region (board.h) after its header and CRC check. */
#include "board.h"
#include "cbvh_fw/frame.h"
#include "port.h"
#include "rp2040_regs.h"

static void cfg_byte(uint8_t b) {
    while (!(SSPSR(SPI1_BASE) & SSPSR_TNF)) {}
    SSPDR(SPI1_BASE) = b;
    while (SSPSR(SPI1_BASE) & SSPSR_RNE) (void)SSPDR(SPI1_BASE); /* nothing to read: keep RX empty */
}

static void cfg_idle(void) {
    while (SSPSR(SPI1_BASE) & SSPSR_BSY) {}
    while (SSPSR(SPI1_BASE) & SSPSR_RNE) (void)SSPDR(SPI1_BASE);
}

static void cfg_clocks(unsigned bytes) {
    for (unsigned i = 0; i < bytes; i++) cfg_byte(0);
    cfg_idle();
}

static void pin_out(unsigned pin, int level) {
    if (level) SIO_GPIO_OUT_SET = 1u << pin;
    else SIO_GPIO_OUT_CLR = 1u << pin;
}

const uint8_t *board_bitstream(uint32_t *len) {
    const uint8_t *h = (const uint8_t *)(uintptr_t)BOARD_BITSTREAM_ADDR;
    uint32_t n = cbvh_get32(h + 4);
    *len = 0;
    if (cbvh_get32(h) != BOARD_BITSTREAM_MAGIC || n == 0 || n > BOARD_BITSTREAM_MAX || cbvh_get32(h + 12) != 0)
        return 0;
    if (cbvh_crc32(0, h + BOARD_BITSTREAM_HDR, n) != cbvh_get32(h + 8)) return 0;
    *len = n;
    return h + BOARD_BITSTREAM_HDR;
}

int board_fpga_configure(void) {
    uint32_t n;
    const uint8_t *bits = board_bitstream(&n);
    if (!bits) return BOARD_FPGA_NO_BITSTREAM;
    board_unreset(RESET_SPI1);
    GPIO_CTRL(BOARD_PIN_CFG_RX) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_CFG_SCK) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_CFG_TX) = GPIO_FUNC_SPI;
    GPIO_CTRL(BOARD_PIN_CFG_SS) = GPIO_FUNC_SIO;
    GPIO_CTRL(BOARD_PIN_FPGA_CRESET) = GPIO_FUNC_SIO;
    GPIO_CTRL(BOARD_PIN_FPGA_CDONE) = GPIO_FUNC_SIO;
    PADS_GPIO(BOARD_PIN_FPGA_CDONE) = PADS_IE | PADS_PUE; /* open drain on the iCE40 side */
    SIO_GPIO_OE_CLR = 1u << BOARD_PIN_FPGA_CDONE;
    SSPCPSR(SPI1_BASE) = BOARD_CFG_CPSDVSR;
    SSPCR0(SPI1_BASE) = BOARD_CFG_SCR << 8 | 1u << 7 | 1u << 6 | 7u; /* SCR, SPH=1, SPO=1 (mode 3), 8 bits */
    SSPCR1(SPI1_BASE) = SSPCR1_SSE;

    pin_out(BOARD_PIN_CFG_SS, 0);
    pin_out(BOARD_PIN_FPGA_CRESET, 0);
    SIO_GPIO_OE_SET = 1u << BOARD_PIN_CFG_SS | 1u << BOARD_PIN_FPGA_CRESET;
    board_wait_us(BOARD_CFG_CRESET_LOW_US);
    pin_out(BOARD_PIN_FPGA_CRESET, 1);
    board_wait_us(BOARD_CFG_WAIT_US);
    pin_out(BOARD_PIN_CFG_SS, 1);
    cfg_clocks(1); /* 8 dummy clocks with SS high */
    pin_out(BOARD_PIN_CFG_SS, 0);
    for (uint32_t i = 0; i < n; i++) cfg_byte(bits[i]);
    cfg_idle();
    pin_out(BOARD_PIN_CFG_SS, 1);
    cfg_clocks(BOARD_CFG_TRAIL_BYTES);
    uint32_t t0 = board_time_us();
    while (!(SIO_GPIO_IN & 1u << BOARD_PIN_FPGA_CDONE)) {
        if (board_time_us() - t0 > BOARD_CFG_CDONE_WAIT_US) return BOARD_FPGA_CDONE_LOW;
    }
    cfg_clocks(BOARD_CFG_USER_IO_BYTES);
    return BOARD_FPGA_OK;
}
