/* JSON for the host tool: every --json output is one cJSON tree written by
 * cbvh_json_print, and JSON text read with cJSON is checked for what cJSON
 * passes over silently (a \u0000 escape ends its C string early). */
#ifndef CBVH_HOST_JSON_H
#define CBVH_HOST_JSON_H

#include <stddef.h>
#include <stdio.h>

#include <cjson/cJSON.h>

/* JSON must be UTF-8, but file names are bytes: a byte that does not belong
 * to a well-formed UTF-8 sequence (RFC 3629: no overlong forms, surrogates or
 * code points past U+10FFFF) is written as \u00XX, the character of the same
 * value (the byte read as Latin-1), so the name stays recognisable. */

/* Length (1..4) of the well-formed UTF-8 sequence starting at s, 0 if none. */
int cbvh_utf8_len(const unsigned char *s);

/* Writes JSON text (cJSON_Print output: it escapes quotes and control bytes
 * but passes other bytes through unchecked) with every byte outside
 * well-formed UTF-8 as \u00XX.  Such bytes can only sit inside strings. */
void cbvh_json_fputs_utf8(const char *s, FILE *f);

/* The --json writer: root as one line of compact JSON and a newline on f,
 * bytes outside UTF-8 as above.  0, or -1 when f reports a write error (the
 * caller's one line; for stdout, main's).  Out of memory is
 * cbvh_out_of_memory. */
int cbvh_json_print(const cJSON *root, FILE *f);
/* The same, indented (cJSON_Print), for `cbvh run --json`. */
int cbvh_json_print_pretty(const cJSON *root, FILE *f);

/* The offset in text (len bytes of JSON) of the first NUL, a raw byte or a
 * \u0000 escape inside a string, or len if none.  cJSON keeps it in the
 * string, where it ends the C string: "a.obj\u0000x" would read as "a.obj". */
size_t cbvh_json_find_nul(const char *text, size_t len);

#endif
