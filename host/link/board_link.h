/* What the board backends (usb, hid, sim) share beyond backend.h: their state
 * starts with a cbvh_link, so tests and `cbvh devices` can read identity and
 * link statistics. */
#ifndef CBVH_HOST_BOARD_LINK_H
#define CBVH_HOST_BOARD_LINK_H

#include "link/backend.h"
#include "link/link_fault.h"
#include "link/protocol.h"

/* The link of an open usb/hid/sim backend, or NULL for the model. */
cbvh_link *cbvh_backend_link(cbvh_backend *b);

/* Faults injected on the host->board direction of an open sim backend (the
 * injector must outlive the backend).  The environment variable
 * CBVH_LINK_FAULTS (link_fault.h syntax) does the same from the command line. */
void cbvh_sim_set_faults(cbvh_backend *b, cbvh_link_fault *f);

/* Human-readable one-line summary of link statistics. */
void cbvh_link_stats_line(const cbvh_link_stats *s, char *buf, size_t n);

/* What the usb and hid backends say when the board's device node cannot be
 * opened or seen (no permission). */
#define CBVH_UDEV_HINT "install firmware/udev/60-cbvh.rules into /etc/udev/rules.d and replug"

#endif
