// Issue 29 item 2: the Rec. 709 mix of camera RGB is not luminance. A synthetic capture of a
// luminaire whose spectrum changes with direction (a broad 2700 K lobe and a narrow 6500 K one)
// with a ColorChecker photo and a lux meter: calibrate colour -> calibrate scale (the meter
// matched to the camera's luminance, the colour calibration's Y weights, recorded in
// calib/scale.json and slab.json) -> reconstruct -> export ies within the seen cone. The file's
// flux and peak are compared with the truth, 683 x the integral of V I_lambda of the emitters'
// blackbodies (Emitter::LuminousIntensity), and the same chain without calib/colour.json shows
// the Rec. 709 error and warns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "../e2e/test_util.h"
#include "core/geometry.h"
#include "core/json.h"
#include "core/slab.h"
#include "lib/photometry/colour.h"
#include "lib/photometry/ies.h"
#include "lib/synthetic/scene.h"

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::ShellQuote;

// The emitters 1 mm behind S near the grid's centre: the 5 x 5 grid's slab holds their light
// over the seen cone (a 3 x 3 grid, or emitters 20 mm behind S, lose light crossing S outside
// the bells' support).
const char kScene[] = R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 5, "nv": 5, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1, -1, -1], "intensity_w_sr": 1.0, "cct_k": 2700, "lobe_exponent": 1},
      {"position_mm": [-1, 1, -1], "intensity_w_sr": 1.0, "cct_k": 6500, "lobe_exponent": 12} ] },
  "camera": { "size_px": [640, 480], "focal_px": 600, "position_mm": [0, -300, 2400],
              "look_at_mm": [0, 0, 750] },
  "calibration_captures": {"colour_chart": "D65"} })";

// The seen cone (the 1.2 m screen at 750 mm sees gamma <= 37.5 degrees in every C plane).
const char kGrid[] = " --gamma-angles 0,5,10,15,20,25,30,35 --c-step 15";
const char kKeywords[] = " --test T-1 --lab Lab --manufacturer Maker --issue-date 2026-12-05";

struct Result {
  double flux = 0, peak = 0;  // lm, cd of the exported file
  std::string export_log;
};

