// Synthetic photos of a calibration checkerboard with a known image -> screen mapping, for the
// calibrate tests: lib/synthetic's board model and renderer (the one the synthetic capture
// uses), seen through a pinhole camera (lib/synthetic/camera.h) and core's distortion model.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/dataset.h"
#include "core/screen_calibration.h"

namespace lumislab {
namespace testing {

// A ScreenCalibration holding the truth: a pinhole camera at `position_mm` looking at
// `look_at_mm` with the screen the plane z = 0 (lab x, y in mm), plus radial distortion k1, k2
// (centre: image centre, scale: half-diagonal, as lumislab-calibrate uses).
ScreenCalibration TrueCalibration(int width, int height, double focal_px,
                                  const Eigen::Vector3d& position_mm,
                                  const Eigen::Vector3d& look_at_mm, double k1 = 0, double k2 = 0);

// A board of squares_x x squares_y squares of square_mm centred on the origin.
CalibrationTarget CentredTarget(int squares_x, int squares_y, double square_mm);

// Photo (CV_32FC1, values in [0, 1]): black squares 0.05, white 0.9, a white quiet zone of one
// square around the board, grey screen 0.5 beyond. Optional Gaussian noise (sigma, fixed seed);
// `dot` false leaves out the orientation dot.
cv::Mat RenderBoard(const CalibrationTarget& target, const ScreenCalibration& truth,
                    double noise_sigma = 0, bool dot = true);

// Largest |recovered(p) - truth(p)| in mm over the pixels whose true screen point lies on the
// board (within its outer squares).
double MaxBoardErrorMm(const ScreenCalibration& recovered, const ScreenCalibration& truth,
                       const CalibrationTarget& target);

// True when the whole board plus its quiet zone projects inside the photo.
bool BoardInView(const CalibrationTarget& target, const ScreenCalibration& truth);

}  // namespace testing
}  // namespace lumislab
