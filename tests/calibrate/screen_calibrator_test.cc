// CalibrateScreenPhoto on rendered boards with a known camera: every pixel of the board maps
// within 0.2 mm of the truth (frontal, oblique, mirrored, distorted, noisy), and bad views are
// refused with BadInput naming the photo.
#include "calibrate/screen/screen_calibrator.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cstdio>

#include "board_renderer.h"
#include "core/error.h"

namespace lumislab {
namespace {

using testing::BoardInView;
using testing::CentredTarget;
using testing::MaxBoardErrorMm;
using testing::RenderBoard;
using testing::TrueCalibration;

constexpr int kWidth = 800, kHeight = 600;
constexpr double kFocal = 700;
constexpr double kToleranceMm = 0.2;  // the brief: every board pixel within 0.2 mm

const CalibrationTarget& Board() {
  static const CalibrationTarget t = CentredTarget(12, 9, 30);  // 360 x 270 mm
  return t;
}

struct Outcome {
  ScreenCalibration result;
  ScreenCalibrationReport report;
  double max_error_mm = 0;
};

Outcome Calibrate(const ScreenCalibration& truth, double noise = 0,
                  const ScreenCalibratorOptions& options = {}) {
  EXPECT_TRUE(BoardInView(Board(), truth)) << "test camera does not see the whole board";
  Outcome o;
  const cv::Mat photo = RenderBoard(Board(), truth, noise);
  o.result = CalibrateScreenPhoto(photo, Board(), "rendered.png", options, &o.report);
  o.max_error_mm = MaxBoardErrorMm(o.result, truth, Board());
  std::printf(
      "%s grid, %d corners, rms %.4f px (OpenCV alone %.4f px), %.4f mm, k1 %.5f (true "
      "%.5f), k2 %.5f (true %.5f), max board error %.4f mm\n",
      o.report.corners.orientation.c_str(), o.result.corners_used, o.result.rms_px,
      o.report.initial_rms_px, o.result.rms_mm, o.result.k1, truth.k1, o.result.k2, truth.k2,
      o.max_error_mm);
  return o;
}

TEST(ScreenCalibrator, Frontal) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {20, -30, 500}, {0, 0, 0});
  const Outcome o = Calibrate(truth);
  EXPECT_EQ(o.result.corners_used, 11 * 8);
  EXPECT_LT(o.max_error_mm, kToleranceMm);
  EXPECT_LT(o.max_error_mm, 0.03);  // what the saddle-point corners give on a clean photo
  EXPECT_LT(o.result.rms_px, 0.02);
  EXPECT_NEAR(o.result.k1, 0, 0.002);
  EXPECT_EQ(o.report.distortion_terms, 0);  // none needed, none fitted
  EXPECT_EQ(o.result.photo, "rendered.png");
  EXPECT_EQ(o.result.image_width, kWidth);
}

// About 50 degrees off the normal, from the side and below.
TEST(ScreenCalibrator, Oblique50Degrees) {
  const double a = 50 * 3.14159265358979 / 180;
  const Eigen::Vector3d camera(640 * std::sin(a), -60, 640 * std::cos(a));
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, camera, {0, 0, 0});
  const Outcome o = Calibrate(truth);
  EXPECT_LT(o.max_error_mm, kToleranceMm);
  EXPECT_LT(o.result.rms_px, 0.05);
  EXPECT_GT(o.report.anisotropy, 1.3);  // the view really is oblique
}

// From behind the screen (z < 0) the photo is the mirror image of the frontal one.
TEST(ScreenCalibrator, MirroredViewFromBehind) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {-15, 25, -500}, {0, 0, 0});
  const Outcome o = Calibrate(truth);
  EXPECT_LT(o.max_error_mm, kToleranceMm);
  // The same handedness as the truth (a mirrored solution would flip the sign).
  const double truth_det = truth.screen_from_image.topLeftCorner<2, 2>().determinant();
  const double det = o.result.screen_from_image.topLeftCorner<2, 2>().determinant();
  EXPECT_GT(truth_det * det, 0);
}

