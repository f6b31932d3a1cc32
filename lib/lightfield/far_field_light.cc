#include "lib/lightfield/far_field_light.h"

#include <algorithm>
#include <cmath>

#include "core/log.h"

namespace lumislab {

namespace {

// The share of |I| dOmega in directions of negative I above which the far field is warned
// (written with those directions as 0): measured 0 % on the demo's slab (63 positions, ies on
// the default 5 x 2.5 degree grid), 1.1 % with a tenth of its positions' slides swapped, 36 %
// with a quarter swapped (total still positive). A warning, not an error: a small slab's dual
// ringing is legitimately large (a 2-position slab has 45 % of its texels' |flux| negative).
constexpr double kMaxFarFieldNegativeShare = 0.25;

}  // namespace

SlabLight MeasureFarFieldLight(const FarField& far) {
  // I dOmega on the C / gamma grid: each direction holds the half-way cells to its neighbours
  // (C wraps around 360 degrees when the planes cover it; gamma is cut at 0 and 90 degrees).
  const double deg = M_PI / 180;
  const size_t nc = far.c_deg.size(), ng = far.gamma_deg.size();
  auto span = [](const std::vector<double>& a, size_t k, double low, double high, bool wrap) {
    const double lo = k > 0 ? (a[k - 1] + a[k]) / 2 : (wrap ? (a.back() - 360 + a[k]) / 2 : low);
    const double hi =
        k + 1 < a.size() ? (a[k] + a[k + 1]) / 2 : (wrap ? (a[k] + a[0] + 360) / 2 : high);
    return std::pair<double, double>(std::max(lo, low), std::min(hi, high));
  };
  const bool full = nc > 1;
  SlabLight light;
  for (size_t ic = 0; ic < nc; ++ic) {
    const auto [c0, c1] =
        nc == 1 ? std::pair<double, double>(0, 360) : span(far.c_deg, ic, -360, 720, full);
    for (size_t ig = 0; ig < ng; ++ig) {
      if (!far.seen.empty() && !far.seen[ic * ng + ig]) continue;
      const auto [g0, g1] = span(far.gamma_deg, ig, 0, 90, false);
      const double omega = (c1 - c0) * deg * (std::cos(g0 * deg) - std::cos(g1 * deg));
      const double f = far.values[ic * ng + ig] * omega;
      light.total += f;
      (f < 0 ? light.negative : light.positive) += std::abs(f);
    }
  }
  light.positions = -1;  // not a count of positions: a far field
  return light;
}

SlabLight CheckFarFieldLight(const FarField& far, const SlabInfo& info, const std::string& slab_dir,
                             CheckLog& checks) {
  const SlabLight light = MeasureFarFieldLight(far);
  const std::string file = slab_dir + "/slab.json";
  nlohmann::json values = SlabLightValues(light);
  for (const char* key : {"positions", "position_negative_share", "negative_positions"})
    values.erase(key);
  values["max_negative_share"] = kMaxFarFieldNegativeShare;
  const std::string sums = "I dOmega over the seen directions " + Num(light.total, 6) +
                           " (positive " + Num(light.positive, 6) + ", negative " +
                           Num(light.negative, 6) + ")";
  JudgeTotalLight("farfield.total_light", "far field's total light", light, info, slab_dir, sums,
                  values, checks);
  if (light.NegativeShare() > kMaxFarFieldNegativeShare) {
    checks.Warn("farfield.negative_share",
                file + ": far field: " + Num(100 * light.NegativeShare(), 3) +
                    " % of |I| dOmega in directions of negative intensity (more than " +
                    Num(100 * kMaxFarFieldNegativeShare, 3) +
                    " %), written as 0: the slab's light is not what its photos meant",
                values);
    return light;
  }
  checks.Pass("farfield.negative_share",
              Num(100 * light.NegativeShare(), 3) + " % of |I| dOmega negative", values);
  return light;
}

}  // namespace lumislab
