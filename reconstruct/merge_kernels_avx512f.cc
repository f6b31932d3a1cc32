// The AVX-512F intrinsics of the bracket merge (merge_kernels.h): the fused slide kernel and the
// quantisation term's table lookups, chosen by merge_kernels_dispatch.cc on processors with
// AVX-512F.
#include "reconstruct/merge_kernels.h"

#ifdef LUMISLAB_MERGE_ISA_COPIES

#pragma GCC push_options
#pragma GCC target("avx512f")

namespace lumislab::merge::avx512f {
namespace {

// 16 entries at a time, the same float operations in the same order as the plain QuantLookups
// (merge_kernels_dispatch.cc). The lookups as permutes from windows of 32 consecutive table
// entries; the lanes outside them gathered. Lane j holds the channel of lane j % 3 (the values
// are R, G, B in turn from lane 0 of each chunk, and a vector is 16 values): three windows, one
// per channel, each from 16 below an entry of that channel (QuantBases). Any window gives the
// same values (the table's entries); the windows only decide how many lanes are gathered.
// `need`: the lanes whose entry is used; the others may hold any entry of the table.
LUMISLAB_INLINE __m512i QuantEntries16(__m512 pilot, float eff, float range, float black) {
  constexpr int kLast = kQuantTable - 1;
  const __m512 l =
      _mm512_add_ps(_mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(eff), pilot), _mm512_set1_ps(range)),
                    _mm512_set1_ps(black));
  // l >= 1: the last entry; 0 < l < 1: int(l * kLast + 0.5); else (and NaN) 0.
  const __m512i e = _mm512_maskz_cvttps_epi32(
      _mm512_cmp_ps_mask(l, _mm512_setzero_ps(), _CMP_GT_OQ),
      _mm512_add_ps(_mm512_mul_ps(l, _mm512_set1_ps(float(kLast))), _mm512_set1_ps(0.5f)));
  return _mm512_mask_mov_epi32(e, _mm512_cmp_ps_mask(l, _mm512_set1_ps(1.f), _CMP_GE_OQ),
                               _mm512_set1_epi32(kLast));
}

// The windows' first entries from the entries e of a vector: for the same vector `first` = 0
// (lanes 0, 1, 2), for the next one `first` = 1 (its lanes 0, 1, 2 hold the channels of lanes 1,
// 2, 3 here, 5 pixels on): the fused merge takes the previous vector's, so that the table reads
// need not wait for this vector's entries.
LUMISLAB_INLINE void QuantBases(__m512i e, int first, int* base) {
  constexpr int kLast = kQuantTable - 1, kWindow = 32;
  alignas(64) int entries[16];
  _mm512_store_si512(entries, e);
  for (int c = 0; c < 3; ++c) base[c] = std::clamp(entries[first + c] - 16, 0, kLast + 1 - kWindow);
}

LUMISLAB_INLINE __m512 QuantLookup16(const float* __restrict table, __m512i e, const int* base,
                                     __mmask16 need) {
  constexpr int kWindow = 32;
  constexpr __mmask16 kChannel1 = 0x2492, kChannel2 = 0x4924;  // lanes 1, 4, ...; 2, 5, ...
  const __m512i lane_base = _mm512_mask_mov_epi32(
      _mm512_mask_mov_epi32(_mm512_set1_epi32(base[0]), kChannel1, _mm512_set1_epi32(base[1])),
      kChannel2, _mm512_set1_epi32(base[2]));
  const __m512i d = _mm512_sub_epi32(e, lane_base);
  const __mmask16 outside = _mm512_cmpge_epu32_mask(d, _mm512_set1_epi32(kWindow)) & need;
  __m512 window[3];
  for (int c = 0; c < 3; ++c)
    window[c] = _mm512_permutex2var_ps(_mm512_loadu_ps(table + base[c]), d,
                                       _mm512_loadu_ps(table + base[c] + 16));
  __m512 v =
      _mm512_mask_mov_ps(_mm512_mask_mov_ps(window[0], kChannel1, window[1]), kChannel2, window[2]);
  if (outside) v = _mm512_mask_i32gather_ps(v, outside, e, table, 4);
  return v;
}

