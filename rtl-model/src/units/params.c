#include "cbvh/datapath.h"

uint32_t cbvh_params_check(const cbvh_params *p) {
    if (p->quant_bits < CBVH_N_MIN || p->quant_bits > CBVH_N_MAX) return CBVH_ST_BAD_PARAM;
    if (p->min_scale < CBVH_SCALE_FLOOR || p->min_scale > CBVH_SCALE_CEIL) return CBVH_ST_BAD_PARAM;
    return 0;
}
