/* Which build of the wide float traversals' loop runs (cbvh_wide_float_isa,
 * docs/traversal.md §15): the AVX one where it was compiled in and the CPU
 * and OS have AVX and POPCNT (every AVX CPU has it; GCC's and Clang's
 * __builtin_cpu_supports checks CPUID and the OS saving the YMM registers),
 * else the baseline.  And whether its binary32 box lanes may run (§16). */
#include <stdatomic.h>

#include "cbvh/traverse.h"

static cbvh_wide_isa isa_limit = CBVH_WIDE_ISA_AVX;

#ifdef CBVH_WIDE_AVX
/* The CPU's answer, asked once (every traversal calls cbvh_wide_float_isa;
 * the two CPUID lookups were a sixtieth of a camera ray): -1 not yet, else
 * 0/1.  Relaxed atomics: threads may race to store the same value. */
static _Atomic int cpu_avx = -1;

static int cpu_has_avx(void) {
    int v = atomic_load_explicit(&cpu_avx, memory_order_relaxed);
    if (v < 0) {
        v = __builtin_cpu_supports("avx") && __builtin_cpu_supports("popcnt");
        atomic_store_explicit(&cpu_avx, v, memory_order_relaxed);
    }
    return v;
}
#endif

cbvh_wide_isa cbvh_wide_float_isa(void) {
#ifdef CBVH_WIDE_AVX
    if (isa_limit >= CBVH_WIDE_ISA_AVX && cpu_has_avx()) return CBVH_WIDE_ISA_AVX;
#endif
    return CBVH_WIDE_ISA_BASE;
}

void cbvh_wide_float_limit_isa(cbvh_wide_isa max) { isa_limit = max; }

const char *cbvh_wide_isa_name(cbvh_wide_isa isa) { return isa == CBVH_WIDE_ISA_AVX ? "avx" : "base"; }

static int box32 = 1;

void cbvh_wide_float_box32(int on) { box32 = on != 0; }

int cbvh_wide_float_box32_on(void) { return box32; }
