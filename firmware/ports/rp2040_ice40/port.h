/* RP2040 + iCE40UP5K port: what main.c needs from the other files. */
#ifndef CBVH_PORT_RP2040_H
#define CBVH_PORT_RP2040_H

#include <stddef.h>
#include <stdint.h>

void board_spi_init(void);
uint32_t board_reg_read(void *ctx, uint32_t addr);
void board_reg_write(void *ctx, uint32_t addr, uint32_t value);

/* USB link (usb_link.c): bytes from the host's bulk OUT endpoint are queued
 * by the USB stack's receive callback; frames go out through board_usb_tx. */
void board_usb_rx_isr(const uint8_t *data, size_t n);
size_t board_usb_take(uint8_t *buf, size_t cap);
void board_usb_send(void *ctx, const uint8_t *frame, size_t len);
size_t board_usb_tx(const uint8_t *data, size_t n);

#endif
