#include "lib/lightfield/far_field.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
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

// SampleSlabRays' cells over (u, v): kRayCellsPerSpacing per h on one axis, covering the bell
// supports [c_0 - h, c_{n-1} + h]; Overlap(a, i) is the bell's integral over cell a around
// centre i (units of h; over all cells it is 1).
constexpr int kRayCellsPerSpacing = 4;
// Positive mass is taken within this many cells (h) of a negative cell.
constexpr int kRayCancelRadius = kRayCellsPerSpacing;
struct RayCellAxis {
  double start_mm = 0, width_mm = 0;
  int cells = 0, positions = 0;
  std::vector<double> overlap;  // overlap[a * positions + i]
  double Overlap(int a, int i) const { return overlap[size_t(a) * positions + i]; }
};
RayCellAxis MakeRayCellAxis(int positions, double h) {
  RayCellAxis axis;
  axis.positions = positions;
  axis.cells = (positions + 1) * kRayCellsPerSpacing;
  axis.width_mm = h / kRayCellsPerSpacing;
  axis.start_mm = -0.5 * (positions - 1) * h - h;
  axis.overlap.assign(size_t(axis.cells) * positions, 0.0);
  for (int a = 0; a < axis.cells; ++a)
    for (int i = 0; i < positions; ++i) {
      const double lo = (a - kRayCellsPerSpacing) / double(kRayCellsPerSpacing) - i;
      axis.overlap[size_t(a) * positions + i] = BellIntegral(lo, lo + 1.0 / kRayCellsPerSpacing);
    }
  return axis;
}

// What the cancelling moved, summed over texels (W, mm).
struct RayCellCancelling {
  double moved = 0;      // the negative part filled = the positive mass taken
  double uncentred = 0;  // of which in profiles where the centroid could not be kept
  double distance = 0;   // sum of taken mass times its distance to the nearest negative cell
  double max_mm = 0;     // the largest such distance
};

