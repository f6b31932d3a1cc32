#include "calibrate/camera/camera_refiner.h"

#include <ceres/ceres.h>

#include <cmath>

#include "calibrate/camera/camera_projection_cost.h"
#include "calibrate/ceres_options.h"
#include "core/error.h"

namespace lumislab {

void CameraRefinerOptions::Check() const {
  if (!(huber_px > 0 && std::isfinite(huber_px)))
    throw BadInput("camera refiner options: huber_px: expected a scale > 0 in pixels, got " +
                   std::to_string(huber_px));
  if (max_iterations < 1)
    throw BadInput("camera refiner options: max_iterations: expected >= 1, got " +
                   std::to_string(max_iterations));
  if (threads < 1)
    throw BadInput("camera refiner options: threads: expected >= 1, got " +
                   std::to_string(threads));
}

std::vector<Eigen::Vector2d> CameraResiduals(const CameraViewData& view,
                                             const Eigen::Vector4d& intrinsics,
                                             const Vector5d& distortion, const Vector6d& pose) {
  std::vector<Eigen::Vector2d> out;
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    const CameraProjectionCost cost(view.pixels[i], view.board_mm[i]);
    Eigen::Vector2d r;
    cost(intrinsics.data(), distortion.data(), pose.data(), r.data());
    out.push_back(-r);
  }
  return out;
}

namespace {

// Standard deviations of the 9 camera parameters, or empty (see CameraRefinement::sigma).
std::vector<double> CameraSigma(ceres::Problem& problem, double* intrinsics, double* distortion,
                                double residual_variance, int threads) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.num_threads = threads;
  ceres::Covariance covariance(options);
  const std::vector<std::pair<const double*, const double*>> blocks = {{intrinsics, intrinsics},
                                                                       {distortion, distortion}};
  if (!covariance.Compute(blocks, &problem)) return {};
  double ci[16], cd[25];
  covariance.GetCovarianceBlock(intrinsics, intrinsics, ci);
  covariance.GetCovarianceBlock(distortion, distortion, cd);
  std::vector<double> sigma;
  for (int k = 0; k < 4; ++k)
    sigma.push_back(std::sqrt(std::max(0.0, ci[k * 5]) * residual_variance));
  for (int k = 0; k < 5; ++k)
    sigma.push_back(std::sqrt(std::max(0.0, cd[k * 6]) * residual_variance));
  for (double s : sigma)
    if (!std::isfinite(s)) return {};
  return sigma;
}

}  // namespace

CameraRefinement RefineCamera(const std::vector<CameraViewData>& views,
                              const Eigen::Vector4d& intrinsics, const Vector5d& distortion,
                              const CameraRefinerOptions& options) {
  options.Check();
  LUMISLAB_CHECK(!views.empty(), "RefineCamera needs at least one view");
  CameraRefinement result;
  result.intrinsics = intrinsics;
  result.distortion = distortion;
  for (const auto& v : views) result.poses.push_back(v.pose);

  ceres::Problem problem;
  int residuals = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    LUMISLAB_CHECK(
        views[v].pixels.size() == views[v].board_mm.size() && views[v].pixels.size() >= 4,
        "RefineCamera: a view needs >= 4 matching corners");
    for (size_t i = 0; i < views[v].pixels.size(); ++i) {
      problem.AddResidualBlock(
          CameraProjectionCost::Create(views[v].pixels[i], views[v].board_mm[i]),
          new ceres::HuberLoss(options.huber_px), result.intrinsics.data(),
          result.distortion.data(), result.poses[v].data());
      residuals += 2;
    }
  }

  // DENSE_SCHUR: the poses are eliminated first.
  const ceres::Solver::Options solver =
      RefinerSolverOptions(ceres::DENSE_SCHUR, options.max_iterations, options.threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable())
    throw Failure("camera refinement failed: " + summary.BriefReport());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.message = summary.BriefReport();

  double sum = 0;
  int count = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    double view_sum = 0;
    for (const auto& r :
         CameraResiduals(views[v], result.intrinsics, result.distortion, result.poses[v]))
      view_sum += r.squaredNorm();
    result.view_rms_px.push_back(std::sqrt(view_sum / double(views[v].pixels.size())));
    sum += view_sum;
    count += int(views[v].pixels.size());
  }
  result.rms_px = std::sqrt(sum / count);
  const int parameters = 9 + 6 * int(views.size());
  if (residuals > parameters)
    result.sigma = CameraSigma(problem, result.intrinsics.data(), result.distortion.data(),
                               sum / double(residuals - parameters), options.threads);
  return result;
}

PoseRefinement RefinePose(const CameraViewData& view, const Eigen::Vector4d& intrinsics,
                          const Vector5d& distortion, const CameraRefinerOptions& options) {
  options.Check();
  LUMISLAB_CHECK(view.pixels.size() == view.board_mm.size() && view.pixels.size() >= 4,
                 "RefinePose: a view needs >= 4 matching corners");
  Eigen::Vector4d camera = intrinsics;
  Vector5d lens = distortion;
  PoseRefinement result;
  result.pose = view.pose;
  ceres::Problem problem;
  for (size_t i = 0; i < view.pixels.size(); ++i)
    problem.AddResidualBlock(CameraProjectionCost::Create(view.pixels[i], view.board_mm[i]),
                             new ceres::HuberLoss(options.huber_px), camera.data(), lens.data(),
                             result.pose.data());
  problem.SetParameterBlockConstant(camera.data());
  problem.SetParameterBlockConstant(lens.data());
  const ceres::Solver::Options solver =
      RefinerSolverOptions(ceres::DENSE_QR, options.max_iterations, options.threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable())
    throw Failure("pose refinement failed: " + summary.BriefReport());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.message = summary.BriefReport();
  double sum = 0;
  for (const auto& r : CameraResiduals(view, camera, lens, result.pose)) sum += r.squaredNorm();
  result.rms_px = std::sqrt(sum / double(view.pixels.size()));
  return result;
}

}  // namespace lumislab
