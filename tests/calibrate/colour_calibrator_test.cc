// lumislab-calibrate colour on synthetic ColorChecker photos (lib/synthetic/spectral.h): the
// chart found by cv::mcc, the fit's residual, the CCT of blackbody light through the fitted
// matrix against the truth, and the refusals (no chart, clipped patches, not a chart's colours).
#include "calibrate/colour/colour_calibrator.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"
#include "lib/lightfield/light_colour.h"
#include "lib/photo/photo_write.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/spectral.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

std::filesystem::path TempDir() {
  const auto dir = std::filesystem::temp_directory_path() / "lumislab_colour_calibrator_test";
  std::filesystem::create_directories(dir);
  return dir;
}

Photo WriteAndDecode(const ImageF& image, const std::string& name, PhotoEncoding encoding) {
  const std::string path = (TempDir() / name).string();
  WritePhoto(path, image, encoding);
  return DecodePhoto(path);
}

ColourCalibration Calibrate(const Photo& photo, const ColourOptions& options, CheckLog* checks) {
  const ChartPatches patches = FindColourChart(photo, ChartReferenceXyz(options.illuminant),
                                               ReferenceWhite(options.illuminant));
  nlohmann::json report;
  return CalibrateColour(patches, options, photo.path, &report, checks);
}

TEST(ColourCalibrator, FindsTheChartAndFitsIt) {
  for (const std::string illuminant : {"D65", "D50"}) {
    ColourChartPhotoSpec spec;
    spec.illuminant = illuminant;
    const Photo photo =
        WriteAndDecode(RenderColourChartPhoto(spec), "chart.exr", PhotoEncoding::kFloatExr);
    ColourOptions options;
    options.illuminant = illuminant;
    CheckLog checks("", "test");
    const ColourCalibration c = Calibrate(photo, options, &checks);
    // The synthetic sensitivities are not a combination of the CIE functions: a realistic
    // residual, neither 0 nor a misfit.
    EXPECT_GT(c.mean_delta_e, 0.2) << illuminant;
    EXPECT_LT(c.mean_delta_e, 4) << illuminant;
    EXPECT_LT(c.max_delta_e, 12) << illuminant;
    ASSERT_EQ(checks.records().size(), 1u);
    EXPECT_EQ(checks.records()[0].check, "colour.fit");
    RecordProperty("mean_delta_e_" + illuminant, std::to_string(c.mean_delta_e));
    std::printf("%s: Delta E*ab mean %.3f max %.3f\n", illuminant.c_str(), c.mean_delta_e,
                c.max_delta_e);
  }
}

TEST(ColourCalibrator, CctOfBlackbodyLightThroughTheFitIsTheTruth) {
  const Photo photo =
      WriteAndDecode(RenderColourChartPhoto({}), "chart_cct.exr", PhotoEncoding::kFloatExr);
  CheckLog checks("", "test");
  const ColourCalibration c = Calibrate(photo, {}, &checks);
  for (double kelvin : {2700.0, 4000.0, 6500.0}) {
    // What the synthetic camera records of a blackbody-like emitter (any scale).
    const LightColour colour = ColourOfRgb(c, 3.7 * BlackbodyRgbPerWatt(kelvin));
    EXPECT_NEAR(colour.cct.kelvin, kelvin, 50) << kelvin;  // issue 29's tolerance
    EXPECT_LT(std::abs(colour.cct.duv), 0.005) << kelvin;
    std::printf("%.0f K: recovered %.1f K, Duv %.5f\n", kelvin, colour.cct.kelvin, colour.cct.duv);
  }
}

