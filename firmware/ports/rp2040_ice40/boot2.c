/* Second-stage boot (boot2) for W25Q-style QSPI flash: the 256 bytes at the
 * start of flash that the RP2040 boot ROM copies to SRAM (0x20041F00), checks
 * (CRC-32 of the first 252 bytes in the last 4: rp2040_image.c, boot2) and
 * runs.  It sets the flash's QE bit, switches the SSI to quad-I/O fast read
 * (EBh) in continuous-read mode, so the image runs in place (XIP), then
 * enters the image through its vector table at 0x10000100.  Written from the
 * RP2040 datasheet (2.8.1 boot sequence, 4.10 SSI) and the W25Q command set
 * (35h/05h/06h/01h/EBh); freestanding, no calls, linked at 0x20041F00 by
 * boot2.ld and checked to fit in 252 bytes. */
#include <stdint.h>

#define R(a) (*(volatile uint32_t *)(a))
/* SSI registers as one block, so the code addresses them from one base. */
typedef struct {
    uint32_t ctrlr0, ctrlr1, ssienr, mwcr, ser, baudr, pad0[4], sr, pad1[13], dr0, pad2[35], rx_sample_dly, spi_ctrlr0;
} ssi_regs;
#define SSI (*(volatile ssi_regs *)0x18000000u)
#define SSI_CTRLR0 SSI.ctrlr0
#define SSI_CTRLR1 SSI.ctrlr1
#define SSI_SSIENR SSI.ssienr
#define SSI_BAUDR SSI.baudr
#define SSI_SR SSI.sr
#define SSI_DR0 SSI.dr0
#define SSI_RX_SAMPLE_DLY SSI.rx_sample_dly
#define SSI_SPI_CTRLR0 SSI.spi_ctrlr0
_Static_assert(__builtin_offsetof(ssi_regs, sr) == 0x28, "SSI SR");
_Static_assert(__builtin_offsetof(ssi_regs, dr0) == 0x60, "SSI DR0");
_Static_assert(__builtin_offsetof(ssi_regs, rx_sample_dly) == 0xF0, "SSI RX_SAMPLE_DLY");
_Static_assert(__builtin_offsetof(ssi_regs, spi_ctrlr0) == 0xF4, "SSI SPI_CTRLR0");
#define SR_BUSY 1u
#define SR_TFE 4u
#define PADS_QSPI_SCLK R(0x40020000u + 0x04u)
#define VTOR R(0xE000ED08u)

/* CTRLR0 fields: SPI_FRF [22:21] (0 standard, 2 quad), DFS_32 [20:16] (frame
 * bits - 1), TMOD [9:8] (0 transmit and receive, 3 EEPROM read). */
#define CTRLR0_STD_8 (7u << 16)
#define CTRLR0_QUAD_32_EEPROM ((2u << 21) | (31u << 16) | (3u << 8))
/* SPI_CTRLR0: XIP_CMD [31:24], WAIT_CYCLES [15:11], INST_L [9:8] (2 = 8 bits),
 * ADDR_L [5:2] (in 4-bit units: 8 = 24 address + 8 mode bits), TRANS_TYPE
 * [1:0] (1 = command serial, address quad; 2 = both quad). */
#define MODE_CONTINUOUS 0xA0u
#define SPI_CTRLR0_FIRST ((4u << 11) | (2u << 8) | (8u << 2) | 1u)
#define SPI_CTRLR0_XIP ((MODE_CONTINUOUS << 24) | (4u << 11) | (0u << 8) | (8u << 2) | 2u)

static void wait_idle(void) {
    while ((SSI_SR & (SR_BUSY | SR_TFE)) != SR_TFE) {}
}

/* Sends the n bytes packed in b (first byte in the low bits) in standard SPI
 * mode; returns the last byte received. */
static uint32_t flash_cmd(uint32_t b, unsigned n) {
    for (unsigned i = 0; i < n; i++) SSI_DR0 = (b >> (8 * i)) & 0xFFu;
    wait_idle();
    uint32_t v = 0;
    for (unsigned i = 0; i < n; i++) v = SSI_DR0;
    return v;
}

__attribute__((section(".boot2.entry"), noreturn, used)) void boot2_entry(void) {
    PADS_QSPI_SCLK = (2u << 4) | 1u; /* 8 mA, fast slew */
    SSI_SSIENR = 0;
    SSI_BAUDR = 4; /* clk_sys / 4: 31.25 MHz once clk_sys is 125 MHz */
    SSI_RX_SAMPLE_DLY = 1;
    SSI_CTRLR0 = CTRLR0_STD_8;
    SSI_SSIENR = 1;

    if (!(flash_cmd(0x35u, 2) & 0x02u)) { /* read status register 2: QE clear, so set it */
        flash_cmd(0x06u, 1);               /* write enable */
        flash_cmd(0x020001u, 3);           /* write status registers 1, 2: 00h, 02h */
        while (flash_cmd(0x05u, 2) & 1u) {} /* status register 1: BUSY */
    }

    SSI_SSIENR = 0;
    SSI_CTRLR0 = CTRLR0_QUAD_32_EEPROM;
    SSI_CTRLR1 = 0; /* one data frame per transfer */
    SSI_SPI_CTRLR0 = SPI_CTRLR0_FIRST;
    SSI_SSIENR = 1;
    /* One EBh read with mode bits A0h puts the flash in continuous-read mode. */
    SSI_DR0 = 0xEB;
    SSI_DR0 = MODE_CONTINUOUS; /* address 0, mode bits */
    wait_idle();
    (void)SSI_DR0;
    /* From now on every XIP access sends only address + mode bits. */
    SSI_SSIENR = 0;
    SSI_SPI_CTRLR0 = SPI_CTRLR0_XIP;
    SSI_SSIENR = 1;

    /* Enter the image: vector table right after boot2. */
    const uint32_t *vt = (const uint32_t *)0x10000100u;
    VTOR = (uint32_t)(uintptr_t)vt;
    __asm__ volatile("msr msp, %0\n\tbx %1" : : "r"(vt[0]), "r"(vt[1]));
    __builtin_unreachable();
}
