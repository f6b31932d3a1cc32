// The x86-64-v4 copy of the bracket merge's row kernels (merge_kernels.h), chosen by
// merge_kernels_dispatch.cc on processors that run it. x86-64-v4 (AVX-512F, BW, DQ, VL): 16
// values per operation and mask registers for the selects. (With AVX-512F alone GCC keeps the
// weighted pass, whose states are bytes, in 256-bit AVX, which measured slower.)
#include "reconstruct/merge_kernels.h"

#ifdef LUMISLAB_MERGE_ISA_COPIES
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
#define LUMISLAB_MERGE_ISA x86_64_v4
#include "reconstruct/merge_kernels_simd.h"
#pragma GCC pop_options
#endif
