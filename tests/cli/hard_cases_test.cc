// Hard cases that must stay numerically stable (issue 10, docs/design.md §8.2 "Hard cases"):
// small synthetic captures at the edges of what the method can do, each run through acquire
// synth -> calibrate screen -> reconstruct and checked against the analytic truth/:
//
//  * every value written is finite, and 0 where the mask is 0;
//  * the mask is 0 off the screen and 1 on it, except a band along the screen's edge whose
//    texels' samples read pixels beyond it (CheckOptions::edge_band) and saturated texels (the
//    cameras here see the whole screen);
//  * the flux of each position (sum of E over the seen texels x texel area) matches the truth's
//    within a bound derived below, and so does the relative L2 error;
//  * a case outside what the method can do is said so (a warning or exit 2), never written as a
//    confident wrong answer.
//
// The bounds (docs/design.md §3.6). The fit matches texel box averages b with the bell stencil
// [1/12, 5/6, 1/12] per axis; that stencil's rows and columns sum to 1 (also at mask edges,
// where a missing neighbour is mirrored), and the first-difference regulariser's columns sum to
// 0, so the normal equations give sum(c) = sum(b) exactly, up to the CG tolerance (relative
// residual 1e-6, times sqrt(texels) <= 64 here: 1e-4 of sum|b|). The fitted value differs from
// the truth at the texel centre by the bell model's own term
//     c - E ~ (a^2/24) lap E  =: Delta, estimated from the truth's second differences
// (Delta_k = (1/24) (sum of the 4 neighbours - 4 E_k), a linear extrapolation at the window's
// edge), plus the smoothing of the sampling chain (pre-average F x F, bilinear reads, K x K
// samples per texel: kernel variance ~ (F p)^2/4 + a^2/(12 K^2) per axis with F p ~ a/3, i.e.
// (a^2/24) x 0.6 more), so 1.6 |Delta| bounds it; the factor 2 used leaves 25 % for the next
// Taylor order. Where a seen texel borders an unseen one (or the window's edge), the fit assumes
// the mirror c_n = c_k instead of the light E_n: b_k then carries (1/12)(E_n - E_k) that the
// model does not, and B^-1 (its entries decay by 0.1 per texel) spreads it at most 1.25x per
// axis: edge_k = (1/12) x 1.25^2 x sum |E_n - E_k| over the mirrored neighbours n.
//   relative L2:  ||c - E|| / ||E|| <= (||2 Delta|| + ||edge|| + solver floor + rounding)
//                 / ||E||  (+ the noise floor where there is noise)
//   flux:  sum(c) - sum(E) = sum(b - E) ~ 1.6 sum(Delta): the interior second differences
//          telescope to the boundary of the seen region, so
//          |F - F_truth| <= 2 (a^2/24) sum over boundary edges |E_n - E_k|
//                           + 2 (a^2/24) sum |lap_k - mean of the neighbours' lap|
//                           + (1e-4 + rounding) a^2 sum|E|.
//          The second term is where the Taylor expansion fails: the filter phi~ is piecewise
//          quadratic, and where its second derivative jumps (a kink) the box average departs
//          from the centre value plus Delta by up to that jump's share.
// The solver floor: the CG stops at ||r|| <= 1e-6 ||B^T b||, so ||c - c_exact|| <= 5.3e-6
// ||b|| (kSolverFloor). Rounding: half-float photos 2^-12 relative per value, through the
// deconvolution's absolute row sum 2.25 (kHalfRounding, kDeconvolutionGain); 16-bit codes
// (CheckOptions::texel_error).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>

#include "core/basis.h"
#include "core/dataset.h"
#include "core/exr_io.h"
#include "core/slab.h"
#include "core/slab_compare.h"
#include "core/srgbe.h"
#include "lib/lightfield/tone_map.h"
#include "noise_floor.h"
#include "slab_masks.h"
#include "test_util.h"

namespace lumislab {
namespace {

using testing::CommandResult;
using testing::FreshDir;
using testing::RunTool;
using testing::WriteFile;

// One texel's sampling chain error, in units of the bell term (see above): 1.6, rounded up.
constexpr double kSamplingFactor = 2.0;
// B^-1 spreads a boundary error over neighbours: at most 1.25x per axis.
constexpr double kEdgeSpread = 1.25 * 1.25;
// The CG tolerance's share of the flux (1e-6 x sqrt(texels), texels <= 64^2).
constexpr double kFitFluxTolerance = 1e-4;
// The CG stops at ||r|| <= 1e-6 ||B^T b||; with the smallest eigenvalue of B^T B + lambda D^T D
// >= 0.19 (docs/design.md §3.6) and ||B|| <= 1, ||c - c_exact|| <= 1e-6 / 0.19 ||b||: a floor
// of 5.3e-6 of the position's own ||E|| on every part of it.
constexpr double kSolverFloor = 1e-6 / 0.19;
// Half-float photos: each slide value rounded by at most 2^-12 relative. With one emitter a
// screen point is lit through one slide only (T+ or T-), so the rounding moves E = peak x
// scale x (v+ - v-) by at most 2^-12 |E|; a texel's b by at most 2^-12 of its |E|, and the
// deconvolution's inverse has absolute row sum 1 / (5/6 - 2/12)^2 = 2.25 in 2D.
const double kHalfRounding = std::ldexp(1.0, -12);
constexpr double kDeconvolutionGain = 2.25;

struct Geometry {
  double d = 750, h = 5;
  int nu = 3, nv = 3;
  double screen_w = 1200, screen_h = 1200;
  int k_max = 1;
};

// A camera 400 x 300 px seeing the default screen from behind and below (e2e's frontal camera
// at a quarter of its pixels): about 5 mm of screen per pixel.
const char* kSmallCamera =
    R"({"size_px": [400, 300], "focal_px": 325, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";

std::string Emitter(double x, double y, double z, double i0, double lobe) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                R"({"position_mm": [%.17g, %.17g, %.17g], "intensity_w_sr": [%.17g, %.17g, )"
                R"(%.17g], "lobe_exponent": %.17g})",
                x, y, z, i0, 0.9 * i0, 0.8 * i0, lobe);
  return buf;
}
// The default luminaire (§5.10).
std::string DefaultEmitters() {
  return Emitter(1.5, -2, -20, 1.0, 8) + ", " + Emitter(-3, 1, -12, 0.5, 3);
}

