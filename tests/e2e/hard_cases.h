// The hard cases' chain and checks (tests/e2e/hard_cases_*_test.cc). Hard cases that must stay
// numerically stable (issue 10, docs/testing.md §2 "Hard cases"):
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
// The bounds (docs/method.md §3.6). The fit matches texel box averages b with the bell stencil
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
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "test_util.h"

namespace lumislab::hard_cases {

using testing::CommandResult;

// One texel's sampling chain error, in units of the bell term (see above): 1.6, rounded up.
inline constexpr double kSamplingFactor = 2.0;
// B^-1 spreads a boundary error over neighbours: at most 1.25x per axis.
inline constexpr double kEdgeSpread = 1.25 * 1.25;
// The CG tolerance's share of the flux (1e-6 x sqrt(texels), texels <= 64^2).
inline constexpr double kFitFluxTolerance = 1e-4;
// The CG stops at ||r|| <= 1e-6 ||B^T b||; with the smallest eigenvalue of B^T B + lambda D^T D
// >= 0.19 (docs/method.md §3.6) and ||B|| <= 1, ||c - c_exact|| <= 1e-6 / 0.19 ||b||: a floor
// of 5.3e-6 of the position's own ||E|| on every part of it.
inline constexpr double kSolverFloor = 1e-6 / 0.19;
// Half-float photos: each slide value rounded by at most 2^-12 relative. With one emitter a
// screen point is lit through one slide only (T+ or T-), so the rounding moves E = peak x
// scale x (v+ - v-) by at most 2^-12 |E|; a texel's b by at most 2^-12 of its |E|, and the
// deconvolution's inverse has absolute row sum 1 / (5/6 - 2/12)^2 = 2.25 in 2D.
inline const double kHalfRounding = std::ldexp(1.0, -12);
inline constexpr double kDeconvolutionGain = 2.25;

struct Geometry {
  double d = 750, h = 5;
  int nu = 3, nv = 3;
  double screen_w = 1200, screen_h = 1200;
  int k_max = 1;
};

// A camera 400 x 300 px seeing the default screen from behind and below (e2e's frontal camera
// at a quarter of its pixels): about 5 mm of screen per pixel.
inline const char* kSmallCamera =
    R"({"size_px": [400, 300], "focal_px": 325, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";

std::string Emitter(double x, double y, double z, double i0, double lobe);
// The default luminaire (docs/formats.md §10).
std::string DefaultEmitters();

std::string Scene(const Geometry& s, const std::string& emitters, const std::string& camera,
                  const std::string& effects = "[]");

struct CaseRun {
  std::string ds;
  CommandResult acquire, calibrate, reconstruct;
};

// acquire synth -> calibrate screen -> reconstruct at `resolution` (the truth at the same).
CaseRun RunCase(const std::string& name, const std::string& scene_json, int resolution,
                const std::string& reconstruct_args = "", const std::string& acquire_args = "");

// Datasets are kept only when a test failed, for inspection.
void CleanUp(const CaseRun& r);

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

// The mask (docs/method.md §3.5 step 3, cameras that see the whole screen): a texel is seen when
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

std::vector<PositionCheck> CheckSlab(const std::string& ds, const CheckOptions& o = {});

// The common assertions; `l2_floor` adds to the derived L2 bound (noise), `flux_floor` (W) to
// the flux bound. Prints one line per position and returns the worst ratios (error / bound).
void ExpectStable(const std::string& label, const std::vector<PositionCheck>& checks,
                  double l2_floor = 0, double flux_floor = 0);

bool Says(const CommandResult& r, const std::string& text);

// Light resolved by the slab and photos exposed within range: nothing to warn about (the
// warnings of the cases below must not fire where the method works).
void ExpectNoWarning(const CaseRun& r);

// A case the method handles: the chain succeeds, no tool warns, and the slab is stable
// (ExpectStable over CheckSlab with `options`); the datasets are removed unless it failed.
void ExpectCleanStableCase(const std::string& name, const std::string& label,
                           const std::string& scene_json, int resolution,
                           const CheckOptions& options = {});

}  // namespace lumislab::hard_cases
