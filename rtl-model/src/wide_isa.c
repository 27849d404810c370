/* Which build of the wide float traversals' loop runs (cbvh_wide_float_isa,
 * docs/traversal.md §15): the AVX one where it was compiled in and the CPU
 * and OS have AVX (GCC's and Clang's __builtin_cpu_supports checks both:
 * CPUID and the OS saving the YMM registers), else the baseline. */
#include "cbvh/traverse.h"

static cbvh_wide_isa isa_limit = CBVH_WIDE_ISA_AVX;

cbvh_wide_isa cbvh_wide_float_isa(void) {
#ifdef CBVH_WIDE_AVX
    if (isa_limit >= CBVH_WIDE_ISA_AVX && __builtin_cpu_supports("avx")) return CBVH_WIDE_ISA_AVX;
#endif
    return CBVH_WIDE_ISA_BASE;
}

void cbvh_wide_float_limit_isa(cbvh_wide_isa max) { isa_limit = max; }

const char *cbvh_wide_isa_name(cbvh_wide_isa isa) { return isa == CBVH_WIDE_ISA_AVX ? "avx" : "base"; }
