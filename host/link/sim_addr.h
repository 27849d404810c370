/* Addresses of the virtual board (`cbvh board-sim`), shared by the host's sim
 * backend (transport_socket.c, which connects) and the board
 * (firmware/ports/sim, which listens).  Library cbvh_link_socket, with
 * link_fault.h.
 *
 * An address is "unix:PATH", "tcp:HOST:PORT" (a decimal PORT in 1..65535) or
 * a bare PATH (contains '/'). */
#ifndef CBVH_HOST_SIM_ADDR_H
#define CBVH_HOST_SIM_ADDR_H

#include <stddef.h>

/* Return a connected or listening fd, or with err set CBVH_SIM_BAD_ADDR when
 * the address itself is wrong (syntax, port range, no such host) and -1 on
 * any other failure.  Listening on a unix PATH that is a socket nobody
 * accepts on (left by a crashed board) replaces it; one a board is listening
 * on fails with "another board is already listening on PATH". */
#define CBVH_SIM_BAD_ADDR (-2)
int cbvh_sim_listen(const char *addr, char *err, size_t errlen);
int cbvh_sim_connect(const char *addr, char *err, size_t errlen);
/* Checks an address's syntax and port range only: 0, or -1 with err set. */
int cbvh_sim_addr_check(const char *addr, char *err, size_t errlen);
/* Removes a unix socket file created by cbvh_sim_listen. */
void cbvh_sim_unlink(const char *addr);

#endif
