/* The wide float traversals' loop (traverse_wide_float.h) compiled with
 * -mavx and without fused multiply-adds (rtl-model/CMakeLists.txt): the box
 * tests' binary64 operations in four-lane registers (cbvh_ref_box4 / box8,
 * CBVH_REF_AVX), every operation per box the baseline's, so the same results
 * bit for bit.  Called only on CPUs with AVX (wide_isa.c).  Internal. */
#include "qbvh/traverse_wide_float.h"

#if !CBVH_REF_AVX
#error "traverse_wide_float_avx.c is compiled with -mavx"
#endif

int cbvh_wide_trace_avx4(const wide_tree *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                         cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    return wide_trace(4, f, tris, ray, mode, hit, st);
}

int cbvh_wide_trace_avx8(const wide_tree *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                         cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    return wide_trace(8, f, tris, ray, mode, hit, st);
}
