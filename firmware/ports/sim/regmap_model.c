/* The FPGA register map backed by the bit-exact model: what the gateware does
 * per vector (latch IN words, evaluate the selected unit, expose OUT words). */
#include <string.h>

#include "cbvh_sim.h"

void cbvh_regmap_model_init(cbvh_regmap_model *m) { memset(m, 0, sizeof *m); }

cbvh_unit_config cbvh_regmap_config(uint32_t w) {
    cbvh_unit_config c;
    c.params.quant_bits = (int8_t)(w & 0xFFu);
    c.params.min_scale = (int16_t)((w >> 8) & 0xFFFFu);
    c.enc = (w >> 24) & 1u ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO;
    return c;
}

static uint32_t units_mask(void) {
    uint32_t m = 0;
    for (int i = 0; i < cbvh_unit_count; i++)
        if (cbvh_units[i]->id < 32) m |= 1u << cbvh_units[i]->id;
    return m;
}

uint32_t cbvh_regmap_model_read(void *ctx, uint32_t addr) {
    cbvh_regmap_model *m = ctx;
    if (addr >= CBVH_REG_OUT(0) && addr < CBVH_REG_OUT(CBVH_REG_WORDS) && addr % 4 == 0)
        return m->out[(addr - CBVH_REG_OUT(0)) / 4];
    switch (addr) {
    case CBVH_REG_ID: return CBVH_REG_ID_VALUE;
    case CBVH_REG_VERSION: return CBVH_DATAPATH_VERSION;
    case CBVH_REG_UNITS: return units_mask();
    case CBVH_REG_CONFIG: return m->config;
    case CBVH_REG_UNIT_SEL: return m->unit_sel;
    case CBVH_REG_SHAPE: {
        const cbvh_unit *u = cbvh_unit_by_id((int)m->unit_sel);
        if (!u) return 0;
        cbvh_unit_config c = cbvh_regmap_config(m->config);
        cbvh_layout lay;
        u->layout(&c, &lay);
        return (uint32_t)lay.n_in | (uint32_t)lay.n_out << 8;
    }
    case CBVH_REG_STATUS: return m->status;
    default: return 0;
    }
}

void cbvh_regmap_model_write(void *ctx, uint32_t addr, uint32_t value) {
    cbvh_regmap_model *m = ctx;
    if (addr >= CBVH_REG_IN(0) && addr < CBVH_REG_IN(CBVH_REG_WORDS) && addr % 4 == 0) {
        m->in[(addr - CBVH_REG_IN(0)) / 4] = value;
        return;
    }
    switch (addr) {
    case CBVH_REG_CONFIG: m->config = value; break;
    case CBVH_REG_UNIT_SEL: m->unit_sel = value; break;
    case CBVH_REG_CTRL:
        if (value & CBVH_CTRL_RESET) {
            memset(m->in, 0, sizeof m->in);
            memset(m->out, 0, sizeof m->out);
            m->status = 0;
        }
        if (value & CBVH_CTRL_START) {
            const cbvh_unit *u = cbvh_unit_by_id((int)m->unit_sel);
            if (!u) {
                m->status = CBVH_STAT_DONE | CBVH_STAT_ERROR;
                break;
            }
            cbvh_unit_config c = cbvh_regmap_config(m->config);
            cbvh_layout lay;
            u->layout(&c, &lay);
            if (lay.n_out > (int)CBVH_REG_WORDS || lay.n_in > (int)CBVH_REG_WORDS) {
                m->status = CBVH_STAT_DONE | CBVH_STAT_ERROR;
                break;
            }
            memset(m->out, 0, sizeof m->out); /* OUT past n_out reads 0, as in the gateware */
            u->eval(&c, m->in, m->out);
            if (m->broken_unit && (int)u->id == m->broken_unit) m->out[0] ^= 1u;
            m->runs++;
            m->status = CBVH_STAT_DONE;
        }
        break;
    default: break;
    }
}
