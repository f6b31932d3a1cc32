// Ceres refinement of the image -> screen mapping: 8 homography parameters plus the radial
// distortion terms k1, k2 of core/screen_calibration.h, with a robust (Huber) loss in pixels.
// One of the two translation units of lumislab_calibrate that include Ceres (camera_refiner.cc
// is the other; both take their solver settings from ceres_options.h).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace lumislab {

// Solver settings in one place (loss type and scale, model size, iterations).
struct RefinerOptions {
  double huber_px = 1.0;     // scale of the Huber loss, pixels of reprojection error
  int distortion_terms = 2;  // 0: pure homography, 1: k1, 2: k1 and k2
  int max_iterations = 200;
  int threads = 1;
  void Check() const;  // BadInput naming the bad field
};

struct RefinementResult {
  Eigen::Matrix3d screen_from_image = Eigen::Matrix3d::Identity();  // undistorted px -> mm
  double k1 = 0;
  double k2 = 0;
  int iterations = 0;
  bool converged = false;
  double initial_cost = 0;  // Ceres cost (0.5 sum of robustified squared px residuals)
  double final_cost = 0;
  std::string message;  // Ceres' one-line summary
};

// d dehomogenise(H [p, 1]) / dp: the local linear map of a homography at p.
Eigen::Matrix2d HomographyJacobian(const Eigen::Matrix3d& h, const Eigen::Vector2d& p);

// pixels[i] (OpenCV pixel centres) shows screen_mm[i] (lab mm). `initial_screen_from_image`
// maps distorted pixels to mm (e.g. cv::findHomography); centre_px/scale_px fix the distortion
// model. Throws Failure when the problem is degenerate (singular local mapping).
RefinementResult RefineScreenMapping(const std::vector<Eigen::Vector2d>& pixels,
                                     const std::vector<Eigen::Vector2d>& screen_mm,
                                     const Eigen::Matrix3d& initial_screen_from_image,
                                     const Eigen::Vector2d& centre_px, double scale_px,
                                     const RefinerOptions& options);

}  // namespace lumislab
