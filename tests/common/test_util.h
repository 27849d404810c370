/* The prelude the tests share: a CHECK-style failure report, the xorshift64
 * generator and binary32 bit helpers.  Header-only (macros, static inline), so
 * each test keeps its own counter, stream and generator state and seed. */
#ifndef CBVH_TEST_UTIL_H
#define CBVH_TEST_UTIL_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cbvh/fp32.h"

/* Count a failed `cond` in `counter`; print the first 20 to `stream` as
 * "FAIL file:line: <message>".  A test wraps it as its CHECK:
 *   #define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__) */
#define TU_CHECK(counter, stream, cond, ...)                                                                           \
    do {                                                                                                               \
        if (!(cond)) {                                                                                                 \
            if ((counter)++ < 20) {                                                                                    \
                fprintf(stream, "FAIL %s:%d: ", __FILE__, __LINE__);                                                   \
                fprintf(stream, __VA_ARGS__);                                                                          \
                fprintf(stream, "\n");                                                                                 \
            }                                                                                                          \
        }                                                                                                              \
    } while (0)

/* xorshift64 (13, 7, 17) on the caller's state; the seed picks the sequence. */
static inline uint64_t tu_xorshift64(uint64_t *s) {
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}
/* xorshift32 (13, 17, 5), for the tests that use 32-bit states. */
static inline uint32_t tu_xorshift32(uint32_t *s) {
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return *s;
}
/* Uniform in [0, 1) from the top 53 bits, as a double and rounded to float. */
static inline double tu_unit_d(uint64_t *s) { return (double)(tu_xorshift64(s) >> 11) / 9007199254740992.0; }
static inline float tu_unit_f(uint64_t *s) { return (float)tu_unit_d(s); }

/* An output digest, FNV-1a 64 over the bytes of each value (low byte
 * first): two builds of a test agree iff their digests do. */
typedef struct {
    uint64_t h;
} digest;
static inline void digest_init(digest *d) { d->h = UINT64_C(0xCBF29CE484222325); }
static inline void digest_u32(digest *d, uint32_t v) {
    for (int i = 0; i < 4; i++) {
        d->h ^= (v >> (8 * i)) & 0xFFu;
        d->h *= UINT64_C(0x100000001B3);
    }
}
static inline void digest_u64(digest *d, uint64_t v) {
    digest_u32(d, (uint32_t)v);
    digest_u32(d, (uint32_t)(v >> 32));
}

/* binary32 bit pattern of a float, and back (short names for the tests). */
static inline cbvh_f32 fb(float f) { return cbvh_f32_of(f); }
static inline float bf(cbvh_f32 b) { return cbvh_float_of(b); }

#endif
