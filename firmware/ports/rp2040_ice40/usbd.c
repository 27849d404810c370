/* Standard and class requests, endpoint 0's control transfers, and the two
 * links (vendor bulk, HID reports) of the USB device stack (usbd.h).  Every
 * request it does not know, or with fields out of range, is answered with a
 * STALL on endpoint 0 (USB 2.0, 9.2.7 "request error"); nothing a host sends
 * can make it wait or write outside its buffers. */
#include "usbd.h"

/* bmRequestType */
#define RT_IN 0x80u
#define RT_TYPE(bm) (((bm) >> 5) & 3u)
#define RT_RECIP(bm) ((bm) & 0x1Fu)
enum { TYPE_STANDARD = 0, TYPE_CLASS = 1 };
enum { RECIP_DEVICE = 0, RECIP_INTERFACE = 1, RECIP_ENDPOINT = 2 };
/* bRequest, standard */
enum {
    GET_STATUS = 0, CLEAR_FEATURE = 1, SET_FEATURE = 3, SET_ADDRESS = 5, GET_DESCRIPTOR = 6,
    GET_CONFIGURATION = 8, SET_CONFIGURATION = 9, GET_INTERFACE = 10, SET_INTERFACE = 11
};
#define FEATURE_ENDPOINT_HALT 0u
/* bRequest, HID class (HID 1.11, 7.2) */
enum { HID_GET_IDLE = 2, HID_GET_PROTOCOL = 3, HID_SET_IDLE = 10, HID_SET_PROTOCOL = 11 };

static const uint8_t out_ep[2] = {USBD_EP_BULK_OUT, USBD_EP_HID_OUT};
static const uint8_t in_ep[2] = {USBD_EP_BULK_IN, USBD_EP_HID_IN};

static void clear_links(usbd_dev *d) {
    for (int i = 0; i < 2; i++) d->halted_in[i] = d->halted_out[i] = d->out_armed[i] = d->in_busy[i] = 0;
    d->zlp_pending = 0;
}

void usbd_init(usbd_dev *d, const usbd_port *port, const usbd_class *cls) {
    uint8_t *p = (uint8_t *)d;
    for (size_t i = 0; i < sizeof *d; i++) p[i] = 0;
    d->port = port;
    d->cls = cls;
}

void usbd_bus_reset(usbd_dev *d) {
    d->n.bus_resets++;
    d->address = d->pending_address = d->config = 0;
    d->ctl_stage = USBD_CTL_IDLE;
    clear_links(d);
    d->port->set_address(d->port->ctx, 0);
    d->port->ep_close_all(d->port->ctx);
}

/* ---- endpoint 0 ---- */

static void ctl_stall(usbd_dev *d) {
    d->n.stalls++;
    d->ctl_stage = USBD_CTL_IDLE;
    d->port->stall(d->port->ctx, 0, 1);
}

static void ctl_status_in(usbd_dev *d) {
    d->ctl_stage = USBD_CTL_STATUS_IN;
    d->port->xfer(d->port->ctx, 0x80, 0, 0);
}

static void ctl_send_next(usbd_dev *d) {
    uint16_t k = d->ctl_left < USBD_MPS ? d->ctl_left : USBD_MPS;
    if (k == 0 && !d->ctl_zlp) { /* data stage over: the host's status packet */
        d->ctl_stage = USBD_CTL_STATUS_OUT;
        d->port->xfer(d->port->ctx, 0x00, d->ep0_out, USBD_MPS);
        return;
    }
    if (k == 0) d->ctl_zlp = 0; /* the zero-length packet that ends a short reply */
    d->port->xfer(d->port->ctx, 0x80, (uint8_t *)(uintptr_t)d->ctl_data, k);
    d->ctl_data += k;
    d->ctl_left = (uint16_t)(d->ctl_left - k);
    if (k < USBD_MPS) d->ctl_zlp = 0; /* a short packet ends the data stage by itself */
}

