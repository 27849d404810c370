/* Golden vector generator (docs/vectors.md, "Generator").
 *
 * Deterministic: the vectors of one file depend only on the unit, its
 * parameters, the level and the seed (xoshiro256** seeded by splitmix64 from
 * the seed and the file's stem), never on the host.  Expected outputs come
 * from the bit-exact model (unit->eval). */
#ifndef CBVH_HOST_VECGEN_H
#define CBVH_HOST_VECGEN_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/unit_table.h"
#include "vectors/vecfile.h"

#define CBVH_VECGEN_VERSION 10
#define CBVH_VECGEN_DEFAULT_SEED UINT64_C(0xCB7C0DE5EED00001)
#define CBVH_VECGEN_LEVEL2_RANDOM 100000 /* random vectors added by level 2 */
#define CBVH_VECGEN_LEVEL2_EXACT 20000   /* then exact-path cases (ray units) */

typedef struct {
    const cbvh_unit *unit;
    cbvh_unit_config cfg; /* cfg.enc only meaningful when unit->uses_encoding */
    int level;            /* 1 or 2 */
    uint64_t seed;
} cbvh_vecgen_spec;

/* File name of a spec: "<unit>-N<bits>-ms<min_scale>[-<encoding>][-L2].vec",
 * e.g. axis_decode-N6-ms-30-modulo.vec. */
void cbvh_vecgen_filename(const cbvh_vecgen_spec *s, char *buf, size_t n);

/* Generates the vectors of one file into vf (caller frees with
 * cbvh_vecfile_free).  0, or -1 when out of memory. */
int cbvh_vecgen_generate(const cbvh_vecgen_spec *s, cbvh_vecfile *vf);

/* Selection of specs to generate.  unit NULL = all units; bits 0 = the
 * default set (N = 3..10, min_scale = ms_given ? min_scale : -30, plus N = 6
 * with min_scale -126 and -10 for the axis units when neither bits nor
 * min_scale was given); enc_given restricts the encoding.  Writes up to max
 * specs and returns how many there are in total. */
typedef struct {
    const cbvh_unit *unit;
    int bits;
    int ms_given, min_scale;
    int enc_given;
    cbvh_encoding enc;
    int level;
    uint64_t seed;
} cbvh_vecgen_select;

size_t cbvh_vecgen_specs(const cbvh_vecgen_select *sel, cbvh_vecgen_spec *out, size_t max);

#endif
