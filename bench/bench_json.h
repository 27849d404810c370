/* A benchmark's --json FILE: the whole document goes to FILE.tmp, which is
 * then renamed, so a failed run leaves no half-written FILE. */
#ifndef CBVH_BENCH_JSON_H
#define CBVH_BENCH_JSON_H

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>

/* 0, or -1 (nothing written, FILE.tmp removed). */
static inline int bench_json_write(const cJSON *root, const char *path) {
    char *txt = cJSON_Print(root), tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    int ok = txt && f && fputs(txt, f) >= 0;
    if (f && fclose(f) != 0) ok = 0;
    free(txt);
    if (ok && rename(tmp, path) == 0) return 0;
    remove(tmp);
    return -1;
}

#endif
