/* USB side of the RP2040 port.  The device stack itself (descriptors with
 * VID:PID 1209:C0B1, product "cbvh board", one vendor interface with a bulk
 * OUT/IN pair, or a 64-byte HID report pair) is NOT part of this repository:
 * TinyUSB/pico-sdk are not packaged in Debian.  Its vendor-class receive
 * callback must call board_usb_rx_isr(); board_usb_tx() is the hook it
 * overrides to write the IN endpoint.  Until then the image builds and its
 * size is measured, but it cannot talk to a host (docs/protocol.md). */
#include "port.h"

#define RX_RING 8192u /* power of two */

static volatile uint8_t ring[RX_RING];
static volatile uint32_t head, tail; /* head: written by the ISR; tail: by the main loop */

void board_usb_rx_isr(const uint8_t *data, size_t n) {
    for (size_t i = 0; i < n; i++) {
        if (head - tail >= RX_RING) return; /* overflow: the host's CRC/timeout logic recovers */
        ring[head % RX_RING] = data[i];
        head++;
    }
}

size_t board_usb_take(uint8_t *buf, size_t cap) {
    size_t n = 0;
    while (n < cap && tail != head) {
        buf[n++] = ring[tail % RX_RING];
        tail++;
    }
    return n;
}

__attribute__((weak)) size_t board_usb_tx(const uint8_t *data, size_t n) {
    (void)data;
    return n; /* no USB stack linked */
}

void board_usb_send(void *ctx, const uint8_t *frame, size_t len) {
    (void)ctx;
    while (len) {
        size_t k = board_usb_tx(frame, len);
        frame += k;
        len -= k;
    }
}
