#include "hard_cases.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/basis.h"
#include "core/dataset.h"
#include "core/exr_io.h"
#include "core/slab.h"
#include "core/slab_compare.h"
#include "slab_masks.h"

namespace lumislab::hard_cases {

using testing::FreshDir;
using testing::RunTool;
using testing::WriteFile;

std::string Emitter(double x, double y, double z, double i0, double lobe) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                R"({"position_mm": [%.17g, %.17g, %.17g], "intensity_w_sr": [%.17g, %.17g, )"
                R"(%.17g], "lobe_exponent": %.17g})",
                x, y, z, i0, 0.9 * i0, 0.8 * i0, lobe);
  return buf;
}

std::string DefaultEmitters() {
  return Emitter(1.5, -2, -20, 1.0, 8) + ", " + Emitter(-3, 1, -12, 0.5, 3);
}

std::string Scene(const Geometry& s, const std::string& emitters, const std::string& camera,
                  const std::string& effects) {
  char setup[512];
  std::snprintf(setup, sizeof setup,
                R"("setup": {"distance_mm": %.17g, "grid": {"nu": %d, "nv": %d, )"
                R"("spacing_mm": %.17g}, "screen_mm": [%.17g, %.17g]}, "filter": {"k_max": %d})",
                s.d, s.nu, s.nv, s.h, s.screen_w, s.screen_h, s.k_max);
  return std::string("{\"schema_version\": 1, ") + setup + ", \"luminaire\": {\"emitters\": [" +
         emitters + "]}, \"camera\": " + camera + ", \"effects\": " + effects + "}\n";
}

CaseRun RunCase(const std::string& name, const std::string& scene_json, int resolution,
                const std::string& reconstruct_args, const std::string& acquire_args) {
  CaseRun r;
  const std::string dir = FreshDir("hard_" + name);
  WriteFile(dir + "/scene.json", scene_json);
  r.ds = dir + "/ds";
  const std::string res = std::to_string(resolution);
  r.acquire = RunTool("lumislab-acquire", "synth --scene " + dir + "/scene.json --out " + r.ds +
                                              " --truth-resolution " + res + " " + acquire_args);
  if (r.acquire.exit_code != 0) return r;
  r.calibrate = RunTool("lumislab-calibrate", "screen --dataset " + r.ds);
  if (r.calibrate.exit_code != 0) return r;
  r.reconstruct = RunTool("lumislab-reconstruct",
                          "--dataset " + r.ds + " --resolution " + res + " " + reconstruct_args);
  return r;
}

void CleanUp(const CaseRun& r) {
  if (!::testing::Test::HasFailure())
    std::filesystem::remove_all(std::filesystem::path(r.ds).parent_path());
}