std::string Scene(const Geometry& s, const std::string& emitters, const std::string& camera,
                  const std::string& effects = "[]") {
  char setup[512];
  std::snprintf(setup, sizeof setup,
                R"("setup": {"distance_mm": %.17g, "grid": {"nu": %d, "nv": %d, )"
                R"("spacing_mm": %.17g}, "screen_mm": [%.17g, %.17g]}, "filter": {"k_max": %d})",
                s.d, s.nu, s.nv, s.h, s.screen_w, s.screen_h, s.k_max);
  return std::string("{\"schema_version\": 1, ") + setup + ", \"luminaire\": {\"emitters\": [" +
         emitters + "]}, \"camera\": " + camera + ", \"effects\": " + effects + "}\n";
}

struct CaseRun {
  std::string ds;
  CommandResult acquire, calibrate, reconstruct;
};

// acquire synth -> calibrate screen -> reconstruct at `resolution` (the truth at the same).
CaseRun RunCase(const std::string& name, const std::string& scene_json, int resolution,
                const std::string& reconstruct_args = "", const std::string& acquire_args = "") {
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

// Datasets are kept only when a test failed, for inspection.
void CleanUp(const CaseRun& r) {
  if (!::testing::Test::HasFailure())
    std::filesystem::remove_all(std::filesystem::path(r.ds).parent_path());
}

struct PositionCheck {
  int i = 0, j = 0;
  bool finite = true, zero_where_unseen = true;
  int seen = 0, expected_seen = 0, mask_mismatch = 0;
  int inner_unseen = 0;  // texels that must be seen but are not (saturated ones, when allowed)
  double flux = 0, truth_flux = 0, flux_bound = 0;  // W (E in W/m^2 x m^2), RGB summed
  double relative_l2 = 0, l2_bound = 0;             // over the seen texels, RGB together
  // Texel values (texels x channels) compared; of them lit (>= 1 % of the position's largest
  // truth, as core/slab_compare.h counts), and ||E|| over the lit ones; texel area.
  int values = 0, lit_values = 0;
  double lit_norm = 0, area_m2 = 0;
  double FluxError() const { return std::abs(flux - truth_flux); }
};

// The mask (docs/design.md §3.5 step 3, cameras that see the whole screen): a texel is seen when
// every photo pixel its samples read lies on the screen. Those reads reach past the texel's edge
// by at most 2F photo pixels (the bilinear read of the F x F average and the averaged block),
// F = round(median texel side in px / 3), i.e. about 2/3 of a texel plus a pixel where texels
// are of the median size: so a texel whose rectangle lies on the screen `edge_band` = 1 texel
// or more from its edge must be seen, one off the screen must not, and one in the band
// between may go either way. Where the view's scale varies over the screen (a grazing camera:
// far texels half the median), edge_band is the ratio of the median to the smallest texel.
struct CheckOptions {
  // Texels that may be unseen although on the screen (saturated ones).
  std::function<bool(int i, int j, int col, int row)> may_drop;
  // Only texels whose truth (largest channel magnitude) within 3 texels is at most this
  // fraction of the position's largest: the faint part of a luminaire on its own.
  double max_truth_fraction = std::numeric_limits<double>::infinity();
  // A bound on each texel's error from the photos' values (rounding), E units per channel:
  // adds sqrt(N) x this to the L2 numerator and N x this x area to the flux bound.
  double texel_error = 0;
  double edge_band = 1;  // texels (above)
  // Relative rounding of the photos' values: half floats (acquire synth's default) keep 11
  // significant bits, 2^-12 at most; float photos 2^-24.
  double photo_rounding = kHalfRounding;
};

std::vector<PositionCheck> CheckSlab(const std::string& ds, const CheckOptions& o = {}) {
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

// The common assertions; `l2_floor` adds to the derived L2 bound (noise), `flux_floor` (W) to
// the flux bound. Prints one line per position and returns the worst ratios (error / bound).
void ExpectStable(const std::string& label, const std::vector<PositionCheck>& checks,
                  double l2_floor = 0, double flux_floor = 0) {
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

// Light resolved by the slab and photos exposed within range: nothing to warn about (the
// warnings of the cases below must not fire where the method works).
void ExpectNoWarning(const CaseRun& r) {
  EXPECT_FALSE(Says(r.acquire, "warning")) << r.acquire.output;
  EXPECT_FALSE(Says(r.reconstruct, "warning")) << r.reconstruct.output;
}

// A case the method handles: the chain succeeds, no tool warns, and the slab is stable
// (ExpectStable over CheckSlab with `options`); the datasets are removed unless it failed.
void ExpectCleanStableCase(const std::string& name, const std::string& label,
                           const std::string& scene_json, int resolution,
                           const CheckOptions& options = {}) {
  const CaseRun r = RunCase(name, scene_json, resolution);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  ExpectNoWarning(r);
  ExpectStable(label, CheckSlab(r.ds, options));
  CleanUp(r);
}

// The reference point: the default luminaire on a 3 x 3 grid at 64 texels (18.75 mm).
TEST(HardCases, Baseline) {
  ExpectCleanStableCase("baseline", "baseline", Scene(Geometry{}, DefaultEmitters(), kSmallCamera),
                        64);
}

// An emitter almost on S (z = -0.05 mm): every ray to the screen crosses S within 0.1 mm of the
// emitter, so each position is the filter's value there times the isotropic emitter's
// cos/r^2: light wider than the screen, running off every edge (the mask-edge terms).
TEST(HardCases, EmitterOnTheFilterPlaneWiderThanTheScreen) {
  ExpectCleanStableCase("on_plane", "on the filter plane",
                        Scene(Geometry{}, Emitter(1, -1.5, -0.05, 1, 0), kSmallCamera), 64);
}

// A pattern running off the screen's edge: the emitter 10 mm off axis puts the filter's image
// (+-385 mm) around s = -375 mm, over the left edge at -600 mm.
TEST(HardCases, PatternRunningOffTheScreenEdge) {
  ExpectCleanStableCase("off_edge", "off the screen edge",
                        Scene(Geometry{}, Emitter(10, 2, -20, 1, 0), kSmallCamera), 64);
}

// The close-up setup A (§1.5): d = 55 mm, an 18 x 27 mm screen, h = 2.5 mm, here a 1 x 5 grid,
// the camera 110 mm behind the screen. Emitters far behind S (z = -10^5 mm, the filter imaged
// 1:1, +-5 mm) and the default ones.
const char* kCloseUpCamera =
    R"({"size_px": [300, 400], "focal_px": 1200, "position_mm": [0, -5, 165],
        "look_at_mm": [0, 0, 55]})";
Geometry CloseUp(int nu, int nv, double h) {
  Geometry s;
  s.d = 55, s.h = h, s.nu = nu, s.nv = nv, s.screen_w = 18, s.screen_h = 27;
  return s;
}
TEST(HardCases, CloseUpSetupGrid1x5) {
  ExpectCleanStableCase("closeup", "close-up 1x5",
                        Scene(CloseUp(1, 5, 2.5), DefaultEmitters(), kCloseUpCamera), 64);
}
TEST(HardCases, EmitterFarBehindTheFilterPlane) {
  ExpectCleanStableCase("far_behind", "far behind, 1x1",
                        Scene(CloseUp(1, 1, 2.5), Emitter(0.5, -0.3, -1e5, 1e7, 0), kCloseUpCamera),
                        64);
}

// h large against d: h = 12 mm at d = 55 mm on a 2 x 1 grid shifts each window by 6 mm of the
// 18 mm screen (a third of every slab unseen); on a 1 x 5 grid of h = 20 mm the outer
// positions' windows (c = +-40 mm) miss the 27 mm screen entirely: exit 2 naming the position,
// not an empty slab.
TEST(HardCases, SpacingLargeAgainstDistance) {
  ExpectCleanStableCase("large_h", "h = 12 mm, d = 55 mm, 2x1",
                        Scene(CloseUp(2, 1, 12), DefaultEmitters(), kCloseUpCamera), 64);
  const CaseRun off =
      RunCase("large_h_off", Scene(CloseUp(1, 5, 20), DefaultEmitters(), kCloseUpCamera), 32);
  EXPECT_EQ(off.reconstruct.exit_code, 2) << off.reconstruct.output;
  EXPECT_TRUE(Says(off.reconstruct, "no texel inside the photo and the screen"))
      << off.reconstruct.output;
  CleanUp(off);
}

// A beam narrower than a texel: lobe exponent 5000 (sigma = 770 mm / sqrt(5000) = 10.9 mm on
// the screen, FWHM 26 mm) on 37.5 mm texels (32 across 1200 mm). The truth at the texel centres
// point-samples it, so its L2 and flux say nothing; the flux is compared with the analytic one:
// the beam's power 2 pi I0 / (n + 1) (the integral of I0 cos^n over the hemisphere) times the
// filter's mean over the beam's footprint on S: the rays cross S at the emitter's (x, y) plus
// z tan(theta) in each axis, with the flux-weighted <tan^2 theta> = 2 / (n - 1), i.e. a
// footprint of sigma_S = |z| / sqrt(n - 1) = 0.28 mm = 0.057 h per axis, close to a Gaussian
// (its higher cumulants are O(1/n) relative: a 1/n term in the bound). The filter's kinks at
// half integers lie within 2 sigma_S of some positions, so the mean is integrated, not expanded.
// The // camera faces the screen squarely (pixel rows along the texel rows) with p = 1650 mm / 352
// = 4.6875 mm = a / 8 per pixel, and the photo is read at 16 samples per texel (F = 1): bilinear
// reads at exactly half the pixel pitch give every pixel the same total weight, so the texel
// sums integrate the photo's samples exactly, and the beam's spectrum at the pixel frequency,
// exp(-2 pi^2 sigma^2 / p^2) = e^-107, is nil. With the fit's tolerance: 1e-4 + 4.6e-4 +
// half-float rounding 2.4e-4. The scale is set (2 W/m^2: the beam peaks at I0 / r^2 = 1.69 W/m^2
// through a slide of transmittance <= 1), since the automatic one's pre-pass sees every 7th pixel
// and misses the beam: acquire warns about that (the second run). The slab cannot hold the beam's
// shape (one texel holds most of it): reconstruct warns.
// The mean of phi~(x + sigma g) over a standard normal g (trapezoid rule over +-8 sigma, 4001
// points: phi~ is piecewise quadratic, the rule's error is far below 1e-9).
double FootprintMean(const DualFilter& filter, double x, double sigma) {
  double sum = 0, weight = 0;
  for (int k = -2000; k <= 2000; ++k) {
    const double g = k * 8.0 / 2000, w = std::exp(-0.5 * g * g) * (std::abs(k) == 2000 ? 0.5 : 1);
    sum += w * filter.Eval(x + sigma * g);
    weight += w;
  }
  return sum / weight;
}

TEST(HardCases, BeamNarrowerThanATexel) {
  const double n = 5000, z = -20, ex = 1.5, ey = -2;
  const std::string camera =
      R"({"size_px": [400, 300], "focal_px": 352, "position_mm": [0, 0, 2400],
          "look_at_mm": [0, 0, 750], "radiometric_scale_w_m2": 2})";
  const CaseRun r = RunCase("narrow", Scene(Geometry{}, Emitter(ex, ey, z, 1, n), camera), 32,
                            "--samples-per-texel 16");
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  EXPECT_TRUE(Says(r.reconstruct, "varies within a texel")) << r.reconstruct.output;
  EXPECT_FALSE(Says(r.reconstruct, "saturated")) << r.reconstruct.output;
  const DualFilter filter = DualFilter::Truncated(1);
  const SamplingGrid grid{3, 3, 5};
  const double power = 2 * M_PI / (n + 1) * (1.0 + 0.9 + 0.8);  // W, RGB summed
  const double sigma = std::abs(z) / std::sqrt(n - 1) / 5;      // footprint per axis, h units
  const double relative = kFitFluxTolerance + kHalfRounding + 1 / n;
  double worst = 0, worst_bound = 0, worst_ratio = 0;
  for (const PositionCheck& p : CheckSlab(r.ds)) {
    const std::string at = "position " + std::to_string(p.i) + "," + std::to_string(p.j);
    EXPECT_TRUE(p.finite) << at;
    EXPECT_TRUE(p.zero_where_unseen) << at;
    EXPECT_EQ(p.mask_mismatch, 0) << at;
    const Eigen::Vector2d c = grid.Centre(p.i, p.j);
    const double x = (ex - c.x()) / 5, y = (ey - c.y()) / 5;
    const double analytic =
        power * FootprintMean(filter, x, sigma) * FootprintMean(filter, y, sigma);
    const double bound = relative * std::abs(analytic);
    EXPECT_LE(std::abs(p.flux - analytic), bound)
        << at << ": flux " << p.flux << " W, analytic " << analytic << " W";
    if (std::abs(p.flux - analytic) / bound >= worst_ratio)
      worst_ratio = std::abs(p.flux - analytic) / bound, worst = std::abs(p.flux / analytic - 1),
      worst_bound = bound / std::abs(analytic);
  }
  std::printf("narrow beam: worst flux error %.3g %% against the analytic beam (bound %.3g %%)\n",
              100 * worst, 100 * worst_bound);
  CleanUp(r);
  // The automatic scale: acquire says that its pre-pass missed the beam.
  const std::string dir = FreshDir("hard_narrow_auto");
  WriteFile(dir + "/scene.json", Scene(Geometry{}, Emitter(ex, ey, z, 1, n), kSmallCamera));
  const CommandResult a =
      RunTool("lumislab-acquire",
              "synth --scene " + dir + "/scene.json --out " + dir + "/ds --truth-resolution 8");
  EXPECT_EQ(a.exit_code, 0) << a.output;
  EXPECT_TRUE(Says(a, "peaks at")) << a.output;
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

