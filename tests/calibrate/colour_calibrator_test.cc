// lumislab-calibrate colour on synthetic ColorChecker photos (lib/synthetic/spectral.h): the
// chart found by cv::mcc, the fit's residual, the CCT of blackbody light through the fitted
// matrix against the truth, and the refusals (no chart, clipped patches, not a chart's colours).
#include "calibrate/colour/colour_calibrator.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.h"
#include "lib/photo/photo_write.h"
#include "lib/synthetic/spectral.h"

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