// The three passes of merge_kernels_simd.h fused into one, 16 values at a time: each
// exposure's values are loaded once and the pilot, its sums and the table terms stay in
// registers (the passes' loops stored and re-read them, and QuantLookups was a call per exposure
// and chunk). The same IEEE operations in the same order on every lane as PilotPass, QuantPass
// and WeightPass, so the same numbers. The table is read only where the exposure's value is well
// exposed (elsewhere its weight is not used): fewer gathers. Slides of up to kMaxUnrolled
// exposures (MergeSlideChunkFused).
template <int kN, bool kCurved>
LUMISLAB_INLINE void FusedSlideChunk(const SlideParams& p, const float* __restrict u, int m,
                                     float* __restrict value, uint8_t* __restrict state,
                                     float* __restrict brightest, float* __restrict faintest) {
  float eff[kN], inv_eff[kN], floor_u[kN], constant[kN], range[kN], black[kN];
  const float* quant_var[kN];
  for (int k = 0; k < kN; ++k) {
    eff[k] = p.eff[k], inv_eff[k] = p.inv_eff[k], floor_u[k] = p.floor_u[k];
    constant[k] = p.constant[k], range[k] = p.range[k], black[k] = p.black[k];
    quant_var[k] = p.quant_var[k];
  }
  const __m512 zero = _mm512_setzero_ps();
  const __m512 inv_full_well = _mm512_set1_ps(p.inv_full_well);
  int base[kN][3] = {};  // QuantLookup16's windows, from the previous vector's entries
  for (int i = 0; i < m; i += 16) {
    const __mmask16 lanes = m - i >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << (m - i)) - 1);
    // Pilot (PilotPass).
    __m512 x[kN];
    __mmask16 well[kN];
    __m512 su = zero, se = zero, lg = zero;
    __mmask16 found = 0;
    for (int k = 0; k < kN; ++k) {
      x[k] = _mm512_maskz_loadu_ps(lanes, u + k * kChunk + i);
      const __mmask16 unclipped = _mm512_cmp_ps_mask(x[k], x[k], _CMP_EQ_OQ);
      well[k] = _mm512_cmp_ps_mask(x[k], _mm512_set1_ps(floor_u[k]), _CMP_GE_OQ) &
                _mm512_cmp_ps_mask(x[k], zero, _CMP_GT_OQ);
      su = _mm512_add_ps(su, _mm512_maskz_mov_ps(well[k], x[k]));
      se = _mm512_add_ps(se, _mm512_maskz_mov_ps(well[k], _mm512_set1_ps(eff[k])));
      lg = _mm512_add_ps(lg, _mm512_maskz_mov_ps(__mmask16(unclipped & ~found),
                                                 _mm512_mul_ps(x[k], _mm512_set1_ps(inv_eff[k]))));
      found = __mmask16(found | unclipped);
    }
    const __m512 pilot = _mm512_div_ps(su, se);
    // Weights (QuantPass, WeightPass).
    __m512 sw = zero, swx = zero;
    for (int k = 0; k < kN; ++k) {
      const __m512 e = _mm512_set1_ps(eff[k]);
      __m512 variance = _mm512_add_ps(_mm512_mul_ps(_mm512_mul_ps(e, pilot), inv_full_well),
                                      _mm512_set1_ps(constant[k]));
      if (kCurved) {
        __m512 q = zero;
        if (quant_var[k]) {
          const __m512i entry = QuantEntries16(pilot, eff[k], range[k], black[k]);
          if (i == 0) QuantBases(entry, 0, base[k]);
          q = QuantLookup16(quant_var[k], entry, base[k], __mmask16(well[k] & lanes));
          QuantBases(entry, 1, base[k]);  // for the next vector
        }
        variance = _mm512_add_ps(variance, q);
      }
      const __m512 w_over_e = _mm512_div_ps(e, variance);
      sw = _mm512_add_ps(sw, _mm512_maskz_mov_ps(well[k], _mm512_mul_ps(w_over_e, e)));
      swx = _mm512_add_ps(swx, _mm512_maskz_mov_ps(well[k], _mm512_mul_ps(w_over_e, x[k])));
    }
    const __mmask16 measured = _mm512_cmp_ps_mask(se, zero, _CMP_GT_OQ);
    // !any: 0; measured: swx / sw; else the longest unclipped value.
    const __m512 v =
        _mm512_maskz_mov_ps(found, _mm512_mask_mov_ps(lg, measured, _mm512_div_ps(swx, sw)));
    _mm512_mask_storeu_ps(value + i, lanes, v);
    const __m512i st = _mm512_mask_mov_epi32(
        _mm512_set1_epi32(kClippedEverywhere), found,
        _mm512_maskz_mov_epi32(__mmask16(~measured), _mm512_set1_epi32(kNearBlackEverywhere)));
    _mm512_mask_cvtepi32_storeu_epi8(state + i, lanes, st);
    const __m512 b = _mm512_maskz_mov_ps(measured, v);
    const __m512 old_b = _mm512_maskz_loadu_ps(lanes, brightest + i);
    _mm512_mask_storeu_ps(brightest + i, lanes,
                          _mm512_mask_mov_ps(old_b, _mm512_cmp_ps_mask(old_b, b, _CMP_LT_OQ), b));
    const __m512 old_f = _mm512_maskz_loadu_ps(lanes, faintest + i);
    const __m512 f =
        _mm512_mask_mov_ps(old_f, __mmask16(measured & _mm512_cmp_ps_mask(v, zero, _CMP_GT_OQ)), v);
    _mm512_mask_storeu_ps(faintest + i, lanes,
                          _mm512_mask_mov_ps(old_f, _mm512_cmp_ps_mask(f, old_f, _CMP_LT_OQ), f));
  }
}

}  // namespace

