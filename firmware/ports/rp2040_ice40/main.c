/* RP2040 + iCE40UP5K firmware: the core with the SPI register-map driver and
 * the USB link.  Cross-compiled in CI for its size; not run on hardware. */
#include "board.h"
#include "cbvh_fw/fw.h"
#include "port.h"
#include "rp2040_regs.h"

static cbvh_fw fw; /* static: no heap anywhere */
static const cbvh_fw_hal hal = {0, board_reg_read, board_reg_write, board_usb_send, "cbvh-rp2040"};

int main(void) {
    board_spi_init();
    cbvh_fw_init(&fw, &hal);
    uint32_t last_rx = TIMER_TIMERAWL;
    for (;;) {
        uint8_t buf[64];
        size_t n = board_usb_take(buf, sizeof buf);
        if (n) {
            cbvh_fw_rx(&fw, buf, n);
            last_rx = TIMER_TIMERAWL;
        } else if (cbvh_fw_rx_partial(&fw) && TIMER_TIMERAWL - last_rx > BOARD_RX_IDLE_US) {
            cbvh_fw_rx_idle(&fw);
        }
    }
}