// The same view with the photo turned by 180 degrees: OpenCV's grid comes out the other way
// round, the dot still names square (0, 0).
TEST(ScreenCalibrator, PhotoTurnedHalfWay) {
  auto truth = TrueCalibration(kWidth, kHeight, kFocal, {20, -30, 500}, {0, 0, 0});
  const Outcome upright = Calibrate(truth);
  Eigen::Matrix3d turn;
  turn << -1, 0, kWidth - 1, 0, -1, kHeight - 1, 0, 0, 1;
  truth.screen_from_image = truth.screen_from_image * turn;
  const Outcome turned = Calibrate(truth);
  EXPECT_LT(turned.max_error_mm, kToleranceMm);
  EXPECT_LT(std::abs(upright.result.rms_px - turned.result.rms_px), 0.05);
}

TEST(ScreenCalibrator, RecoversRadialDistortion) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {10, 10, 460}, {0, 0, 0}, -0.08);
  const Outcome o = Calibrate(truth);
  EXPECT_LT(o.max_error_mm, kToleranceMm);
  EXPECT_NEAR(o.result.k1, truth.k1, 0.002);
  EXPECT_LT(o.result.rms_px, 0.02);
  EXPECT_EQ(o.report.distortion_terms, 1);
  EXPECT_GT(o.report.initial_rms_px, 3 * o.result.rms_px);  // the homography alone misses it
}

// A board that fills the frame (corners beyond 0.7 half-diagonals) also pins down k2.
TEST(ScreenCalibrator, FullFrameBoardRecoversK2) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {5, -5, 405}, {0, 0, 0}, -0.06, 0.03);
  const Outcome o = Calibrate(truth);
  EXPECT_EQ(o.report.distortion_terms, 2);
  EXPECT_LT(o.max_error_mm, kToleranceMm);
  EXPECT_NEAR(o.result.k1, truth.k1, 0.003);
  EXPECT_NEAR(o.result.k2, truth.k2, 0.005);
}

TEST(ScreenCalibrator, NoisyObliquePhoto) {
  const double a = 45 * 3.14159265358979 / 180;
  const Eigen::Vector3d camera(0, -560 * std::sin(a), 560 * std::cos(a));
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, camera, {0, 0, 0}, 0.05);
  const Outcome o = Calibrate(truth, 0.03);
  EXPECT_LT(o.max_error_mm, kToleranceMm);
  EXPECT_NEAR(o.result.k1, truth.k1, 0.02);
}

// Corners found on a downscaled copy (as for large photos), refined at full resolution.
TEST(ScreenCalibrator, DetectionOnADownscaledCopy) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {20, -30, 500}, {0, 0, 0}, -0.03);
  ScreenCalibratorOptions options;
  options.detection.max_detection_px = 400;
  const Outcome o = Calibrate(truth, 0, options);
  EXPECT_LT(o.max_error_mm, kToleranceMm);
  EXPECT_EQ(o.report.corners.saddle_refined, o.result.corners_used);
}

// Small squares (~16 px): the saddle fit shrinks its blur and window with them.
TEST(ScreenCalibrator, SmallSquares) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {-40, 30, 1300}, {0, 0, 0});
  const Outcome o = Calibrate(truth);
  EXPECT_LT(o.report.corners.square_px, 17);
  EXPECT_LT(o.max_error_mm, kToleranceMm);  // at 1.9 mm per pixel
  EXPECT_LT(o.result.rms_px, 0.1);
  // The board reaches only ~0.25 half-diagonals: distortion is left out, not extrapolated.
  EXPECT_LT(o.report.board_radius, 0.5);
  EXPECT_LT(o.report.distortion_terms, 2);
  EXPECT_LT(std::abs(o.result.k1) + std::abs(o.result.k2), 0.02);
}

