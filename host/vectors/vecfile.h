/* Golden vector files: a strict reader and the writer (docs/vectors.md).
 *
 * A file is a text header of "key: value" lines, a "---" line, then one vector
 * per line: the unit's input fields, then its output fields, each written as
 * exactly the field's hex_digits upper-case hex digits (cbvh_layout order).
 *
 * The reader parses from a memory buffer, never trusts the header's count for
 * allocation, and reports the first problem as one line "name:line: what". */
#ifndef CBVH_HOST_VECFILE_H
#define CBVH_HOST_VECFILE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "cbvh/unit_table.h"

#define CBVH_VEC_MAGIC "# cbvh golden vectors"
#define CBVH_VEC_FORMAT 1
#define CBVH_VEC_MAX_COUNT 100000000u /* sanity bound on the count header */
#define CBVH_READ_MAX_BYTES (UINT64_C(1) << 31) /* vector files and manifests: 2 GiB at most */

/* Reader results.  Each names one class of bad input; the message says more. */
typedef enum {
    CBVH_VEC_OK = 0,
    CBVH_VEC_E_IO,          /* cannot open/read the file */
    CBVH_VEC_E_EMPTY,       /* zero bytes */
    CBVH_VEC_E_MAGIC,       /* first line is not CBVH_VEC_MAGIC (or binary garbage) */
    CBVH_VEC_E_HEADER,      /* malformed, unknown, duplicate or missing header key */
    CBVH_VEC_E_UNIT,        /* unknown unit name */
    CBVH_VEC_E_VERSION,     /* unsupported format version */
    CBVH_VEC_E_PARAM,       /* parameter out of range (quant_bits, min_scale, level, encoding...) */
    CBVH_VEC_E_FIELDS,      /* the fields header does not match the unit layout */
    CBVH_VEC_E_HEX,         /* a character that is not an upper-case hex digit */
    CBVH_VEC_E_WIDTH,       /* a field with the wrong number of digits */
    CBVH_VEC_E_FIELD_COUNT, /* a vector line with too few / too many fields */
    CBVH_VEC_E_COUNT,       /* number of vector lines differs from the count header */
    CBVH_VEC_E_NOMEM,
} cbvh_vec_status;

typedef struct {
    const cbvh_unit *unit;
    cbvh_unit_config cfg; /* cfg.enc is CBVH_ENC_MODULO when the unit has no encoding */
    int level;            /* generator level: 1 or 2 */
    uint64_t seed;        /* generator seed (as given to `vectors gen`) */
    unsigned generator;   /* generator version */
    cbvh_layout layout;
    size_t count;     /* number of vectors */
    size_t first_line; /* line number (1-based) of vector 0; vector i is on first_line + i */
    uint32_t *in;     /* count * layout.n_in words */
    uint32_t *out;    /* count * layout.n_out words (expected outputs) */
} cbvh_vecfile;

/* Parses buf[0..len).  name is used in messages only.  On error *vf is left
 * empty (nothing to free) and err holds "name:line: message". */
cbvh_vec_status cbvh_vecfile_parse(const char *buf, size_t len, const char *name, cbvh_vecfile *vf, char *err,
                                   size_t errlen);

/* Reads a whole file into memory (malloc'd, caller frees).  0 on success, else
 * err holds "path: reason". */
int cbvh_read_file(const char *path, char **buf, size_t *len, char *err, size_t errlen);

/* Reads and parses a file. */
cbvh_vec_status cbvh_vecfile_load(const char *path, cbvh_vecfile *vf, char *err, size_t errlen);

void cbvh_vecfile_free(cbvh_vecfile *vf);

/* Writes vf in the file format.  Returns 0, or -1 when a value does not fit
 * its field (a generator bug) or the stream fails. */
int cbvh_vecfile_write(FILE *f, const cbvh_vecfile *vf);

/* Short name of a reader status ("bad hex", "count mismatch", ...). */
const char *cbvh_vec_status_name(cbvh_vec_status st);

#endif
