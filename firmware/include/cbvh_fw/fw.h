/* Firmware core: frame parser, command dispatcher, batch streaming and the
 * datapath register-map driver.  Freestanding C, no malloc: the caller owns
 * the cbvh_fw object (static storage on the MCU).  A port supplies the HAL. */
#ifndef CBVH_FW_FW_H
#define CBVH_FW_FW_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh_fw/frame.h"

#define CBVH_FW_VERSION_MAJOR 0
#define CBVH_FW_VERSION_MINOR 1
#define CBVH_FW_VERSION_PATCH 0

/* The hardware-abstraction layer a port provides. */
typedef struct {
    void *ctx;
    uint32_t (*reg_read)(void *ctx, uint32_t addr);
    void (*reg_write)(void *ctx, uint32_t addr, uint32_t value);
    /* Sends one whole frame to the host (USB IN endpoint / socket). */
    void (*send)(void *ctx, const uint8_t *frame, size_t len);
    const char *board_name; /* up to 15 characters, in IDENTIFY */
} cbvh_fw_hal;

/* Counters returned by STATUS, in this order (u32 LE each). */
typedef struct {
    uint32_t frames_ok, error_replies, crc_errors, sync_errors, header_errors, rx_timeouts, vectors, batches,
        datapath_errors;
} cbvh_fw_counters;
#define CBVH_FW_COUNTERS 9

typedef struct {
    const cbvh_fw_hal *hal;
    cbvh_parser rx;
    uint8_t tx[CBVH_FRAME_MAX];
    cbvh_fw_counters n;
} cbvh_fw;

void cbvh_fw_init(cbvh_fw *fw, const cbvh_fw_hal *hal);
/* Feeds bytes received from the host; replies go out through hal->send. */
void cbvh_fw_rx(cbvh_fw *fw, const uint8_t *data, size_t n);
/* The port calls this when no byte arrived for the inter-byte timeout. */
void cbvh_fw_rx_idle(cbvh_fw *fw);
static inline int cbvh_fw_rx_partial(const cbvh_fw *fw) { return cbvh_parser_partial(&fw->rx); }

/* Datapath driver (datapath_driver.c). */
typedef struct {
    int8_t quant_bits;
    int16_t min_scale;
    uint8_t encoding;
} cbvh_fw_config;
uint32_t cbvh_dp_config_word(const cbvh_fw_config *c);
/* Selects unit and config: CBVH_E_OK with *shape = n_in | n_out << 8,
 * CBVH_E_UNIT when the unit is absent, CBVH_E_CONFIG when the datapath has
 * the unit but not for this configuration (SHAPE reads 0). */
int cbvh_dp_select(const cbvh_fw_hal *hal, uint8_t unit, const cbvh_fw_config *c, uint32_t *shape);
/* Runs one vector: 0 or CBVH_E_DATAPATH. */
int cbvh_dp_run_one(const cbvh_fw_hal *hal, const uint8_t *in_le, unsigned n_in, uint8_t *out_le, unsigned n_out);

#endif
