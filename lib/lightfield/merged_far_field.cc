#include "lib/lightfield/merged_far_field.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "core/error.h"
#include "core/geometry.h"
#include "core/parallel.h"
#include "lib/photometry/intensity_distribution.h"

namespace lumislab {
namespace {

std::vector<OrientationCone> Cones(const std::vector<PosedSlab>& slabs) {
  std::vector<OrientationCone> cones;
  for (const PosedSlab& s : slabs) cones.push_back(s.cone);
  return cones;
}
std::vector<Eigen::Matrix3d> Rotations(const std::vector<PosedSlab>& slabs) {
  std::vector<Eigen::Matrix3d> r;
  for (const PosedSlab& s : slabs) r.push_back(s.capture_from_luminaire);
  return r;
}

// Orientation k's far field on a capture-frame C / gamma grid of kTableStepDeg (gamma 0-90):
// the seen mask and the intensity, read at the nearest grid direction. The rays' blend needs
// every orientation's seen mask at arbitrary directions, and their counts the share of each
// slab's flux the blend keeps.
constexpr double kTableStepDeg = 1.0;
struct FarFieldTable {
  int nc = 0, ng = 0;
  FarField ff;
  size_t Index(const Eigen::Vector3d& w_capture) const {
    const Eigen::Vector2d a = TypeCAngles(w_capture);
    const int ic = int(std::lround(a.x() / kTableStepDeg)) % nc;
    const int ig = std::min(ng - 1, int(std::lround(a.y() / kTableStepDeg)));
    return size_t(ic) * ng + ig;
  }
  bool Seen(const Eigen::Vector3d& w_capture) const {
    return w_capture.z() > 1e-9 && ff.seen[Index(w_capture)];
  }
};
FarFieldTable MakeTable(const PosedSlab& slab, int threads) {
  FarFieldTable t;
  t.nc = int(std::lround(360 / kTableStepDeg));
  t.ng = int(std::lround(90 / kTableStepDeg)) + 1;
  std::vector<double> c, g;
  for (int k = 0; k < t.nc; ++k) c.push_back(k * kTableStepDeg);
  for (int k = 0; k < t.ng; ++k) g.push_back(k * kTableStepDeg);
  FarFieldOptions options;
  options.samples = 2;
  options.threads = threads;
  t.ff = ComputeFarField(slab.info, slab.positions, c, g, options);
  return t;
}

// The weights of every orientation at luminaire direction w from the tables' seen masks.
std::vector<double> TableWeights(const std::vector<PosedSlab>& slabs,
                                 const std::vector<FarFieldTable>& tables,
                                 const std::vector<OrientationCone>& cones,
                                 const std::vector<Eigen::Matrix3d>& rotations,
                                 const Eigen::Vector3d& w) {
  std::vector<uint8_t> seen(slabs.size());
  for (size_t j = 0; j < slabs.size(); ++j) seen[j] = tables[j].Seen(rotations[j] * w);
  return BlendWeights(cones, rotations, seen, w);
}

}  // namespace

std::vector<double> BlendWeights(const std::vector<OrientationCone>& cones,
                                 const std::vector<Eigen::Matrix3d>& capture_from_luminaire,
                                 const std::vector<uint8_t>& seen, const Eigen::Vector3d& w,
                                 double taper_deg) {
  LUMISLAB_CHECK(cones.size() == capture_from_luminaire.size() && cones.size() == seen.size(),
                 "one cone, pose and seen flag per orientation");
  std::vector<double> t(cones.size(), 0.0);
  double sum = 0;
  int seen_count = 0;
  for (size_t k = 0; k < cones.size(); ++k) {
    if (!seen[k]) continue;
    ++seen_count;
    t[k] = ConeTaper(cones[k], capture_from_luminaire[k] * w, taper_deg);
    sum += t[k];
  }
  for (size_t k = 0; k < cones.size(); ++k)
    t[k] = sum > 0 ? t[k] / sum : seen[k] ? 1.0 / seen_count : 0.0;
  return t;
}

std::string CommonUnits(const std::vector<PosedSlab>& slabs) {
  LUMISLAB_CHECK(!slabs.empty(), "at least one slab");
  const std::string& units = slabs.front().info.units;
  if (units == "relative" && slabs.size() > 1)
    throw InputError(slabs.front().slab_dir + "/slab.json", "units",
                     "lux or W/m^2 (a slab without a radiometric scale has the level of its own "
                     "capture's exposure, unlike another orientation's: calibrate the scale of "
                     "every orientation's dataset, lumislab-calibrate scale, then reconstruct "
                     "it again)",
                     units);
  for (const PosedSlab& s : slabs)
    if (s.info.units != units)
      throw InputError(s.slab_dir + "/slab.json", "units",
                       units + ", the unit of " + slabs.front().slab_dir +
                           " (every orientation's slab scaled alike, so that the merged light is "
                           "in one unit: calibrate the scale of each orientation's dataset the "
                           "same way, then reconstruct it again)",
                       s.info.units);
  return units;
}

MergedFarField ComputeMergedFarField(const std::vector<PosedSlab>& slabs,
                                     const std::vector<double>& c_deg,
                                     const std::vector<double>& gamma_deg,
                                     const FarFieldOptions& options) {
  LUMISLAB_CHECK(!slabs.empty(), "at least one slab");
  CommonUnits(slabs);
  const size_t ng = gamma_deg.size(), count = c_deg.size() * ng, n = slabs.size();
  std::vector<Eigen::Vector3d> grid(count);
  for (size_t k = 0; k < count; ++k) grid[k] = TypeCDirection(c_deg[k / ng], gamma_deg[k % ng]);
  const std::vector<OrientationCone> cones = Cones(slabs);
  const std::vector<Eigen::Matrix3d> rotations = Rotations(slabs);
  std::vector<FarFieldAt> at(n);
  for (size_t o = 0; o < n; ++o) {
    std::vector<Eigen::Vector3d> turned(count);
    for (size_t k = 0; k < count; ++k) turned[k] = rotations[o] * grid[k];
    at[o] = ComputeFarFieldAt(slabs[o].info, slabs[o].positions, turned, options);
  }
  MergedFarField out;
  out.ff.c_deg = c_deg;
  out.ff.gamma_deg = gamma_deg;
  out.ff.values.assign(count, 0.0);
  out.ff.seen.assign(count, 0);
  out.seen_by.assign(count, 0);
  std::vector<IntensityDistribution> part(n);
  for (IntensityDistribution& d : part) {
    d.c_deg = c_deg;
    d.gamma_deg = gamma_deg;
    d.values.assign(count, 0.0);
  }
  // Pair scales: sums of I_a and I_b dOmega over the directions both weigh (cells of the grid's
  // zonal sum: the pair's own IntensityDistribution over those directions).
  std::vector<IntensityDistribution> pair_a, pair_b;
  std::vector<MergedFarField::PairScale> pairs;
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b) {
      pairs.push_back({int(a), int(b), 0, 1});
      pair_a.push_back(part[0]);
      pair_b.push_back(part[0]);
    }
  for (size_t k = 0; k < count; ++k) {
    std::vector<uint8_t> seen(n);
    for (size_t o = 0; o < n; ++o) seen[o] = at[o].seen[k];
    const std::vector<double> w = BlendWeights(cones, rotations, seen, grid[k]);
    double value = 0;
    for (size_t o = 0; o < n; ++o) {
      if (!(w[o] > 0)) continue;
      value += w[o] * at[o].values[k];
      part[o].values[k] = std::max(0.0, w[o] * at[o].values[k]);
      ++out.seen_by[k];
    }
    out.ff.values[k] = value;
    out.ff.seen[k] = out.seen_by[k] > 0;
    out.ff.unseen += !out.ff.seen[k];
    for (size_t p = 0; p < pairs.size(); ++p) {
      const size_t a = size_t(pairs[p].a), b = size_t(pairs[p].b);
      if (!(w[a] > 0 && w[b] > 0)) continue;
      ++pairs[p].directions;
      pair_a[p].values[k] = std::max(0.0, at[a].values[k]);
      pair_b[p].values[k] = std::max(0.0, at[b].values[k]);
    }
  }
  for (const IntensityDistribution& d : part) out.contribution.push_back(d.TotalFlux());
  for (size_t p = 0; p < pairs.size(); ++p) {
    if (pairs[p].directions == 0) continue;
    const double fa = pair_a[p].TotalFlux(), fb = pair_b[p].TotalFlux();
    pairs[p].ratio = fa > 0 ? fb / fa : 1;
    out.pair_scales.push_back(pairs[p]);
  }
  return out;
}

