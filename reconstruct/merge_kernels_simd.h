// The portable row kernels of the bracket merge (merge_kernels.h), included once per ISA by
// merge_kernels_dispatch.cc (baseline), merge_kernels_avx2.cc and merge_kernels_x86_64_v4.cc, each
// time with LUMISLAB_MERGE_ISA naming the copy's namespace and the ISA's `#pragma GCC target`
// in force. Everything it needs is included by merge_kernels.h before the pragma, so that the
// standard library's functions are the baseline's in every copy. No include guard: it is meant
// to be included several times.

namespace lumislab::merge::LUMISLAB_MERGE_ISA {

// A slide's per-exposure parameters, copied to the stack when the count is a constant: the
// loops over the values may then load them unconditionally (if-converted and vectorised) where
// they are only used under a condition.
template <int kN>
struct Local {
  float local[kN > 0 ? kN : 1];
  const float* values;
  explicit Local(const std::vector<float>& v) : values(kN > 0 ? local : v.data()) {
    if (kN > 0) std::copy_n(v.data(), kN, local);
  }
  float operator[](int k) const { return values[k]; }
};

// Pilot: over the well-exposed values (Exposure::floor_u), sum u / sum exposure, the
// maximum-likelihood estimate under shot noise alone (weights = exposures). Longest first, so
// the first unclipped value met is the longest exposure's (used where all are near-black).
// u: the slide's values, [k * kChunk + i], NaN where clipped.
template <int kN>
LUMISLAB_INLINE void PilotPass(const SlideParams& p, const float* __restrict u, int m,
                               SlideScratch& __restrict s) {
  const int n = kN > 0 ? kN : p.n;
  Local<kN> eff(p.eff), inv_eff(p.inv_eff), floor_u(p.floor_u);
  for (int i = 0; i < m; ++i) {
    float su = 0, se = 0, lg = 0, found = 0;
    for (int k = 0; k < n; ++k) {
      const float x = u[k * kChunk + i];
      const float unclipped = x == x ? 1.f : 0.f;
      const bool well = (x >= floor_u[k]) & (x > 0.f);  // false where clipped (NaN)
      su += well ? x : 0.f;
      se += well ? eff[k] : 0.f;
      // lg is 0 until the first unclipped value, then stays.
      lg += (1.f - found) * unclipped > 0.f ? x * inv_eff[k] : 0.f;
      found = std::max(found, unclipped);
    }
    s.pilot[i] = su / se;  // 0 / 0 where nothing is well exposed: never used
    s.longest[i] = lg;
    s.sum_e[i] = se;
    s.found[i] = found;
  }
}

// The table term of each curved exposure's variance at the pilot's expected u = e * pilot; 0 for
// the others.
LUMISLAB_INLINE void QuantPass(const SlideParams& p, int m, SlideScratch& __restrict s,
                               float* __restrict quant) {
  for (int k = 0; k < p.n; ++k) {
    float* __restrict q = quant + k * kChunk;
    if (!p.quant_var[k]) {
      std::fill_n(q, m, 0.f);
      continue;
    }
    merge::QuantLookups(p.quant_var[k], s.pilot, m, p.eff[k], p.range[k], p.black[k], s.entry, q);
  }
}

// Inverse-variance weights e^2 / var(u) at the pilot's expected u = e * pilot: the read-noise
// and quantisation terms favour the longer exposures more than the shot-noise weights do. (Each
// exposure's own u would bias the weights towards values that read low.) With one well-exposed
// value this is that value / its exposure. Computed on every lane and selected (where the value
// is not well exposed, 0 / 0 pilots and zero variances may give NaN or inf, never used). Then
// the merged value and state, and per lane the brightest and faintest measured values.
template <int kN, bool kCurved>
LUMISLAB_INLINE void WeightPass(const SlideParams& p, const float* __restrict u, int m,
                                const SlideScratch& __restrict s, const float* __restrict quant,
                                float* __restrict value, uint8_t* __restrict state,
                                float* __restrict brightest, float* __restrict faintest) {
  const int n = kN > 0 ? kN : p.n;
  Local<kN> eff(p.eff), floor_u(p.floor_u), constant(p.constant);
  const float inv_full_well = p.inv_full_well;
  for (int i = 0; i < m; ++i) {
    const float pilot = s.pilot[i];
    float sw = 0, swx = 0;
    for (int k = 0; k < n; ++k) {
      const float x = u[k * kChunk + i];
      const bool well = (x >= floor_u[k]) & (x > 0.f);
      const float u_expected = eff[k] * pilot;
      float variance = u_expected * inv_full_well + constant[k];
      if (kCurved) variance += quant[k * kChunk + i];
      // w / e = e / var(u), applied to u: sum_wx = sum w * (u / e).
      const float w_over_e = eff[k] / variance;
      sw += well ? w_over_e * eff[k] : 0.f;
      swx += well ? w_over_e * x : 0.f;
    }
    const bool measured = s.sum_e[i] > 0.f;
    const bool any = s.found[i] != 0.f;
    const float v = !any ? 0.f : measured ? swx / sw : s.longest[i];
    value[i] = v;
    state[i] = !any ? kClippedEverywhere : measured ? kMeasured : kNearBlackEverywhere;
    // As std::max / std::min, lane by lane (a NaN value is never taken).
    const float b = measured ? v : 0.f;
    brightest[i] = brightest[i] < b ? b : brightest[i];
    const float f = (measured & (v > 0.f)) ? v : faintest[i];
    faintest[i] = f < faintest[i] ? f : faintest[i];
  }
}

template <int kN>
LUMISLAB_INLINE void MergeSlideChunkN(const SlideParams& p, const float* u, int m, SlideScratch& s,
                                      float* value, uint8_t* state, float* brightest,
                                      float* faintest) {
  PilotPass<kN>(p, u, m, s);
  if (!p.curved) {
    WeightPass<kN, false>(p, u, m, s, nullptr, value, state, brightest, faintest);
    return;
  }
  float* quant = p.n <= kMaxUnrolled ? s.quant : s.quant_more.data();
  QuantPass(p, m, s, quant);
  WeightPass<kN, true>(p, u, m, s, quant, value, state, brightest, faintest);
}

// This ISA's copy of merge_kernels.h's MergeSlideChunk.
void MergeSlideChunk(const SlideParams& p, const float* u, int m, SlideScratch& s, float* value,
                     uint8_t* state, float* brightest, float* faintest) {
  static_assert(kMaxUnrolled == 4, "MergeSlideChunk: one case per unrolled count");
  switch (p.n) {
    case 1:
      return MergeSlideChunkN<1>(p, u, m, s, value, state, brightest, faintest);
    case 2:
      return MergeSlideChunkN<2>(p, u, m, s, value, state, brightest, faintest);
    case 3:
      return MergeSlideChunkN<3>(p, u, m, s, value, state, brightest, faintest);
    case 4:
      return MergeSlideChunkN<4>(p, u, m, s, value, state, brightest, faintest);
    default:
      return MergeSlideChunkN<0>(p, u, m, s, value, state, brightest, faintest);
  }
}

// This ISA's copy of merge_kernels.h's CombineSlides.
void CombineSlides(const float* __restrict v0, const float* __restrict v1,
                   const uint8_t* __restrict s0, const uint8_t* __restrict s1, int pixels,
                   float gain, float* __restrict difference, float* __restrict saturated,
                   int* saturated_count, int* near_black_count) {
  int n_saturated = 0, n_near_black = 0;
  for (int x = 0; x < pixels; ++x) {
    const int i = 3 * x;
    const int any = s0[i] | s0[i + 1] | s0[i + 2] | s1[i] | s1[i + 1] | s1[i + 2];
    const bool sat = any & kClippedEverywhere;
    n_saturated += sat;
    n_near_black += !sat & ((any & kNearBlackEverywhere) != 0);
    saturated[x] = sat ? 1.f : 0.f;
    for (int c = 0; c < 3; ++c) difference[i + c] = sat ? 0.f : gain * (v0[i + c] - v1[i + c]);
  }
  *saturated_count += n_saturated;
  *near_black_count += n_near_black;
}

}  // namespace lumislab::merge::LUMISLAB_MERGE_ISA

#undef LUMISLAB_MERGE_ISA
