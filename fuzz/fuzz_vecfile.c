/* libFuzzer: the golden-vector file reader (host/vectors/vecfile.h). */
#include <stdint.h>
#include <stdlib.h>

#include "vectors/vecfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    cbvh_vecfile vf;
    char err[256];
    if (cbvh_vecfile_parse((const char *)data, size, "fuzz", &vf, err, sizeof err) == CBVH_VEC_OK) {
        /* A parsed file is internally consistent: touch every word. */
        volatile uint32_t sink = 0;
        for (size_t i = 0; i < vf.count * (size_t)vf.layout.n_in; i++) sink ^= vf.in[i];
        for (size_t i = 0; i < vf.count * (size_t)vf.layout.n_out; i++) sink ^= vf.out[i];
        if (sink == 0x12345678u && vf.count == 0) abort(); /* keeps the reads */
        cbvh_vecfile_free(&vf);
    } else if (!err[0]) {
        abort(); /* every rejection names its reason */
    }
    return 0;
}