// Intensities spanning 10^-6 ... 10^6 W/sr in one luminaire: a bright emitter whose filter image
// lies left of the screen's centre and a dim one right of it (their images barely overlap).
// Float photos (half floats would flush the dim one, 10^-12 of full scale, to 0) keep it; no
// threshold anywhere may drop it or blow it up. Where it alone lights, the slab's error is
// bounded by the fit's floor, 5.3e-6 of the position's ||E|| (kSolverFloor): light 10^-12
// below a position's peak is below what the slab resolves, and the bound says so.
TEST(HardCases, IntensitiesSpanningTwelveDecades) {
  const CaseRun r =
      RunCase("span",
              Scene(Geometry{}, Emitter(10, 0, -20, 1e6, 2) + ", " + Emitter(-10, 0, -20, 1e-6, 2),
                    kSmallCamera),
              64, "", "--photo-format float");
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  CheckOptions all;
  all.photo_rounding = std::ldexp(1.0, -24);
  ExpectStable("1e6 and 1e-6 W/sr", CheckSlab(r.ds, all));
  CheckOptions dim = all;
  dim.max_truth_fraction = 1e-9;
  ExpectStable("1e6 and 1e-6 W/sr, where the dim one alone lights", CheckSlab(r.ds, dim));
  CleanUp(r);
}

