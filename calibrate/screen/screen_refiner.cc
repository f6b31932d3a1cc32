#include "calibrate/screen/screen_refiner.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>

#include "calibrate/ceres_options.h"
#include "calibrate/screen/homography_distortion_cost.h"
#include "core/error.h"

namespace lumislab {

namespace {

// x_n = T x: translate by -centre, scale by 1/scale.
Eigen::Matrix3d Normaliser(const Eigen::Vector2d& centre, double scale) {
  Eigen::Matrix3d t = Eigen::Matrix3d::Identity();
  t(0, 0) = t(1, 1) = 1.0 / scale;
  t(0, 2) = -centre.x() / scale;
  t(1, 2) = -centre.y() / scale;
  return t;
}

}  // namespace

Eigen::Matrix2d HomographyJacobian(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  const Eigen::Vector3d q = h * p.homogeneous();
  const Eigen::Vector2d x = q.head<2>() / q.z();
  return (h.topLeftCorner<2, 2>() - x * h.block<1, 2>(2, 0)) / q.z();
}

void RefinerOptions::Check() const {
  if (!(huber_px > 0 && std::isfinite(huber_px)))
    throw BadInput("refiner options: huber_px: expected a scale > 0 in pixels, got " +
                   std::to_string(huber_px));
  if (distortion_terms < 0 || distortion_terms > 2)
    throw BadInput("refiner options: distortion_terms: expected 0, 1 or 2, got " +
                   std::to_string(distortion_terms));
  if (max_iterations < 1)
    throw BadInput("refiner options: max_iterations: expected >= 1, got " +
                   std::to_string(max_iterations));
  if (threads < 1)
    throw BadInput("refiner options: threads: expected >= 1, got " + std::to_string(threads));
}

RefinementResult RefineScreenMapping(const std::vector<Eigen::Vector2d>& pixels,
                                     const std::vector<Eigen::Vector2d>& screen_mm,
                                     const Eigen::Matrix3d& initial_screen_from_image,
                                     const Eigen::Vector2d& centre_px, double scale_px,
                                     const RefinerOptions& options) {
  options.Check();
  LUMISLAB_CHECK(pixels.size() == screen_mm.size() && pixels.size() >= 6,
                 "RefineScreenMapping needs >= 6 matching points");
  // Screen normalisation: centroid and RMS radius of the board points.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& x : screen_mm) mean += x;
  mean /= double(screen_mm.size());
  double spread = 0;
  for (const auto& x : screen_mm) spread += (x - mean).squaredNorm();
  spread = std::sqrt(spread / double(screen_mm.size()));
  LUMISLAB_CHECK(spread > 0, "board points coincide");
  const Eigen::Matrix3d t_screen = Normaliser(mean, spread);
  const Eigen::Matrix3d t_image = Normaliser(centre_px, scale_px);

  Eigen::Matrix3d h_n = t_screen * initial_screen_from_image * t_image.inverse();
  if (!(std::abs(h_n(2, 2)) > 1e-9 * h_n.norm()))
    throw Failure("the image centre maps to infinity on the screen (degenerate view)");
  h_n /= h_n(2, 2);
  double h[8];
  for (int k = 0; k < 8; ++k) h[k] = h_n(k / 3, k % 3);
  double dist[2] = {0, 0};

  const Eigen::Matrix3d screen_n_from_image = t_screen * initial_screen_from_image;
  ceres::Problem problem;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Matrix2d jac = HomographyJacobian(screen_n_from_image, pixels[i]);
    const double det = jac.determinant();
    if (!std::isfinite(det) || std::abs(det) < 1e-18 * jac.squaredNorm() || det == 0)
      throw Failure("singular image -> screen mapping at a board corner (degenerate view)");
    const Eigen::Vector2d x_n = (t_screen * screen_mm[i].homogeneous()).head<2>();
    problem.AddResidualBlock(
        HomographyDistortionCost::Create(pixels[i], centre_px, scale_px, x_n, jac.inverse()),
        new ceres::HuberLoss(options.huber_px), h, dist);
  }
  if (options.distortion_terms == 0) {
    problem.SetParameterBlockConstant(dist);
  } else if (options.distortion_terms == 1) {
    problem.SetManifold(dist, new ceres::SubsetManifold(2, {1}));
  }

  const ceres::Solver::Options solver =
      RefinerSolverOptions(ceres::DENSE_QR, options.max_iterations, options.threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  RefinementResult result;
  for (int k = 0; k < 8; ++k) h_n(k / 3, k % 3) = h[k];
  h_n(2, 2) = 1;
  Eigen::Matrix3d hs = t_screen.inverse() * h_n * t_image;
  if (std::abs(hs(2, 2)) > 1e-12 * hs.norm()) hs /= hs(2, 2);
  result.screen_from_image = hs;
  result.k1 = dist[0];
  result.k2 = dist[1];
  result.iterations = int(summary.iterations.size());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.message = summary.BriefReport();
  if (!summary.IsSolutionUsable())
    throw Failure("screen refinement failed: " + summary.BriefReport());
  return result;
}

}  // namespace lumislab