template <typename F>
void ExpectBadInput(F&& f, const std::vector<std::string>& mentions) {
  try {
    f();
    ADD_FAILURE() << "expected BadInput";
  } catch (const Error& e) {
    std::printf("refused: %s\n", e.what());
    EXPECT_EQ(e.code(), ExitCode::kBadInput) << e.what();
    for (const auto& m : mentions)
      EXPECT_NE(std::string(e.what()).find(m), std::string::npos) << e.what();
  }
}

TEST(ScreenCalibratorErrors, BlankPhoto) {
  const cv::Mat blank(kHeight, kWidth, CV_32FC1, cv::Scalar(0.4));
  ExpectBadInput([&] { CalibrateScreenPhoto(blank, Board(), "blank.png", {}); },
                 {"blank.png", "blank"});
  cv::Mat noise(kHeight, kWidth, CV_32FC1);
  cv::RNG(3).fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  ExpectBadInput([&] { CalibrateScreenPhoto(noise, Board(), "noise.png", {}); },
                 {"noise.png", "no checkerboard"});
}

TEST(ScreenCalibratorErrors, WrongBoardSize) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {0, 0, 500}, {0, 0, 0});
  const cv::Mat photo = RenderBoard(Board(), truth);
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, CentredTarget(10, 9, 30), "p.png", {}); },
                 {"p.png", "9x8 inner corners"});
}

TEST(ScreenCalibratorErrors, MissingDot) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {0, 0, 500}, {0, 0, 0});
  const cv::Mat photo = RenderBoard(Board(), truth, 0, /*dot=*/false);
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, Board(), "nodot.png", {}); },
                 {"nodot.png", "dot"});
}

TEST(ScreenCalibratorErrors, BoardCoversASliver) {
  // Far away: the board is ~100 px wide in an 800 x 600 photo.
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {0, 0, 2600}, {0, 0, 0});
  const cv::Mat photo = RenderBoard(Board(), truth);
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, Board(), "far.png", {}); }, {"far.png"});
}

TEST(ScreenCalibratorErrors, GrazingView) {
  const double a = 80 * 3.14159265358979 / 180;
  const Eigen::Vector3d camera(420 * std::sin(a), 0, 420 * std::cos(a));
  const auto truth = TrueCalibration(kWidth, kHeight, 1400, camera, {0, 0, 0});
  const cv::Mat photo = RenderBoard(Board(), truth);
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, Board(), "grazing.png", {}); }, {"grazing.png"});
}

// The view checks themselves, with limits tightened so that a good view trips them.
TEST(ScreenCalibratorErrors, StretchAndRmsLimits) {
  const double a = 50 * 3.14159265358979 / 180;
  const Eigen::Vector3d camera(640 * std::sin(a), -60, 640 * std::cos(a));
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, camera, {0, 0, 0});
  const cv::Mat photo = RenderBoard(Board(), truth);
  ScreenCalibratorOptions options;
  options.max_anisotropy = 1.2;  // the 50 degree view stretches ~1.5
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, Board(), "oblique.png", options); },
                 {"oblique.png", "grazing"});
  options = {};
  options.max_rms_px = 0.005;
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, Board(), "oblique.png", options); },
                 {"oblique.png", "reprojection RMS"});
  options = {};
  options.refiner.huber_px = -1;
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, Board(), "oblique.png", options); },
                 {"huber_px"});
}

TEST(ScreenCalibratorErrors, SquareBoardIsAmbiguous) {
  const auto truth = TrueCalibration(kWidth, kHeight, kFocal, {0, 0, 500}, {0, 0, 0});
  const CalibrationTarget square = CentredTarget(9, 9, 30);
  const cv::Mat photo = RenderBoard(square, truth);
  ExpectBadInput([&] { CalibrateScreenPhoto(photo, square, "sq.png", {}); },
                 {"calibration.target.squares", "9 x 9"});
}

}  // namespace
}  // namespace lumislab
