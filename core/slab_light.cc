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

SlabLightSum::SlabLightSum(const SlabInfo& info, const Eigen::Vector3d& channel_weights)
    : weights_(channel_weights),
      area_m2_(info.layout.TexelW() * info.layout.TexelH() * 1e-6),
      texel_flux_(size_t(info.layout.res_x) * info.layout.res_y, 0.0) {}

void SlabLightSum::Add(const SlabPosition& pos) {
  if (pos.irradiance.empty()) return;
  ++light_.positions;
  double sum = 0;
  for (size_t t = 0; t < texel_flux_.size(); ++t)
    if (pos.mask.data[t] >= 0.5f) {
      const double f = (weights_.x() * pos.irradiance.data[3 * t] +
                        weights_.y() * pos.irradiance.data[3 * t + 1] +
                        weights_.z() * pos.irradiance.data[3 * t + 2]) *
                       area_m2_;
      texel_flux_[t] += f;
      sum += f;
    }
  (sum < 0 ? light_.position_negative : light_.position_positive) += std::abs(sum);
  if (sum < 0) ++light_.negative_positions;
  if (sum < lowest_) lowest_ = sum, light_.most_negative = {pos.i, pos.j};
}

SlabLight SlabLightSum::Result() const {
  SlabLight light = light_;
  for (const double f : texel_flux_) {
    light.total += f;
    (f < 0 ? light.negative : light.positive) += std::abs(f);
  }
  return light;
}

SlabLight MeasureSlabLight(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                           const Eigen::Vector3d& channel_weights) {
  SlabLightSum sum(info, channel_weights);
  for (const SlabPosition& pos : positions) sum.Add(pos);
  return sum.Result();
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
  CheckSlabLight(info, light, slab_dir, checks);
  return light;
}

void CheckSlabLight(const SlabInfo& info, const SlabLight& light, const std::string& slab_dir,
                    CheckLog& checks) {
  const std::string sums = "its " + std::to_string(light.positions) + " position(s) sum to " +
                           Num(light.total, 6) + " (positive texels " + Num(light.positive, 6) +
                           ", negative " + Num(light.negative, 6) + ")";
  JudgeTotalLight("slab.total_light", "total light", light, info, slab_dir, sums,
                  SlabLightValues(light), checks);
}

std::string DatasetOfSlab(const std::string& slab_dir) {
  namespace fs = std::filesystem;
  fs::path slab = fs::absolute(slab_dir).lexically_normal();
  if (slab.filename().empty()) slab = slab.parent_path();
  const fs::path dataset = slab.parent_path();
  return fs::exists(dataset / "dataset.json") ? dataset.string() : std::string();
}

}  // namespace lumislab
