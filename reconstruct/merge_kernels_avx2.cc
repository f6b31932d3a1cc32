// The AVX2 copy of the bracket merge's row kernels (merge_kernels.h), chosen by
// merge_kernels_dispatch.cc on processors that run it.
#include "reconstruct/merge_kernels.h"

#ifdef LUMISLAB_MERGE_ISA_COPIES
#pragma GCC push_options
#pragma GCC target("avx2")
#define LUMISLAB_MERGE_ISA avx2
#include "reconstruct/merge_kernels_simd.h"
#pragma GCC pop_options
#endif
