// lumislab-calibrate camera: many photos of a board -> the camera's intrinsics and distortion
// (core/camera_calibration.h, docs/formats.md §12). The board is found in every photo
// (camera_board.h), cv::calibrateCamera gives the start, views whose RMS is an outlier are
// dropped, and Ceres refines the intrinsics, distortion and every pose (camera_refiner.h).
#pragma once

#include <string>
#include <vector>

#include "calibrate/camera/camera_board.h"
#include "calibrate/camera/camera_refiner.h"
#include "core/camera_calibration.h"

namespace lumislab {

struct CameraCalibratorOptions {
  CameraRefinerOptions refiner;
  int min_views = 3;  // usable views needed
  // A view is an outlier (and dropped) when its RMS under OpenCV's calibration exceeds both
  // `outlier_factor` times the median view RMS and `outlier_floor_px`.
  double outlier_factor = 3;
  double outlier_floor_px = 1.0;
  // The views constrain the focal length only when some board is tilted from facing the camera
  // and the boards are not all parallel: the largest tilt and the largest angle between two
  // board normals must both reach this.
  double min_tilt_deg = 5;
  double max_focal_sigma = 0.02;  // refuse when sigma(fx) / fx or sigma(fy) / fy exceeds this
  int threads = 1;                // photos decoded and searched in parallel
  void Check() const;             // BadInput naming the bad field
};

// --photos arguments -> photo paths: a folder gives its non-hidden regular files whose content
// is a photo (DetectPhotoFormat), sorted; a pattern with * ? or [ its matches (glob(3), sorted);
// anything else is one photo (which must exist). BadInput when a pattern matches nothing or
// nothing is left.
std::vector<std::string> ExpandPhotoArguments(const std::vector<std::string>& arguments);

// Calibrates from the photos (one camera, one image size). BadInput (exit 2) naming the photo or
// the reason for: photos of different sizes, the board found in no photo, fewer than
// `min_views` usable views, views that do not constrain the focal length.
CameraCalibration CalibrateCamera(const std::vector<std::string>& photos, const CameraBoard& board,
                                  const CameraCalibratorOptions& options);

// The same camera as an OpenCV FileStorage YAML (camera_matrix, distortion_coefficients,
// image_width, image_height, as OpenCV's calibration sample writes them); atomic.
void WriteCameraYaml(const CameraCalibration& camera, const std::string& path);

}  // namespace lumislab