// Saturated photos: exposure 4 clips the brightest part of every position's photos; those
// texels leave the fit (mask 0) with a warning, the rest stays within the bound. Exposure 10^4
// on light that covers the whole screen (an emitter on S) clips everything: exit 2 naming the
// position, nothing confident written.
std::string ExposedCamera(double exposure) {
  return R"({"size_px": [400, 300], "focal_px": 325, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750], "exposure": )" +
         std::to_string(exposure) + "}";
}
TEST(HardCases, SaturatedPhotos) {
  const CaseRun r =
      RunCase("saturated", Scene(Geometry{}, DefaultEmitters(), ExposedCamera(4)), 64);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  EXPECT_TRUE(Says(r.reconstruct, "saturated photo pixels")) << r.reconstruct.output;
  CheckOptions o;
  o.may_drop = [](int, int, int, int) { return true; };
  const auto checks = CheckSlab(r.ds, o);
  for (const auto& p : checks) EXPECT_GT(p.inner_unseen, 0) << p.i << "," << p.j;
  ExpectStable("saturated (exposure 4)", checks);
  CleanUp(r);
  const CaseRun all = RunCase(
      "all_saturated", Scene(Geometry{}, Emitter(1, -1.5, -0.05, 1, 0), ExposedCamera(1e4)), 32);
  EXPECT_EQ(all.reconstruct.exit_code, 2) << all.reconstruct.output;
  EXPECT_TRUE(Says(all.reconstruct, "only saturated texels")) << all.reconstruct.output;
  CleanUp(all);
}

