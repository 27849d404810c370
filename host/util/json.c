/* JSON output and input checks (json.h). */
#include "util/json.h"

#include <stdlib.h>
#include <string.h>

#include "cbvh/oom.h"

int cbvh_utf8_len(const unsigned char *s) {
    unsigned c = s[0];
    if (c < 0x80) return 1;
    int n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    if (!n) return 0;
    /* the second byte's range excludes overlong forms, surrogates and > U+10FFFF */
    unsigned lo = c == 0xE0 ? 0xA0 : c == 0xF0 ? 0x90 : 0x80, hi = c == 0xED ? 0x9F : c == 0xF4 ? 0x8F : 0xBF;
    if (s[1] < lo || s[1] > hi) return 0;
    for (int i = 2; i < n; i++)
        if ((s[i] & 0xC0) != 0x80) return 0;
    return n;
}

void cbvh_json_fputs_utf8(const char *s, FILE *f) {
    const unsigned char *p = (const unsigned char *)s;
    while (*p) {
        int n = cbvh_utf8_len(p);
        if (n)
            fwrite(p, 1, (size_t)n, f);
        else
            fprintf(f, "\\u%04x", *p);
        p += n ? n : 1;
    }
}

static int json_write(const cJSON *root, FILE *f, int pretty) {
    char *txt = pretty ? cJSON_Print(root) : cJSON_PrintUnformatted(root);
    if (!txt) cbvh_out_of_memory("JSON output");
    cbvh_json_fputs_utf8(txt, f); /* file names may hold bytes that are not UTF-8 */
    fputc('\n', f);
    free(txt);
    return fflush(f) == 0 && !ferror(f) ? 0 : -1;
}

int cbvh_json_print(const cJSON *root, FILE *f) { return json_write(root, f, 0); }
int cbvh_json_print_pretty(const cJSON *root, FILE *f) { return json_write(root, f, 1); }

size_t cbvh_json_find_nul(const char *text, size_t len) {
    /* Outside strings a backslash is not JSON at all (the parser refuses it),
     * so every backslash starts an escape: step over each, "\\" included. */
    for (size_t i = 0; i < len; i++) {
        if (!text[i]) return i;
        if (text[i] != '\\' || i + 1 == len || !text[i + 1]) continue;
        if (text[i + 1] == 'u' && i + 6 <= len && strncmp(text + i + 2, "0000", 4) == 0) return i;
        i++;
    }
    return len;
}
