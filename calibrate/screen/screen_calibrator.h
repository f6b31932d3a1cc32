// lumislab-calibrate screen: the calibration photo of a checkerboard on the screen ->
// calib/screen.json (core/screen_calibration.h). OpenCV finds the corners and a starting
// homography. Without a calibrated camera, Ceres refines the homography and two radial
// distortion terms (screen_refiner.h); with one (calib/camera.json), the lens is known and only
// the screen's pose is solved: cv::solvePnP, then Ceres (calibrate/camera/camera_refiner.h
// RefinePose).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calibrate/screen/board_detector.h"
#include "calibrate/screen/screen_refiner.h"
#include "core/camera_calibration.h"
#include "core/dataset.h"
#include "core/screen_calibration.h"

namespace lumislab {

struct ScreenCalibratorOptions {
  DetectionOptions detection;
  RefinerOptions refiner;
  // Degenerate views are refused (BadInput) rather than calibrated badly.
  double max_rms_px = 1.0;           // reprojection RMS above this: blur, grazing view, bent board
  double min_board_fraction = 0.01;  // area of the corner grid / area of the photo
  double max_anisotropy = 8;         // local stretch ratio (~ 1 / cos of the viewing angle)
  double max_scale_ratio = 25;       // largest / smallest local area scale over the board
  double max_condition = 1e6;        // of the homography in normalised coordinates
  // Model selection for the distortion (each extra term must earn its place): a term is only
  // fitted when the corners reach far enough from the photo centre (radius in half-diagonals;
  // a 16 px-square board in the middle fitted k2 = 0.8), and only kept when dropping it would
  // raise the reprojection RMS by more than `keep_term_rms_ratio` (a spurious k2 of 0.005 on a
  // distortion-free photo cost 0.3 mm at the screen edge, a true k2 of 0.03 left out cost 1 mm).
  double min_radius_k1 = 0.25;
  double min_radius_k2 = 0.45;
  double keep_term_rms_ratio = 1.1;
  void Check() const;  // BadInput naming the bad field
};

// What the calibration saw and did, for logs and tests.
struct ScreenCalibrationReport {
  BoardCorners corners;
  RefinementResult refinement;
  int distortion_terms = 0;  // used in the end (fewer for small boards or a non-monotonic fit)
  std::vector<double> rms_px_by_terms;  // reprojection RMS with 0, 1, 2 terms (those tried)
  double board_radius = 0;              // farthest corner from the photo centre, in half-diagonals
  double board_fraction = 0;
  double anisotropy = 0;   // worst over the corners
  double scale_ratio = 0;  // max / min local area scale
  double condition = 0;
  // The sign of det(d screen / d image) over the board (the same at every corner, or the view is
  // refused as folded): which way round the camera sees the board (MirroredBoard).
  int handedness = 0;
  double initial_rms_px = 0;  // OpenCV homography, before refinement
  // With a known camera: the screen's pose (camera_from_screen: angle-axis rad, translation mm;
  // screen frame = lab x, y on the screen plane) and cv::solvePnP's RMS before Ceres.
  bool camera_known = false;
  Eigen::Matrix<double, 6, 1> pose = Eigen::Matrix<double, 6, 1>::Zero();
  double pnp_rms_px = 0;
};

// The handedness (ScreenCalibrationReport::handedness) of the usual set-up: the board pinned
// the right way round on the screen, the camera behind the screen (away from the luminaire,
// docs/formats.md "The board"), image x right and y down. Measured -1 in the synthetic lab
// (acquire synth, the real-camera fixtures: camera at z = 2400 mm, screen at 750 mm). +1: the
// board pinned mirrored, or the camera on the luminaire's side of the screen (a calibrate test
// puts it at z = -520 mm).
inline constexpr int kUsualHandedness = -1;

// True when the board is seen the other way round from the usual set-up. Legitimate (a camera
// on the luminaire's side, a board pinned mirrored on purpose), but if the lab did not mean it
// the slab comes out mirrored: calibrate screen records a warning, "screen.board_mirrored".
inline bool MirroredBoard(const ScreenCalibrationReport& report) {
  return report.handedness == -kUsualHandedness;
}

// `photo`: CV_32FC1 (lib/photo LinearGray), any value range. `photo_name` names the
// photo in messages and in the result. `camera`: the calibrated camera (of the photo's size),
// or null to fit the lens from this photo. Throws BadInput for a missing board or dot and for
// degenerate views.
ScreenCalibration CalibrateScreenPhoto(const cv::Mat& photo, const CalibrationTarget& target,
                                       const std::string& photo_name,
                                       const ScreenCalibratorOptions& options,
                                       ScreenCalibrationReport* report = nullptr,
                                       const CameraModel* camera = nullptr);

// The dataset's calibrated camera, calib/camera.json, when it exists. Its image size must be
// the board photo's (`photo_width` x `photo_height`, of `photo`): otherwise BadInput naming the
// file and field.
std::optional<CameraCalibration> LoadDatasetCamera(const Dataset& dataset, int photo_width,
                                                   int photo_height, const std::string& photo);

// Loads the dataset's calibration photo and calibrates, with calib/camera.json when it exists;
// the result is not written.
ScreenCalibration CalibrateScreen(const Dataset& dataset, const ScreenCalibratorOptions& options,
                                  ScreenCalibrationReport* report = nullptr);

}  // namespace lumislab
