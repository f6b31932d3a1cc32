// Finds the checkerboard of a CalibrationTarget (core/dataset.h) in a photo and names every
// inner corner by its lab position. OpenCV's corner grid is ambiguous up to a flip or a half
// turn (the camera may look at the screen from behind, so the photo can be mirrored); the white
// dot in board square (0, 0) resolves it.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/dataset.h"

namespace lumislab {

struct DetectionOptions {
  int max_detection_px = 2000;    // corners are found on a copy whose long side is at most this
  bool sb_fallback = true;        // try cv::findChessboardCornersSB when the classic detector fails
  double min_dot_contrast = 0.3;  // dot brightness over its ring, relative to black/white
  void Check() const;             // BadInput naming the bad field
};

struct BoardCorners {
  std::vector<Eigen::Vector2d> pixels;     // sub-pixel corners, OpenCV pixel centres
  std::vector<Eigen::Vector2d> screen_mm;  // the same corners on the screen, lab mm
  std::string orientation;  // how OpenCV's grid maps onto the board: identity, flip_x, ...
  std::string detector;     // "classic" or "sb"
  double square_px = 0;     // median distance of adjacent corners, pixels
  int saddle_refined = 0;   // corners placed by the saddle-point fit (the rest: cornerSubPix)
  double dot_contrast = 0;  // dot over ring, relative to black/white; and the runner-up
  double runner_up_contrast = 0;
};

// `gray8`: the photo stretched to 8 bits (calibrate/gray_stretch.h); `photo`: its path, for
// messages. Throws BadInput naming the photo when the board or the dot is not found.
BoardCorners DetectBoard(const cv::Mat& gray8, const CalibrationTarget& target,
                         const std::string& photo, const DetectionOptions& options);

}  // namespace lumislab
