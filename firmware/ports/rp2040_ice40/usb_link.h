/* The board protocol's byte stream over the USB device stack: a receive
 * ring filled from the OUT endpoints (with back-pressure: an OUT endpoint is
 * re-armed only when the ring has room, so a host that sends too much is
 * NAKed, never overrun), and the reply path that streams a frame into IN
 * packets while servicing the controller, giving up on a host that stopped
 * reading.  Hardware-independent: the port's poll and clock come in. */
#ifndef CBVH_USB_LINK_H
#define CBVH_USB_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "usbd.h"

#define USB_LINK_RING 8192u /* power of two */

typedef struct {
    usbd_dev *usb;
    void (*poll)(void *ctx); /* services the controller: may call usbd events */
    uint32_t (*now_us)(void *ctx);
    void *ctx;
    uint32_t tx_stall_us; /* no IN progress for this long: the reply is dropped */
    uint8_t ring[USB_LINK_RING];
    volatile uint32_t head, tail;
    uint32_t tx_dropped; /* replies dropped: host gone, reset, or not reading */
    usbd_class cls;
} usb_link;

void usb_link_init(usb_link *l, usbd_dev *usb, void (*poll)(void *), uint32_t (*now_us)(void *), void *ctx,
                   uint32_t tx_stall_us);
size_t usb_link_take(usb_link *l, uint8_t *buf, size_t cap); /* and re-arms OUT endpoints */
void usb_link_clear(usb_link *l);
/* cbvh_fw_hal.send: ctx is the usb_link. */
void usb_link_send(void *ctx, const uint8_t *frame, size_t len);

#endif
