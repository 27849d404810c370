/* Clocks and resets (RP2040 datasheet 2.14-2.18): XOSC 12 MHz; PLL_SYS to
 * 125 MHz for clk_sys and clk_peri; PLL_USB to 48 MHz for clk_usb; clk_ref
 * from the XOSC; the timer's microsecond tick from clk_ref; the FPGA's clock
 * (the XOSC's 12 MHz) on GPIO24 through clk_gpout2. */
#include "board.h"
#include "port.h"
#include "rp2040_regs.h"

static void pll_start(uint32_t base, uint32_t fbdiv, uint32_t postdiv1, uint32_t postdiv2) {
    PLL_CS(base) = 1; /* REFDIV 1: reference 12 MHz */
    PLL_FBDIV_INT(base) = fbdiv;
    REG_CLR(PLL_PWR(base)) = PLL_PWR_PD | PLL_PWR_VCOPD;
    while (!(PLL_CS(base) & PLL_CS_LOCK)) {}
    PLL_PRIM(base) = postdiv1 << 16 | postdiv2 << 12;
    REG_CLR(PLL_PWR(base)) = PLL_PWR_POSTDIVPD;
}

void board_unreset(uint32_t bits) {
    REG_CLR(RESETS_RESET) = bits;
    while ((RESETS_DONE & bits) != bits) {}
}

void board_clocks_init(void) {
    CLK_SYS_RESUS_CTRL = 0;
    XOSC_CTRL = XOSC_FREQ_1_15MHZ;
    XOSC_STARTUP = (BOARD_XOSC_HZ / 1000u + 128u) / 256u; /* about 1 ms, in units of 256 cycles */
    REG_SET(XOSC_CTRL) = XOSC_ENABLE;
    while (!(XOSC_STATUS & XOSC_STABLE)) {}

    /* Off the PLLs' outputs (the boot ROM may have left clk_sys on one) before resetting them. */
    REG_CLR(CLK_SYS_CTRL) = 1u; /* SRC = clk_ref */
    while (CLK_SYS_SELECTED != 1u << CLK_SYS_SRC_REF) {}
    CLK_REF_CTRL = CLK_REF_SRC_ROSC;
    while (CLK_REF_SELECTED != 1u << CLK_REF_SRC_ROSC) {}
    REG_SET(RESETS_RESET) = RESET_PLL_SYS | RESET_PLL_USB;
    board_unreset(RESET_PLL_SYS | RESET_PLL_USB);
    pll_start(PLL_SYS_BASE, 125, 6, 2); /* VCO 1500 MHz / 12 = 125 MHz */
    pll_start(PLL_USB_BASE, 100, 5, 5); /* VCO 1200 MHz / 25 = 48 MHz */

    CLK_REF_CTRL = CLK_REF_SRC_XOSC;
    while (CLK_REF_SELECTED != 1u << CLK_REF_SRC_XOSC) {}
    CLK_REF_DIV = CLK_DIV_INT(1);
    CLK_SYS_DIV = CLK_DIV_INT(1);
    CLK_SYS_CTRL = CLK_AUXSRC(CLK_SYS_AUX_PLL_SYS) | CLK_SYS_SRC_REF;
    CLK_SYS_CTRL = CLK_AUXSRC(CLK_SYS_AUX_PLL_SYS) | CLK_SYS_SRC_AUX;
    while (CLK_SYS_SELECTED != 1u << CLK_SYS_SRC_AUX) {}
    CLK_USB_DIV = CLK_DIV_INT(1);
    CLK_USB_CTRL = CLK_ENABLE | CLK_AUXSRC(CLK_USB_AUX_PLL_USB);
    CLK_PERI_CTRL = CLK_ENABLE | CLK_AUXSRC(CLK_PERI_AUX_CLK_SYS);
    WATCHDOG_TICK = WATCHDOG_TICK_ENABLE | (BOARD_XOSC_HZ / 1000000u); /* 1 us from clk_ref */

    board_unreset(RESET_IO_BANK0 | RESET_PADS_BANK0 | RESET_TIMER);
    CLK_GPOUT2_DIV = CLK_DIV_INT(1);
    CLK_GPOUT2_CTRL = CLK_ENABLE | CLK_AUXSRC(CLK_GPOUT_AUX_XOSC);
    GPIO_CTRL(BOARD_PIN_FPGA_CLK) = GPIO_FUNC_GPCK;
}

uint32_t board_time_us(void) { return TIMER_TIMERAWL; }

void board_wait_us(uint32_t us) {
    uint32_t t0 = TIMER_TIMERAWL;
    while (TIMER_TIMERAWL - t0 <= us) {}
}
