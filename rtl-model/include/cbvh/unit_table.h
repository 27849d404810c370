/* Every datapath unit seen as "words in -> words out", the one shape that the
 * vector files, the board protocol and every backend share.  A field is one
 * 32-bit word written as a fixed number of hex digits (docs/vectors.md). */
#ifndef CBVH_UNIT_TABLE_H
#define CBVH_UNIT_TABLE_H

#include <stdint.h>

#include "cbvh/datapath.h"

#define CBVH_MAX_FIELDS 40

typedef struct {
    cbvh_params params;
    cbvh_encoding enc; /* used by units with uses_encoding */
} cbvh_unit_config;

typedef struct {
    const char *name;
    int hex_digits;
} cbvh_field;

typedef struct {
    int n_in, n_out;
    cbvh_field in[CBVH_MAX_FIELDS], out[CBVH_MAX_FIELDS];
} cbvh_layout;

typedef struct cbvh_unit {
    const char *name; /* as in vector files and on the command line */
    uint8_t id;       /* unit number on the board protocol */
    int uses_encoding;
    void (*layout)(const cbvh_unit_config *cfg, cbvh_layout *lay);
    void (*eval)(const cbvh_unit_config *cfg, const uint32_t *in, uint32_t *out);
} cbvh_unit;

extern const cbvh_unit *const cbvh_units[];
extern const int cbvh_unit_count;

const cbvh_unit *cbvh_unit_find(const char *name);
const cbvh_unit *cbvh_unit_by_id(int id);

/* Scales travel as 8-bit two's complement. */
static inline uint32_t cbvh_scale_to_word(int s) { return (uint32_t)s & 0xFFu; }
static inline int cbvh_scale_from_word(uint32_t w) { return (w & 0x80u) ? (int)(w & 0xFFu) - 256 : (int)(w & 0xFFu); }

const char *cbvh_encoding_name(cbvh_encoding e);
int cbvh_encoding_parse(const char *s, cbvh_encoding *e);

#endif
