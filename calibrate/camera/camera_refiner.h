// Ceres refinement of a camera calibration from many board views: the intrinsics (fx, fy, cx,
// cy), OpenCV's five distortion coefficients (k1, k2, p1, p2, k3) and every view's pose together,
// under a robust (Huber) loss in pixels, then the parameters' covariance. Starts from
// cv::calibrateCamera's answer (camera_calibrator.cc).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace lumislab {

// Solver settings in one place (loss type and scale, iterations).
struct CameraRefinerOptions {
  double huber_px = 1.0;  // scale of the Huber loss, pixels of reprojection error
  int max_iterations = 200;
  int threads = 1;
  void Check() const;  // BadInput naming the bad field
};

using Vector5d = Eigen::Matrix<double, 5, 1>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct CameraViewData {
  std::vector<Eigen::Vector2d> pixels;    // detected corners, OpenCV pixel centres
  std::vector<Eigen::Vector3d> board_mm;  // the same corners on the board (z = 0)
  Vector6d pose = Vector6d::Zero();       // camera_from_board: angle-axis (rad), translation mm
};

struct CameraRefinement {
  Eigen::Vector4d intrinsics = Eigen::Vector4d::Zero();  // fx, fy, cx, cy (px)
  Vector5d distortion = Vector5d::Zero();                // k1, k2, p1, p2, k3
  std::vector<Vector6d> poses;                           // one per view
  std::vector<double> view_rms_px;                       // one per view
  double rms_px = 0;                                     // over all corners
  // One standard deviation of fx, fy, cx, cy, k1, k2, p1, p2, k3: the covariance (J^T J)^-1 at
  // the solution scaled by the residual variance (sum r^2 / (residuals - parameters)), as
  // OpenCV's stdDeviationsIntrinsics. Empty when the covariance is rank deficient.
  std::vector<double> sigma;
  bool converged = false;
  std::string message;  // Ceres' one-line summary
};

// Reprojection residuals (px) of `view` under the given camera: detected minus projected.
std::vector<Eigen::Vector2d> CameraResiduals(const CameraViewData& view,
                                             const Eigen::Vector4d& intrinsics,
                                             const Vector5d& distortion, const Vector6d& pose);

// `views` carry their starting poses. Throws Failure when Ceres finds no usable solution.
CameraRefinement RefineCamera(const std::vector<CameraViewData>& views,
                              const Eigen::Vector4d& intrinsics, const Vector5d& distortion,
                              const CameraRefinerOptions& options);

// One view's pose with the camera known (calibrate screen with calib/camera.json): the same
// cost (camera_projection_cost.h), Huber loss and solver settings, the camera held constant.
struct PoseRefinement {
  Vector6d pose = Vector6d::Zero();  // camera_from_board: angle-axis (rad), translation mm
  double rms_px = 0;                 // over the view's corners
  bool converged = false;
  std::string message;  // Ceres' one-line summary
};

// `view` carries the starting pose (e.g. cv::solvePnP's). Throws Failure when Ceres finds no
// usable solution.
PoseRefinement RefinePose(const CameraViewData& view, const Eigen::Vector4d& intrinsics,
                          const Vector5d& distortion, const CameraRefinerOptions& options);

}  // namespace lumislab
