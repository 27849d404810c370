/* Driver for the datapath's register map (cbvh_fw/regmap.h): select a unit,
 * write a vector's input words, start, poll, read the output words. */
#include "cbvh_fw/fw.h"
#include "cbvh_fw/regmap.h"

uint32_t cbvh_dp_config_word(const cbvh_fw_config *c) {
    return (uint32_t)(uint8_t)c->quant_bits | (uint32_t)(uint16_t)c->min_scale << 8 | (uint32_t)(c->encoding & 1u) << 24;
}

int cbvh_dp_select(const cbvh_fw_hal *hal, uint8_t unit, const cbvh_fw_config *c, uint32_t *shape) {
    if (unit >= 32 || !(hal->reg_read(hal->ctx, CBVH_REG_UNITS) & (1u << unit))) return CBVH_E_UNIT;
    hal->reg_write(hal->ctx, CBVH_REG_CONFIG, cbvh_dp_config_word(c));
    hal->reg_write(hal->ctx, CBVH_REG_UNIT_SEL, unit);
    *shape = hal->reg_read(hal->ctx, CBVH_REG_SHAPE) & 0xFFFFu;
    return *shape ? CBVH_E_OK : CBVH_E_CONFIG;
}

int cbvh_dp_run_one(const cbvh_fw_hal *hal, const uint8_t *in_le, unsigned n_in, uint8_t *out_le, unsigned n_out) {
    for (unsigned i = 0; i < n_in; i++) hal->reg_write(hal->ctx, CBVH_REG_IN(i), cbvh_get32(in_le + 4 * i));
    hal->reg_write(hal->ctx, CBVH_REG_CTRL, CBVH_CTRL_START);
    uint32_t st = 0;
    unsigned polls = 0;
    do {
        st = hal->reg_read(hal->ctx, CBVH_REG_STATUS);
    } while ((st & CBVH_STAT_BUSY) && ++polls < CBVH_DATAPATH_POLL_LIMIT);
    if ((st & (CBVH_STAT_BUSY | CBVH_STAT_ERROR)) || !(st & CBVH_STAT_DONE)) return CBVH_E_DATAPATH;
    for (unsigned i = 0; i < n_out; i++) cbvh_put32(out_le + 4 * i, hal->reg_read(hal->ctx, CBVH_REG_OUT(i)));
    return CBVH_E_OK;
}
