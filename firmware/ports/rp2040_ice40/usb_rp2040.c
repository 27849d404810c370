/* The RP2040 USB controller as the device stack's port (usbd_port), written
 * from the RP2040 datasheet, 4.1 (device mode, DPRAM layout, buffer control,
 * SIE status, buffer status).  Polled: board_usb_poll() turns the
 * controller's SETUP, BUFF_STATUS and BUS_RESET events into usbd events; no
 * interrupt is used.  Endpoint n > 0 uses the 64-byte DPRAM buffers at
 * 0x180 + 0x80 (n - 1) (IN) and + 0x40 (OUT); endpoint 0 the one at 0x100. */
#include "port.h"
#include "rp2040_regs.h"
#include "usbd.h"

#define DPRAM ((volatile uint8_t *)(uintptr_t)USBCTRL_DPRAM_BASE)
#define EP_ABORT REG32(USBCTRL_REGS_BASE + 0x60u)
#define EP_ABORT_DONE REG32(USBCTRL_REGS_BASE + 0x64u)

static usbd_dev *dev;
static uint8_t next_pid[16][2]; /* [endpoint][out]: DATA1 next */
static uint8_t *out_dst[16];

static uint32_t buf_offset(unsigned n, int out) {
    return n == 0 ? USB_DPRAM_EP0_BUF : USB_DPRAM_DATA + 0x80u * (n - 1) + (out ? 0x40u : 0u);
}

static void set_address(void *ctx, uint8_t addr) {
    (void)ctx;
    USB_ADDR_ENDP = addr;
}

static void ep_open(void *ctx, uint8_t ep, uint8_t type, uint16_t mps) {
    (void)ctx, (void)mps;
    unsigned n = ep & 0xFu;
    int out = !(ep & 0x80u);
    if (n == 0) return;
    next_pid[n][out] = 0;
    USB_DPRAM_BUF_CTRL(n, out) = 0;
    USB_DPRAM_EP_CTRL(n, out) = USB_EP_CTRL_ENABLE | USB_EP_CTRL_INT_PER_BUFF | USB_EP_CTRL_TYPE(type) |
                                buf_offset(n, out);
}

static void ep_close_all(void *ctx) {
    (void)ctx;
    for (unsigned n = 1; n < 16; n++)
        for (int out = 0; out < 2; out++) {
            USB_DPRAM_EP_CTRL(n, out) = 0;
            USB_DPRAM_BUF_CTRL(n, out) = 0;
        }
}

static void xfer(void *ctx, uint8_t ep, uint8_t *data, uint16_t len) {
    (void)ctx;
    unsigned n = ep & 0xFu;
    int out = !(ep & 0x80u);
    uint32_t off = buf_offset(n, out);
    uint32_t bc = len | (next_pid[n][out] ? USB_BUF_DATA1 : 0u);
    if (out) {
        out_dst[n] = data;
    } else {
        for (uint16_t i = 0; i < len; i++) DPRAM[off + i] = data[i];
        bc |= USB_BUF_FULL;
    }
    USB_DPRAM_BUF_CTRL(n, out) = bc;
    /* AVAILABLE only after the rest of the word has settled in clk_usb's domain (4.1.2.5.1) */
    __asm__ volatile("nop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop");
    USB_DPRAM_BUF_CTRL(n, out) = bc | USB_BUF_AVAILABLE;
}

static void ep_abort(void *ctx, uint8_t ep) {
    (void)ctx;
    unsigned n = ep & 0xFu;
    int out = !(ep & 0x80u);
    uint32_t bit = 1u << (2 * n + (out ? 1 : 0));
    EP_ABORT = bit;
    for (unsigned i = 0; i < 100000u && !(EP_ABORT_DONE & bit); i++) {}
    USB_DPRAM_BUF_CTRL(n, out) = 0;
    EP_ABORT = 0;
    EP_ABORT_DONE = bit;
}

static void stall(void *ctx, uint8_t ep, int on) {
    (void)ctx;
    unsigned n = ep & 0xFu;
    int out = !(ep & 0x80u);
    if (n == 0) {
        USB_EP_STALL_ARM = on ? 3u : 0u;
        USB_DPRAM_BUF_CTRL(0, 0) = on ? USB_BUF_STALL : 0u;
        USB_DPRAM_BUF_CTRL(0, 1) = on ? USB_BUF_STALL : 0u;
        return;
    }
    USB_DPRAM_BUF_CTRL(n, out) = on ? USB_BUF_STALL : 0u;
    next_pid[n][out] = 0;
}

static const usbd_port port = {0, set_address, ep_open, ep_close_all, xfer, ep_abort, stall};

void board_usb_init(usbd_dev *d, const usbd_class *cls) {
    dev = d;
    usbd_init(d, &port, cls);
    REG_SET(RESETS_RESET) = RESET_USBCTRL;
    board_unreset(RESET_USBCTRL);
    for (uint32_t i = 0; i < 4096u; i += 4) REG32(USBCTRL_DPRAM_BASE + i) = 0;
    USB_MUXING = USB_MUXING_TO_PHY | USB_MUXING_SOFTCON;
    USB_PWR = USB_PWR_VBUS_DETECT | USB_PWR_VBUS_DETECT_OVERRIDE_EN; /* no VBUS sense pin: always present */
    USB_MAIN_CTRL = USB_MAIN_CTRL_CONTROLLER_EN;
    USB_SIE_CTRL = USB_SIE_CTRL_EP0_INT_1BUF;
    USB_INTE = USB_INT_BUFF_STATUS | USB_INT_BUS_RESET | USB_INT_SETUP_REQ;
    USB_SIE_CTRL = USB_SIE_CTRL_EP0_INT_1BUF | USB_SIE_CTRL_PULLUP_EN; /* connect: the host sees the device */
}

void board_usb_poll(void *ctx) {
    (void)ctx;
    uint32_t ints = USB_INTS;
    if (ints & USB_INT_BUS_RESET) {
        USB_SIE_STATUS = USB_SIE_STATUS_BUS_RESET;
        USB_BUFF_STATUS = 0xFFFFFFFFu;
        for (unsigned n = 0; n < 16; n++) next_pid[n][0] = next_pid[n][1] = 0;
        usbd_bus_reset(dev);
        return;
    }
    if (ints & USB_INT_BUFF_STATUS) {
        uint32_t bs = USB_BUFF_STATUS;
        for (unsigned bit = 0; bit < 32; bit++) {
            if (!(bs & (1u << bit))) continue;
            USB_BUFF_STATUS = 1u << bit;
            unsigned n = bit / 2;
            int out = bit & 1;
            uint16_t len = (uint16_t)(USB_DPRAM_BUF_CTRL(n, out) & USB_BUF_LEN_MASK);
            next_pid[n][out] ^= 1u;
            if (out && out_dst[n]) {
                if (len > 64) len = 64; /* every buffer here is 64 bytes */
                uint32_t off = buf_offset(n, out);
                for (uint16_t i = 0; i < len; i++) out_dst[n][i] = DPRAM[off + i];
            }
            usbd_xfer_done(dev, (uint8_t)(n | (out ? 0u : 0x80u)), len);
        }
    }
    if (ints & USB_INT_SETUP_REQ) {
        USB_SIE_STATUS = USB_SIE_STATUS_SETUP_REC;
        uint8_t s[8];
        for (unsigned i = 0; i < 8; i++) s[i] = DPRAM[i];
        next_pid[0][0] = next_pid[0][1] = 1; /* data and status stages start with DATA1 */
        USB_EP_STALL_ARM = 0;
        usbd_setup(dev, s);
    }
}
