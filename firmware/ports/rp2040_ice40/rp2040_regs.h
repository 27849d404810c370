/* The RP2040 registers this port touches, written from the RP2040 datasheet
 * (chapters 2.14-2.19 clocks/XOSC/PLL/resets/GPIO, 4.1 USB, 4.4 SPI, 4.6
 * timer, 4.7 watchdog tick, 4.10 SSI).  Run in emulation (rp2040js,
 * tests/board/emu); not on silicon. */
#ifndef CBVH_RP2040_REGS_H
#define CBVH_RP2040_REGS_H

#include <stdint.h>

#define REG32(a) (*(volatile uint32_t *)(uintptr_t)(a))
/* Atomic aliases of an APB register: +0x1000 XOR, +0x2000 set, +0x3000 clear. */
#define REG_SET(a) REG32((uintptr_t)&(a) + 0x2000u)
#define REG_CLR(a) REG32((uintptr_t)&(a) + 0x3000u)

/* Resets (2.14) */
#define RESETS_BASE 0x4000C000u
#define RESETS_RESET REG32(RESETS_BASE + 0x0u)
#define RESETS_DONE REG32(RESETS_BASE + 0x8u)
#define RESET_IO_BANK0 (1u << 5)
#define RESET_PADS_BANK0 (1u << 8)
#define RESET_PLL_SYS (1u << 12)
#define RESET_PLL_USB (1u << 13)
#define RESET_SPI0 (1u << 16)
#define RESET_SPI1 (1u << 17)
#define RESET_TIMER (1u << 21)
#define RESET_USBCTRL (1u << 24)

/* Clocks (2.15) */
#define CLOCKS_BASE 0x40008000u
#define CLK_GPOUT2_CTRL REG32(CLOCKS_BASE + 0x18u)
#define CLK_GPOUT2_DIV REG32(CLOCKS_BASE + 0x1Cu)
#define CLK_REF_CTRL REG32(CLOCKS_BASE + 0x30u)
#define CLK_REF_DIV REG32(CLOCKS_BASE + 0x34u)
#define CLK_REF_SELECTED REG32(CLOCKS_BASE + 0x38u)
#define CLK_SYS_CTRL REG32(CLOCKS_BASE + 0x3Cu)
#define CLK_SYS_DIV REG32(CLOCKS_BASE + 0x40u)
#define CLK_SYS_SELECTED REG32(CLOCKS_BASE + 0x44u)
#define CLK_PERI_CTRL REG32(CLOCKS_BASE + 0x48u)
#define CLK_USB_CTRL REG32(CLOCKS_BASE + 0x54u)
#define CLK_USB_DIV REG32(CLOCKS_BASE + 0x58u)
#define CLK_SYS_RESUS_CTRL REG32(CLOCKS_BASE + 0x78u)
#define CLK_ENABLE (1u << 11)
#define CLK_AUXSRC(n) ((uint32_t)(n) << 5)
#define CLK_DIV_INT(n) ((uint32_t)(n) << 8)
#define CLK_REF_SRC_ROSC 0u
#define CLK_REF_SRC_XOSC 2u
#define CLK_SYS_SRC_REF 0u
#define CLK_SYS_SRC_AUX 1u
#define CLK_SYS_AUX_PLL_SYS 0u
#define CLK_USB_AUX_PLL_USB 0u
#define CLK_PERI_AUX_CLK_SYS 0u
#define CLK_GPOUT_AUX_XOSC 5u

/* Crystal oscillator (2.16) */
#define XOSC_BASE 0x40024000u
#define XOSC_CTRL REG32(XOSC_BASE + 0x0u)
#define XOSC_STATUS REG32(XOSC_BASE + 0x4u)
#define XOSC_STARTUP REG32(XOSC_BASE + 0xCu)
#define XOSC_FREQ_1_15MHZ 0xAA0u
#define XOSC_ENABLE (0xFABu << 12)
#define XOSC_STABLE (1u << 31)

/* PLLs (2.18) */
#define PLL_SYS_BASE 0x40028000u
#define PLL_USB_BASE 0x4002C000u
#define PLL_CS(b) REG32((b) + 0x0u)
#define PLL_PWR(b) REG32((b) + 0x4u)
#define PLL_FBDIV_INT(b) REG32((b) + 0x8u)
#define PLL_PRIM(b) REG32((b) + 0xCu)
#define PLL_CS_LOCK (1u << 31)
#define PLL_PWR_PD (1u << 0)
#define PLL_PWR_POSTDIVPD (1u << 3)
#define PLL_PWR_VCOPD (1u << 5)

/* Watchdog tick: the timer's microsecond reference (4.7) */
#define WATCHDOG_TICK REG32(0x40058000u + 0x2Cu)
#define WATCHDOG_TICK_ENABLE (1u << 9)