// One texel's profile f over the cells (row-major, ax.cells per row) made non-negative with its
// flux and centroid kept (docs/formats.md §17): the negative cells are set to 0 and positive
// cell c gives w_c = clamp(k_c (alpha + beta . (x_c - x_n)), 0, f_c), where k_c is the negative
// mass within kRayCancelRadius cells of c (so only cells near a negative lobe give, most where
// the lobes are deepest) and x_n the negative part's centroid; alpha and beta solve
// sum w = the negative mass and sum w (x - x_n) = 0 (Newton's method: the equations are
// piecewise linear and monotone along alpha). This w is the weighted least-squares change,
// sum w^2 / k, subject to those three conditions. Where no such solution exists (the negative
// part's centroid outside the cells that could give, e.g. a lobe on one side only) beta = 0:
// flux kept, centroid not (counted in `uncentred`).
void CancelNegativeRayCells(const RayCellAxis& ax, const RayCellAxis& ay,
                            std::vector<double>* profile, RayCellCancelling* stats) {
  std::vector<double>& f = *profile;
  const int nx = ax.cells, ny = ay.cells;
  double negative = 0, mx = 0, my = 0, signed_flux = 0;
  for (int b = 0; b < ny; ++b)
    for (int a = 0; a < nx; ++a) {
      const double v = f[size_t(b) * nx + a];
      signed_flux += v;
      if (!(v < 0)) continue;
      negative -= v;
      mx -= v * a;
      my -= v * b;
    }
  if (!(negative > 0)) return;
  mx /= negative;
  my /= negative;
  // The cells that may give: positive ones with their k (the negative mass in the (2R + 1)^2
  // window around them) and the distance to the nearest negative cell in that window.
  struct Giver {
    size_t cell;
    double f, k, nearest_mm;
    Eigen::Vector3d g;  // (1, offsets from the negative part's centroid in cells)
  };
  std::vector<Giver> givers;
  double available = 0;
  const int radius = kRayCancelRadius;
  // The distance (mm) from cell (a, b) to the nearest negative cell within `window` cells.
  auto nearest_negative_mm = [&](int a, int b, int window) {
    double nearest2 = std::numeric_limits<double>::infinity();  // mm^2
    for (int y = std::max(0, b - window); y <= std::min(ny - 1, b + window); ++y) {
      const double dy2 = std::pow((y - b) * ay.width_mm, 2);
      for (int x = std::max(0, a - window); x <= std::min(nx - 1, a + window); ++x)
        if (f[size_t(y) * nx + x] < 0)
          nearest2 = std::min(nearest2, std::pow((x - a) * ax.width_mm, 2) + dy2);
    }
    return std::sqrt(nearest2);
  };
  // k by two box passes: along rows, then along columns.
  std::vector<double> row_box(f.size(), 0.0);
  for (int b = 0; b < ny; ++b) {
    const double* line = &f[size_t(b) * nx];
    for (int a = 0; a < nx; ++a) {
      double sum = 0;
      for (int x = std::max(0, a - radius); x <= std::min(nx - 1, a + radius); ++x)
        sum += std::max(0.0, -line[x]);
      row_box[size_t(b) * nx + a] = sum;
    }
  }
  for (int b = 0; b < ny; ++b)
    for (int a = 0; a < nx; ++a) {
      const size_t c = size_t(b) * nx + a;
      if (!(f[c] > 0)) continue;
      double k = 0;
      for (int y = std::max(0, b - radius); y <= std::min(ny - 1, b + radius); ++y)
        k += row_box[size_t(y) * nx + a];
      if (!(k > 0)) continue;
      givers.push_back(
          {c, f[c], k, nearest_negative_mm(a, b, radius), Eigen::Vector3d(1, a - mx, b - my)});
      available += f[c];
    }
  if (available < negative) {
    // Too little light near the lobes: every positive cell gives, weighed alike (the distance
    // to the nearest negative cell searched over the whole profile).
    givers.clear();
    for (int b = 0; b < ny; ++b)
      for (int a = 0; a < nx; ++a) {
        const size_t c = size_t(b) * nx + a;
        if (!(f[c] > 0)) continue;
        givers.push_back({c, f[c], 1.0, nearest_negative_mm(a, b, std::max(nx, ny)),
                          Eigen::Vector3d(1, a - mx, b - my)});
      }
  }
  if (givers.empty()) {
    // No positive cell at all: only where the texel's net flux, positive, is below the rounding
    // of its sums over the cells. The profile is left empty; a ray drawn for such a texel (its
    // share of the flux is at that rounding level) starts at the grid's centre cell.
    std::fill(f.begin(), f.end(), 0.0);
    stats->moved += negative;
    stats->uncentred += negative;
    return;
  }
  double k_max = 0;
  for (const Giver& g : givers) k_max = std::max(k_max, g.k);
  for (Giver& g : givers) g.k /= k_max;
  // The residual of the three conditions at p = (alpha, beta) and its Jacobian.
  auto residual = [&](const Eigen::Vector3d& p, Eigen::Matrix3d* jacobian) {
    Eigen::Vector3d r(-negative, 0, 0);
    jacobian->setZero();
    for (const Giver& g : givers) {
      const double want = g.k * p.dot(g.g);
      r += std::clamp(want, 0.0, g.f) * g.g;
      if (want > 0 && want < g.f) *jacobian += g.k * g.g * g.g.transpose();
    }
    return r;
  };
  // alpha alone (beta = 0) exactly: sum w = sum min(k alpha, f) is piecewise linear and rises
  // from 0 to `available`; its breaks are at f / k.
  std::vector<std::pair<double, double>> breaks;  // (f / k, k)
  breaks.reserve(givers.size());
  for (const Giver& g : givers) breaks.emplace_back(g.f / g.k, g.k);
  std::sort(breaks.begin(), breaks.end());
  double alpha = 0, slope = 0, below = 0;  // below: the flux of the cells already at f
  for (const auto& br : breaks) slope += br.second;
  for (const auto& br : breaks) {
    if (below + slope * br.first >= negative) break;
    below += br.first * br.second;
    slope -= br.second;
  }
  alpha = slope > 0 ? (negative - below) / slope : breaks.back().first;
  Eigen::Vector3d p(alpha, 0, 0);
  // Then beta by Newton's method with backtracking from there.
  const double tolerance = 1e-10 * negative;
  bool centred = false;
  {
    Eigen::Vector3d q = p;
    Eigen::Matrix3d jacobian, next_jacobian;
    Eigen::Vector3d r = residual(q, &jacobian);
    for (int it = 0; it < 50; ++it) {
      if (r.cwiseAbs().maxCoeff() <= tolerance) {
        centred = true;
        break;
      }
      const Eigen::Vector3d step = jacobian.fullPivLu().solve(-r);
      if (!step.allFinite()) break;
      double t = 1;
      Eigen::Vector3d next;
      for (; t > 1e-6; t *= 0.5) {
        next = residual(q + t * step, &next_jacobian);
        if (next.norm() < r.norm()) break;
      }
      if (!(t > 1e-6)) break;
      q += t * step;
      r = next;
      jacobian = next_jacobian;
    }
    if (centred) p = q;
  }
  for (size_t c = 0; c < f.size(); ++c) f[c] = std::max(0.0, f[c]);
  for (const Giver& g : givers) {
    const double w = std::clamp(g.k * p.dot(g.g), 0.0, g.f);
    if (!(w > 0)) continue;
    f[g.cell] = std::max(0.0, f[g.cell] - w);
    stats->distance += w * g.nearest_mm;
    stats->max_mm = std::max(stats->max_mm, g.nearest_mm);
  }
  // The flux off by rounding: the result rescaled to the profile's signed flux.
  double kept = 0;
  for (const double v : f) kept += v;
  if (kept > 0)
    for (double& v : f) v *= signed_flux / kept;
  stats->moved += negative;
  if (!centred) stats->uncentred += negative;
}

}  // namespace

