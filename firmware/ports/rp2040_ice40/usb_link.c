/* Receive ring and reply path between the USB device stack and the firmware
 * core (usb_link.h). */
#include "usb_link.h"

static size_t room(void *ctx) {
    usb_link *l = ctx;
    return USB_LINK_RING - (l->head - l->tail);
}

static void rx(void *ctx, const uint8_t *data, size_t n) {
    usb_link *l = ctx;
    for (size_t i = 0; i < n && l->head - l->tail < USB_LINK_RING; i++) { /* never more than room() said */
        l->ring[l->head % USB_LINK_RING] = data[i];
        l->head++;
    }
}

void usb_link_init(usb_link *l, usbd_dev *usb, void (*poll)(void *), uint32_t (*now_us)(void *), void *ctx,
                   uint32_t tx_stall_us) {
    l->usb = usb;
    l->poll = poll;
    l->now_us = now_us;
    l->ctx = ctx;
    l->tx_stall_us = tx_stall_us;
    l->head = l->tail = 0;
    l->tx_dropped = 0;
    l->cls.ctx = l;
    l->cls.rx = rx;
    l->cls.rx_room = room;
}

size_t usb_link_take(usb_link *l, uint8_t *buf, size_t cap) {
    size_t n = 0;
    while (n < cap && l->tail != l->head) {
        buf[n++] = l->ring[l->tail % USB_LINK_RING];
        l->tail++;
    }
    usbd_rx_resume(l->usb);
    return n;
}

void usb_link_clear(usb_link *l) { l->tail = l->head; }

void usb_link_send(void *ctx, const uint8_t *frame, size_t len) {
    usb_link *l = ctx;
    uint32_t since = l->now_us(l->ctx);
    uint32_t session = l->usb->sessions;
    while (len) {
        l->poll(l->ctx);
        if (!usbd_configured(l->usb) || l->usb->sessions != session) { /* reset, deconfigured: nobody to send to */
            l->tx_dropped++;
            return;
        }
        size_t k = usbd_tx(l->usb, frame, len, 1);
        if (k) {
            frame += k;
            len -= k;
            since = l->now_us(l->ctx);
        } else if (l->now_us(l->ctx) - since > l->tx_stall_us) { /* the host stopped reading */
            usbd_tx_abort(l->usb);
            l->tx_dropped++;
            return;
        }
    }
}
