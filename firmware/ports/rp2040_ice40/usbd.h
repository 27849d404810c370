/* A small USB device stack for this one device (full speed): standard
 * requests, descriptors, one vendor interface with a bulk OUT/IN pair and
 * one HID interface with 64-byte reports (docs/protocol.md "Transports",
 * docs/board.md).  Hardware-independent, TinyUSB-style: the request and class
 * logic here, the controller in a port (usb_rp2040.c on the RP2040, a mock in
 * tests/board/test_usbd.c) that supplies usbd_port and feeds the three events
 * usbd_bus_reset, usbd_setup and usbd_xfer_done.  Freestanding, no malloc. */
#ifndef CBVH_USBD_H
#define CBVH_USBD_H

#include <stddef.h>
#include <stdint.h>

#define USBD_VID 0x1209u
#define USBD_PID 0xC0B1u
#define USBD_BCD_DEVICE 0x0010u /* firmware 0.1.0 */
#define USBD_MPS 64u
#define USBD_IFACE_VENDOR 0u
#define USBD_IFACE_HID 1u
#define USBD_EP_BULK_OUT 0x01u
#define USBD_EP_BULK_IN 0x81u
#define USBD_EP_HID_OUT 0x02u
#define USBD_EP_HID_IN 0x82u
#define USBD_HID_REPORT 64u             /* report size, no report IDs */
#define USBD_HID_DATA (USBD_HID_REPORT - 1u) /* byte 0 = count of frame bytes */

enum { USBD_XFER_CONTROL = 0, USBD_XFER_BULK = 2, USBD_XFER_INTERRUPT = 3 };
enum { USBD_LINK_BULK = 0, USBD_LINK_HID = 1 };

/* What the controller port does for the stack.  Endpoint addresses carry the
 * direction in bit 7 (0x80 = IN). */
typedef struct {
    void *ctx;
    void (*set_address)(void *ctx, uint8_t addr);
    void (*ep_open)(void *ctx, uint8_t ep, uint8_t type, uint16_t mps); /* data toggle DATA0 */
    void (*ep_close_all)(void *ctx); /* endpoints 1..15 disabled, nothing armed */
    /* Arms one packet: an IN endpoint sends data[0..len) (copied now); an OUT
     * endpoint receives up to len bytes into data (copied on completion). */
    void (*xfer)(void *ctx, uint8_t ep, uint8_t *data, uint16_t len);
    /* Takes back a packet armed on ep that the host has not collected. */
    void (*abort)(void *ctx, uint8_t ep);
    /* stall = 1: ep answers STALL (endpoint 0: both directions, until the next
     * SETUP); 0: clears the stall and resets the data toggle to DATA0. */
    void (*stall)(void *ctx, uint8_t ep, int stall);
} usbd_port;

/* Where the host's frame bytes go (the link's receive ring). */
typedef struct {
    void *ctx;
    void (*rx)(void *ctx, const uint8_t *data, size_t n);
    size_t (*rx_room)(void *ctx); /* bytes rx can take now */
} usbd_class;

enum { USBD_CTL_IDLE, USBD_CTL_DATA_IN, USBD_CTL_STATUS_OUT, USBD_CTL_STATUS_IN };

typedef struct {
    uint32_t setups, stalls, bus_resets, hid_bad_reports, rx_held, tx_aborts;
} usbd_counters;

typedef struct {
    const usbd_port *port;
    const usbd_class *cls;
    uint8_t address, pending_address, config;
    uint32_t sessions; /* SET_CONFIGURATION(1) count: a new host session */
    /* control transfer on endpoint 0 */
    uint8_t ctl_stage, ctl_zlp;
    const uint8_t *ctl_data;
    uint16_t ctl_left;
    uint8_t ctl_buf[USBD_MPS];     /* replies built at request time */
    uint8_t ep0_out[USBD_MPS];     /* status-stage OUT packet */
    /* the two links: index USBD_LINK_BULK / USBD_LINK_HID */
    uint8_t halted_in[2], halted_out[2], out_armed[2], in_busy[2], zlp_pending;
    uint8_t out_buf[2][USBD_MPS], in_buf[USBD_MPS];
    uint8_t link; /* the link the host's bytes last came from; replies go there */
    usbd_counters n;
} usbd_dev;

void usbd_init(usbd_dev *d, const usbd_port *port, const usbd_class *cls);

/* Events from the port. */
void usbd_bus_reset(usbd_dev *d);
void usbd_setup(usbd_dev *d, const uint8_t setup[8]);
void usbd_xfer_done(usbd_dev *d, uint8_t ep, uint16_t len);

/* The link's side. */
static inline int usbd_configured(const usbd_dev *d) { return d->config != 0; }
void usbd_rx_resume(usbd_dev *d); /* re-arms OUT endpoints held back for lack of room */
int usbd_tx_ready(const usbd_dev *d);
/* Queues the next packet of the reply stream on the active link: returns the
 * bytes taken (0 when not ready).  last: data[0..n) ends a frame, so a full
 * bulk packet gets a zero-length packet after it. */
size_t usbd_tx(usbd_dev *d, const uint8_t *data, size_t n, int last);
void usbd_tx_abort(usbd_dev *d); /* the host stopped reading: take the packet back */

/* Descriptors (usb_desc.c): the bytes of descriptor (type, index), strings
 * built into scratch (USBD_MPS bytes); 0 when there is none. */
size_t usbd_descriptor(uint8_t type, uint8_t index, uint8_t *scratch, const uint8_t **out);
#define USBD_DESC_DEVICE 1u
#define USBD_DESC_CONFIG 2u
#define USBD_DESC_STRING 3u
#define USBD_DESC_HID 0x21u
#define USBD_DESC_HID_REPORT 0x22u

#endif
