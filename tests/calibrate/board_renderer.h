// Synthetic photos of a calibration checkerboard with a known image -> screen mapping, for the
// calibrate tests: every pixel is the area average of point samples of the analytic board on a
// Fibonacci lattice (sharp, anti-aliased corners), seen through core's distortion model. A
// lattice, not an n x n grid: an n x n grid quantises axis-aligned edges to 1/n pixel, which
// showed up as corner errors of up to 1/(2n) pixel.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/dataset.h"
#include "core/screen_calibration.h"

namespace lumislab {
namespace testing {

// Pinhole camera at `position_mm` looking at `look_at_mm`; the screen is the plane z = 0 (lab
// x, y in mm). Returns screen_from_image (undistorted pixel -> mm), OpenCV pixel centres.
Eigen::Matrix3d CameraScreenFromImage(int width, int height, double focal_px,
                                      const Eigen::Vector3d& position_mm,
                                      const Eigen::Vector3d& look_at_mm);

// A ScreenCalibration holding the truth: the camera above plus radial distortion k1, k2
// (centre: image centre, scale: half-diagonal, as lumislab-calibrate uses).
ScreenCalibration TrueCalibration(int width, int height, double focal_px,
                                  const Eigen::Vector3d& position_mm,
                                  const Eigen::Vector3d& look_at_mm, double k1 = 0, double k2 = 0);

// A board of squares_x x squares_y squares of square_mm centred on the origin.
CalibrationTarget CentredTarget(int squares_x, int squares_y, double square_mm);

// Fibonacci lattice of kSamples points in the unit square (offsets within a pixel).
constexpr int kSamples = 34, kSampleStride = 21;
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
