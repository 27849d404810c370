/* RP2040 + iCE40UP5K firmware (pico-ice, docs/board.md): configures the
 * FPGA, brings up USB, and runs the firmware core on the bytes from the host.
 * IDENTIFY's board name says whether the FPGA came up: "cbvh-rp2040", or
 * "cbvh-cdone-low" (configuration sent, CDONE stayed low) or "cbvh-no-bits"
 * (no valid bitstream in its flash region); without an FPGA every register
 * reads 0, so the datapath reports no units and RUN is refused (error 9). */
#include "board.h"
#include "cbvh_fw/fw.h"
#include "port.h"
#include "usb_link.h"

static cbvh_fw fw; /* static: no heap anywhere */
static usbd_dev usb;
static usb_link link;
static cbvh_fw_hal hal;

static const char *const board_names[] = {"cbvh-rp2040", "cbvh-no-bits", "cbvh-cdone-low"};

static uint32_t now_us(void *ctx) {
    (void)ctx;
    return board_time_us();
}

int main(void) {
    int fpga = board_fpga_configure();
    board_spi_init(fpga == BOARD_FPGA_OK);
    usb_link_init(&link, &usb, board_usb_poll, now_us, 0, BOARD_TX_STALL_US);
    board_usb_init(&usb, &link.cls);
    hal.ctx = &link; /* send's context; the register map needs none */
    hal.reg_read = board_reg_read;
    hal.reg_write = board_reg_write;
    hal.send = usb_link_send;
    hal.board_name = board_names[fpga];
    cbvh_fw_init(&fw, &hal);
    uint32_t session = usb.sessions;
    uint32_t last_rx = board_time_us();
    for (;;) {
        board_usb_poll(0);
        if (usb.sessions != session) { /* a new host session starts with an empty parser */
            session = usb.sessions;
            usb_link_clear(&link);
            cbvh_fw_init(&fw, &hal);
        }
        uint8_t buf[64];
        size_t n = usb_link_take(&link, buf, sizeof buf);
        if (n) {
            cbvh_fw_rx(&fw, buf, n);
            last_rx = board_time_us();
        } else if (cbvh_fw_rx_partial(&fw) && board_time_us() - last_rx > BOARD_RX_IDLE_US) {
            cbvh_fw_rx_idle(&fw);
        }
    }
}
