// lumislab-calibrate screen, run in-process through RunMain: exit codes, messages naming the
// file, calib/screen.json written atomically and skipped unless --force.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "board_renderer.h"
#include "calibrate/cli.h"
#include "calibrate/screen/screen_calibrator.h"
#include "core/error.h"
#include "core/exr_io.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::CentredTarget;
using testing::MaxBoardErrorMm;
using testing::RenderBoard;
using testing::TrueCalibration;

struct Result {
  int exit_code;
  std::string output;  // stderr
};

Result RunTool(std::vector<std::string> args) {
  args.insert(args.begin(), "lumislab-calibrate");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  ::testing::internal::CaptureStderr();
  const int code =
      RunMain("calibrate", [&] { return RunCalibrate(int(argv.size()), argv.data()); });
  return {code, ::testing::internal::GetCapturedStderr()};
}

class CalibrateCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("lumislab_calibrate_" + std::to_string(::getpid()) + "_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ + "/photos");
    truth_ = TrueCalibration(800, 600, 700, {30, -20, -520}, {0, 0, 0}, -0.05);
  }
  // dataset.json with a 1 x 1 grid and the board; `photo` relative to the dataset folder.
  void WriteDataset(const std::string& photo = "photos/calib_0.png") {
    Dataset ds;
    ds.distance_mm = 750;
    ds.grid = {1, 1, 5};
    ds.screen_w_mm = 600;
    ds.screen_h_mm = 450;
    ds.filter.spacing_mm = 5;
    ds.filter.dual_coefficients = {1.0};
    ds.filter.peak = 1;
    ds.calibration = target_;
    ds.calibration.photo = photo;
    ds.photos = {{0, 0, true, "photos/pos_0_0_p.png", 1.0},
                 {0, 0, false, "photos/pos_0_0_n.png", 1.0}};
    ds.Save(dir_);
  }
  // The board as a dark 16-bit linear PNG (as the synthetic acquisition writes them).
  void WritePhoto16(const ScreenCalibration& truth) {
    cv::Mat photo = RenderBoard(target_, truth), out;
    photo.convertTo(out, CV_16U, 0.3 * 65535);
    ASSERT_TRUE(cv::imwrite(dir_ + "/photos/calib_0.png", out));
  }
  Result Calibrate(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"screen", "--dataset", dir_, "--threads", "2"};
    args.insert(args.end(), extra.begin(), extra.end());
    return RunTool(args);
  }
  void ExpectBadInput(const Result& r, const std::string& mention) {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(mention), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir_ + "/calib/screen.json"));
  }
  std::string dir_;
  CalibrationTarget target_ = CentredTarget(12, 9, 30);
  ScreenCalibration truth_;
};

TEST_F(CalibrateCli, WritesScreenJsonThenSkipsUnlessForced) {
  WriteDataset();
  WritePhoto16(truth_);
  Result r = Calibrate();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("parameters: dataset="), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("rms: "), std::string::npos) << r.output;
  const ScreenCalibration c = ScreenCalibration::Load(dir_ + "/calib/screen.json");
  EXPECT_EQ(c.photo, "photos/calib_0.png");
  EXPECT_EQ(c.corners_used, 11 * 8);
  EXPECT_LT(c.rms_px, 0.1);
  EXPECT_LT(MaxBoardErrorMm(c, truth_, target_), 0.2);
  EXPECT_NEAR(c.k1, truth_.k1, 0.01);
  for (const auto& e : fs::directory_iterator(dir_ + "/calib"))
    EXPECT_NE(e.path().filename().string()[0], '.') << "temporary file left: " << e.path();

  // A second run skips: even a broken photo does not matter without --force.
  std::ofstream(dir_ + "/photos/calib_0.png", std::ios::trunc) << "garbage";
  r = Calibrate();
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("skipping"), std::string::npos) << r.output;
  r = Calibrate({"--force"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("calib_0.png"), std::string::npos) << r.output;
  // The old calibration is still there, untouched.
  EXPECT_NO_THROW(ScreenCalibration::Load(dir_ + "/calib/screen.json"));
}

TEST_F(CalibrateCli, FloatExrPhoto) {
  WriteDataset("photos/calib_0.exr");
  const cv::Mat gray = RenderBoard(target_, truth_);
  ImageF rgb(gray.cols, gray.rows, 3);
  for (int y = 0; y < gray.rows; ++y)
    for (int x = 0; x < gray.cols; ++x)
      for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = 1e-3f * gray.at<float>(y, x);  // W/m^2-ish
  WriteExr(dir_ + "/photos/calib_0.exr", rgb, {"R", "G", "B"});
  const Result r = Calibrate();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ScreenCalibration c = ScreenCalibration::Load(dir_ + "/calib/screen.json");
  EXPECT_LT(MaxBoardErrorMm(c, truth_, target_), 0.2);
}

TEST_F(CalibrateCli, MissingPhoto) {
  WriteDataset();
  ExpectBadInput(Calibrate(), "calib_0.png");
}

TEST_F(CalibrateCli, CorruptPng) {
  WriteDataset();
  std::ofstream(dir_ + "/photos/calib_0.png", std::ios::binary)
      << "\x89PNG\r\n\x1a\n garbage, not a real PNG stream";
  ExpectBadInput(Calibrate(), "calib_0.png");
}

TEST_F(CalibrateCli, BlankPhoto) {
  WriteDataset();
  ASSERT_TRUE(
      cv::imwrite(dir_ + "/photos/calib_0.png", cv::Mat(600, 800, CV_8UC1, cv::Scalar(90))));
  ExpectBadInput(Calibrate(), "calib_0.png");
}

TEST_F(CalibrateCli, DegenerateView) {
  WriteDataset();
  WritePhoto16(TrueCalibration(800, 600, 700, {0, 0, 3000}, {0, 0, 0}));  // a sliver
  ExpectBadInput(Calibrate(), "calib_0.png");
}

TEST_F(CalibrateCli, MissingOrInvalidDatasetJson) {
  ExpectBadInput(Calibrate(), dir_ + "/dataset.json");
  target_.squares_y = 12;  // square board: ambiguous orientation
  WriteDataset();
  ExpectBadInput(Calibrate(), "calibration.target.squares");
}

TEST_F(CalibrateCli, HelpAndBadUsage) {
  EXPECT_EQ(RunTool({"--help"}).exit_code, 0);
  EXPECT_EQ(RunTool({"screen", "--help"}).exit_code, 0);
  EXPECT_EQ(RunTool({}).exit_code, 2);          // no subcommand
  EXPECT_EQ(RunTool({"screen"}).exit_code, 2);  // no --dataset
  const Result r = Calibrate({"--distortion-terms", "3"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--distortion-terms"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace lumislab