std::vector<PositionCheck> CheckSlab(const std::string& ds, const CheckOptions& o) {
  const Dataset dataset = Dataset::Load(ds);
  const SlabInfo info = SlabInfo::Load(ds + "/slab");
  const SlabInfo truth_info = SlabInfo::Load(ds + "/truth");
  const SlabLayout& l = info.layout;
  EXPECT_EQ(l.res_x, truth_info.layout.res_x);
  const double area_m2 = l.TexelW() * l.TexelH() * 1e-6;
  std::vector<PositionCheck> out;
  for (const auto& [i, j] : info.present) {
    const SlabPosition s = ReadSlabPosition(ds + "/slab", info, i, j);
    const SlabPosition t = ReadSlabPosition(ds + "/truth", truth_info, i, j);
    const Eigen::Vector2d c = info.grid.Centre(i, j);
    PositionCheck p;
    p.i = i, p.j = j;
    auto inside = [&](int col, int row) {
      return col >= 0 && row >= 0 && col < l.res_x && row < l.res_y;
    };
    auto magnitude = [&](int col, int row) {
      double m = 0;
      for (int ch = 0; ch < 3; ++ch)
        m = std::max(m, double(std::abs(t.irradiance.at(col, row, ch))));
      return m;
    };
    double peak = 0;
    for (int row = 0; row < l.res_y; ++row)
      for (int col = 0; col < l.res_x; ++col) peak = std::max(peak, magnitude(col, row));
    auto seen = [&](int col, int row) { return s.mask.at(col, row, 0) == 1.f; };
    // Selected: seen, and the truth within 3 texels at most max_truth_fraction of the peak (the
    // fit's inverse stencil decays by 0.1 per texel: light 3 texels away reaches a texel at
    // 1e-3 of its own error, below the solver's floor).
    std::vector<unsigned char> dim(size_t(l.res_x) * l.res_y, 1);
    if (std::isfinite(o.max_truth_fraction))
      for (int row = 0; row < l.res_y; ++row)
        for (int col = 0; col < l.res_x; ++col)
          for (int dy = -3; dy <= 3; ++dy)
            for (int dx = -3; dx <= 3; ++dx)
              if (inside(col + dx, row + dy) &&
                  magnitude(col + dx, row + dy) > o.max_truth_fraction * peak)
                dim[size_t(row) * l.res_x + col] = 0;
    auto selected = [&](int col, int row) {
      return seen(col, row) && dim[size_t(row) * l.res_x + col];
    };
    // The truth beyond the window's edge, extrapolated linearly; its second differences.
    auto truth = [&](int col, int row, int dc, int dr, int ch) {
      if (inside(col + dc, row + dr)) return double(t.irradiance.at(col + dc, row + dr, ch));
      const double e = t.irradiance.at(col, row, ch);
      return inside(col - dc, row - dr) ? 2 * e - t.irradiance.at(col - dc, row - dr, ch) : e;
    };
    const int dc[4] = {1, -1, 0, 0}, dr[4] = {0, 0, 1, -1};
    std::vector<double> laplacian(size_t(l.res_x) * l.res_y * 3);
    for (int row = 0; row < l.res_y; ++row)
      for (int col = 0; col < l.res_x; ++col)
        for (int ch = 0; ch < 3; ++ch) {
          double lap = 0;
          for (int q = 0; q < 4; ++q)
            lap += truth(col, row, dc[q], dr[q], ch) - t.irradiance.at(col, row, ch);
          laplacian[(size_t(row) * l.res_x + col) * 3 + ch] = lap;
        }
    double err2 = 0, ref2 = 0, bound2_delta = 0, bound2_edge = 0, boundary = 0, abs_sum = 0;
    double kinks = 0, all2 = 0;
    for (int row = 0; row < l.res_y; ++row)
      for (int col = 0; col < l.res_x; ++col)
        for (int ch = 0; ch < 3 && seen(col, row); ++ch)
          all2 += double(t.irradiance.at(col, row, ch)) * t.irradiance.at(col, row, ch);
    int& values = p.values;
    p.area_m2 = area_m2;
    for (int row = 0; row < l.res_y; ++row)
      for (int col = 0; col < l.res_x; ++col) {
        const float m = s.mask.at(col, row, 0);
        if (!std::isfinite(m) || (m != 0.f && m != 1.f)) p.finite = false;
        const bool may_drop = o.may_drop && o.may_drop(i, j, col, row);
        const bool on =
            testing::TexelOnScreen(l, c, dataset.screen_w_mm, dataset.screen_h_mm, col, row);
        const bool inner = testing::TexelOnScreen(l, c, dataset.screen_w_mm, dataset.screen_h_mm,
                                                  col, row, o.edge_band);
        p.expected_seen += inner;
        if (m == 1.f) ++p.seen;
        if ((m == 1.f && !on) || (m == 0.f && inner && !may_drop)) ++p.mask_mismatch;
        if (m == 0.f && inner) ++p.inner_unseen;
        for (int ch = 0; ch < 3; ++ch) {
          const float v = s.irradiance.at(col, row, ch);
          if (!std::isfinite(v)) p.finite = false;
          if (m == 0.f && v != 0.f) p.zero_where_unseen = false;
        }
        if (!selected(col, row)) continue;
        for (int ch = 0; ch < 3; ++ch) {
          const double e = t.irradiance.at(col, row, ch), v = s.irradiance.at(col, row, ch);
          p.flux += v * area_m2;
          p.truth_flux += e * area_m2;
          err2 += (v - e) * (v - e);
          ref2 += e * e;
          abs_sum += std::abs(e);
          ++values;
          if (magnitude(col, row) >= 0.01 * peak) ++p.lit_values, p.lit_norm += e * e;
          // The bell term (second differences); the mirrored neighbours' edge term; the
          // region's boundary for the flux; where the second differences jump (kinks).
          const double lap = laplacian[(size_t(row) * l.res_x + col) * 3 + ch];
          double edge = 0, lap_mean = 0;
          for (int q = 0; q < 4; ++q) {
            const int nc = col + dc[q], nr = row + dr[q];
            const double en = truth(col, row, dc[q], dr[q], ch);
            if (!inside(nc, nr) || !seen(nc, nr)) edge += std::abs(en - e);
            if (!inside(nc, nr) || !selected(nc, nr)) boundary += std::abs(en - e);
            lap_mean +=
                0.25 * (inside(nc, nr) ? laplacian[(size_t(nr) * l.res_x + nc) * 3 + ch] : lap);
          }
          kinks += std::abs(lap - lap_mean);
          const double delta = kSamplingFactor * lap / 24, mirror = kEdgeSpread * edge / 12;
          bound2_delta += delta * delta;
          bound2_edge += mirror * mirror;
        }
      }
    p.lit_norm = std::sqrt(p.lit_norm);
    if (ref2 > 0) {
      p.relative_l2 = std::sqrt(err2 / ref2);
      p.l2_bound = (std::sqrt(bound2_delta) + std::sqrt(bound2_edge) +
                    std::sqrt(double(values)) * o.texel_error + kSolverFloor * std::sqrt(all2) +
                    kDeconvolutionGain * o.photo_rounding * std::sqrt(ref2)) /
                   std::sqrt(ref2);
    }
    p.flux_bound = (kSamplingFactor * (boundary + kinks) / 24 +
                    (kFitFluxTolerance + o.photo_rounding) * abs_sum +
                    kSolverFloor * std::sqrt(all2 * values) + values * o.texel_error) *
                   area_m2;
    out.push_back(p);
  }
  return out;
}

