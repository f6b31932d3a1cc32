// The issue's TM-25 evidence: a TM-25 ray file as the synthetic source (a Lambertian disc 10 mm
// across, 3 mm behind S) -> lumislab-acquire synth -> calibrate screen -> reconstruct ->
// lumislab-export tm25: the irradiance the exported rays put on planes at d and 4d against the
// input rays', binned alike, within what the planner's accuracy model (lumislab-plan,
// docs/method.md §4.8) predicts for the capture's geometry plus the two ray sets' Monte-Carlo error
// on the bins.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>

#include "../e2e/test_util.h"
#include "../lib/synthetic/ray_samples.h"
#include "core/atomic_file.h"
#include "core/slab.h"
#include "lib/lightfield/far_field.h"
#include "lib/photometry/tm25.h"
#include "lib/synthetic/scene.h"
#include "plan/plan.h"

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::ShellQuote;

// Flux per bin of the rays on the plane z = D over [-w/2, w/2] x [-h/2, h/2] (n x n bins), and the
// sum of the squared ray flux per bin (for the Monte-Carlo variance of each bin).
struct Bins {
  std::vector<double> flux, flux2;
};
Bins BinOnPlane(const Tm25RaySet& set, double plane_mm, double w, double h, int n) {
  Bins b{std::vector<double>(size_t(n) * n, 0.0), std::vector<double>(size_t(n) * n, 0.0)};
  for (const Tm25Ray& r : set.rays) {
    if (!(r.kz > 0) || r.z > plane_mm) continue;
    const double t = (plane_mm - r.z) / r.kz;
    const double x = r.x + r.kx * t, y = r.y + r.ky * t;
    const int i = int(std::floor((x + 0.5 * w) / w * n)),
              j = int(std::floor((y + 0.5 * h) / h * n));
    if (i < 0 || j < 0 || i >= n || j >= n) continue;
    b.flux[size_t(j) * n + i] += r.flux;
    b.flux2[size_t(j) * n + i] += double(r.flux) * r.flux;
  }
  return b;
}

struct Comparison {
  double rel_l2 = 0, flux_ratio = 0, mc = 0;
};
// Relative L2 of the output's bins against the input's, their flux ratio, and the Monte-Carlo
// error of the difference: each bin's variance is the sum of its rays' squared flux (Poisson),
// both sets taken as independent (conservative: the slab was fit to the input's rays).
Comparison Compare(const Bins& out, const Bins& in) {
  double num = 0, den = 0, var = 0, fo = 0, fi = 0;
  for (size_t k = 0; k < in.flux.size(); ++k) {
    num += std::pow(out.flux[k] - in.flux[k], 2);
    den += in.flux[k] * in.flux[k];
    var += out.flux2[k] + in.flux2[k];
    fo += out.flux[k];
    fi += in.flux[k];
  }
  return {std::sqrt(num / den), fo / fi, std::sqrt(var / den)};
}