/* Replies with data[0..len), cut to what the host asked for (wlength). */
static void ctl_reply(usbd_dev *d, const uint8_t *data, size_t len, uint16_t wlength) {
    if (wlength == 0) { /* no data stage: the status stage is ours (USB 2.0, 8.5.3) */
        ctl_status_in(d);
        return;
    }
    if (len > wlength) len = wlength;
    d->ctl_data = data;
    d->ctl_left = (uint16_t)len;
    d->ctl_zlp = len < wlength && len % USBD_MPS == 0; /* the host cannot tell the end otherwise */
    d->ctl_stage = USBD_CTL_DATA_IN;
    ctl_send_next(d);
}

static void reply2(usbd_dev *d, uint8_t b0, uint16_t wlength) {
    d->ctl_buf[0] = b0;
    d->ctl_buf[1] = 0;
    ctl_reply(d, d->ctl_buf, 2, wlength);
}

static void reply1(usbd_dev *d, uint8_t b0, uint16_t wlength) {
    d->ctl_buf[0] = b0;
    ctl_reply(d, d->ctl_buf, 1, wlength);
}

/* Link index of a data endpoint address, or -1 (endpoint 0: 2). */
static int ep_link(uint8_t ep) {
    for (int i = 0; i < 2; i++)
        if (ep == out_ep[i] || ep == in_ep[i]) return i;
    return (ep & 0x7Fu) == 0 ? 2 : -1;
}

static void arm_out(usbd_dev *d, int i) {
    if (!d->config || d->halted_out[i] || d->out_armed[i]) return;
    if (d->cls->rx_room(d->cls->ctx) < USBD_MPS) { /* no room: NAK the host until the link drains */
        d->n.rx_held++;
        return;
    }
    d->out_armed[i] = 1;
    d->port->xfer(d->port->ctx, out_ep[i], d->out_buf[i], USBD_MPS);
}

void usbd_rx_resume(usbd_dev *d) {
    for (int i = 0; i < 2; i++) arm_out(d, i);
}

static void set_configuration(usbd_dev *d, uint8_t value) {
    d->port->ep_close_all(d->port->ctx);
    clear_links(d);
    d->config = value;
    if (!value) return;
    d->sessions++;
    for (int i = 0; i < 2; i++) {
        uint8_t type = i == USBD_LINK_BULK ? USBD_XFER_BULK : USBD_XFER_INTERRUPT;
        d->port->ep_open(d->port->ctx, out_ep[i], type, USBD_MPS);
        d->port->ep_open(d->port->ctx, in_ep[i], type, USBD_MPS);
    }
    usbd_rx_resume(d);
}

static void set_halt(usbd_dev *d, uint8_t ep, int halt) {
    int i = ep_link(ep);
    int in = (ep & 0x80u) != 0;
    if (in) {
        if (d->in_busy[i]) d->port->abort(d->port->ctx, ep);
        d->in_busy[i] = 0;
        if (i == d->link) d->zlp_pending = 0;
        d->halted_in[i] = (uint8_t)halt;
    } else {
        if (d->out_armed[i]) d->port->abort(d->port->ctx, ep);
        d->out_armed[i] = 0;
        d->halted_out[i] = (uint8_t)halt;
    }
    d->port->stall(d->port->ctx, ep, halt); /* clearing also resets the data toggle (9.4.5) */
    if (!halt && !in) arm_out(d, i);
}