MergedRays SampleMergedRays(const std::vector<PosedSlab>& slabs, int64_t count, uint64_t seed,
                            int threads) {
  LUMISLAB_CHECK(!slabs.empty() && count >= 1, "at least one slab and one ray");
  CommonUnits(slabs);
  const size_t n = slabs.size();
  const std::vector<OrientationCone> cones = Cones(slabs);
  const std::vector<Eigen::Matrix3d> rotations = Rotations(slabs);
  std::vector<FarFieldTable> tables;
  for (const PosedSlab& s : slabs) tables.push_back(MakeTable(s, threads));
  MergedRays out;
  // q_k and Phi_k from the tables: the blend's kept share of each slab's far-field flux.
  double kept_flux = 0;
  for (size_t k = 0; k < n; ++k) {
    const FarFieldTable& t = tables[k];
    IntensityDistribution all, kept;
    all.c_deg = kept.c_deg = t.ff.c_deg;
    all.gamma_deg = kept.gamma_deg = t.ff.gamma_deg;
    all.values.assign(t.ff.values.size(), 0.0);
    kept.values = all.values;
    for (size_t i = 0; i < t.ff.values.size(); ++i) {
      if (!t.ff.seen[i]) continue;
      const Eigen::Vector3d w_capture =
          TypeCDirection(t.ff.c_deg[i / size_t(t.ng)], t.ff.gamma_deg[i % size_t(t.ng)]);
      const double weight =
          TableWeights(slabs, tables, cones, rotations, rotations[k].transpose() * w_capture)[k];
      all.values[i] = std::max(0.0, t.ff.values[i]);
      kept.values[i] = weight * all.values[i];
    }
    const double phi = all.TotalFlux();
    out.slab_flux.push_back(phi);
    out.kept_share.push_back(phi > 0 ? kept.TotalFlux() / phi : 0);
    kept_flux += phi * out.kept_share.back();
  }
  out.rays.total_flux = 0;
  std::vector<double> flux_per_ray(n, 0.0);
  for (size_t k = 0; k < n; ++k) {
    const int64_t drawn = std::max<int64_t>(
        1, int64_t(std::llround(double(count) * out.slab_flux[k] / std::max(kept_flux, 1e-300))));
    out.drawn.push_back(drawn);
    const SlabRays rays = SampleSlabRays(slabs[k].info, slabs[k].positions, drawn,
                                         seed + 0x9E3779B97F4A7C15ull * (k + 1), threads);
    flux_per_ray[k] = rays.flux_per_ray;
    out.slab_flux[k] = rays.total_flux;  // the slab's own sum (the table's is a far field's)
    std::mt19937_64 rng(seed ^ (0xD1B54A32D192ED03ull * (k + 1)));
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const Eigen::Matrix3d luminaire_from_capture = rotations[k].transpose();
    int64_t kept = 0;
    for (const SlabRay& r : rays.rays) {
      const Eigen::Vector3d w = luminaire_from_capture * r.direction;
      const double weight = TableWeights(slabs, tables, cones, rotations, w)[k];
      if (!(uniform(rng) < weight)) continue;
      out.rays.rays.push_back(
          {luminaire_from_capture * (r.origin_mm - slabs[k].centre_mm), w.normalized()});
      out.ray_flux.push_back(rays.flux_per_ray);
      ++kept;
    }
    out.kept.push_back(kept);
    out.rays.total_flux += kept * rays.flux_per_ray;
  }
  out.rays.flux_per_ray =
      out.rays.rays.empty() ? 0 : out.rays.total_flux / double(out.rays.rays.size());
  return out;
}

}  // namespace lumislab
