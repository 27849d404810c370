/* The table of formats (cbvh/format.h): one entry per file of this folder.
 * A new format is its file and its line here. */
#include <stdio.h>
#include <string.h>

#include "cbvh/format.h"

extern const cbvh_format cbvh_format_float, cbvh_format_cbvh, cbvh_format_qbvh, cbvh_format_tlist;

static const cbvh_format *const table[] = {
    &cbvh_format_float, /* the reference: first */
    &cbvh_format_cbvh,
    &cbvh_format_qbvh,
    &cbvh_format_tlist,
};

#define NFORMATS (sizeof table / sizeof table[0])

const cbvh_format *const *cbvh_formats(size_t *n) {
    *n = NFORMATS;
    return table;
}

const cbvh_format *cbvh_format_find(const char *spec) {
    for (size_t i = 0; i < NFORMATS; i++) {
        const cbvh_format *f = table[i];
        size_t len = strlen(f->name);
        if (strcmp(spec, f->name) == 0 || ((f->flags & CBVH_FORMAT_OPTIONS) && strncmp(spec, f->name, len) == 0))
            return f;
    }
    return NULL;
}

void cbvh_format_names(char *out, size_t n) {
    size_t used = 0;
    out[0] = 0;
    for (size_t i = 0; i < NFORMATS && used < n; i++) {
        const char *sep = i == 0 ? "" : i + 1 == NFORMATS ? " or " : ", ";
        int k = snprintf(out + used, n - used, "%s%s%s", sep, table[i]->name,
                         table[i]->flags & CBVH_FORMAT_OPTIONS ? "[:options]" : "");
        if (k < 0) break;
        used += (size_t)k;
    }
}

int cbvh_format_parse(const char *spec, const cbvh_format **f, char *canon, size_t n, char *err, size_t errlen) {
    *f = cbvh_format_find(spec);
    if (!*f) {
        char names[256];
        cbvh_format_names(names, sizeof names);
        snprintf(err, errlen, "format '%s': expected %s", spec, names);
        return -1;
    }
    if ((*f)->parse) return (*f)->parse(spec, canon, n, err, errlen);
    snprintf(canon, n, "%s", spec);
    return 0;
}
