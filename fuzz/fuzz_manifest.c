/* libFuzzer: the vector set's MANIFEST reader (host/vectors/manifest.h).  An accepted
 * manifest holds only well-formed entries (a plain printable file name, 64
 * lower-case hex digits), each findable by its name; every rejection names
 * its reason on one line. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "vectors/manifest.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    cbvh_manifest m;
    char err[256] = "";
    if (cbvh_manifest_parse((const char *)data, size, "MANIFEST", &m, err, sizeof err) == 0) {
        for (size_t i = 0; i < m.n; i++) {
            const cbvh_manifest_entry *e = &m.e[i];
            if (!cbvh_manifest_name_ok(e->name, strlen(e->name))) abort();
            if (strlen(e->sha256) != CBVH_SHA256_HEX_LEN || strspn(e->sha256, "0123456789abcdef") != CBVH_SHA256_HEX_LEN)
                abort();
            if (cbvh_manifest_find(&m, e->name) == NULL) abort();
        }
        cbvh_manifest_free(&m);
    } else if (!err[0] || strchr(err, '\n') || m.n != 0) {
        abort(); /* a reason, on one line, and nothing kept */
    }
    return 0;
}
