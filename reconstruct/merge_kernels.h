// The bracket merge's row kernels (reconstruct/photo_merge.cc merges a row a chunk at a time
// through them) and the run-time choice of their instruction set, after OpenCV's
// *.dispatch.cpp / *.simd.hpp pattern:
//   merge_kernels_simd.h        the portable kernels, written once, included once per ISA;
//   merge_kernels_dispatch.cc   the baseline (SSE2) copy and the choice (this header's functions);
//   merge_kernels_avx2.cc       the AVX2 copy;
//   merge_kernels_x86_64_v4.cc  the x86-64-v4 copy (AVX-512F, BW, DQ, VL);
//   merge_kernels_avx512f.cc    the AVX-512F intrinsics: the fused slide kernel and table lookups.
// Every copy does the same IEEE operations in the same order (nothing is contracted into FMAs:
// -ffp-contract=off, reconstruct/CMakeLists.txt): the same numbers on every machine. A copy's ISA
// is set by `#pragma GCC target` after the file's includes, not by -m flags for the whole file:
// the inline functions of the standard library and OpenCV, of which the linker keeps one copy
// for the program, are then compiled for the baseline in every file.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

// GCC on x86-64 Linux: the kernels have AVX2, x86-64-v4 and AVX-512F copies besides the baseline,
// and the best one the processor runs is chosen at the first call (__builtin_cpu_supports, as
// GCC's function multiversioning does). Elsewhere, or with LUMISLAB_NO_TARGET_CLONES defined,
// only the baseline.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(LUMISLAB_NO_TARGET_CLONES)
#define LUMISLAB_MERGE_ISA_COPIES 1
#endif
#define LUMISLAB_INLINE inline __attribute__((always_inline))

namespace lumislab::merge {

// Entries of an exposure's table of the quantisation term (Exposure::quant_var): the curve value
// in 1/1024 steps.
constexpr int kQuantTable = 1025;
// The entry of such a table at curve value l: the nearest 1/1024 step, the last at l >= 1, the
// first at l <= 0 and NaN (an unused lane of the merge).
inline int QuantTableEntry(float l) {
  static_assert(kQuantTable == 1025, "QuantTableEntry: the last entry is 1024");
  constexpr int kLast = 1024;
  return l >= 1.f ? kLast : l > 0.f ? int(l * kLast + 0.5f) : 0;
}

// How a slide's channel at a pixel was merged.
// Bits, so that the states of a pixel's channels combine with OR.
enum : uint8_t { kMeasured = 0, kNearBlackEverywhere = 1, kClippedEverywhere = 2 };

// A row is merged in chunks of this many values (128 pixels x 3 channels), so that the
// per-exposure values and the scratch of the passes stay in the L1 cache (48 kB on Zen 5; 256
// pixels measured slower).
constexpr int kChunk = 3 * 128;
// Slides with up to this many exposures get kernels with the exposure loop unrolled (vectorised
// over the values); more take the same code with a run-time count.
constexpr int kMaxUnrolled = 4;

// One slide's exposures as the kernels read them, longest effective exposure first.
struct SlideParams {
  int n = 0;
  bool curved = false;  // some exposure's quantisation term varies (a table over the curve)
  float inv_full_well = 0;
  std::vector<float> eff, inv_eff, floor_u;
  // var(u) = (u / FW + constant) + table term: constant = read_var + quant_var[0] where the
  // term is constant (and the table term 0), read_var where it comes from the table.
  std::vector<float> constant, range, black;
  std::vector<const float*> quant_var;  // the exposure's table, nullptr where constant
};

// The per-chunk scratch of one slide: the pilot estimate, the longest unclipped value over its
// exposure, the sum of the well-exposed exposures (> 0: measured), whether any value was
// unclipped, and each exposure's table term of the variance.
struct SlideScratch {
  float pilot[kChunk], longest[kChunk], sum_e[kChunk], found[kChunk];
  float quant[kMaxUnrolled * kChunk];
  int entry[kChunk];
  std::vector<float> quant_more;  // [n * kChunk] for slides with more exposures
};

// One slide over a chunk of m values (m <= kChunk): u holds the slide's values, [k * kChunk + i]
// for its k-th exposure (longest first), NaN where clipped; value and state out, brightest and
// faintest updated lane by lane. In three passes over the chunk (pilot, the table term of curved
// photos, weighted sums) whose loops over the slide's exposures are unrolled so that the compiler
// vectorises over the values.
void MergeSlideChunk(const SlideParams& p, const float* u, int m, SlideScratch& s, float* value,
                     uint8_t* state, float* brightest, float* faintest);
// The same in one fused pass with AVX-512F intrinsics; false (nothing done) for slides of more
// than kMaxUnrolled exposures and on processors without AVX-512F, where MergeSlideChunk does the
// work.
bool MergeSlideChunkFused(const SlideParams& p, const float* u, int m, float* value, uint8_t* state,
                          float* brightest, float* faintest);
// Both slides of `pixels` pixels into gain * (v+ - v-) per value, 0 where the pixel is saturated
// (a channel of a slide clipped in every exposure: the states are bits, so one OR over the six
// channels tells), and 1 / 0 per pixel for saturated; counts the saturated and the near-black
// pixels.
void CombineSlides(const float* v0, const float* v1, const uint8_t* s0, const uint8_t* s1,
                   int pixels, float gain, float* difference, float* saturated,
                   int* saturated_count, int* near_black_count);
// The table term of m values: table[entry] at the expected u = eff * pilot (Exposure's
// quant_var, at QuantTableEntry of the curve value eff * pilot * range + black). A NaN pilot (an
// unused lane) reads entry 0. entry: scratch of m ints. (MergeSlideChunk's table pass.)
void QuantLookups(const float* table, const float* pilot, int m, float eff, float range,
                  float black, int* entry, float* q);

}  // namespace lumislab::merge
