#include "preview/point_emitters.h"

#include <cmath>

#include "core/atomic_file.h"
#include "core/basis.h"

namespace lumislab {

std::vector<PointEmitter> DefaultPointEmitters() {
  return {{{1.5, -2.0, -20.0}, 8.0, {1.0, 0.85, 0.6}}, {{-3.0, 1.0, -12.0}, 3.0, {0.4, 0.6, 1.0}}};
}

Eigen::Vector3d PlaneIrradiance(const std::vector<PointEmitter>& emitters, double x_mm, double y_mm,
                                double plane_z_mm) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const PointEmitter& e : emitters) {
    const Eigen::Vector3d rel = Eigen::Vector3d(x_mm, y_mm, plane_z_mm) - e.position_mm;
    const double r = rel.norm();
    const double cos_m = rel.z() / r;
    if (cos_m <= 0) continue;
    sum += e.intensity * std::pow(cos_m, e.lobe + 1) / std::pow(r / 1000.0, 2);
  }
  return sum;
}

SlabInfo MakeSlabInfo(double d_mm, int nu, int nv, double h_mm, double window_mm, int res) {
  SlabInfo info;
  info.distance_mm = d_mm;
  info.grid = {nu, nv, h_mm};
  info.layout = {window_mm, window_mm, res, res};
  info.filter.spacing_mm = h_mm;
  const DualFilter dual = DualFilter::Truncated(1);
  info.filter.dual_coefficients = dual.coefficients();
  info.filter.peak = std::pow(dual.Eval(0.0), 2);
  return info;
}

SlabPosition TruthPosition(const std::vector<PointEmitter>& emitters, const SlabInfo& info, int i,
                           int j) {
  const DualFilter dual = DualFilter::Truncated(1);
  const Eigen::Vector2d c = info.grid.Centre(i, j);
  const double h = info.grid.spacing_mm;
  const double d = info.distance_mm;
  SlabPosition p;
  p.i = i;
  p.j = j;
  p.irradiance = ImageF(info.layout.res_x, info.layout.res_y, 3);
  p.mask = ImageF(info.layout.res_x, info.layout.res_y, 1, 1.f);
  for (int row = 0; row < info.layout.res_y; ++row) {
    for (int col = 0; col < info.layout.res_x; ++col) {
      const Eigen::Vector2d st = info.layout.TexelCentre(col, row);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const PointEmitter& e : emitters) {
        const Eigen::Vector3d target(st.x(), st.y(), d);
        const Eigen::Vector3d rel = target - e.position_mm;
        const double r = rel.norm();
        const double k = -e.position_mm.z() / rel.z();  // where the line crosses z = 0
        const double u = e.position_mm.x() + k * rel.x();
        const double v = e.position_mm.y() + k * rel.y();
        const double weight = dual.Eval2D((u - c.x()) / h, (v - c.y()) / h);
        if (weight == 0) continue;
        const double cos_m = rel.z() / r;
        sum += weight * e.intensity * std::pow(cos_m, e.lobe + 1) / std::pow(r / 1000.0, 2);
      }
      for (int ch = 0; ch < 3; ++ch) p.irradiance.at(col, row, ch) = float(sum[ch]);
    }
  }
  return p;
}

void WriteTruthSlab(const std::vector<PointEmitter>& emitters, const SlabInfo& info,
                    const std::string& dir) {
  MakeDirectories(dir);
  SlabInfo written = info;
  written.present.clear();
  for (int j = 0; j < info.grid.nv; ++j) {
    for (int i = 0; i < info.grid.nu; ++i) {
      WriteSlabPosition(dir, written, TruthPosition(emitters, info, i, j));
      written.MarkPresent(i, j);
    }
  }
  written.Save(dir);
}

}  // namespace lumislab
