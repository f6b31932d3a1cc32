#include "lib/lightfield/far_field.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/parallel.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/reference_render.h"

namespace lumislab {
namespace {

// Inside the window, and the (up to) four texels a bilinear lookup at (s, t) reads all seen.
bool Seen(const SlabLayout& layout, const ImageF& mask, double s, double t) {
  if (std::abs(s) > 0.5 * layout.window_w_mm || std::abs(t) > 0.5 * layout.window_h_mm)
    return false;
  if (mask.empty()) return true;
  const Eigen::Vector2d p = layout.ToTexel(s, t);
  const int x0 = std::clamp(int(std::floor(p.x())), 0, mask.width - 1);
  const int y0 = std::clamp(int(std::floor(p.y())), 0, mask.height - 1);
  const int x1 = std::min(x0 + 1, mask.width - 1), y1 = std::min(y0 + 1, mask.height - 1);
  return mask.at(x0, y0, 0) > 0.5f && mask.at(x1, y0, 0) > 0.5f && mask.at(x0, y1, 0) > 0.5f &&
         mask.at(x1, y1, 0) > 0.5f;
}

}  // namespace

std::vector<SlabPosition> ReadSlabPositions(const std::string& slab_dir, const SlabInfo& info,
                                            int threads) {
  std::vector<SlabPosition> out(info.grid.count());
  ParallelFor(int(info.present.size()), threads, [&](int k) {
    const auto [i, j] = info.present[k];
    out[info.grid.Index(i, j)] = ReadSlabPosition(slab_dir, info, i, j);
  });
  return out;
}

FarField ComputeFarField(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                         const std::vector<double>& c_deg, const std::vector<double>& gamma_deg,
                         const FarFieldOptions& options) {
  if (options.samples < 1 || options.samples > 64) throw Failure("far field: samples 1..64");
  if (positions.size() != size_t(info.grid.count()))
    throw Failure("far field: one slab position per grid position expected");
  std::vector<double> offsets, weights;
  BellQuadrature(options.samples, &offsets, &weights);
  FarField out;
  out.c_deg = c_deg;
  out.gamma_deg = gamma_deg;
  const size_t ng = gamma_deg.size(), count = c_deg.size() * ng;
  out.values.assign(count, 0);
  out.seen.assign(count, 0);
  const double d = info.distance_mm, h = info.grid.spacing_mm;
  ParallelFor(int(count), options.threads, [&](int k) {
    const double c = c_deg[k / ng] * M_PI / 180, g = gamma_deg[k % ng] * M_PI / 180;
    const double cos_g = std::cos(g);
    if (!(cos_g > 1e-9)) return;  // behind S: no light leaves that way
    const Eigen::Vector2d shift = d * std::tan(g) * Eigen::Vector2d(std::cos(c), std::sin(c));
    double sum = 0;
    for (int j = 0; j < info.grid.nv; ++j)
      for (int i = 0; i < info.grid.nu; ++i) {
        const SlabPosition& p = positions[info.grid.Index(i, j)];
        if (p.irradiance.empty()) continue;
        const Eigen::Vector2d centre = info.grid.Centre(i, j) + shift;
        for (int b = 0; b < options.samples; ++b)
          for (int a = 0; a < options.samples; ++a) {
            const double s = centre.x() + h * offsets[a], t = centre.y() + h * offsets[b];
            if (!Seen(info.layout, p.mask, s, t)) return;  // unseen: left at 0
            sum += weights[a] * weights[b] *
                   SampleLayout(info.layout, p.irradiance, s, t).dot(options.channel_weights);
          }
      }
    // d^2 / cos^3 theta in mm^2 -> m^2: W/m^2 x m^2 = W (per sr).
    out.values[k] = sum * d * d * 1e-6 / (cos_g * cos_g * cos_g);
    out.seen[k] = 1;
  });
  for (size_t k = 0; k < count; ++k) {
    if (out.seen[k]) continue;
    ++out.unseen;
    if (!(std::cos(gamma_deg[k % ng] * M_PI / 180) > 1e-9)) ++out.behind;
  }
  return out;
}

}  // namespace lumislab