FarFieldAt ComputeFarFieldAt(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                             const std::vector<Eigen::Vector3d>& directions,
                             const FarFieldOptions& options) {
  LUMISLAB_CHECK(int(positions.size()) == info.grid.count(), "one slab position per grid index");
  std::vector<double> offsets, weights;
  BellQuadrature(options.samples, &offsets, &weights);
  const int n = options.samples;
  const double h = info.grid.spacing_mm, d = info.distance_mm;
  const Eigen::Vector3d channel_weights = options.channel_weights.value_or(info.channel_weights);
  FarFieldAt out;
  out.values.assign(directions.size(), 0.0);
  out.seen.assign(directions.size(), 0);
  ParallelFor(int(directions.size()), options.threads, [&](int k) {
    const Eigen::Vector3d w = directions[size_t(k)].normalized();
    const double cos_g = w.z();
    if (!(cos_g > 1e-9)) return;  // light leaves S only towards +z
    // (s, t) - (u, v) on M, mm: where the direction meets M from a point of S.
    const double ds = d * w.x() / cos_g, dt = d * w.y() / cos_g;
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
                   channel_weights.dot(SampleLayout(info.layout, p.irradiance, s, t));
          }
        }
      }
    }
    out.values[size_t(k)] = sum * d * d / (cos_g * cos_g * cos_g * 1e6);
    out.seen[size_t(k)] = 1;
  });
  return out;
}

FarField ComputeFarField(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                         const std::vector<double>& c_deg, const std::vector<double>& gamma_deg,
                         const FarFieldOptions& options) {
  const size_t ng = gamma_deg.size(), count = c_deg.size() * ng;
  std::vector<Eigen::Vector3d> directions(count);
  for (size_t k = 0; k < count; ++k)
    directions[k] = TypeCDirection(c_deg[k / ng], gamma_deg[k % ng]);
  FarFieldAt at = ComputeFarFieldAt(info, positions, directions, options);
  FarField out;
  out.c_deg = c_deg;
  out.gamma_deg = gamma_deg;
  out.values = std::move(at.values);
  out.seen = std::move(at.seen);
  for (size_t k = 0; k < count; ++k) {
    if (!out.seen[k]) ++out.unseen;
    if (!out.seen[k] && !(directions[k].z() > 1e-9)) ++out.behind;
  }
  return out;
}

