/* Fault injection on a socket link: each outgoing frame may be dropped,
 * corrupted, duplicated, truncated, delayed, or the connection cut.  Used on
 * both ends of the sim link: the host's requests (transport_socket.c) and the
 * virtual board's replies (firmware/ports/sim).  Library cbvh_link_socket,
 * with sim_addr.h. */
#ifndef CBVH_HOST_LINK_FAULT_H
#define CBVH_HOST_LINK_FAULT_H

#include <stddef.h>
#include <stdint.h>

enum { CBVH_FAULT_DROP, CBVH_FAULT_CORRUPT, CBVH_FAULT_DUP, CBVH_FAULT_TRUNC, CBVH_FAULT_DELAY, CBVH_FAULT_DISCONNECT,
       CBVH_FAULT_KINDS };

typedef struct cbvh_link_fault {
    double rate[CBVH_FAULT_KINDS]; /* probability per frame of each fault */
    int delay_ms;                  /* how long DELAY holds a frame */
    uint64_t rng;
    uint64_t injected[CBVH_FAULT_KINDS];
    uint64_t frames;
} cbvh_link_fault;

extern const char *const cbvh_fault_names[CBVH_FAULT_KINDS];

#define CBVH_FAULT_DELAY_MS_MAX 10000

/* Parses "drop=0.01,corrupt=0.02,dup=..,trunc=..,delay=..,disconnect=..,
 * delay_ms=N,seed=N" (also "all=R" for the kinds not named).  Strict:
 * rates in [0,1] adding up to at most 1, delay_ms 0..CBVH_FAULT_DELAY_MS_MAX,
 * seed a decimal uint64, each item at most once.  0, or -1 with err naming the
 * item and why. */
int cbvh_link_fault_parse(cbvh_link_fault *f, const char *spec, char *err, size_t errlen);
void cbvh_link_fault_init(cbvh_link_fault *f, uint64_t seed);

/* Sends one frame through the injector.  Returns 0 when the link is still
 * up, -1 when the connection was cut (by the fault or by a send error). */
int cbvh_link_fault_send(cbvh_link_fault *f, int fd, const uint8_t *frame, size_t len);

/* Plain full send (MSG_NOSIGNAL): 0 or -1. */
int cbvh_send_all(int fd, const uint8_t *p, size_t n);

#endif