// calibrate scale (from truth/reference.json) -> reconstruct -> export ies of the dataset `ds`.
Result ScaleReconstructExport(const std::string& ds, const std::string& out) {
  auto r = RunTool("lumislab-calibrate", "scale --dataset " + ShellQuote(ds) + " --reference " +
                                             ShellQuote(ds + "/truth/reference.json"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-reconstruct", "--dataset " + ShellQuote(ds) + " --resolution 32");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-export",
              "ies --slab " + ShellQuote(ds) + " --out " + ShellQuote(out) + kKeywords + kGrid);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  Result result;
  result.export_log = r.output;
  if (r.exit_code != 0) return result;
  const IntensityDistribution d = ReadIes(out);
  result.flux = d.TotalFlux();
  result.peak = *std::max_element(d.values.begin(), d.values.end());
  return result;
}

TEST(LuminanceWeights, ColourCalibratedLuxChainGivesTheTruthLumens) {
  const std::string dir = FreshDir("luminance_weights");
  testing::WriteFile(dir + "/scene.json", kScene);
  const std::string ds = dir + "/ds", ds709 = dir + "/ds709";
  auto r =
      RunTool("lumislab-acquire", "synth --scene " + ShellQuote(dir + "/scene.json") + " --out " +
                                      ShellQuote(ds) + " --truth-resolution 16 --meter lux");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-calibrate", "screen --dataset " + ShellQuote(ds));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::filesystem::copy(ds, ds709, std::filesystem::copy_options::recursive);
  r = RunTool("lumislab-calibrate", "colour --photo " +
                                        ShellQuote(ds + "/calibration/colour/chart.exr") +
                                        " --out " + ShellQuote(ds));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Result colour = ScaleReconstructExport(ds, dir + "/colour.ies");
  const Result rec709 = ScaleReconstructExport(ds709, dir + "/rec709.ies");

  // The truth on the file's grid: 683 x the integral of V I_lambda of each blackbody.
  const Luminaire luminaire = LoadLuminaire(ds);
  IntensityDistribution truth = ReadIes(dir + "/colour.ies");
  const size_t ng = truth.gamma_deg.size();
  for (size_t ic = 0; ic < truth.c_deg.size(); ++ic)
    for (size_t ig = 0; ig < ng; ++ig) {
      double cd = 0;
      for (const Emitter& e : luminaire.emitters)
        cd += e.LuminousIntensity(TypeCDirection(truth.c_deg[ic], truth.gamma_deg[ig]));
      truth.values[ic * ng + ig] = cd;
    }
  const double truth_flux = truth.TotalFlux();

  const double truth_peak = *std::max_element(truth.values.begin(), truth.values.end());
  std::printf(
      "truth %.4g lm, peak %.4g cd; colour calibration %.4g lm (%+.2f %%), peak %+.2f %%; "
      "Rec. 709 %.4g lm (%+.2f %%), peak %+.2f %%\n",
      truth_flux, truth_peak, colour.flux, 100 * (colour.flux / truth_flux - 1),
      100 * (colour.peak / truth_peak - 1), rec709.flux, 100 * (rec709.flux / truth_flux - 1),
      100 * (rec709.peak / truth_peak - 1));
  // Measured: colour calibration +0.09 % lm, peak -0.54 %; Rec. 709 -1.89 % lm, peak -0.55 %.
  // The peak is on the axis, where the meter's reading (the screen's centre) fixes both chains'
  // level; away from it the 2700 K lobe dominates, whose luminance the Rec. 709 mix of this
  // camera's RGB underrates against the mix at the meter. The peak's -0.5 % is the grid's
  // (h 5 mm on the narrow n = 12 lobe), the same in both chains.
  EXPECT_NEAR(colour.flux / truth_flux, 1, 0.005);
  EXPECT_NEAR(colour.peak / truth_peak, 1, 0.01);
  EXPECT_LT(rec709.flux / truth_flux, 0.99);
  EXPECT_NEAR(rec709.peak / colour.peak, 1, 0.002);

  // The weights travel: calib/scale.json and slab.json (version 2) record the colour
  // calibration's; without it Rec. 709's (version 1), and the export warns.
  const Eigen::Vector3d w = ColourCalibration::Load(ds + "/calib/colour.json").LuminanceWeights();
  const JsonDocument scale = JsonDocument::Load(ds + "/calib/scale.json");
  EXPECT_EQ(scale.root()["schema_version"].Int(), 2);
  EXPECT_EQ(scale.root()["channel_weights"]["from"].String(), "colour");
  EXPECT_NEAR(scale.root()["channel_weights"]["rgb"][1].Number(), w.y(), 1e-12);
  const SlabInfo info = SlabInfo::Load(ds + "/slab");
  EXPECT_TRUE(info.channel_weights_from_colour);
  EXPECT_LT((info.channel_weights - w).norm(), 1e-12);
  EXPECT_EQ(JsonDocument::Load(ds + "/slab/slab.json").root()["schema_version"].Int(), 2);
  const SlabInfo info709 = SlabInfo::Load(ds709 + "/slab");
  EXPECT_FALSE(info709.channel_weights_from_colour);
  EXPECT_EQ(info709.channel_weights, Rec709Weights());
  EXPECT_EQ(JsonDocument::Load(ds709 + "/slab/slab.json").root()["schema_version"].Int(), 1);
  EXPECT_EQ(colour.export_log.find("Rec. 709 mix"), std::string::npos) << colour.export_log;
  EXPECT_NE(rec709.export_log.find("the luminance is the Rec. 709 mix of the camera's RGB"),
            std::string::npos)
      << rec709.export_log;

  // A slab.json from before the member (none): Rec. 709's weights.
  nlohmann::json old = JsonDocument::Load(ds709 + "/slab/slab.json").raw();
  old.erase("channel_weights");
  std::filesystem::create_directories(dir + "/old");
  testing::WriteFile(dir + "/old/slab.json", old.dump());
  EXPECT_EQ(SlabInfo::Load(dir + "/old").channel_weights, Rec709Weights());
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