SlabRays SampleSlabRays(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                        int64_t count, uint64_t seed, int threads) {
  const Eigen::Vector3d& channel_weights = info.channel_weights;
  LUMISLAB_CHECK(int(positions.size()) == info.grid.count(), "one slab position per grid index");
  LUMISLAB_CHECK(count >= 1 && count <= std::numeric_limits<int32_t>::max(),
                 "between 1 and 2^31 - 1 rays");
  const SlabLayout& layout = info.layout;
  const SamplingGrid& grid = info.grid;
  const int texels = layout.res_x * layout.res_y;
  const double area_m2 = layout.TexelW() * layout.TexelH() * 1e-6;
  const double h = grid.spacing_mm, d = info.distance_mm;
  // E dA of each position in the one channel (W), 0 where unseen, and each texel's signed
  // flux sum_ij E_ij dA: the slab's irradiance at d.
  std::vector<std::vector<double>> e(positions.size());
  std::vector<double> texel_flux(size_t(texels), 0.0);
  for (size_t p = 0; p < positions.size(); ++p) {
    const SlabPosition& pos = positions[p];
    if (pos.irradiance.empty()) continue;
    e[p].resize(size_t(texels));
    for (int t = 0; t < texels; ++t) {
      e[p][t] = pos.mask.data[t] >= 0.5f ? (channel_weights.x() * pos.irradiance.data[3 * t] +
                                            channel_weights.y() * pos.irradiance.data[3 * t + 1] +
                                            channel_weights.z() * pos.irradiance.data[3 * t + 2]) *
                                               area_m2
                                         : 0.0;
      texel_flux[t] += e[p][t];
    }
  }
  double signed_total = 0;
  for (const double f : texel_flux) signed_total += f;
  // (CheckSlabLight refuses a negative total on grids where its sign means something; rays need
  // a positive one on every grid.)
  if (!(signed_total > 0))
    throw BadInput("the slab holds no light (its seen texels sum to " +
                   std::to_string(signed_total) + " W): no rays to draw");
  SlabRays out;
  out.total_flux = signed_total;
  out.flux_per_ray = signed_total / double(count);

  // Texels whose net flux is negative (the dual's ringing in (s, t)) are cancelled against the
  // nearest texels with positive flux, ring by ring, each giving in proportion to its flux (a
  // scale of its whole profile): scale[t] times texel t's profile is what the rays draw.
  std::vector<double> scale(size_t(texels), 1.0);
  double texel_distance = 0;
  for (int t = 0; t < texels; ++t) {
    if (!(texel_flux[t] < 0)) continue;
    double need = -texel_flux[t];
    out.texel_moved_flux += need;
    scale[t] = 0;
    const int col = t % layout.res_x, row = t / layout.res_x;
    for (int r = 1; need > 0 && r < std::max(layout.res_x, layout.res_y); ++r) {
      double ring = 0;
      auto for_ring = [&](auto&& visit) {
        for (int y = row - r; y <= row + r; ++y)
          for (int x = col - r; x <= col + r; ++x) {
            if (std::max(std::abs(x - col), std::abs(y - row)) != r) continue;
            if (x < 0 || y < 0 || x >= layout.res_x || y >= layout.res_y) continue;
            const int k = y * layout.res_x + x;
            if (texel_flux[k] > 0 && scale[k] > 0) visit(k, x, y);
          }
      };
      for_ring([&](int k, int, int) { ring += scale[k] * texel_flux[k]; });
      if (!(ring > 0)) continue;
      const double take = std::min(1.0, need / ring);
      for_ring([&](int k, int x, int y) {
        texel_distance += take * scale[k] * texel_flux[k] *
                          std::hypot((x - col) * layout.TexelW(), (y - row) * layout.TexelH());
        scale[k] *= 1 - take;
      });
      need -= take * ring;
    }
  }
  if (out.texel_moved_flux > 0) out.texel_moved_mean_mm = texel_distance / out.texel_moved_flux;

  // Each ray's texel, drawn from the texels' flux after that; the rays grouped by texel.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> cumulative(static_cast<size_t>(texels));
  double running = 0;
  for (int t = 0; t < texels; ++t) {
    running += std::max(0.0, scale[t] * texel_flux[t]);
    cumulative[t] = running;
  }
  std::vector<int> first(size_t(texels) + 1, 0);
  std::vector<int32_t> ray_texel(static_cast<size_t>(count));
  for (int32_t& t : ray_texel) {
    const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), uniform(rng) * running);
    t = int32_t(std::min<ptrdiff_t>(it - cumulative.begin(), texels - 1));
    ++first[size_t(t) + 1];
  }
  for (int t = 0; t < texels; ++t) first[t + 1] += first[t];
  std::vector<int32_t> order(static_cast<size_t>(count));  // ray indices, texel by texel
  {
    std::vector<int> next(first.begin(), first.end() - 1);
    for (int64_t k = 0; k < count; ++k) order[size_t(next[ray_texel[size_t(k)]]++)] = int32_t(k);
    std::vector<int32_t>().swap(ray_texel);
  }

  // Each texel's profile over (u, v) on cells of h / kRayCellsPerSpacing: the signed flux
  // sum_ij E_ij dA times the bell's integral over the cell, its negative part cancelled against
  // nearby positive mass (CancelNegativeRayCells), the rays drawn from what is left: a cell by
  // its flux, (u, v) uniform in it, (s, t) uniform in the texel.
  // Texels run in parallel, each with its own random stream (seeded by the seed and the texel),
  // so the rays do not depend on the thread count.
  const RayCellAxis ax = MakeRayCellAxis(grid.nu, h), ay = MakeRayCellAxis(grid.nv, h);
  std::vector<RayCellCancelling> per_texel(static_cast<size_t>(texels));
  out.rays.resize(size_t(count));
  ParallelFor(texels, threads, [&](int t) {
    if (!(scale[t] > 0) || texel_flux[t] == 0) return;
    // row_sum[j][a] = sum_i E_ij overlap_x(a, i); profile[b][a] = sum_j row_sum[j][a]
    // overlap_y(b, j).
    std::vector<double> profile(size_t(ax.cells) * ay.cells, 0.0);
    std::vector<double> row_sum(size_t(ax.cells) * grid.nv, 0.0);
    for (int j = 0; j < grid.nv; ++j)
      for (int i = 0; i < grid.nu; ++i) {
        const std::vector<double>& ek = e[size_t(grid.Index(i, j))];
        if (ek.empty() || ek[t] == 0) continue;
        for (int a = 0; a < ax.cells; ++a)
          row_sum[size_t(j) * ax.cells + a] += scale[t] * ek[t] * ax.Overlap(a, i);
      }
    for (int b = 0; b < ay.cells; ++b)
      for (int j = 0; j < grid.nv; ++j) {
        const double w = ay.Overlap(b, j);
        if (w == 0) continue;
        for (int a = 0; a < ax.cells; ++a)
          profile[size_t(b) * ax.cells + a] += w * row_sum[size_t(j) * ax.cells + a];
      }
    CancelNegativeRayCells(ax, ay, &profile, &per_texel[size_t(t)]);
    if (first[t + 1] == first[t]) return;
    std::vector<double>& cell_cumulative = row_sum;  // reused
    cell_cumulative.resize(profile.size());
    double cell_running = 0;
    for (size_t c = 0; c < profile.size(); ++c) cell_cumulative[c] = cell_running += profile[c];
    std::seed_seq texel_seed{uint32_t(seed), uint32_t(seed >> 32), uint32_t(t)};
    std::mt19937_64 texel_rng(texel_seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const Eigen::Vector2d centre = layout.TexelCentre(t % layout.res_x, t / layout.res_x);
    for (int k = first[t]; k < first[t + 1]; ++k) {
      const auto it = std::upper_bound(cell_cumulative.begin(), cell_cumulative.end(),
                                       unit(texel_rng) * cell_running);
      const size_t c = cell_running > 0
                           ? size_t(std::min<ptrdiff_t>(it - cell_cumulative.begin(),
                                                        ptrdiff_t(profile.size()) - 1))
                           : size_t(ay.cells / 2) * ax.cells + ax.cells / 2;  // an empty profile
      const double u = ax.start_mm + (double(c % ax.cells) + unit(texel_rng)) * ax.width_mm;
      const double v = ay.start_mm + (double(c / ax.cells) + unit(texel_rng)) * ay.width_mm;
      const double s = centre.x() + (unit(texel_rng) - 0.5) * layout.TexelW();
      const double tt = centre.y() + (unit(texel_rng) - 0.5) * layout.TexelH();
      SlabRay& ray = out.rays[size_t(order[size_t(k)])];
      ray.origin_mm = {u, v, 0.0};
      ray.direction = Eigen::Vector3d(s - u, tt - v, d).normalized();
    }
  });
  RayCellCancelling cancelled;  // summed in texel order: the same for any thread count
  for (const RayCellCancelling& c : per_texel) {
    cancelled.moved += c.moved;
    cancelled.uncentred += c.uncentred;
    cancelled.distance += c.distance;
    cancelled.max_mm = std::max(cancelled.max_mm, c.max_mm);
  }
  out.moved_flux = cancelled.moved;
  out.uncentred_flux = cancelled.uncentred;
  out.moved_max_mm = cancelled.max_mm;
  if (cancelled.moved > 0) out.moved_mean_mm = cancelled.distance / cancelled.moved;
  return out;
}

}  // namespace lumislab
