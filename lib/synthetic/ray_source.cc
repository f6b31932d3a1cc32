#include "lib/synthetic/ray_source.h"

#include <Eigen/Geometry>
#include <cmath>

#include "core/error.h"
#include "core/geometry.h"
#include "core/log.h"
#include "lib/photometry/tm25.h"

namespace lumislab {

RaySource RaySource::Load(const std::string& file, const Eigen::Vector3d& position_mm,
                          const Eigen::Vector3d& rotation_deg, const Eigen::Vector3d& rgb,
                          double cell_mm) {
  const Tm25RaySet set = ReadTm25(file);
  RaySource source;
  source.file = file;
  source.position_mm = position_mm;
  source.rotation_deg = rotation_deg;
  source.rgb = rgb;
  source.cell_mm = cell_mm;
  source.photometric = set.photometric;
  source.file_rays = set.rays.size();
  const Eigen::Matrix3d rotation = RotationZyxDegrees(rotation_deg);
  auto rays = std::make_shared<std::vector<SourceRay>>();
  rays->reserve(set.rays.size());
  // A ray on S itself (z = 0, as a slab's exported rays start) passes the slide where it starts;
  // the tolerance absorbs the rounding of a rotation.
  const double on_s = 1e-9 * std::max(1.0, position_mm.norm());
  for (const Tm25Ray& in : set.rays) {
    SourceRay ray;
    ray.origin_mm = rotation * Eigen::Vector3d(in.x, in.y, in.z) + position_mm;
    // The reader renormalises directions within +-50 % of unit length; normalise in double.
    ray.direction = (rotation * Eigen::Vector3d(in.kx, in.ky, in.kz)).normalized();
    ray.flux = in.flux;
    if (!(ray.direction.z() > 0)) {
      ++source.skipped_away;
    } else if (ray.origin_mm.z() > on_s) {
      ++source.skipped_front;
    } else if (ray.flux > 0) {
      source.flux += ray.flux;
      rays->push_back(ray);
    }
  }
  if (source.skipped_away + source.skipped_front > 0)
    LogInfo(file, ": ", source.skipped_away, " of ", source.file_rays,
            " rays leave away from S (k_z <= 0) and ", source.skipped_front,
            " start in front of S (z > 0) in the luminaire frame: skipped");
  if (rays->empty() || !(source.flux > 0))
    throw BadInput(file + ": rays: expected rays that cross the filter plane S from behind " +
                   "(k_z > 0, z <= 0 in the luminaire frame) with flux, got none of " +
                   std::to_string(source.file_rays));
  source.rays = std::move(rays);
  return source;
}

RaySplat::RaySplat(double x0_mm, double x1_mm, double y0_mm, double y1_mm, double cell_mm,
                   int channels)
    : cell_(cell_mm), channels_(channels) {
  k0_ = long(std::floor(x0_mm / cell_)) - 1;
  l0_ = long(std::floor(y0_mm / cell_)) - 1;
  nx_ = int(long(std::ceil(x1_mm / cell_)) + 1 - k0_ + 1);
  ny_ = int(long(std::ceil(y1_mm / cell_)) + 1 - l0_ + 1);
  if (!(cell_mm > 0) || nx_ < 2 || ny_ < 2 || double(nx_) * ny_ * channels > 4e8)
    throw Failure("ray splat: region " + std::to_string(x1_mm - x0_mm) + " x " +
                  std::to_string(y1_mm - y0_mm) + " mm at cell " + std::to_string(cell_mm) +
                  " mm is not a lattice this machine holds");
  nodes_.assign(size_t(nx_) * ny_ * channels_, 0.0);
}

template <typename F>
void RaySplat::ForEachNode(double x_mm, double y_mm, F f) const {
  const double fx = x_mm / cell_, fy = y_mm / cell_;
  if (!(std::abs(fx) < 1e15 && std::abs(fy) < 1e15)) return;
  const double kf = std::floor(fx), lf = std::floor(fy);
  const long k = long(kf) - k0_, l = long(lf) - l0_;
  const double ax = fx - kf, ay = fy - lf;
  const double w[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  for (int n = 0; n < 4; ++n) {
    const long kk = k + (n & 1), ll = l + (n >> 1);
    if (kk < 0 || ll < 0 || kk >= nx_ || ll >= ny_) continue;  // beyond the region's nodes
    f((size_t(ll) * nx_ + size_t(kk)) * channels_, w[n]);
  }
}

void RaySplat::Add(double x_mm, double y_mm, const double* flux) {
  ForEachNode(x_mm, y_mm, [&](size_t node, double w) {
    for (int c = 0; c < channels_; ++c) nodes_[node + c] += w * flux[c];
  });
}

void RaySplat::At(double x_mm, double y_mm, double* irradiance) const {
  for (int c = 0; c < channels_; ++c) irradiance[c] = 0;
  // Flux per node over the cell's area (mm^2 -> m^2: 1e6).
  const double per_area = 1e6 / (cell_ * cell_);
  ForEachNode(x_mm, y_mm, [&](size_t node, double w) {
    for (int c = 0; c < channels_; ++c) irradiance[c] += w * per_area * nodes_[node + c];
  });
}

}  // namespace lumislab
