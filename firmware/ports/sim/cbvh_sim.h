/* The sim port: the firmware core on the host.  The USB endpoints are a
 * socket; the FPGA register map is backed by the bit-exact model (libcbvh).
 * The board's addresses and the fault injector on its replies are the host's
 * link library (host/link/sim_addr.h, host/link/link_fault.h), which the
 * host's sim backend uses too. */
#ifndef CBVH_FW_SIM_H
#define CBVH_FW_SIM_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/unit_table.h"
#include "cbvh_fw/fw.h"
#include "cbvh_fw/regmap.h"

/* host/link/link_fault.h, not included: this header cross-compiles without
 * the host's headers (the qemu self-test uses the register-map model). */
typedef struct cbvh_link_fault cbvh_link_fault;

/* Model-backed register map (regmap_model.c). */
typedef struct {
    uint32_t config, unit_sel, status;
    uint32_t in[CBVH_REG_WORDS], out[CBVH_REG_WORDS];
    uint64_t runs;
    int broken_unit; /* test aid: unit id whose OUT[0] gets bit 0 flipped (a gateware bug), 0 = none */
} cbvh_regmap_model;

void cbvh_regmap_model_init(cbvh_regmap_model *m);
uint32_t cbvh_regmap_model_read(void *ctx, uint32_t addr);
void cbvh_regmap_model_write(void *ctx, uint32_t addr, uint32_t value);
/* Unit configuration as the datapath decodes the CONFIG register. */
cbvh_unit_config cbvh_regmap_config(uint32_t config_word);

/* Gateware-backed register map (regmap_gateware.c): the board top's RTL
 * simulated by Icarus (program built by gateware/scripts/build-board-sim),
 * driven over SPI byte by byte.  broken_unit as in cbvh_regmap_model. */
typedef struct cbvh_gateware cbvh_gateware;
/* Whether program can be a simulation at all (a readable file, and a vvp
 * script or executable): 0, or -1 with err naming the problem. */
int cbvh_gateware_check(const char *program, char *err, size_t errlen);
cbvh_gateware *cbvh_gateware_start(const char *program, int broken_unit, char *err, size_t errlen);
uint32_t cbvh_gateware_read(void *ctx, uint32_t addr);
void cbvh_gateware_write(void *ctx, uint32_t addr, uint32_t value);
/* The first failure of the simulation (it ended, hung, answered garbage), or NULL. */
const char *cbvh_gateware_error(const cbvh_gateware *g);
uint64_t cbvh_gateware_transactions(const cbvh_gateware *g);
/* While *stop is zero a transaction waits up to 30 s for the simulation; once
 * it is not, the transaction in progress is abandoned within 50 ms (an
 * error, cbvh_gateware_error) and cbvh_gateware_stop kills the simulation
 * without waiting.  cbvh_sim_board_serve sets it to its opts' stop. */
void cbvh_gateware_watch_stop(cbvh_gateware *g, volatile int *stop);
void cbvh_gateware_stop(cbvh_gateware *g);

typedef struct {
    int listen_fd;            /* from cbvh_sim_listen (host/link/sim_addr.h) */
    volatile int *stop;       /* serve returns soon after *stop becomes non-zero */
    int rx_idle_ms;           /* inter-byte timeout of the firmware parser */
    cbvh_link_fault *faults;  /* faults on the reply direction, or NULL */
    int verbose;
    int broken_unit;          /* see cbvh_regmap_model.broken_unit */
    cbvh_gateware *gateware;  /* the FPGA as simulated RTL, or NULL for the model */
    int host_idle_ms;         /* a host that sends nothing for this long is let go; 0: never */
} cbvh_sim_board_opts;

/* board-sim's --host-idle-ms unless given (docs/protocol.md, "Virtual board"). */
#define CBVH_SIM_HOST_IDLE_MS_DEFAULT 10000
#define CBVH_SIM_HOST_IDLE_MS_MAX 3600000

/* Accepts one connection at a time and runs the firmware core on it until
 * *stop.  Another host that connects meanwhile is refused at once: an error
 * frame with status busy (CBVH_E_BUSY), then the connection is closed.  A
 * host that sends nothing for host_idle_ms is disconnected.  Returns 0, or -1
 * on a listening-socket error or a failed gateware simulation, including a
 * transaction abandoned by *stop (cbvh_gateware_error says why). */
int cbvh_sim_board_serve(const cbvh_sim_board_opts *o);

#endif