static void standard_request(usbd_dev *d, uint8_t bm, uint8_t req, uint16_t wvalue, uint16_t windex, uint16_t wlength) {
    const uint8_t *desc;
    size_t len;
    switch (RT_RECIP(bm)) {
    case RECIP_DEVICE:
        if (req == GET_STATUS && (bm & RT_IN) && wvalue == 0 && windex == 0) { reply2(d, 0, wlength); return; }
        if (req == SET_ADDRESS && !(bm & RT_IN) && wvalue <= 127 && windex == 0 && !d->config) {
            d->pending_address = (uint8_t)wvalue; /* takes effect after the status stage */
            ctl_status_in(d);
            return;
        }
        if (req == GET_DESCRIPTOR && (bm & RT_IN)) {
            len = usbd_descriptor((uint8_t)(wvalue >> 8), (uint8_t)wvalue, d->ctl_buf, &desc);
            if ((wvalue >> 8) == USBD_DESC_HID || (wvalue >> 8) == USBD_DESC_HID_REPORT) len = 0; /* interface ones */
            if (len) { ctl_reply(d, desc, len, wlength); return; }
            break;
        }
        if (req == GET_CONFIGURATION && (bm & RT_IN) && wvalue == 0 && windex == 0) { reply1(d, d->config, wlength); return; }
        if (req == SET_CONFIGURATION && !(bm & RT_IN) && wvalue <= 1 && windex == 0) {
            set_configuration(d, (uint8_t)wvalue);
            ctl_status_in(d);
            return;
        }
        break; /* remote wakeup and test mode are not supported: SET/CLEAR_FEATURE stall */
    case RECIP_INTERFACE:
        if (!d->config || windex > USBD_IFACE_HID) break;
        if (req == GET_STATUS && (bm & RT_IN) && wvalue == 0) { reply2(d, 0, wlength); return; }
        if (req == GET_INTERFACE && (bm & RT_IN) && wvalue == 0) { reply1(d, 0, wlength); return; }
        if (req == SET_INTERFACE && !(bm & RT_IN) && wvalue == 0) { ctl_status_in(d); return; }
        if (req == GET_DESCRIPTOR && (bm & RT_IN) && windex == USBD_IFACE_HID &&
            ((wvalue >> 8) == USBD_DESC_HID || (wvalue >> 8) == USBD_DESC_HID_REPORT)) {
            len = usbd_descriptor((uint8_t)(wvalue >> 8), (uint8_t)wvalue, d->ctl_buf, &desc);
            if (len) { ctl_reply(d, desc, len, wlength); return; }
        }
        break;
    case RECIP_ENDPOINT: {
        uint8_t ep = (uint8_t)windex;
        int i = ep_link(ep);
        if ((windex >> 8) != 0 || i < 0 || (i < 2 && !d->config)) break;
        if (req == GET_STATUS && (bm & RT_IN) && wvalue == 0) {
            int halted = i == 2 ? 0 : (ep & 0x80u) ? d->halted_in[i] : d->halted_out[i];
            reply2(d, (uint8_t)halted, wlength);
            return;
        }
        if ((req == CLEAR_FEATURE || req == SET_FEATURE) && !(bm & RT_IN) && wvalue == FEATURE_ENDPOINT_HALT) {
            if (i == 2) { /* endpoint 0 cannot be halted: clearing is a no-op, setting a request error */
                if (req == CLEAR_FEATURE) { ctl_status_in(d); return; }
                break;
            }
            set_halt(d, ep, req == SET_FEATURE);
            ctl_status_in(d);
            return;
        }
        break;
    }
    default:
        break;
    }
    ctl_stall(d);
}

static void hid_request(usbd_dev *d, uint8_t bm, uint8_t req, uint16_t wvalue, uint16_t windex, uint16_t wlength) {
    if (RT_RECIP(bm) == RECIP_INTERFACE && windex == USBD_IFACE_HID && d->config) {
        if (req == HID_SET_IDLE && !(bm & RT_IN)) { ctl_status_in(d); return; } /* reports go out when there is data */
        if (req == HID_GET_IDLE && (bm & RT_IN)) { reply1(d, 0, wlength); return; }
        if (req == HID_GET_PROTOCOL && (bm & RT_IN) && wvalue == 0) { reply1(d, 1, wlength); return; } /* report protocol */
        if (req == HID_SET_PROTOCOL && !(bm & RT_IN) && wvalue == 1) { ctl_status_in(d); return; }
    }
    ctl_stall(d); /* GET_REPORT/SET_REPORT too: reports travel on the interrupt endpoints */
}

