#include "reconstruct/bracket_ratios.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

#include "core/error.h"

namespace lumislab {
namespace merge {
namespace {

// The k-th smallest of n non-negative floats (k < n), the value std::nth_element would put at
// k: their bit patterns order as unsigned integers, so two counting passes, over the upper 16
// bits and then the lower 16 bits of the values in the upper bits' bin, find it (cheaper than
// nth_element's partitions for the ~790 k ratios per pair of EstimateRatios).
float KthSmallestNonNegative(const float* v, size_t n, size_t k) {
  std::vector<uint32_t> count(65536, 0);
  auto bits = [](float f) {
    uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    return b;
  };
  for (size_t i = 0; i < n; ++i) ++count[bits(v[i]) >> 16];
  uint32_t high = 0;
  size_t below = 0;  // values in the bins before `high`
  while (below + count[high] <= k) below += count[high++];
  std::fill(count.begin(), count.end(), 0);
  for (size_t i = 0; i < n; ++i)
    if (bits(v[i]) >> 16 == high) ++count[bits(v[i]) & 0xFFFF];
  uint32_t low = 0;
  while (below + count[low] <= k) below += count[low++];
  const uint32_t b = high << 16 | low;
  float value;
  std::memcpy(&value, &b, sizeof value);
  return value;
}

}  // namespace

std::vector<BracketRatio> EstimateRatios(std::vector<Exposure>& exposures, int w, int h) {
  // A grid of at most ~2^18 pixels: the median of that many ratios is precise to ~1e-4.
  const int stride = std::max(1, int(std::ceil(std::sqrt(double(w) * h / 262144.0))));
  const size_t grid = size_t((h - stride / 2 + stride - 1) / stride) *
                      size_t((w - stride / 2 + stride - 1) / stride);
  std::vector<BracketRatio> ratios;
  for (int slide : {0, 1}) {
    const std::vector<size_t> order = SlideOrder(exposures, slide);
    if (order.size() < 2) continue;
    // The ratios long / short; their median is taken, then its log (the median of the logs,
    // as the log is monotonic, with one log instead of one per sample).
    // At most 3 per grid pixel; plain arrays with a count (push_back was not inlined: a call
    // per sample).
    std::vector<std::unique_ptr<float[]>> sample_ratios(order.size() - 1),
        sample_values(order.size() - 1);  // and the shorter exposure's value
    std::vector<size_t> samples(order.size() - 1, 0);
    for (auto& v : sample_ratios) v.reset(new float[3 * grid]);
    for (auto& v : sample_values) v.reset(new float[3 * grid]);
    std::vector<float> u(order.size() * 3);  // NaN where clipped
    for (int y = stride / 2; y < h; y += stride)
      for (int x = stride / 2; x < w; x += stride) {
        for (size_t k = 0; k < order.size(); ++k)
          ReadRow(exposures[order[k]], y, x, 1, &u[k * 3]);  // the values the merge reads
        for (size_t k = 0; k + 1 < order.size(); ++k)
          for (int ch = 0; ch < 3; ++ch) {
            // Well exposed in both (not clipped: NaN fails the tests), and well above the
            // near-black floor: the ratio of two values a few codes above black is dominated by
            // their quantisation.
            const float a = u[k * 3 + ch], b = u[(k + 1) * 3 + ch];
            // And at codes where the curve is trusted (kTrustedCode), and at a signal of at
            // least kMinRatioValue in both: the noise model's floor is the dataset's assumption,
            // and where the camera's real noise or dark level lies above it, values near it are
            // the same in both photos whatever their exposures (a ratio of 1 where 4 was
            // recorded, on the unlit positions of the study's noisy bracket point).
            const Exposure &ea = exposures[order[k]], &eb = exposures[order[k + 1]];
            const float lowest_a = std::max({4 * ea.floor_u, ea.trusted_u[ch], kMinRatioValue});
            const float lowest_b = std::max({4 * eb.floor_u, eb.trusted_u[ch], kMinRatioValue});
            if (!(a >= lowest_a) || !(b >= lowest_b)) continue;
            sample_values[k][samples[k]] = a;
            sample_ratios[k][samples[k]++] = b / a;
          }
      }
    for (size_t k = 0; k + 1 < order.size(); ++k) {
      BracketRatio r;
      r.positive = slide == 0;
      r.recorded_short = exposures[order[k]].recorded;
      r.recorded_long = exposures[order[k + 1]].recorded;
      r.estimated = r.Recorded();
      const size_t n = samples[k];
      if (n >= size_t(kMinRatioSamples)) {
        // (The ratios are > 0: both values are.)
        const float median = KthSmallestNonNegative(sample_ratios[k].get(), n, n / 2);
        r.estimated = std::exp(double(std::log(median)));
        r.samples = (long long)n;
        // The halves by the shorter exposure's value.
        const float split = KthSmallestNonNegative(sample_values[k].get(), n, n / 2);
        std::vector<float> dim, bright;
        for (size_t s = 0; s < n; ++s)
          (sample_values[k][s] < split ? dim : bright).push_back(sample_ratios[k][s]);
        r.estimated_dim = dim.empty()
                              ? r.estimated
                              : KthSmallestNonNegative(dim.data(), dim.size(), dim.size() / 2);
        r.estimated_bright = bright.empty() ? r.estimated
                                            : KthSmallestNonNegative(bright.data(), bright.size(),
                                                                     bright.size() / 2);
      }
      ratios.push_back(r);
    }
  }
  return ratios;
}

void ApplyRatios(std::vector<Exposure>& exposures, const std::vector<BracketRatio>& ratios) {
  size_t r0 = 0;
  for (int slide : {0, 1}) {
    const std::vector<size_t> order = SlideOrder(exposures, slide);
    if (order.size() < 2) continue;
    const size_t m = (order.size() - 1) / 2;
    for (size_t k = m + 1; k < order.size(); ++k)
      exposures[order[k]].effective =
          float(exposures[order[k - 1]].effective * ratios[r0 + k - 1].estimated);
    for (size_t k = m; k-- > 0;)
      exposures[order[k]].effective =
          float(exposures[order[k + 1]].effective / ratios[r0 + k].estimated);
    r0 += order.size() - 1;
  }
}

}  // namespace merge

bool BracketRatio::DeviationIsTheExposures() const {
  const double spread = std::abs(std::log(estimated_bright / estimated_dim));
  return spread <= std::max(0.01, std::abs(std::log(estimated / Recorded())) / 3);
}

std::vector<BracketRatio> EstimateBracketRatios(const std::vector<DecodedPhoto>& photos,
                                                const MergeOptions& options) {
  LUMISLAB_CHECK(!photos.empty(), "EstimateBracketRatios: no photos");
  std::vector<merge::Exposure> exposures = merge::MakeExposures(photos, options);
  return merge::EstimateRatios(exposures, photos[0].photo.pixels.cols, photos[0].photo.pixels.rows);
}

}  // namespace lumislab
