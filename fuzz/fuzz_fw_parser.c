/* libFuzzer: the firmware's frame parser and dispatcher.  Input = a byte
 * stream from the host, cut into chunks (first byte = chunk size) with an
 * inter-byte timeout between chunks when the chunk-size byte is odd.  Every
 * reply must be a well-formed reply frame; the core must never stop. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh_sim.h"

static cbvh_regmap_model regs;
static cbvh_fw fw;

static void check_reply(void *ctx, const uint8_t *frame, size_t len) {
    (void)ctx;
    cbvh_frame f;
    if (cbvh_frame_decode(frame, len, &f) != CBVH_E_OK || !(f.cmd & CBVH_REPLY)) abort();
}
static const cbvh_fw_hal hal = {&regs, cbvh_regmap_model_read, cbvh_regmap_model_write, check_reply, "fuzz"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    cbvh_regmap_model_init(&regs);
    cbvh_fw_init(&fw, &hal);
    size_t chunk = size ? (size_t)data[0] + 1 : 1;
    int idle = size ? data[0] & 1 : 0;
    if (size) data++, size--;
    while (size) {
        size_t k = size < chunk ? size : chunk;
        cbvh_fw_rx(&fw, data, k);
        if (idle) cbvh_fw_rx_idle(&fw);
        data += k;
        size -= k;
    }
    /* Each timeout drops at least one byte (the rescan may find another
     * candidate frame in the rest), so repeated timeouts must drain it. */
    for (int i = 0; i < (int)CBVH_FRAME_MAX + 1 && cbvh_fw_rx_partial(&fw); i++) cbvh_fw_rx_idle(&fw);
    if (cbvh_fw_rx_partial(&fw)) abort();
    return 0;
}