void ExpectStable(const std::string& label, const std::vector<PositionCheck>& checks,
                  double l2_floor, double flux_floor) {
  double worst_l2 = 0, worst_flux = 0, l2_at = 0, l2_bound_at = 0, flux_at = 0, flux_bound_at = 0;
  for (const auto& p : checks) {
    const std::string at = label + " position " + std::to_string(p.i) + "," + std::to_string(p.j);
    EXPECT_TRUE(p.finite) << at;
    EXPECT_TRUE(p.zero_where_unseen) << at;
    EXPECT_EQ(p.mask_mismatch, 0) << at << ": seen " << p.seen << ", expected " << p.expected_seen;
    const double l2_bound = p.l2_bound + l2_floor;
    const double flux_bound = p.flux_bound + flux_floor;
    const double rel_flux = p.truth_flux != 0 ? p.FluxError() / std::abs(p.truth_flux) : 0;
    EXPECT_LE(p.relative_l2, l2_bound) << at;
    EXPECT_LE(p.FluxError(), flux_bound)
        << at << ": flux " << p.flux << " W, truth " << p.truth_flux << " W";
    if (l2_bound > 0 && p.relative_l2 / l2_bound >= worst_l2)
      worst_l2 = p.relative_l2 / l2_bound, l2_at = p.relative_l2, l2_bound_at = l2_bound;
    if (flux_bound > 0 && p.FluxError() / flux_bound >= worst_flux)
      worst_flux = p.FluxError() / flux_bound, flux_at = rel_flux,
      flux_bound_at = p.truth_flux != 0 ? flux_bound / std::abs(p.truth_flux) : 0;
  }
  std::printf(
      "%s: %zu positions; worst relative L2 %.3g %% (bound %.3g %%), worst flux error "
      "%.3g %% (bound %.3g %%)\n",
      label.c_str(), checks.size(), 100 * l2_at, 100 * l2_bound_at, 100 * flux_at,
      100 * flux_bound_at);
}

bool Says(const CommandResult& r, const std::string& text) {
  return r.output.find(text) != std::string::npos;
}

void ExpectNoWarning(const CaseRun& r) {
  EXPECT_FALSE(Says(r.acquire, "warning")) << r.acquire.output;
  EXPECT_FALSE(Says(r.reconstruct, "warning")) << r.reconstruct.output;
}

void ExpectCleanStableCase(const std::string& name, const std::string& label,
                           const std::string& scene_json, int resolution,
                           const CheckOptions& options) {
  const CaseRun r = RunCase(name, scene_json, resolution);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  ExpectNoWarning(r);
  ExpectStable(label, CheckSlab(r.ds, options));
  CleanUp(r);
}

}  // namespace lumislab::hard_cases