void usbd_setup(usbd_dev *d, const uint8_t s[8]) {
    d->n.setups++;
    d->ctl_stage = USBD_CTL_IDLE; /* a SETUP ends whatever control transfer was under way */
    uint8_t bm = s[0], req = s[1];
    uint16_t wvalue = (uint16_t)(s[2] | s[3] << 8), windex = (uint16_t)(s[4] | s[5] << 8),
             wlength = (uint16_t)(s[6] | s[7] << 8);
    if (!(bm & RT_IN) && wlength) { ctl_stall(d); return; } /* no request of this device takes data */
    if (RT_TYPE(bm) == TYPE_STANDARD) standard_request(d, bm, req, wvalue, windex, wlength);
    else if (RT_TYPE(bm) == TYPE_CLASS) hid_request(d, bm, req, wvalue, windex, wlength);
    else ctl_stall(d); /* vendor and reserved types */
}

/* ---- completions ---- */

static void link_rx(usbd_dev *d, int i, uint16_t len) {
    const uint8_t *p = d->out_buf[i];
    if (len > USBD_MPS) len = USBD_MPS; /* a port never reports more; trust nothing */
    if (i == USBD_LINK_HID) { /* [n][n frame bytes][padding] */
        if (len < 1 || p[0] < 1 || p[0] > USBD_HID_DATA || p[0] > len - 1) {
            d->n.hid_bad_reports++;
            return;
        }
        len = p[0];
        p++;
    }
    if (!len) return;
    d->link = (uint8_t)i;
    d->cls->rx(d->cls->ctx, p, len);
}

void usbd_xfer_done(usbd_dev *d, uint8_t ep, uint16_t len) {
    if ((ep & 0x7Fu) == 0) {
        if (ep == 0x80 && d->ctl_stage == USBD_CTL_DATA_IN) {
            ctl_send_next(d);
        } else if (ep == 0x80 && d->ctl_stage == USBD_CTL_STATUS_IN) {
            d->ctl_stage = USBD_CTL_IDLE;
            if (d->pending_address) {
                d->address = d->pending_address;
                d->pending_address = 0;
                d->port->set_address(d->port->ctx, d->address);
            }
        } else if (ep == 0x00 && d->ctl_stage == USBD_CTL_STATUS_OUT) {
            d->ctl_stage = USBD_CTL_IDLE;
        }
        return; /* anything else on endpoint 0 is stale */
    }
    int i = ep_link(ep);
    if (i < 0 || i > 1 || !d->config) return;
    if (ep & 0x80u) {
        d->in_busy[i] = 0;
        if (i == d->link && d->zlp_pending) {
            d->zlp_pending = 0;
            d->in_busy[i] = 1;
            d->port->xfer(d->port->ctx, ep, 0, 0);
        }
        return;
    }
    if (!d->out_armed[i]) return;
    d->out_armed[i] = 0;
    link_rx(d, i, len);
    arm_out(d, i);
}

int usbd_tx_ready(const usbd_dev *d) {
    return d->config && !d->halted_in[d->link] && !d->in_busy[d->link] && !d->zlp_pending;
}

size_t usbd_tx(usbd_dev *d, const uint8_t *data, size_t n, int last) {
    if (!usbd_tx_ready(d) || n == 0) return 0;
    int i = d->link;
    size_t k;
    if (i == USBD_LINK_HID) {
        k = n < USBD_HID_DATA ? n : USBD_HID_DATA;
        d->in_buf[0] = (uint8_t)k;
        for (size_t j = 0; j < USBD_HID_DATA; j++) d->in_buf[1 + j] = j < k ? data[j] : 0;
        d->in_busy[i] = 1;
        d->port->xfer(d->port->ctx, in_ep[i], d->in_buf, USBD_HID_REPORT);
        return k;
    }
    k = n < USBD_MPS ? n : USBD_MPS;
    for (size_t j = 0; j < k; j++) d->in_buf[j] = data[j];
    d->in_busy[i] = 1;
    d->zlp_pending = last && k == n && k == USBD_MPS;
    d->port->xfer(d->port->ctx, in_ep[i], d->in_buf, (uint16_t)k);
    return k;
}

void usbd_tx_abort(usbd_dev *d) {
    int i = d->link;
    if (d->in_busy[i]) d->port->abort(d->port->ctx, in_ep[i]);
    d->in_busy[i] = 0;
    d->zlp_pending = 0;
    d->n.tx_aborts++;
}
