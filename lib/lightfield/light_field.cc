#include "lib/lightfield/light_field.h"

#include <algorithm>
#include <cmath>

#include "core/geometry.h"
#include "core/parallel.h"

namespace lumislab {

ImageF IntensityFromIrradiance(const SlabInfo& info, int i, int j, const ImageF& irradiance) {
  const Eigen::Vector2d c = info.grid.Centre(i, j);
  ImageF out(irradiance.width, irradiance.height, 3);
  for (int row = 0; row < irradiance.height; ++row) {
    for (int col = 0; col < irradiance.width; ++col) {
      const Eigen::Vector2d st = info.layout.TexelCentre(col, row);
      const double g_m2 = ShiftInvariantGeometry(info.distance_mm, c, st.x(), st.y()) * 1e6;
      for (int ch = 0; ch < 3; ++ch) {
        out.at(col, row, ch) = float(irradiance.at(col, row, ch) / g_m2);
      }
    }
  }
  return out;
}

Eigen::Vector3d SampleLayout(const SlabLayout& layout, const ImageF& texture, double s, double t) {
  if (std::abs(s) > 0.5 * layout.window_w_mm || std::abs(t) > 0.5 * layout.window_h_mm) {
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector2d p = layout.ToTexel(s, t);
  const double x = std::clamp(p.x(), 0.0, double(texture.width - 1));
  const double y = std::clamp(p.y(), 0.0, double(texture.height - 1));
  const int x0 = std::min(int(x), texture.width - 2 < 0 ? 0 : texture.width - 2);
  const int y0 = std::min(int(y), texture.height - 2 < 0 ? 0 : texture.height - 2);
  const int x1 = std::min(x0 + 1, texture.width - 1);
  const int y1 = std::min(y0 + 1, texture.height - 1);
  const double fx = x - x0;
  const double fy = y - y0;
  Eigen::Vector3d out;
  for (int ch = 0; ch < 3; ++ch) {
    const double top = (1 - fx) * texture.at(x0, y0, ch) + fx * texture.at(x1, y0, ch);
    const double bottom = (1 - fx) * texture.at(x0, y1, ch) + fx * texture.at(x1, y1, ch);
    out[ch] = (1 - fy) * top + fy * bottom;
  }
  return out;
}

Eigen::Vector3d SpotIrradiance(const SlabInfo& info, int i, int j, const ImageF& intensity,
                               const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
  const Eigen::Vector2d c2 = info.grid.Centre(i, j);
  const Eigen::Vector3d c(c2.x(), c2.y(), 0.0);
  const Eigen::Vector3d rel = x - c;
  if (rel.z() <= 0) return Eigen::Vector3d::Zero();
  const double delta = rel.norm();
  const double cos_emit = rel.z() / delta;
  const double cos_recv = std::max(0.0, -n.dot(rel) / delta);
  const double f_m2 = cos_emit * cos_recv / (delta * delta) * 1e6;
  const double s = c.x() + rel.x() * info.distance_mm / rel.z();
  const double t = c.y() + rel.y() * info.distance_mm / rel.z();
  return SampleLayout(info.layout, intensity, s, t) * f_m2;
}

ImageF ReadIntensity(const std::string& slab_dir, const SlabInfo& info, int i, int j) {
  const SlabPosition position = ReadSlabPosition(slab_dir, info, i, j);
  return IntensityFromIrradiance(info, i, j, position.irradiance);
}

std::vector<ImageF> ReadIntensities(const std::string& slab_dir, const SlabInfo& info,
                                    const std::vector<std::pair<int, int>>& positions,
                                    int threads) {
  std::vector<ImageF> out(positions.size());
  ParallelFor(int(positions.size()), threads, [&](int k) {
    out[k] = ReadIntensity(slab_dir, info, positions[k].first, positions[k].second);
  });
  return out;
}

}  // namespace lumislab
