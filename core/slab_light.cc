#include "core/slab_light.h"

#include <cmath>
#include <filesystem>

#include "core/log.h"

namespace lumislab {

namespace {}  // namespace

nlohmann::json SlabLightValues(const SlabLight& light) {
  return {{"total", light.total},
          {"positive", light.positive},
          {"negative", light.negative},
          {"negative_share", light.NegativeShare()},
          {"positions", light.positions},
          {"position_negative_share", light.PositionNegativeShare()},
          {"negative_positions", light.negative_positions}};
}

SlabLight MeasureSlabLight(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                           const Eigen::Vector3d& channel_weights) {
  const SlabLayout& layout = info.layout;
  const int texels = layout.res_x * layout.res_y;
  const double area_m2 = layout.TexelW() * layout.TexelH() * 1e-6;
  std::vector<double> texel_flux(size_t(texels), 0.0);
  SlabLight light;
  double lowest = 0;
  for (size_t p = 0; p < positions.size(); ++p) {
    const SlabPosition& pos = positions[p];
    if (pos.irradiance.empty()) continue;
    ++light.positions;
    double sum = 0;
    for (int t = 0; t < texels; ++t)
      if (pos.mask.data[t] >= 0.5f) {
        const double f = (channel_weights.x() * pos.irradiance.data[3 * t] +
                          channel_weights.y() * pos.irradiance.data[3 * t + 1] +
                          channel_weights.z() * pos.irradiance.data[3 * t + 2]) *
                         area_m2;
        texel_flux[t] += f;
        sum += f;
      }
    (sum < 0 ? light.position_negative : light.position_positive) += std::abs(sum);
    if (sum < 0) ++light.negative_positions;
    if (sum < lowest) {
      lowest = sum;
      light.most_negative = {int(p) % info.grid.nu, int(p) / info.grid.nu};
    }
  }
  for (const double f : texel_flux) {
    light.total += f;
    (f < 0 ? light.negative : light.positive) += std::abs(f);
  }
  return light;
}

bool TotalLightHasASign(const SlabInfo& info) { return info.grid.nu >= 2 && info.grid.nv >= 2; }

void JudgeTotalLight(const std::string& check, const std::string& what, const SlabLight& light,
                     const SlabInfo& info, const std::string& slab_dir, const std::string& sums,
                     const nlohmann::json& values, CheckLog& checks) {
  const std::string file = slab_dir + "/slab.json";
  if (std::isnan(light.total) || (light.total < 0 && TotalLightHasASign(info)))
    checks.Fail(check,
                file + ": " + what + ": expected a positive number, got " + Num(light.total, 6) +
                    " (" + sums +
                    "): the slides T+ and T- swapped (dataset.json photos); reconstruct it from "
                    "photos in the right order",
                values);
  if (light.total == 0) {
    checks.Warn(check, file + ": " + what + ": 0, the slab holds no light (" + sums + ")", values);
    return;
  }
  checks.Pass(
      check,
      sums + "; " + Num(100 * light.NegativeShare(), 3) + " % of |flux| negative" +
          (TotalLightHasASign(info) ? "" : " (a grid of one row or column: its sign not held)"),
      values);
}

SlabLight CheckSlabLight(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                         const std::string& slab_dir, CheckLog& checks) {
  const SlabLight light = MeasureSlabLight(info, positions);
  const std::string sums = "its " + std::to_string(light.positions) + " position(s) sum to " +
                           Num(light.total, 6) + " (positive texels " + Num(light.positive, 6) +
                           ", negative " + Num(light.negative, 6) + ")";
  JudgeTotalLight("slab.total_light", "total light", light, info, slab_dir, sums,
                  SlabLightValues(light), checks);
  return light;
}

std::string DatasetOfSlab(const std::string& slab_dir) {
  namespace fs = std::filesystem;
  fs::path slab = fs::absolute(slab_dir).lexically_normal();
  if (slab.filename().empty()) slab = slab.parent_path();
  const fs::path dataset = slab.parent_path();
  return fs::exists(dataset / "dataset.json") ? dataset.string() : std::string();
}

}  // namespace lumislab
