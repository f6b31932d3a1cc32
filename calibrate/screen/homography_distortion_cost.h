// Ceres cost of one board corner for the screen calibration model of core/screen_calibration.h:
//   p_u = centre + (p - centre)(1 + k1 r^2 + k2 r^4),  r = |p - centre| / scale_px,
//   screen = dehomogenise(H [p_u, 1]).
// Everything is in normalised coordinates so that the 8 homography parameters are O(1):
//   image:  p_n = (p_u - centre) / scale_px,  screen: X_n = (X_mm - screen_centre) / screen_scale.
// The residual is the screen-space error mapped back to pixels with a fixed 2x2 weight
// (the inverse local Jacobian dX_n/dp of the initial estimate), so it reads in pixels and the
// robust loss scale is in pixels for frontal and oblique views alike.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>

namespace lumislab {

class HomographyDistortionCost {
 public:
  // pixel: detected corner (OpenCV pixel centres); screen_n: its normalised board position;
  // px_from_screen_n: the weight (pixels per normalised screen unit, 2x2).
  HomographyDistortionCost(const Eigen::Vector2d& pixel, const Eigen::Vector2d& centre_px,
                           double scale_px, const Eigen::Vector2d& screen_n,
                           const Eigen::Matrix2d& px_from_screen_n)
      : pixel_(pixel),
        centre_px_(centre_px),
        scale_px_(scale_px),
        screen_n_(screen_n),
        weight_(px_from_screen_n) {}

  // h: the 8 parameters of H (row-major, h22 = 1); k: (k1, k2).
  template <typename T>
  bool operator()(const T* const h, const T* const k, T* residual) const {
    const double dx = (pixel_.x() - centre_px_.x()) / scale_px_;
    const double dy = (pixel_.y() - centre_px_.y()) / scale_px_;
    const double r2 = dx * dx + dy * dy;
    const T factor = T(1.0) + k[0] * r2 + k[1] * (r2 * r2);
    const T x = factor * dx;  // p_n
    const T y = factor * dy;
    const T w = h[6] * x + h[7] * y + T(1.0);
    const T sx = (h[0] * x + h[1] * y + h[2]) / w - screen_n_.x();
    const T sy = (h[3] * x + h[4] * y + h[5]) / w - screen_n_.y();
    residual[0] = weight_(0, 0) * sx + weight_(0, 1) * sy;
    residual[1] = weight_(1, 0) * sx + weight_(1, 1) * sy;
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& pixel, const Eigen::Vector2d& centre_px,
                                     double scale_px, const Eigen::Vector2d& screen_n,
                                     const Eigen::Matrix2d& px_from_screen_n) {
    return new ceres::AutoDiffCostFunction<HomographyDistortionCost, 2, 8, 2>(
        new HomographyDistortionCost(pixel, centre_px, scale_px, screen_n, px_from_screen_n));
  }

 private:
  Eigen::Vector2d pixel_;
  Eigen::Vector2d centre_px_;
  double scale_px_;
  Eigen::Vector2d screen_n_;
  Eigen::Matrix2d weight_;
};

}  // namespace lumislab