// Nearly dark photos, 16-bit: exposure 10^-3 puts the peak at 56 codes. Rounding moves each
// photo value by at most half a code q = 1/65535 (sensor units), i.e. E by
// peak x scale / exposure x q/2 per slide, two slides; a texel averages such values (no gain)
// and the deconvolution's inverse stencil has absolute row sum 1 / (5/6 - 2/12)^2 = 2.25 in 2D:
// |c - c_exact| <= 2.25 x peak x scale / exposure x q per texel, an L2 floor of that over
// ||E||. Exposure 10^-6 leaves every code 0: the slab would be all zero with a success line;
// reconstruct must warn that no light was measured.
TEST(HardCases, NearlyDarkPhotos) {
  const char* kQuantized = R"([{"type": "quantization", "bit_depth": 16}])";
  const CaseRun r =
      RunCase("dark", Scene(Geometry{}, DefaultEmitters(), ExposedCamera(1e-3), kQuantized), 64);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  const Dataset dataset = Dataset::Load(r.ds);
  const double step =
      2.25 * dataset.filter.peak * dataset.radiometric_scale.value_or(1) / 1e-3 / 65535;
  CheckOptions o;
  o.texel_error = step;
  ExpectStable("nearly dark (exposure 1e-3, 16-bit)", CheckSlab(r.ds, o));
  CleanUp(r);
  const CaseRun black =
      RunCase("black", Scene(Geometry{}, DefaultEmitters(), ExposedCamera(1e-6), kQuantized), 32);
  EXPECT_EQ(black.reconstruct.exit_code, 0) << black.reconstruct.output;
  EXPECT_TRUE(Says(black.reconstruct, "no light measured")) << black.reconstruct.output;
  CleanUp(black);
}

// A grazing camera, 75 degrees off the screen's normal (from the side, behind the screen): the
// screen is foreshortened 4x across, texels are 4 x 14 px, the far side half the near side's.
TEST(HardCases, GrazingCamera75Degrees) {
  const double a = 75 * M_PI / 180, dist = 2500;
  char camera[256];
  std::snprintf(camera, sizeof camera,
                R"({"size_px": [1200, 900], "focal_px": 1050, "position_mm": [%.6f, 0, %.6f],)"
                R"( "look_at_mm": [0, 0, 750]})",
                dist * std::sin(a), 750 + dist * std::cos(a));
  Geometry s;
  s.nu = 2, s.nv = 1;
  const CaseRun r = RunCase("grazing", Scene(s, DefaultEmitters(), camera), 64);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  // The far side's texels are half the median's size in pixels (distance 3080 mm against the
  // centre's 2500, and the foreshortening): the reads reach up to 2 texels there.
  CheckOptions o;
  o.edge_band = 2;
  ExpectNoWarning(r);
  ExpectStable("grazing 75 deg", CheckSlab(r.ds, o));
  CleanUp(r);
}

// A camera 700 mm from the centre of a large screen (8 x 8 m), 60 degrees off its normal: its
// focal plane crosses the screen at x = 700 / sin 60 = 808 mm, and the screen beyond lies
// behind it. Such points map through the homography to mirrored pixels inside the photo; their
// texels read the light of other points (errors > 10 %, written as seen) until rectify.cc
// rejected points behind the camera. The camera sees only part of the screen, so any on-screen
// texel may be unseen; none behind the camera may be seen, and the seen ones keep the bound.
TEST(HardCases, ScreenReachingBehindTheCamera) {
  const double dist = 700, a = 60 * M_PI / 180;
  char camera[256];
  std::snprintf(camera, sizeof camera,
                R"({"size_px": [400, 300], "focal_px": 220, "position_mm": [%.6f, 0, %.6f],)"
                R"( "look_at_mm": [0, 0, 750]})",
                dist * std::sin(a), 750 + dist * std::cos(a));
  Geometry g;
  g.nu = g.nv = 1;
  g.screen_w = g.screen_h = 8000;
  std::string scene = Scene(g, Emitter(1, -1.5, -0.05, 1, 0), camera);
  // A board of 7 x 6 squares of 70 mm, which the camera sees whole.
  scene.insert(scene.rfind('}'), R"(, "calibration": {"squares": [7, 6], "square_mm": 70})");
  const CaseRun r = RunCase("behind_camera", scene, 32);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  CheckOptions o;
  o.may_drop = [](int, int, int, int) { return true; };
  ExpectStable("screen behind the camera", CheckSlab(r.ds, o));
  const SlabInfo info = SlabInfo::Load(r.ds + "/slab");
  const SlabPosition p = ReadSlabPosition(r.ds + "/slab", info, 0, 0);
  const double behind_x = dist / std::sin(a);  // lab x of the focal plane on the screen
  int seen_behind = 0, seen = 0;
  for (int row = 0; row < info.layout.res_y; ++row)
    for (int col = 0; col < info.layout.res_x; ++col) {
      if (p.mask.at(col, row, 0) != 1.f) continue;
      ++seen;
      seen_behind += info.layout.TexelCentre(col, row).x() > behind_x;
    }
  EXPECT_GT(seen, 50);
  EXPECT_EQ(seen_behind, 0);
  CleanUp(r);
}

