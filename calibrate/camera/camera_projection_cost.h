// Ceres cost of one board corner for the camera model of core/camera_calibration.h (OpenCV's
// five-coefficient model): the board point is moved into the camera frame by the view's pose,
// projected, distorted and compared with the detected corner. The residual is in pixels, so the
// robust loss scale reads in pixels.
#pragma once

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

namespace lumislab {

class CameraProjectionCost {
 public:
  // pixel: detected corner (OpenCV pixel centres); board_mm: the corner on the board (z = 0).
  CameraProjectionCost(const Eigen::Vector2d& pixel, const Eigen::Vector3d& board_mm)
      : pixel_(pixel), board_mm_(board_mm) {}

  // intrinsics: fx, fy, cx, cy (px); distortion: k1, k2, p1, p2, k3 (OpenCV's order);
  // pose: camera_from_board as angle-axis (rad) then translation (mm).
  template <typename T>
  bool operator()(const T* const intrinsics, const T* const distortion, const T* const pose,
                  T* residual) const {
    const T board[3] = {T(board_mm_.x()), T(board_mm_.y()), T(board_mm_.z())};
    T camera[3];
    ceres::AngleAxisRotatePoint(pose, board, camera);
    camera[0] += pose[3];
    camera[1] += pose[4];
    camera[2] += pose[5];
    const T x = camera[0] / camera[2];
    const T y = camera[1] / camera[2];
    const T& k1 = distortion[0];
    const T& k2 = distortion[1];
    const T& p1 = distortion[2];
    const T& p2 = distortion[3];
    const T& k3 = distortion[4];
    const T r2 = x * x + y * y;
    const T radial = T(1.0) + r2 * (k1 + r2 * (k2 + r2 * k3));
    const T xd = x * radial + T(2.0) * p1 * x * y + p2 * (r2 + T(2.0) * x * x);
    const T yd = y * radial + p1 * (r2 + T(2.0) * y * y) + T(2.0) * p2 * x * y;
    residual[0] = intrinsics[0] * xd + intrinsics[2] - pixel_.x();
    residual[1] = intrinsics[1] * yd + intrinsics[3] - pixel_.y();
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& pixel,
                                     const Eigen::Vector3d& board_mm) {
    return new ceres::AutoDiffCostFunction<CameraProjectionCost, 2, 4, 5, 6>(
        new CameraProjectionCost(pixel, board_mm));
  }

 private:
  Eigen::Vector2d pixel_;
  Eigen::Vector3d board_mm_;
};

}  // namespace lumislab