void QuantLookups(const float* __restrict table, const float* __restrict pilot, int m, float eff,
                  float range, float black, int* __restrict, float* __restrict q) {
  for (int i = 0; i < m; i += 16) {
    const __mmask16 lanes = m - i >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << (m - i)) - 1);
    const __m512i e = QuantEntries16(_mm512_maskz_loadu_ps(lanes, pilot + i), eff, range, black);
    int base[3];
    QuantBases(e, 0, base);
    const __m512 v = QuantLookup16(table, e, base, lanes);
    _mm512_mask_storeu_ps(q + i, lanes, v);
  }
}

bool MergeSlideChunkFused(const SlideParams& p, const float* u, int m, float* value, uint8_t* state,
                          float* brightest, float* faintest) {
  static_assert(kMaxUnrolled == 4, "MergeSlideChunkFused: one case per unrolled count");
#define LUMISLAB_FUSED_CASE(kN)                                               \
  case kN:                                                                    \
    if (p.curved)                                                             \
      FusedSlideChunk<kN, true>(p, u, m, value, state, brightest, faintest);  \
    else                                                                      \
      FusedSlideChunk<kN, false>(p, u, m, value, state, brightest, faintest); \
    return true;
  switch (p.n) {
    LUMISLAB_FUSED_CASE(1)
    LUMISLAB_FUSED_CASE(2)
    LUMISLAB_FUSED_CASE(3)
    LUMISLAB_FUSED_CASE(4)
    default:
      return false;
  }
#undef LUMISLAB_FUSED_CASE
}

}  // namespace lumislab::merge::avx512f

#pragma GCC pop_options

#endif  // LUMISLAB_MERGE_ISA_COPIES
