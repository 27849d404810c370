/* Input words for board tests and benchmarks: per field, a mix of plausible
 * values (small floats, scales near the range, codes below 2^N) and raw bits. */
#ifndef CBVH_TEST_GEN_INPUTS_H
#define CBVH_TEST_GEN_INPUTS_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "cbvh/unit_table.h"

static inline uint64_t cbvh_gen_next(uint64_t *s) {
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static inline void cbvh_gen_inputs(uint64_t *rng, const cbvh_unit_config *cfg, const cbvh_layout *lay, uint32_t *in,
                                   size_t count) {
    for (size_t v = 0; v < count; v++)
        for (int f = 0; f < lay->n_in; f++) {
            uint64_t r = cbvh_gen_next(rng);
            uint32_t w;
            int digits = lay->in[f].hex_digits;
            if ((r & 15) == 0) w = (uint32_t)(r >> 32); /* raw bits, any field */
            else if (digits == 8) w = cbvh_f32_of((float)((int64_t)(r >> 40) - (1 << 23)) / (float)(1u << (r % 20)));
            else if (digits == 2) w = cbvh_scale_to_word((int)((r >> 8) % 80) - 40);
            else if (digits == 3) w = (uint32_t)(r >> 8) & ((1u << cfg->params.quant_bits) - 1u);
            else w = (uint32_t)(r >> 8) & ((1u << (4 * digits)) - 1u);
            in[v * (size_t)lay->n_in + (size_t)f] = w;
        }
    /* Contexts keep parent_scale >= scale: the model's relative node-pair
     * encoder shifts by (parent_scale - scale) unchecked, which is undefined
     * for a negative difference (reported to the model's owner). */
    for (size_t v = 0; v < count; v++) {
        uint32_t *w = in + v * (size_t)lay->n_in;
        for (int f = 0; f + 1 < lay->n_in; f++) {
            size_t l = strlen(lay->in[f].name);
            if (l >= 12 && strcmp(lay->in[f].name + l - 12, "parent_scale") == 0 &&
                cbvh_scale_from_word(w[f]) < cbvh_scale_from_word(w[f + 1])) {
                uint32_t t = w[f];
                w[f] = w[f + 1];
                w[f + 1] = t;
            }
        }
    }
    /* Make lb <= ub where the layout has an (lb, ub) pair of floats, so most
     * vectors take the non-reject path. */
    for (size_t v = 0; v < count; v++) {
        uint32_t *w = in + v * (size_t)lay->n_in;
        for (int f = 0; f + 1 < lay->n_in; f++)
            if (lay->in[f].hex_digits == 8 && lay->in[f + 1].hex_digits == 8 && strstr(lay->in[f].name, "lb") &&
                strstr(lay->in[f + 1].name, "ub")) {
                float a, b;
                memcpy(&a, &w[f], 4);
                memcpy(&b, &w[f + 1], 4);
                if (a > b) {
                    uint32_t t = w[f];
                    w[f] = w[f + 1];
                    w[f + 1] = t;
                }
            }
    }
}

#endif