// A tiny full well (50 e-, read noise 3 e-): noise dominates every texel. The slab's error
// against the truth must stay within the noise floor predicted for this sensor
// (tests/cli/noise_floor.h, the same capture without noise as the expected values) plus the
// derived model bound; the flux within what that L2 error allows (Cauchy-Schwarz: |sum err| <=
// sqrt(n) ||err||).
TEST(HardCases, TinyFullWellNoiseDominated) {
  if (testing::kSanitized)
    GTEST_SKIP() << "accuracy only (two captures against a noise floor): the Release build's "
                    "(the sanitized build runs noise through acquire and the fit in "
                    "tests/acquire and reconstruct_test)";
  const char* kTinyWell = R"([{"type": "sensor_noise", "full_well_e": 50, "read_noise_e": 3,
                               "seed": 11}])";
  const CaseRun clean =
      RunCase("tiny_well_clean", Scene(Geometry{}, DefaultEmitters(), kSmallCamera), 64);
  const CaseRun noisy =
      RunCase("tiny_well", Scene(Geometry{}, DefaultEmitters(), kSmallCamera, kTinyWell), 64);
  ASSERT_EQ(clean.reconstruct.exit_code, 0) << clean.reconstruct.output;
  ASSERT_EQ(noisy.reconstruct.exit_code, 0)
      << noisy.acquire.output << noisy.calibrate.output << noisy.reconstruct.output;
  testing::SensorNoiseModel sensor;
  sensor.full_well_e = 50;
  sensor.read_noise_e = 3;
  sensor.code_step = [](double) { return 0.0; };  // float EXR photos: no rounding
  const testing::NoiseFloor floor = testing::PredictNoiseFloor(
      noisy.ds + "/slab", clean.ds, clean.ds + "/calib/screen.json", clean.ds + "/truth", sensor);
  const SlabComparison lit = CompareSlabs(noisy.ds + "/slab", noisy.ds + "/truth");
  // Noise of sigma sqrt(0.85 / 50) = 0.13 at the peak clips some pixels at 1: their texels
  // leave the fit, with a warning.
  EXPECT_TRUE(Says(noisy.reconstruct, "saturated photo pixels")) << noisy.reconstruct.output;
  CheckOptions o;
  o.may_drop = [](int, int, int, int) { return true; };
  const auto checks = CheckSlab(noisy.ds, o);
  double model = 0;
  for (const auto& p : checks) model = std::max(model, p.l2_bound);
  std::printf("tiny full well: lit texels %s; predicted noise floor %.3g %%, model bound %.3g %%\n",
              lit.Summary().c_str(), 100 * floor.overall, 100 * model);
  EXPECT_GT(floor.overall, 0.02);  // noise-dominated indeed
  EXPECT_LE(lit.overall_relative_l2, 1.5 * floor.overall + model);
  for (const auto& p : checks) {
    const std::string at = "position " + std::to_string(p.i) + "," + std::to_string(p.j);
    EXPECT_TRUE(p.finite) << at;
    EXPECT_TRUE(p.zero_where_unseen) << at;
    EXPECT_EQ(p.mask_mismatch, 0) << at;
    // The flux's noise: a sum of independent texel box averages b (sum c = sum b), whose
    // variance is the fitted values' divided by the deconvolution's white-noise gain 1.531^2
    // (noise_floor.h); the lit texels' share is (1.5 x floor x ||E||_lit)^2 and a dark texel's
    // variance (read noise alone) is below a lit one's, so over all values at most
    // values / lit_values times that. 4 sigma.
    const double sigma = p.area_m2 * 1.5 * floor.overall * p.lit_norm *
                         std::sqrt(double(p.values) / std::max(p.lit_values, 1)) / 1.531;
    EXPECT_LE(p.FluxError(), p.flux_bound + 4 * sigma) << at;
  }
  CleanUp(clean);
  CleanUp(noisy);
}

// A seeded randomised sweep over scene parameters (a property test): distance 55 ... 1500 mm,
// screens of 0.5 ... 1.6 d wide and 3:4 ... 4:3 (texels rarely square), h = 0.4 ... 3 % of d, grids
// of 1 ... 3 per axis, one or two emitters from 0.01 h to 20 h behind S with lobes 0 ... 50 and
// intensities 10^-3 ... 10^3 W/sr, a camera 0 ... 45 degrees off the normal in any direction. Each
// scene must give finite values, the masks of the geometry, and flux and L2 within the derived
// bounds. The bounds assume light resolved by the slab (the Taylor terms above): each emitter's
// filter image, 4 h (d - z) / (-z) wide, spans at least 8 texels.
TEST(HardCases, RandomisedSweep) {
  const int scenes = testing::kSanitized ? 2 : 10;
  std::mt19937 rng(20261202);
  auto uniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  for (int k = 0; k < scenes; ++k) {
    Geometry s;
    s.d = 55 * std::pow(1500 / 55.0, uniform(0, 1));
    s.screen_w = s.d * uniform(0.5, 1.6);
    // Aspect within 3:4 ... 4:3: the default board (14 x 13 squares sized by the shorter side)
    // then keeps squares of >= 10 px in the camera below, which frames the longer side.
    s.screen_h = s.screen_w * uniform(0.75, 1.33);
    s.h = std::max(0.01, s.d * uniform(0.004, 0.03));
    s.nu = 1 + int(uniform(0, 3));
    s.nv = 1 + int(uniform(0, 3));
    const int resolution = 32;
    const double texel = std::max(s.screen_w, s.screen_h) / resolution;
    std::string emitters;
    const int count = uniform(0, 1) < 0.5 ? 1 : 2;
    for (int e = 0; e < count; ++e) {
      // -z at most where the image is 8 texels wide: 4 h (d - z) / (-z) >= 8 texel.
      const double max_depth =
          std::min(20 * s.h, 4 * s.h * s.d / std::max(8 * texel - 4 * s.h, 1e-9));
      const double depth = std::min(max_depth, s.h * std::pow(10, uniform(-2, 1.3)));
      if (e) emitters += ", ";
      emitters += Emitter(uniform(-1, 1) * s.h, uniform(-1, 1) * s.h, -depth,
                          std::pow(10, uniform(-3, 3)), uniform(0, 1) < 0.3 ? 0 : uniform(0, 50));
    }
    const double size = std::max(s.screen_w, s.screen_h), dist = 2.2 * size;
    const double tilt = uniform(0, 45) * M_PI / 180, azimuth = uniform(0, 2 * M_PI);
    char camera[320];
    std::snprintf(camera, sizeof camera,
                  R"({"size_px": [400, 300], "focal_px": 484, "position_mm": [%.9g, %.9g, %.9g],)"
                  R"( "look_at_mm": [0, 0, %.9g]})",
                  dist * std::sin(tilt) * std::cos(azimuth),
                  dist * std::sin(tilt) * std::sin(azimuth), s.d + dist * std::cos(tilt), s.d);
    const std::string scene = Scene(s, emitters, camera);
    const std::string label = "sweep " + std::to_string(k);
    SCOPED_TRACE(label + ": " + scene);
    const CaseRun r = RunCase("sweep_" + std::to_string(k), scene, resolution);
    ASSERT_EQ(r.reconstruct.exit_code, 0)
        << r.acquire.output << r.calibrate.output << r.reconstruct.output;
    char what[160];
    std::snprintf(what, sizeof what, "%s (d %.0f mm, h %.2f mm, %dx%d, tilt %.0f deg)",
                  label.c_str(), s.d, s.h, s.nu, s.nv, tilt * 180 / M_PI);
    // Light that varies on the scale of a texel (the filter's lobes, h, spanning 2 texels
    // where its image is 8 texels wide) is inside the bounds, and reconstruct says so.
    if (Says(r.reconstruct, "varies within a texel"))
      std::printf("%s: warns, light finer than a texel\n", label.c_str());
    ExpectStable(what, CheckSlab(r.ds));
    CleanUp(r);
  }
}

