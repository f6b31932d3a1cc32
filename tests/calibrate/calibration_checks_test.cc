// The calibration products' checks (calibrate/radiometric/calibration_checks.h) on small
// synthetic frames: each fires on what it is for and passes a legitimate input untouched. Not
// recorded (CheckLog without a dataset folder); the chain cases are
// tests/e2e/consistency_calibration_test.cc.
#include "calibrate/radiometric/calibration_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "lib/photo/photo_write.h"

namespace lumislab {
namespace {

namespace fs = std::filesystem;

// A 96 x 64 frame written as 16-bit linear PNG and decoded: value(x, y) at exposure `e`, the
// light a smooth ramp across the frame (0.02 .. 0.3 at exposure 1) plus `spot` in a disc.
CalibrationFrame Frame(const std::string& name, double e, double spot = 0, double base = -1) {
  const std::string dir = (fs::temp_directory_path() / "lumislab_calibration_checks_test").string();
  fs::create_directories(dir);
  ImageF img(96, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 96; ++x) {
      const double ramp = base >= 0 ? base : 0.02 + 0.28 * x / 95.0;
      const bool in_spot = std::hypot(x - 48, y - 32) < 14;
      for (int c = 0; c < 3; ++c)
        img.data[(size_t(y) * 96 + x) * 3 + c] =
            float(std::min(1.0, (ramp + (in_spot ? spot : 0)) * e));
    }
  const std::string path = dir + "/" + name + ".png";
  WritePhoto(path, img, PhotoEncoding::kLinear16Png);
  CalibrationFrame f;
  f.photo = DecodePhoto(path);
  f.exposure = e;
  f.exposure_known = true;
  return f;
}

TEST(CalibrationChecks, ExposureOrderPassesABracketedSeries) {
  CheckLog checks("", "calibrate response");
  CheckExposureOrder({Frame("a", 0.5), Frame("b", 1), Frame("c", 2)}, &checks);
  ASSERT_EQ(checks.records().size(), 1u);
  EXPECT_EQ(checks.records()[0].outcome, CheckOutcome::kPassed);
  EXPECT_EQ(checks.records()[0].values["worst_fraction"].get<double>(), 1.0);
}

TEST(CalibrationChecks, ExposureOrderRefusesSwappedExposures) {
  CheckLog checks("", "calibrate response");
  std::vector<CalibrationFrame> frames = {Frame("a", 0.5), Frame("b", 1), Frame("c", 2)};
  std::swap(frames[1].exposure, frames[2].exposure);  // c stated 1, b stated 2
  try {
    CheckExposureOrder(frames, &checks);
    FAIL() << "no failure";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    const std::string m = e.what();
    EXPECT_NE(m.find("b.png: exposure: stated 2"), std::string::npos) << m;
    EXPECT_NE(m.find("a.png, " + frames[1].photo.path + ", " + frames[2].photo.path),
              std::string::npos)
        << m;
  }
  EXPECT_EQ(checks.records().back().outcome, CheckOutcome::kFailed);
}

TEST(CalibrationChecks, DarkFramesMustBeDark) {
  {
    CheckLog checks("", "calibrate dark");
    CheckDarkFrames({Frame("dark", 1, 0, 0.003)}, &checks);
    EXPECT_EQ(checks.records().back().outcome, CheckOutcome::kPassed);
  }
  {
    CheckLog checks("", "calibrate dark");  // a lit spot: structure of light
    EXPECT_THROW(CheckDarkFrames({Frame("lit", 1, 0.3, 0.003)}, &checks), Error);
  }
  {
    CheckLog checks("", "calibrate dark");  // even, but at 60 % of full scale
    EXPECT_THROW(CheckDarkFrames({Frame("white", 1, 0, 0.6)}, &checks), Error);
  }
  {
    CheckLog checks("", "calibrate dark");  // 8 %: a lab could mean it (a long exposure)
    CheckDarkFrames({Frame("warm", 1, 0, 0.08)}, &checks);
    EXPECT_EQ(checks.records().back().outcome, CheckOutcome::kWarning);
  }
}

TEST(CalibrationChecks, FlatSignalAndSpread) {
  {
    CheckLog checks("", "calibrate flat");
    EXPECT_THROW(CheckFlatSignal("dark.png", 0.001, &checks), Error);
    CheckFlatSignal("flat.png", 0.4, &checks);
    EXPECT_EQ(checks.records().back().outcome, CheckOutcome::kPassed);
  }
  nlohmann::json report = {{"frames", {{{"file", "f.png"}}}},
                           {"structured_fraction", 0.0},
                           {"gain_percentiles_1_99", {0.7, 1.2}}};
  CheckLog checks("", "calibrate flat");
  CheckFlat(report, &checks);
  EXPECT_EQ(checks.records().back().outcome, CheckOutcome::kPassed);
  report["gain_percentiles_1_99"] = {0.1, 4.0};
  EXPECT_THROW(CheckFlat(report, &checks), Error);
}

}  // namespace
}  // namespace lumislab