/* GPIO (2.19) */
#define IO_BANK0_BASE 0x40014000u
#define GPIO_CTRL(n) REG32(IO_BANK0_BASE + 8u * (n) + 4u)
#define GPIO_FUNC_SPI 1u
#define GPIO_FUNC_SIO 5u
#define GPIO_FUNC_GPCK 8u
#define PADS_BANK0_BASE 0x4001C000u
#define PADS_GPIO(n) REG32(PADS_BANK0_BASE + 4u + 4u * (n))
#define PADS_IE (1u << 6)
#define PADS_PUE (1u << 3)
#define PADS_PDE (1u << 2)

#define SIO_BASE 0xD0000000u
#define SIO_GPIO_IN REG32(SIO_BASE + 0x04u)
#define SIO_GPIO_OUT_SET REG32(SIO_BASE + 0x14u)
#define SIO_GPIO_OUT_CLR REG32(SIO_BASE + 0x18u)
#define SIO_GPIO_OE_SET REG32(SIO_BASE + 0x24u)
#define SIO_GPIO_OE_CLR REG32(SIO_BASE + 0x28u)

/* SPI0/SPI1: ARM PL022 (4.4) */
#define SPI0_BASE 0x4003C000u
#define SPI1_BASE 0x40040000u
#define SSPCR0(b) REG32((b) + 0x00u)
#define SSPCR1(b) REG32((b) + 0x04u)
#define SSPDR(b) REG32((b) + 0x08u)
#define SSPSR(b) REG32((b) + 0x0Cu)
#define SSPCPSR(b) REG32((b) + 0x10u)
#define SSPSR_TNF (1u << 1)
#define SSPSR_RNE (1u << 2)
#define SSPSR_BSY (1u << 4)
#define SSPCR1_SSE (1u << 1)

/* Timer (4.6): microseconds since reset */
#define TIMER_TIMERAWL REG32(0x40054000u + 0x28u)

/* USB controller (4.1) */
#define USBCTRL_DPRAM_BASE 0x50100000u
#define USBCTRL_REGS_BASE 0x50110000u
#define USB_ADDR_ENDP REG32(USBCTRL_REGS_BASE + 0x00u)
#define USB_MAIN_CTRL REG32(USBCTRL_REGS_BASE + 0x40u)
#define USB_SIE_CTRL REG32(USBCTRL_REGS_BASE + 0x4Cu)
#define USB_SIE_STATUS REG32(USBCTRL_REGS_BASE + 0x50u)
#define USB_BUFF_STATUS REG32(USBCTRL_REGS_BASE + 0x58u)
#define USB_EP_STALL_ARM REG32(USBCTRL_REGS_BASE + 0x68u)
#define USB_MUXING REG32(USBCTRL_REGS_BASE + 0x74u)
#define USB_PWR REG32(USBCTRL_REGS_BASE + 0x78u)
#define USB_INTE REG32(USBCTRL_REGS_BASE + 0x90u)
#define USB_INTS REG32(USBCTRL_REGS_BASE + 0x98u)
#define USB_MAIN_CTRL_CONTROLLER_EN (1u << 0)
#define USB_SIE_CTRL_EP0_INT_1BUF (1u << 29)
#define USB_SIE_CTRL_PULLUP_EN (1u << 16)
#define USB_SIE_STATUS_SETUP_REC (1u << 17)
#define USB_SIE_STATUS_BUS_RESET (1u << 19)
#define USB_MUXING_TO_PHY (1u << 0)
#define USB_MUXING_SOFTCON (1u << 3)
#define USB_PWR_VBUS_DETECT (1u << 2)
#define USB_PWR_VBUS_DETECT_OVERRIDE_EN (1u << 3)
#define USB_INT_BUFF_STATUS (1u << 4)
#define USB_INT_BUS_RESET (1u << 12)
#define USB_INT_SETUP_REQ (1u << 16)
/* DPRAM, device mode: setup packet at 0, endpoint control words from 8
 * (EPn IN at 8n, OUT at 8n + 4, n >= 1), buffer control words from 0x80
 * (EPn IN at 0x80 + 8n, OUT at 0x84 + 8n), EP0's buffer at 0x100. */
#define USB_DPRAM_EP_CTRL(n, out) REG32(USBCTRL_DPRAM_BASE + 8u * (n) + ((out) ? 4u : 0u))
#define USB_DPRAM_BUF_CTRL(n, out) REG32(USBCTRL_DPRAM_BASE + 0x80u + 8u * (n) + ((out) ? 4u : 0u))
#define USB_DPRAM_EP0_BUF 0x100u
#define USB_DPRAM_DATA 0x180u
#define USB_EP_CTRL_ENABLE (1u << 31)
#define USB_EP_CTRL_INT_PER_BUFF (1u << 29)
#define USB_EP_CTRL_TYPE(t) ((uint32_t)(t) << 26)
#define USB_BUF_FULL (1u << 15)
#define USB_BUF_DATA1 (1u << 13)
#define USB_BUF_STALL (1u << 11)
#define USB_BUF_AVAILABLE (1u << 10)
#define USB_BUF_LEN_MASK 0x3FFu

/* Cortex-M0+ system control block */
#define SCB_VTOR REG32(0xE000ED08u)

#endif
