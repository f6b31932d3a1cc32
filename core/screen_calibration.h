// calib/screen.json: the mapping from photo pixels to the screen plane (lab frame, mm).
// Written by lumislab-calibrate screen, read by lumislab-reconstruct. Pixel coordinates follow
// OpenCV: (0,0) is the centre of the top-left pixel, x right, y down.
//
// Model: a pixel p is first undistorted, then mapped by the homography:
// screen = dehomogenise(H * [p_u, 1]). Two distortion models (distortion.model):
//  * "radial2" (fitted from the one board photo): two radial terms around `centre_px`,
//      r = |p - centre| / scale_px,  p_u = centre + (p - centre) * (1 + k1 r^2 + k2 r^4);
//  * "opencv5" (the camera calibrated from many views, calib/camera.json): p_u is the ideal
//    pinhole pixel (fx x + cx, fy y + cy) of the undistorted ray (x, y) of p under the camera's
//    five-coefficient model (CameraModel), and H = (K [r1 r2 t])^-1 holds the screen's pose.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "core/camera_calibration.h"

namespace lumislab {

constexpr int kScreenCalibrationSchemaVersion = 1;

struct ScreenCalibration {
  int image_width = 0;
  int image_height = 0;
  Eigen::Matrix3d screen_from_image = Eigen::Matrix3d::Identity();  // undistorted px -> lab mm
  double k1 = 0;
  double k2 = 0;
  Eigen::Vector2d centre_px{0, 0};
  double scale_px = 1;
  // "opencv5": the camera (intrinsics and distortion, from `camera_file`); k1, k2, centre_px and
  // scale_px are then unused. None: "radial2".
  std::optional<CameraModel> camera;
  std::string camera_file;  // the calib/camera.json it came from, relative to the dataset
  // Report.
  double rms_px = 0;  // reprojection RMS in pixels
  double rms_mm = 0;  // residual RMS on the screen, mm
  int corners_used = 0;
  std::string photo;  // calibration photo it came from
  // How the mapping was found: "homography+radial2" (fitted from the board photo alone) or
  // "camera+pose" (the known camera, the screen's pose solved). Empty in files that predate it.
  std::string method;

  Eigen::Vector2d Undistort(const Eigen::Vector2d& pixel) const;
  Eigen::Vector2d Distort(const Eigen::Vector2d& undistorted) const;        // inverse, iterative
  Eigen::Vector2d ScreenFromImage(const Eigen::Vector2d& pixel) const;      // px -> lab mm
  Eigen::Vector2d ImageFromScreen(const Eigen::Vector2d& screen_mm) const;  // lab mm -> px

  static ScreenCalibration Load(const std::string& path);  // validates calib/screen.json
  void Save(const std::string& path) const;                // atomic
};

}  // namespace lumislab
