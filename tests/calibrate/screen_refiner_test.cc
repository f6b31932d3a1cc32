// RefineScreenMapping on exact correspondences from a known mapping: recovers it from a rough
// start, and the Huber loss keeps one wrong corner from spoiling the fit.
#include "calibrate/screen/screen_refiner.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <random>

#include "board_renderer.h"
#include "core/screen_calibration.h"

namespace lumislab {
namespace {

struct Problem {
  ScreenCalibration truth;
  std::vector<Eigen::Vector2d> pixels, screen_mm;
};

// 13 x 12 corners every 40 mm seen by an oblique camera with barrel distortion.
Problem MakeProblem(double noise_px) {
  Problem p;
  p.truth = testing::TrueCalibration(1600, 1200, 1200, {500, -300, 900}, {0, 0, 0}, -0.1, 0.02);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, noise_px);
  for (int b = -6; b <= 5; ++b)
    for (int a = -6; a <= 6; ++a) {
      const Eigen::Vector2d s(40.0 * a, 40.0 * b);
      p.screen_mm.push_back(s);
      p.pixels.push_back(p.truth.ImageFromScreen(s) + Eigen::Vector2d(noise(rng), noise(rng)));
    }
  return p;
}

ScreenCalibration WithResult(const ScreenCalibration& truth, const RefinementResult& r) {
  ScreenCalibration c = truth;
  c.screen_from_image = r.screen_from_image;
  c.k1 = r.k1;
  c.k2 = r.k2;
  return c;
}

double MaxErrorMm(const Problem& p, const ScreenCalibration& c) {
  double worst = 0;
  for (const auto& s : p.screen_mm)
    worst = std::max(worst, (c.ScreenFromImage(p.truth.ImageFromScreen(s)) - s).norm());
  return worst;
}

// The homography alone (k = 0) fitted by DLT would be the usual start; a perturbed truth is a
// start of the same quality and keeps the test independent of OpenCV.
Eigen::Matrix3d RoughStart(const ScreenCalibration& truth) {
  Eigen::Matrix3d perturb = Eigen::Matrix3d::Identity();
  perturb(0, 0) = 1.02;
  perturb(0, 2) = 15;
  perturb(1, 2) = -10;
  perturb(2, 0) = 1e-5;
  return truth.screen_from_image * perturb;
}

TEST(ScreenRefiner, RecoversExactMapping) {
  const Problem p = MakeProblem(0);
  const RefinementResult r = RefineScreenMapping(p.pixels, p.screen_mm, RoughStart(p.truth),
                                                 p.truth.centre_px, p.truth.scale_px, {});
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r.k1, -0.1, 1e-6);
  EXPECT_NEAR(r.k2, 0.02, 1e-6);
  EXPECT_LT(MaxErrorMm(p, WithResult(p.truth, r)), 1e-6);
}

TEST(ScreenRefiner, HuberLossIgnoresOneWrongCorner) {
  Problem p = MakeProblem(0.05);
  p.pixels[40] += Eigen::Vector2d(6, -4);  // a corner detected on the wrong feature
  RefinerOptions robust;
  robust.huber_px = 0.5;
  RefinerOptions plain = robust;
  plain.huber_px = 1e6;  // effectively least squares
  const Eigen::Matrix3d start = RoughStart(p.truth);
  const double robust_error = MaxErrorMm(
      p, WithResult(p.truth, RefineScreenMapping(p.pixels, p.screen_mm, start, p.truth.centre_px,
                                                 p.truth.scale_px, robust)));
  const double plain_error = MaxErrorMm(
      p, WithResult(p.truth, RefineScreenMapping(p.pixels, p.screen_mm, start, p.truth.centre_px,
                                                 p.truth.scale_px, plain)));
  std::printf("max error with one 7 px outlier: Huber %.4f mm, least squares %.4f mm\n",
              robust_error, plain_error);
  EXPECT_LT(robust_error, 0.5 * plain_error);
  EXPECT_LT(robust_error, 0.1);
}

TEST(ScreenRefiner, DistortionTermsCanBeFixed) {
  const Problem p = MakeProblem(0);
  RefinerOptions options;
  options.distortion_terms = 1;
  const RefinementResult one = RefineScreenMapping(p.pixels, p.screen_mm, RoughStart(p.truth),
                                                   p.truth.centre_px, p.truth.scale_px, options);
  EXPECT_EQ(one.k2, 0);
  EXPECT_NE(one.k1, 0);
  options.distortion_terms = 0;
  const RefinementResult none = RefineScreenMapping(p.pixels, p.screen_mm, RoughStart(p.truth),
                                                    p.truth.centre_px, p.truth.scale_px, options);
  EXPECT_EQ(none.k1, 0);
  EXPECT_EQ(none.k2, 0);
}

}  // namespace
}  // namespace lumislab