TEST(Tm25Source, RoundTripsThroughACapture) {
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run: the Release build's";
  const std::string dir = FreshDir("export_tm25_source");
  // The disc: radius 5 mm, 3 mm behind S, radiance 1e4 W/m^2/sr (2.47 W), 500 000 rays.
  Tm25RaySet input;
  ray_samples::AddLambertianDisc(0, 0, -3, 5, 1e4, 500000, 11, &input);
  WriteTm25(input, dir + "/disc.ray");
  // h = 8 mm on 5 x 5 positions covers the rays from the disc to the screen and to the plane at
  // 4d (lumislab-plan's coverage, checked below).
  testing::WriteFile(dir + "/scene.json", R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 5, "nv": 5, "spacing_mm": 8},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [ {"position_mm": [0, 0, 0], "rays": {"file": "disc.ray"}} ] },
  "camera": {"size_px": [400, 300], "focal_px": 325, "position_mm": [0, -400, 2400],
             "look_at_mm": [0, 0, 750], "radiometric_scale_w_m2": 1.6} })");
  const std::string ds = ShellQuote(dir + "/ds");
  // Bad input first: a missing ray file is exit 2 naming the scene's field and the file, and
  // nothing is written.
  std::string missing = ReadTextFile(dir + "/scene.json");
  missing.replace(missing.find("disc.ray"), 8, "none.ray");
  testing::WriteFile(dir + "/missing.json", missing);
  auto r = RunTool("lumislab-acquire",
                   "synth --scene " + ShellQuote(dir + "/missing.json") + " --out " + ds);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("missing.json: luminaire.emitters[0].rays.file: " + dir + "/none.ray"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/ds"));
  const auto start = std::chrono::steady_clock::now();
  r = RunTool("lumislab-acquire", "synth --scene " + ShellQuote(dir + "/scene.json") + " --out " +
                                      ds + " --truth-resolution 16");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/ds/truth/emitter_0.ray"));
  r = RunTool("lumislab-calibrate", "screen --dataset " + ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-reconstruct", "--dataset " + ds + " --resolution 64");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double chain_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Three exports of the slab (seeds 0, 1, 2), each checked below.
  const int n_out = 1000000;
  std::vector<Tm25RaySet> outputs;
  for (int seed = 0; seed < 3; ++seed) {
    const std::string out = dir + "/out" + std::to_string(seed) + ".ray";
    r = RunTool("lumislab-export", "tm25 --slab " + ds + " --out " + ShellQuote(out) + " --rays " +
                                       std::to_string(n_out) + " --seed " + std::to_string(seed) +
                                       " --allow-partial");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    if (seed == 0) {  // what making the light field non-negative moved (the export's log)
      const size_t at = r.output.find("rays of");
      if (at != std::string::npos)
        std::printf("export: %s\n", r.output.substr(at, r.output.find('\n', at) - at).c_str());
    }
    outputs.push_back(ReadTm25(out));
    ASSERT_EQ(outputs.back().rays.size(), size_t(n_out));
  }

  // The slab's own irradiance at d, sum_ij E_ij (exact at D = d, no rays drawn), on bins of 4 x 4
  // texels against the input rays': what the capture and the reconstruction got right.
  const SlabInfo info = SlabInfo::Load(dir + "/ds/slab");
  const int texels_per_bin = 4, nb = info.layout.res_x / texels_per_bin;
  Bins slab_bins{std::vector<double>(size_t(nb) * nb, 0.0), std::vector<double>(size_t(nb) * nb)};
  const double texel_m2 = info.layout.TexelW() * info.layout.TexelH() * 1e-6;
  for (const SlabPosition& p : ReadSlabPositions(dir + "/ds/slab", info, 2))
    for (int row = 0; row < info.layout.res_y; ++row)
      for (int col = 0; col < info.layout.res_x; ++col) {
        if (!(p.mask.at(col, row, 0) > 0)) continue;
        const Eigen::Vector3d e(p.irradiance.at(col, row, 0), p.irradiance.at(col, row, 1),
                                p.irradiance.at(col, row, 2));
        // Rows run from +t down; the bins from -y up.
        const size_t bin = size_t(nb - 1 - row / texels_per_bin) * nb + col / texels_per_bin;
        slab_bins.flux[bin] += Rec709Weights().dot(e) * texel_m2;
      }

  // The planner's prediction for this capture (the disc's box and depth from the scene's rays).
  const SynthScene scene = LoadScene(dir + "/scene.json");
  PlanInput plan_in = PlanInputFromScene(scene);
  PlanSetting setting;
  setting.h_mm = 8;
  setting.nu = setting.nv = 5;
  setting.resolution = 64;
  std::printf("TM-25 source round trip: capture, calibration, reconstruction %.1f s\n", chain_s);
  for (const double factor : {1.0, 4.0}) {
    plan_in.receiver_mm = factor * scene.distance_mm;
    const Plan plan = EvaluatePlan(plan_in, setting);
    EXPECT_TRUE(plan.covers);
    // The region: the window at d, what the screen holds at 4d (the plan's roi_max).
    const double w = factor == 1 ? scene.screen_w_mm : plan.roi_max.u_mm;
    const double h = factor == 1 ? scene.screen_h_mm : plan.roi_max.v_mm;
    if (factor == 1) {
      const Comparison c = Compare(slab_bins, BinOnPlane(input, plan_in.receiver_mm, w, h, nb));
      const double bound = std::sqrt(std::pow(plan.at_D.total, 2) + std::pow(c.mc, 2));
      std::printf(
          "  plane at %.0f mm, the slab's sum_ij E_ij (%d x %d bins): relative L2 %.4f, flux "
          "%.5f; predicted: plan %.4f, input rays' Monte-Carlo %.4f, together %.4f\n",
          plan_in.receiver_mm, nb, nb, c.rel_l2, c.flux_ratio, plan.at_D.total, c.mc, bound);
      EXPECT_LT(c.rel_l2, bound);
      EXPECT_NEAR(c.flux_ratio, 1, bound);
    }
    const Bins in = BinOnPlane(input, plan_in.receiver_mm, w, h, 12);
    for (size_t seed = 0; seed < outputs.size(); ++seed) {
      const Bins out = BinOnPlane(outputs[seed], plan_in.receiver_mm, w, h, 12);
      const Comparison c = Compare(out, in);
      const double bound = std::sqrt(std::pow(plan.at_D.total, 2) + std::pow(c.mc, 2));
      std::printf(
          "  plane at %.0f mm (%.0f x %.0f mm, 12 x 12 bins), seed %zu: relative L2 %.4f, flux "
          "out / in %.5f; predicted: plan %.4f, rays' Monte-Carlo %.4f, together %.4f (%.2f x)\n",
          plan_in.receiver_mm, w, h, seed, c.rel_l2, c.flux_ratio, plan.at_D.total, c.mc, bound,
          c.rel_l2 / bound);
      // Within the prediction itself: the exported rays carry the slab's light field, its
      // negative part cancelled within each texel keeping the texel's flux and centroid
      // (SampleSlabRays, docs/formats.md §17). Measured 0.5 - 0.6 x at d and 4d (when the rays
      // kept only the positive part, 1.12 x and 1.03 x: a +-4 % centre-to-edge pattern).
      EXPECT_LT(c.rel_l2, bound);
      EXPECT_NEAR(c.flux_ratio, 1, bound);
    }
  }
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
