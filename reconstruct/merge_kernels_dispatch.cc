// The baseline copy of the bracket merge's row kernels and the choice between the copies
// (merge_kernels.h).
#include "reconstruct/merge_kernels.h"

#define LUMISLAB_MERGE_ISA baseline
#include "reconstruct/merge_kernels_simd.h"

namespace lumislab::merge {

namespace baseline {
// The plain table lookups: the entries first (vectorised), then the lookups.
void QuantLookups(const float* __restrict table, const float* __restrict pilot, int m, float eff,
                  float range, float black, int* __restrict entry, float* __restrict q) {
  for (int i = 0; i < m; ++i) entry[i] = QuantTableEntry(eff * pilot[i] * range + black);
  for (int i = 0; i < m; ++i) q[i] = table[entry[i]];
}
}  // namespace baseline

#ifdef LUMISLAB_MERGE_ISA_COPIES
// The other copies (merge_kernels_avx2.cc, merge_kernels_x86_64_v4.cc, merge_kernels_avx512f.cc).
namespace avx2 {
decltype(merge::MergeSlideChunk) MergeSlideChunk;
decltype(merge::CombineSlides) CombineSlides;
}  // namespace avx2
namespace x86_64_v4 {
decltype(merge::MergeSlideChunk) MergeSlideChunk;
decltype(merge::CombineSlides) CombineSlides;
}  // namespace x86_64_v4
namespace avx512f {
decltype(merge::MergeSlideChunkFused) MergeSlideChunkFused;
decltype(merge::QuantLookups) QuantLookups;
}  // namespace avx512f
#endif

namespace {

struct Kernels {
  decltype(&merge::MergeSlideChunk) merge_slide_chunk = baseline::MergeSlideChunk;
  decltype(&merge::MergeSlideChunkFused) merge_slide_chunk_fused = nullptr;  // none: false
  decltype(&merge::CombineSlides) combine_slides = baseline::CombineSlides;
  decltype(&merge::QuantLookups) quant_lookups = baseline::QuantLookups;
};

// The best copy of each kernel that the processor runs, in the order of preference of GCC's
// target_clones("arch=x86-64-v4", "avx2", "default") for the row kernels, and AVX-512F or not for
// the fused kernel and the table lookups.
Kernels Choose() {
  Kernels k;
#ifdef LUMISLAB_MERGE_ISA_COPIES
  __builtin_cpu_init();
  if (__builtin_cpu_supports("x86-64-v4")) {
    k.merge_slide_chunk = x86_64_v4::MergeSlideChunk;
    k.combine_slides = x86_64_v4::CombineSlides;
  } else if (__builtin_cpu_supports("avx2")) {
    k.merge_slide_chunk = avx2::MergeSlideChunk;
    k.combine_slides = avx2::CombineSlides;
  }
  if (__builtin_cpu_supports("avx512f")) {
    k.merge_slide_chunk_fused = avx512f::MergeSlideChunkFused;
    k.quant_lookups = avx512f::QuantLookups;
  }
#endif
  return k;
}

const Kernels& Chosen() {
  static const Kernels kernels = Choose();
  return kernels;
}

}  // namespace

void MergeSlideChunk(const SlideParams& p, const float* u, int m, SlideScratch& s, float* value,
                     uint8_t* state, float* brightest, float* faintest) {
  Chosen().merge_slide_chunk(p, u, m, s, value, state, brightest, faintest);
}

bool MergeSlideChunkFused(const SlideParams& p, const float* u, int m, float* value, uint8_t* state,
                          float* brightest, float* faintest) {
  const auto fused = Chosen().merge_slide_chunk_fused;
  return fused && fused(p, u, m, value, state, brightest, faintest);
}

void CombineSlides(const float* v0, const float* v1, const uint8_t* s0, const uint8_t* s1,
                   int pixels, float gain, float* difference, float* saturated,
                   int* saturated_count, int* near_black_count) {
  Chosen().combine_slides(v0, v1, s0, s1, pixels, gain, difference, saturated, saturated_count,
                          near_black_count);
}

void QuantLookups(const float* table, const float* pilot, int m, float eff, float range,
                  float black, int* entry, float* q) {
  Chosen().quant_lookups(table, pilot, m, eff, range, black, entry, q);
}

}  // namespace lumislab::merge
