// calib/camera.json: the camera's intrinsics and lens distortion, from many views of a board
// (lumislab-calibrate camera, docs/formats.md §12). Pixel coordinates follow OpenCV: (0,0) is the
// centre of the top-left pixel, x right, y down; camera frame x right, y down, z forward (mm).
//
// Model (OpenCV's five-coefficient Brown-Conrady model, so that the same numbers mean the same
// thing in calib/camera.yaml and in any OpenCV tool): a point (X, Y, Z) in the camera frame has
// normalised coordinates x = X/Z, y = Y/Z, r^2 = x^2 + y^2, and
//   x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
//   y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y
//   pixel = (fx x_d + cx, fy y_d + cy).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/json.h"

namespace lumislab {

constexpr int kCameraCalibrationSchemaVersion = 1;

// The board views were of (for the record and for re-running).
struct CameraBoardInfo {
  std::string type = "chessboard";  // "chessboard" or "charuco"
  int inner_cols = 0;               // inner corners, as OpenCV counts them
  int inner_rows = 0;
  double square_mm = 0;
  std::string dictionary;  // ChArUco only: OpenCV's predefined dictionary name
  double marker_mm = 0;    // ChArUco only
};

// One photo's part in the calibration.
struct CameraViewReport {
  std::string photo;
  bool used = false;
  std::string rejected;  // why not used ("board not found", "outlier: RMS ..."); empty if used
  int corners = 0;       // board corners found (0 when the board was not found)
  double rms_px = 0;     // reprojection RMS of this view's corners under the final camera
  double tilt_deg = 0;   // angle between the board normal and the optical axis (used views)
  Eigen::Vector3d rotation{0, 0, 0};        // camera_from_board, angle-axis (rad), used views
  Eigen::Vector3d translation_mm{0, 0, 0};  // camera_from_board, board origin in camera mm
};

// The camera model alone: image size, intrinsics and distortion. One implementation of the
// model for the calibration (calib/camera.json), the screen calibration that uses it
// (core/screen_calibration.h) and the synthetic camera's lens (lib/synthetic/camera.h).
struct CameraModel {
  int image_width = 0;
  int image_height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;          // px
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;  // OpenCV order in distortion_coefficients

  // Camera-frame point (mm, z > 0) -> distorted pixel.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_camera) const;
  // Normalised (x, y) -> distorted normalised (x_d, y_d).
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalised) const;
  // Distorted pixel -> undistorted normalised coordinates (x, y): Newton's method on the model
  // from x = x_d (quadratic convergence; exact to ~1e-15 inside the calibrated field of view),
  // with cv::undistortPoints' fixed-point iteration as the fallback where Newton does not
  // converge. Exact (x = x_d, bit for bit) without distortion.
  Eigen::Vector2d UndistortToNormalised(const Eigen::Vector2d& pixel) const;
  // Undistorted normalised (x, y) -> the ideal pinhole pixel (fx x + cx, fy y + cy), and back.
  Eigen::Vector2d PinholePixel(const Eigen::Vector2d& normalised) const {
    return {fx * normalised.x() + cx, fy * normalised.y() + cy};
  }
  Eigen::Vector2d Normalised(const Eigen::Vector2d& pinhole_pixel) const {
    return {(pinhole_pixel.x() - cx) / fx, (pinhole_pixel.y() - cy) / fy};
  }
  bool HasDistortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
};

// calib/camera.json's members for a camera model, also used by calib/screen.json's "opencv5"
// model: `camera_matrix` {fx, fy, cx, cy} and `distortion` {model "opencv5", k1, k2, p1, p2, k3},
// with their limits (m's image size must be set before reading).
void ReadCameraModel(const JsonView& camera_matrix, const JsonView& distortion, CameraModel* m);
nlohmann::json CameraMatrixJson(const CameraModel& m);
nlohmann::json DistortionJson(const CameraModel& m);

struct CameraCalibration : CameraModel {
  // Report.
  double rms_px = 0;         // reprojection RMS over the used views' corners (final, Ceres)
  double opencv_rms_px = 0;  // the same for cv::calibrateCamera's start
  // One standard deviation of fx, fy, cx, cy, k1, k2, p1, p2, k3 (from the refinement's
  // covariance); empty when it could not be computed.
  std::vector<double> sigma;
  CameraBoardInfo board;
  std::vector<CameraViewReport> views;  // every photo given, used or not

  int ViewsUsed() const;

  static CameraCalibration Load(const std::string& path);  // validates calib/camera.json
  void Save(const std::string& path) const;                // atomic
};

}  // namespace lumislab