// Receivers very near the sampling plane S (D -> 0, docs/design.md §8.2): the receiver plane at
// D = 0.2 d and 0.05 d lit by the built-in luminaire's exact slab (`--write-test-slab`: 9 x 7,
// h = 5 mm, d = 750 mm, 300 texels), rendered four ways by lumislab-preview: the analytic image
// straight from the emitters (the truth), the exact reference at N = 8 and N = 1 (§4.5), and
// OpenGL (eq. 14). The view (--extent) keeps every ray from the emitters to it inside the grid's
// covered region on S (|u| <= ((9 - 1)/2 - K) h = 15 mm, |v| <= 10 mm; the crossing
// u = (e D + x z)/(D + z), §4.8), so what is measured is the method, not the coverage.
//
// Bounds, derived:
//  * Reference (N = 8) against the analytic image: the exact model's parallax error is first
//    order in a = z/(d + z) |1 - d/D| and bounded pointwise by 2 a sum|c_m| (§4.5; sum|c_m| =
//    67/39 for K = 1); with the deeper emitter (z = 20 mm) a = 0.104 at 0.2 d: 36 %. Second
//    order adds (2 a sum|c_m|)^2 / 2 at most (the next Taylor term of the same expansion), so
//    the bound is B = 2 a S + (2 a S)^2 / 2, 42 % at 0.2 d. At 0.05 d, a = 0.49 and 2 a S = 1.7:
//    the expansion does not converge, no bound holds, and lumislab-plan refuses the distance
//    (exit 0 with its warning); the preview and the reference warn the same way given the
//    light's depth (--luminaire-depth-mm, or the dataset's truth/luminaire.json).
//  * OpenGL against the reference at N = 1: both sum one sample per position at c_ij (eq. 14);
//    they differ by E' = E / g interpolated bilinearly and multiplied by g at the sample
//    (shift-invariant model, §3.4) against E interpolated: g = d^2 cos^4 over M varies by at
//    most 4 (a_t / d)^2 ~ 1.6e-4 relative over a texel a_t = 4 mm, plus float rounding in the
//    GPU sum: bound 10^-3 (the CPU-GL agreement test's at d, §4.5).
//  * Every value finite and the flux of each image positive.
TEST(HardCases, ReceiverPlaneNearTheSamplingPlane) {
  if (testing::kSanitized)
    GTEST_SKIP() << "accuracy run: the Release build's (the renderers' paths run under the "
                    "sanitizers in tests/lightfield and tests/preview)";
  const std::string dir = FreshDir("hard_near_s");
  const std::string slab = dir + "/slab";
  const double d = 750, z = 20, sum_c = 67.0 / 39.0;
  struct Plane {
    double fraction, extent_mm;
  };
  for (const Plane& plane : {Plane{0.2, 120}, Plane{0.05, 40}}) {
    const double D = plane.fraction * d;
    char common[256];
    std::snprintf(common, sizeof common,
                  "--slab %s --write-test-slab --scene plane --receiver-plane %.9g --extent %.9g "
                  "--size 48x48 --threads 2",
                  slab.c_str(), D, plane.extent_mm);
    std::string log;  // the last render's output
    const auto render = [&](const std::string& name, const std::string& args) {
      const std::string out = dir + "/" + name + ".exr";
      const auto r =
          RunTool("lumislab-preview", std::string(common) + " " + args + " --out " + out);
      EXPECT_EQ(r.exit_code, 0) << name << "\n" << r.output;
      log = r.output;
      const ImageF image = ReadExr(out, {"R", "G", "B"});
      double flux = 0;
      for (float v : image.data) {
        EXPECT_TRUE(std::isfinite(v)) << name;
        flux += v;
      }
      EXPECT_GT(flux, 0) << name;
      return image;
    };
    const std::string tag = "D" + std::to_string(int(std::lround(100 * plane.fraction)));
    const ImageF analytic = render(tag + "_analytic", "--analytic default");
    const ImageF reference = render(tag + "_ref8", "--reference --samples 8");
    const ImageF reference1 = render(tag + "_ref1", "--reference --samples 1");
    // The preview checks the plane against the light's depth (given: --write-test-slab's slab
    // has no truth/ beside it) and warns where no bound holds, as lumislab-plan does.
    const ImageF opengl = render(tag + "_gl", "--luminaire-depth-mm 20");
    EXPECT_EQ(log.find("too close to S") != std::string::npos, plane.fraction < 0.1) << log;
    const double a = z / (d + z) * std::abs(1 - d / D), first = 2 * a * sum_c;
    const double ref_error = CompareImages(reference, analytic).relative_l2;
    const double ref1_error = CompareImages(reference1, analytic).relative_l2;
    const double gl_error = CompareImages(opengl, reference1).relative_l2;
    std::printf(
        "D = %.2f d: reference N=8 vs analytic %.3g %% (first order 2aS %.3g %%), N=1 vs "
        "analytic %.3g %%, OpenGL vs N=1 %.3g %%\n",
        plane.fraction, 100 * ref_error, 100 * first, 100 * ref1_error, 100 * gl_error);
    EXPECT_LE(gl_error, 1e-3) << tag;
    if (first < 1) {
      EXPECT_LE(ref_error, first + first * first / 2) << tag;
    }
  }
  // At 0.05 d the first-order parallax 2 a sum|c_m| exceeds 1: lumislab-plan says the distance
  // is outside what the method can do, as the preview did above.
  const auto plan = RunTool("lumislab-plan", "--scene default --receiver-mm 37.5 --target 5%");
  EXPECT_EQ(plan.exit_code, 0) << plan.output;
  EXPECT_NE(plan.output.find("too close to S"), std::string::npos) << plan.output;
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

// sRGBE at its edges (core/srgbe.h, docs/design.md §4.3, §8.2), beyond the unit tests of
// tests/core/srgbe_test.cc: what the preview's sRGBE accumulation does with it, emulated on the
// CPU (each light pass decodes the running sum, adds and re-encodes).
//  * Every word decodes to a finite value within kSrgbeMax, and re-encoding a decoded value gives
//    the same value back (a pass that adds nothing leaves the image unchanged; no drift).
//  * Near 0 and through the float denormals (2^-149 ... 2^-126) every triple is within
//    max(max|x| / 127.5, 2^-136) of its input; below 2^-136 it is exactly 0, with no sign.
//  * At the top, sums saturate at +-kSrgbeMax (no Inf, no NaN), sign kept.
//  * NaN and +-Inf input are clamped (NaN to 0, Inf to +-kSrgbeMax), never propagated.
//  * Accumulation: P re-encodings of the running sums S_k leave an error of at most
//    sum_k max|S_k| / 127.5 per channel (each encode's bound, §4.3); over intensities spanning
//    10^-30 ... 10^30 the sum of 63 positions stays within it.
TEST(HardCases, SrgbeAtItsEdges) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Every exponent byte with every byte in R (G and B fixed at two patterns): finite, bounded,
  // and a fixed point of decode -> encode -> decode.
  int words = 0;
  for (uint32_t e = 0; e < 256; ++e)
    for (uint32_t byte = 0; byte < 256; ++byte)
      for (uint32_t gb : {0x0000u, 0xff7fu}) {
        const uint32_t w = byte | gb << 8 | e << 24;
        const auto v = DecodeSrgbe(w);
        for (float x : v) {
          ASSERT_TRUE(std::isfinite(x)) << std::hex << w;
          ASSERT_LE(std::abs(x), kSrgbeMax) << std::hex << w;
        }
        const auto again = DecodeSrgbe(EncodeSrgbe(v[0], v[1], v[2]));
        for (int c = 0; c < 3; ++c) ASSERT_EQ(again[c], v[c]) << std::hex << w << " channel " << c;
        ++words;
      }
  EXPECT_EQ(words, 256 * 256 * 2);
  // Near 0: every power of two from 2^-150 to 2^-120 (through the float denormals), alone and
  // next to a channel 2^5 times larger.
  for (int k = -150; k <= -120; ++k) {
    const float x = std::ldexp(1.0f, k);
    for (const auto& in : {std::array<float, 3>{x, -x, 0}, std::array<float, 3>{x, x * 32, -x}}) {
      const auto out = DecodeSrgbe(EncodeSrgbe(in[0], in[1], in[2]));
      const float bound = SrgbeErrorBound(in[0], in[1], in[2]);
      EXPECT_LE(bound, std::max(std::ldexp(1.0f, -136), 32 * x / 127.5f));
      for (int c = 0; c < 3; ++c) {
        EXPECT_LE(std::abs(out[c] - in[c]), bound) << "2^" << k << " channel " << c;
        if (out[c] != 0) {
          EXPECT_EQ(std::signbit(out[c]), std::signbit(in[c])) << "2^" << k;
        }
      }
    }
    if (k < -136) {
      EXPECT_EQ(EncodeSrgbe(x, -x, x), 0u) << "2^" << k;  // exactly 0, not -0
    }
  }
  // The top: the largest value round-trips exactly; beyond it, and +-Inf, clamp with the sign.
  auto top = DecodeSrgbe(EncodeSrgbe(kSrgbeMax, -kSrgbeMax, 0));
  EXPECT_EQ(top[0], kSrgbeMax);
  EXPECT_EQ(top[1], -kSrgbeMax);
  for (float big : {std::nextafter(kSrgbeMax, inf), std::numeric_limits<float>::max(), inf}) {
    top = DecodeSrgbe(EncodeSrgbe(big, -big, nan));
    EXPECT_EQ(top[0], kSrgbeMax);
    EXPECT_EQ(top[1], -kSrgbeMax);
    EXPECT_EQ(top[2], 0.f);
  }
  // Accumulation over 63 positions, each decade of 10^-30 ... 10^30 in turn, in a shuffled
  // order with signs (signed E_ij): within the sum of the encodes' bounds; and saturation
  // without Inf when the sum passes kSrgbeMax.
  std::mt19937 rng(10);
  for (int trial = 0; trial < 200; ++trial) {
    uint32_t acc = 0;
    double exact[3] = {0, 0, 0}, bound[3] = {0, 0, 0};
    std::uniform_real_distribution<double> exponent(-30, 30), sign(-0.3, 1);
    for (int k = 0; k < 63; ++k) {
      const double scale = std::pow(10.0, exponent(rng));
      const auto prev = DecodeSrgbe(acc);
      float next[3];
      for (int c = 0; c < 3; ++c) {
        const double x = scale * sign(rng);
        exact[c] += x;
        next[c] = float(double(prev[c]) + x);
      }
      acc = EncodeSrgbe(next[0], next[1], next[2]);
      const double largest = std::max({std::abs(next[0]), std::abs(next[1]), std::abs(next[2])});
      for (int c = 0; c < 3; ++c)
        bound[c] += std::max(largest / 127.5, std::ldexp(1.0, -136)) + 1e-7 * largest;
    }
    const auto sum = DecodeSrgbe(acc);
    for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(sum[c] - exact[c]), bound[c]) << trial;
  }
  uint32_t acc = 0;
  for (int k = 0; k < 4; ++k) {
    const auto prev = DecodeSrgbe(acc);
    acc = EncodeSrgbe(prev[0] + kSrgbeMax / 2, prev[1] - kSrgbeMax / 2, prev[2]);
  }
  const auto saturated = DecodeSrgbe(acc);
  EXPECT_EQ(saturated[0], kSrgbeMax);
  EXPECT_EQ(saturated[1], -kSrgbeMax);
}

}  // namespace
}  // namespace lumislab
