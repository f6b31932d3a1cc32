// HomographyDistortionCost: zero at the truth, and its residual reads in pixels.
#include "calibrate/screen/homography_distortion_cost.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>

namespace lumislab {
namespace {

// A mildly perspective homography in normalised coordinates and a distortion.
struct Truth {
  double h[8] = {0.9, 0.1, 0.05, -0.08, 1.1, -0.02, 0.03, -0.04};
  double k[2] = {-0.12, 0.03};
  Eigen::Vector2d centre{399.5, 299.5};
  double scale = 500;

  Eigen::Vector2d ScreenN(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = (p - centre) / scale;
    const double r2 = d.squaredNorm();
    const Eigen::Vector2d x = d * (1 + k[0] * r2 + k[1] * r2 * r2);
    const double w = h[6] * x.x() + h[7] * x.y() + 1;
    return {(h[0] * x.x() + h[1] * x.y() + h[2]) / w, (h[3] * x.x() + h[4] * x.y() + h[5]) / w};
  }
  // d ScreenN / dp by central differences.
  Eigen::Matrix2d Jacobian(const Eigen::Vector2d& p) const {
    Eigen::Matrix2d j;
    for (int c = 0; c < 2; ++c) {
      Eigen::Vector2d e = Eigen::Vector2d::Zero();
      e(c) = 1e-3;
      j.col(c) = (ScreenN(p + e) - ScreenN(p - e)) / 2e-3;
    }
    return j;
  }
};

Eigen::Vector2d Evaluate(const ceres::CostFunction& cost, const double* h, const double* k) {
  const double* params[2] = {h, k};
  double residual[2];
  EXPECT_TRUE(cost.Evaluate(params, residual, nullptr));
  return {residual[0], residual[1]};
}

TEST(HomographyDistortionCost, ZeroAtTheTruth) {
  const Truth t;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(10, 20), Eigen::Vector2d(399.5, 299.5),
                                   Eigen::Vector2d(790, 590), Eigen::Vector2d(123.4, 456.7)}) {
    std::unique_ptr<ceres::CostFunction> cost(HomographyDistortionCost::Create(
        p, t.centre, t.scale, t.ScreenN(p), t.Jacobian(p).inverse()));
    EXPECT_LT(Evaluate(*cost, t.h, t.k).norm(), 1e-12);
  }
}

// With the weight = inverse local Jacobian, a corner detected `delta` pixels off gives a
// residual of about -delta pixels (first order), whatever the view.
TEST(HomographyDistortionCost, ResidualIsThePixelError) {
  const Truth t;
  const Eigen::Vector2d p(650, 120);
  const Eigen::Vector2d delta(0.3, -0.2);
  std::unique_ptr<ceres::CostFunction> cost(HomographyDistortionCost::Create(
      p + delta, t.centre, t.scale, t.ScreenN(p), t.Jacobian(p).inverse()));
  const Eigen::Vector2d r = Evaluate(*cost, t.h, t.k);
  EXPECT_NEAR(r.x(), delta.x(), 2e-3);
  EXPECT_NEAR(r.y(), delta.y(), 2e-3);
}

TEST(HomographyDistortionCost, SensitiveToEveryParameter) {
  const Truth t;
  const Eigen::Vector2d p(700, 80);  // far from the centre, so k1 and k2 matter
  std::unique_ptr<ceres::CostFunction> cost(HomographyDistortionCost::Create(
      p, t.centre, t.scale, t.ScreenN(p), t.Jacobian(p).inverse()));
  const double* params[2] = {t.h, t.k};
  double residual[2], jh[2 * 8], jk[2 * 2];
  double* jacobians[2] = {jh, jk};
  ASSERT_TRUE(cost->Evaluate(params, residual, jacobians));
  for (int c = 0; c < 8; ++c) EXPECT_GT(std::hypot(jh[c], jh[8 + c]), 1e-3) << "h" << c;
  for (int c = 0; c < 2; ++c) EXPECT_GT(std::hypot(jk[c], jk[2 + c]), 1e-3) << "k" << c + 1;
}

}  // namespace
}  // namespace lumislab
