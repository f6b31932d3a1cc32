#include "lib/lightfield/far_field.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "core/basis.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/parallel.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/reference_render.h"

namespace lumislab {
namespace {

// True when (s, t) is inside the window and the texels its bilinear lookup reads are all seen.
bool SeenAt(const SlabLayout& layout, const ImageF& mask, double s, double t) {
  if (std::abs(s) > 0.5 * layout.window_w_mm || std::abs(t) > 0.5 * layout.window_h_mm)
    return false;
  const Eigen::Vector2d p = layout.ToTexel(s, t);
  const double x = std::clamp(p.x(), 0.0, double(mask.width - 1));
  const double y = std::clamp(p.y(), 0.0, double(mask.height - 1));
  const int x0 = int(x), y0 = int(y);
  const int x1 = std::min(x0 + 1, mask.width - 1), y1 = std::min(y0 + 1, mask.height - 1);
  return mask.at(x0, y0, 0) >= 0.5f && mask.at(x1, y0, 0) >= 0.5f && mask.at(x0, y1, 0) >= 0.5f &&
         mask.at(x1, y1, 0) >= 0.5f;
}

}  // namespace

std::vector<SlabPosition> ReadSlabPositions(const std::string& slab_dir, const SlabInfo& info,
                                            int threads) {
  if (info.present.empty())
    throw InputError(slab_dir + "/slab.json", "present", "at least one position", "none");
  std::vector<SlabPosition> out(size_t(info.grid.count()));
  ParallelFor(int(info.present.size()), threads, [&](int k) {
    const auto [i, j] = info.present[k];
    out[size_t(info.grid.Index(i, j))] = ReadSlabPosition(slab_dir, info, i, j);
  });
  return out;
}

FarField ComputeFarField(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                         const std::vector<double>& c_deg, const std::vector<double>& gamma_deg,
                         const FarFieldOptions& options) {
  LUMISLAB_CHECK(int(positions.size()) == info.grid.count(), "one slab position per grid index");
  std::vector<double> offsets, weights;
  BellQuadrature(options.samples, &offsets, &weights);
  const int n = options.samples;
  const double h = info.grid.spacing_mm, d = info.distance_mm;
  FarField out;
  out.c_deg = c_deg;
  out.gamma_deg = gamma_deg;
  const size_t ng = gamma_deg.size(), count = c_deg.size() * ng;
  out.values.assign(count, 0.0);
  out.seen.assign(count, 0);
  ParallelFor(int(count), options.threads, [&](int k) {
    const double c = c_deg[k / ng] * kPi / 180, g = gamma_deg[k % ng] * kPi / 180;
    const double cos_g = std::cos(g);
    if (!(cos_g > 1e-9)) return;           // light leaves S only towards +z
    const double reach = d * std::tan(g);  // (s, t) - (u, v) on M, mm
    const double ds = reach * std::cos(c), dt = reach * std::sin(c);
    double sum = 0;
    for (int j = 0; j < info.grid.nv; ++j) {
      for (int i = 0; i < info.grid.nu; ++i) {
        const SlabPosition& p = positions[size_t(info.grid.Index(i, j))];
        if (p.irradiance.empty()) continue;
        const Eigen::Vector2d centre = info.grid.Centre(i, j);
        for (int b = 0; b < n; ++b) {
          for (int a = 0; a < n; ++a) {
            const double s = centre.x() + h * offsets[a] + ds;
            const double t = centre.y() + h * offsets[b] + dt;
            if (!SeenAt(info.layout, p.mask, s, t)) return;  // unseen: left at 0
            sum += weights[a] * weights[b] *
                   options.channel_weights.dot(SampleLayout(info.layout, p.irradiance, s, t));
          }
        }
      }
    }
    out.values[k] = sum * d * d / (cos_g * cos_g * cos_g * 1e6);
    out.seen[k] = 1;
  });
  for (size_t k = 0; k < count; ++k) {
    if (!out.seen[k]) ++out.unseen;
    if (!out.seen[k] && !(std::cos(gamma_deg[k % ng] * kPi / 180) > 1e-9)) ++out.behind;
  }
  return out;
}

SlabRays SampleSlabRays(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                        int64_t count, uint64_t seed, const Eigen::Vector3d& channel_weights) {
  LUMISLAB_CHECK(int(positions.size()) == info.grid.count(), "one slab position per grid index");
  LUMISLAB_CHECK(count >= 1, "at least one ray");
  const SlabLayout& layout = info.layout;
  const SamplingGrid& grid = info.grid;
  const size_t texels = size_t(layout.res_x) * layout.res_y;
  const double area_m2 = layout.TexelW() * layout.TexelH() * 1e-6;
  // E of each position in the one channel, 0 where unseen; the cumulative |E| dA over
  // (position, texel), positions by linear index: the proposal.
  std::vector<std::vector<float>> e(positions.size());
  std::vector<double> cumulative(positions.size() * texels, 0.0);
  double absolute = 0, signed_total = 0;
  for (size_t p = 0; p < positions.size(); ++p) {
    const SlabPosition& pos = positions[p];
    if (!pos.irradiance.empty()) {
      e[p].resize(texels);
      for (size_t t = 0; t < texels; ++t)
        e[p][t] = pos.mask.data[t] >= 0.5f
                      ? float(channel_weights.x() * pos.irradiance.data[3 * t] +
                              channel_weights.y() * pos.irradiance.data[3 * t + 1] +
                              channel_weights.z() * pos.irradiance.data[3 * t + 2])
                      : 0.f;
    }
    for (size_t t = 0; t < texels; ++t) {
      const double v = e[p].empty() ? 0.0 : e[p][t];
      absolute += std::abs(v) * area_m2;
      signed_total += v * area_m2;
      cumulative[p * texels + t] = absolute;
    }
  }
  if (!(signed_total > 0))
    throw BadInput("the slab holds no light (its seen texels sum to " +
                   std::to_string(signed_total) + "): no rays to draw");
  SlabRays out;
  out.total_flux = signed_total;
  out.flux_per_ray = signed_total / double(count);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double h = grid.spacing_mm, d = info.distance_mm;
  auto bell_sample = [&] {  // x with density Bell(x) on [-1, 1] (rejection: accepts half)
    for (;;) {
      const double x = 2 * uniform(rng) - 1;
      if (uniform(rng) < Bell(x)) return x;
    }
  };
  const int64_t max_tries = 1000 * count + 1000000;
  int64_t tries = 0;
  out.rays.resize(size_t(count));
  for (SlabRay& ray : out.rays) {
    for (;;) {
      if (++tries > max_tries)
        throw Failure("drawing rays: the slab's light field is negative almost everywhere");
      const double r = uniform(rng) * absolute;
      size_t k =
          size_t(std::upper_bound(cumulative.begin(), cumulative.end(), r) - cumulative.begin());
      k = std::min(k, cumulative.size() - 1);
      const int index = int(k / texels), texel = int(k % texels);
      const Eigen::Vector2d c = grid.Centre(index % grid.nu, index / grid.nu);
      const double u = c.x() + h * bell_sample(), v = c.y() + h * bell_sample();
      // Keep (u, v, texel) with probability max(0, sum Phi E) / sum Phi |E| over the positions
      // whose supports hold (u, v): the accepted rays follow the light field where it is
      // positive.
      double field = 0, magnitude = 0;
      const int i0 = int(std::ceil(u / h + 0.5 * (grid.nu - 1) - 1));
      const int j0 = int(std::ceil(v / h + 0.5 * (grid.nv - 1) - 1));
      for (int j = std::max(j0, 0); j <= std::min(j0 + 1, grid.nv - 1); ++j)
        for (int i = std::max(i0, 0); i <= std::min(i0 + 1, grid.nu - 1); ++i) {
          const std::vector<float>& ek = e[size_t(grid.Index(i, j))];
          if (ek.empty()) continue;
          const Eigen::Vector2d ck = grid.Centre(i, j);
          const double phi = Bell((u - ck.x()) / h) * Bell((v - ck.y()) / h);
          field += phi * ek[texel];
          magnitude += phi * std::abs(ek[texel]);
        }
      if (!(magnitude > 0) || uniform(rng) * magnitude >= field) continue;
      const Eigen::Vector2d centre = layout.TexelCentre(texel % layout.res_x, texel / layout.res_x);
      const double s = centre.x() + (uniform(rng) - 0.5) * layout.TexelW();
      const double t = centre.y() + (uniform(rng) - 0.5) * layout.TexelH();
      ray.origin_mm = {u, v, 0.0};
      ray.direction = Eigen::Vector3d(s - u, t - v, d).normalized();
      break;
    }
  }
  // The accepted fraction estimates the positive part of the field, absolute * count / tries;
  // what exceeds the signed total is the negative part left out.
  out.negative_flux = std::max(0.0, absolute * double(count) / double(tries) - signed_total);
  return out;
}

}  // namespace lumislab
