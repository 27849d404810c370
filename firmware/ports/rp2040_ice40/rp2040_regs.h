/* The few RP2040 registers this port touches (RP2040 datasheet, chapter 2-4).
 * Written from the datasheet; nothing here has run on silicon. */
#ifndef CBVH_RP2040_REGS_H
#define CBVH_RP2040_REGS_H

#include <stdint.h>

#define REG32(a) (*(volatile uint32_t *)(uintptr_t)(a))
#define ATOMIC_CLR(a) ((a) + 0x3000u) /* write-1-to-clear alias */

#define RESETS_BASE 0x4000C000u
#define RESETS_RESET REG32(RESETS_BASE + 0x0u)
#define RESETS_DONE REG32(RESETS_BASE + 0x8u)
#define RESET_IO_BANK0 (1u << 5)
#define RESET_PADS_BANK0 (1u << 8)
#define RESET_SPI0 (1u << 16)
#define RESET_TIMER (1u << 21)

#define CLOCKS_BASE 0x40008000u
#define CLK_PERI_CTRL REG32(CLOCKS_BASE + 0x48u)
#define CLK_PERI_ENABLE (1u << 11)

#define IO_BANK0_BASE 0x40014000u
#define GPIO_CTRL(n) REG32(IO_BANK0_BASE + 8u * (n) + 4u)
#define GPIO_FUNC_SPI 1u
#define GPIO_FUNC_SIO 5u

#define SIO_BASE 0xD0000000u
#define SIO_GPIO_OUT_SET REG32(SIO_BASE + 0x14u)
#define SIO_GPIO_OUT_CLR REG32(SIO_BASE + 0x18u)
#define SIO_GPIO_OE_SET REG32(SIO_BASE + 0x24u)
#define SIO_GPIO_IN REG32(SIO_BASE + 0x04u)

/* SPI0 is an ARM PL022. */
#define SPI0_BASE 0x4003C000u
#define SSPCR0 REG32(SPI0_BASE + 0x00u)
#define SSPCR1 REG32(SPI0_BASE + 0x04u)
#define SSPDR REG32(SPI0_BASE + 0x08u)
#define SSPSR REG32(SPI0_BASE + 0x0Cu)
#define SSPCPSR REG32(SPI0_BASE + 0x10u)
#define SSPSR_TNF (1u << 1)
#define SSPSR_RNE (1u << 2)
#define SSPSR_BSY (1u << 4)

#define TIMER_BASE 0x40054000u
#define TIMER_TIMERAWL REG32(TIMER_BASE + 0x28u) /* microseconds, free running */

#endif
