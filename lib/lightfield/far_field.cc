#include "lib/lightfield/far_field.h"

#include <cmath>

#include "core/error.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/reference_render.h"

namespace lumislab {

Eigen::Vector3d DirectionFromCGamma(double c_deg, double gamma_deg) {
  const double c = c_deg * M_PI / 180, g = gamma_deg * M_PI / 180;
  return {std::sin(g) * std::cos(c), std::sin(g) * std::sin(c), std::cos(g)};
}

bool SlabSeesDirection(const SlabInfo& info, const Eigen::Vector3d& w) {
  if (!(w.z() > 0)) return false;
  const double h = info.grid.spacing_mm;
  // The outermost samples of the outermost positions: centre +- (n - 1)/2 h, support +- h.
  const double reach_u = 0.5 * (info.grid.nu - 1) * h + h;
  const double reach_v = 0.5 * (info.grid.nv - 1) * h + h;
  const double s = std::abs(info.distance_mm * w.x() / w.z());
  const double t = std::abs(info.distance_mm * w.y() / w.z());
  return s + reach_u <= 0.5 * info.layout.window_w_mm &&
         t + reach_v <= 0.5 * info.layout.window_h_mm;
}

Eigen::Vector3d SlabFarFieldIntensity(const SlabInfo& info, const std::vector<ImageF>& irradiance,
                                      const Eigen::Vector3d& w, int samples) {
  if (samples < 1 || samples > 64) throw Failure("far field: samples must be 1..64");
  if (irradiance.size() != size_t(info.grid.count()))
    throw Failure("far field: one irradiance image per grid position expected");
  const Eigen::Vector3d dir = w.normalized();
  if (!(dir.z() > 0)) return Eigen::Vector3d::Zero();
  std::vector<double> offsets, weights;
  BellQuadrature(samples, &offsets, &weights);
  const double d = info.distance_mm, h = info.grid.spacing_mm;
  const Eigen::Vector2d shift(d * dir.x() / dir.z(), d * dir.y() / dir.z());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i) {
      const ImageF& e = irradiance[info.grid.Index(i, j)];
      if (e.empty()) continue;
      const Eigen::Vector2d c = info.grid.Centre(i, j) + shift;
      for (int b = 0; b < samples; ++b)
        for (int a = 0; a < samples; ++a)
          sum += weights[a] * weights[b] *
                 SampleLayout(info.layout, e, c.x() + h * offsets[a], c.y() + h * offsets[b]);
    }
  // d^2 / cos^3 theta in mm^2 -> m^2 (1e-6): W/m^2 x m^2 = W (per sr).
  return sum * (d * d * 1e-6 / std::pow(dir.z(), 3));
}

}  // namespace lumislab