TEST(ColourCalibrator, CctOfASyntheticLuminaireFromItsSlab) {
  // A scene luminaire with a spectrum (emitter field cct_k): its truth slab's total light and far
  // field through the matrix fitted to the synthetic chart photo give its temperature.
  const Photo photo =
      WriteAndDecode(RenderColourChartPhoto({}), "chart_slab.exr", PhotoEncoding::kFloatExr);
  CheckLog checks("", "test");
  const ColourCalibration c = Calibrate(photo, {}, &checks);
  const SlabInfo info = DefaultSlabInfo(5, 5, 5, 24);
  for (double kelvin : {2700.0, 4000.0, 6500.0}) {
    const std::string file = (TempDir() / "luminaire.json").string();
    WriteTextAtomically(file, R"({"schema_version": 1, "luminaire": {"emitters": [
        {"position_mm": [0.5, -1, -15], "intensity_w_sr": 1.3, "cct_k": )" +
                                  std::to_string(kelvin) + R"(, "lobe_exponent": 4}]}})");
    const Luminaire luminaire = LoadLuminaire(file);
    ASSERT_EQ(luminaire.emitters[0].cct_k, kelvin);
    std::vector<SlabPosition> positions;
    for (int j = 0; j < info.grid.nv; ++j)
      for (int i = 0; i < info.grid.nu; ++i)
        positions.push_back(TruthPosition(luminaire, info, i, j));
    const LightColour total = TotalLightColour(info, positions, c);
    EXPECT_NEAR(total.cct.kelvin, kelvin, 50) << kelvin;
    const FarFieldColour far =
        ComputeFarFieldColour(info, positions, {0, 90, 180, 270}, {0, 10, 20}, c);
    int seen = 0;
    for (size_t k = 0; k < far.colour.size(); ++k) {
      // A direction whose far field is negative (the dual filter's lobes at a small grid's
      // edge) has no chromaticity: NaN, by design.
      if (!far.seen[k] || !(far.colour[k].xyz.y() > 0)) continue;
      ++seen;
      EXPECT_NEAR(far.colour[k].cct.kelvin, kelvin, 50)
          << kelvin << " direction " << k << " xyz " << far.colour[k].xyz.transpose();
    }
    EXPECT_GE(seen, 8);
    std::printf("%.0f K luminaire: total light %.1f K, xy (%.4f, %.4f); %d directions seen\n",
                kelvin, total.cct.kelvin, total.xy.x(), total.xy.y(), seen);
  }
}

TEST(ColourCalibrator, LuminousEfficacyOfTheScene) {
  SynthScene scene = DefaultScene();  // RGB emitters, no spectrum: the documented default
  EXPECT_NEAR(scene.LuminousEfficacy(), DefaultLuminousEfficacy(), 1e-12);
  EXPECT_NEAR(DefaultLuminousEfficacy(), 683 * Cmf1931().col(1).mean(), 1e-9);
  for (Emitter& e : scene.luminaire.emitters) {
    e.cct_k = 2856;  // CIE illuminant A's temperature
    e.radiant_w_sr = 1;
  }
  // Planck at 2856 K over 380 - 780 nm: ~ 683 x 0.2 = 137 lm/W (of the visible radiant power).
  EXPECT_NEAR(scene.LuminousEfficacy(), LuminousEfficacy(Blackbody(2856)), 1e-9);
  std::printf("luminous efficacy: default %.2f lm/W, 2856 K %.2f lm/W\n", DefaultLuminousEfficacy(),
              scene.LuminousEfficacy());
}

TEST(ColourCalibrator, RefusesAPhotoWithoutAChart) {
  ImageF grey(800, 600, 3, 0.3f);
  const Photo photo = WriteAndDecode(grey, "grey.exr", PhotoEncoding::kFloatExr);
  CheckLog checks("", "test");
  try {
    Calibrate(photo, {}, &checks);
    FAIL() << "a grey photo gave a chart";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("no ColorChecker"), std::string::npos) << e.what();
  }
}

TEST(ColourCalibrator, RefusesClippedPatches) {
  ColourChartPhotoSpec spec;
  spec.exposure = 2.5;  // the light patches above full scale of a 16-bit camera
  const Photo photo =
      WriteAndDecode(RenderColourChartPhoto(spec), "clipped.png", PhotoEncoding::kLinear16Png);
  CheckLog checks("", "test");
  try {
    Calibrate(photo, {}, &checks);
    FAIL() << "clipped patches were accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("clipped"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("white"), std::string::npos) << e.what();
  }
}

TEST(ColourCalibrator, RefusesAFitThatIsNotAChart) {
  // Patches whose colours are not the chart's: refused on the residual.
  std::vector<Eigen::Vector3d> rgb, reference = ChartReferenceXyz("D65");
  for (int k = 0; k < 24; ++k) rgb.push_back(reference[(k * 7) % 24]);
  ChartPatches patches;
  patches.rgb = rgb;
  patches.clipped_fraction.assign(24, 0.0);
  patches.centre_px.assign(24, Eigen::Vector2d::Zero());
  CheckLog checks("", "test");
  nlohmann::json report;
  try {
    CalibrateColour(patches, {}, "shuffled", &report, &checks);
    FAIL() << "a shuffled chart was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("Delta E"), std::string::npos) << e.what();
  }
  EXPECT_EQ(checks.records().back().outcome, CheckOutcome::kFailed);
}

}  // namespace
}  // namespace lumislab
