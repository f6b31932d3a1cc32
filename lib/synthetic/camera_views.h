// Views of a free-standing chessboard for the camera calibration (`acquire synth
// --calibration-views N`, docs/formats.md §10): N poses of a printed board in front of the
// scene's camera, tilted and moved so that they constrain the focal length, rendered through the
// camera (and its lens) as lumislab-calibrate camera expects them.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/dataset.h"
#include "core/image.h"

namespace lumislab {

struct SynthScene;

// The board: 13 x 10 squares of 25 mm, i.e. 12 x 9 inner corners as OpenCV counts them
// (`calibrate camera --board 12x9 --square-mm 25`), centred on its frame's origin, no dot,
// printed with a one-square white margin on a grey (reflectance 0.25) sheet that fills the view.
constexpr int kViewBoardInnerCols = 12, kViewBoardInnerRows = 9;
constexpr double kViewBoardSquareMm = 25;
CalibrationTarget ViewBoardTarget();

// camera_from_board: a board point (x, y, 0) (mm, board frame) is R (x, y, 0) + t in the camera
// frame (x right, y down, z forward, mm).
struct BoardPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation_mm{0, 0, 0};
  double TiltDeg() const;  // between the board normal and the optical axis
};

// `count` poses (deterministic): tilts of 12 - 35 degrees about axes in every direction, distances
// from 0.8 to 1.3 times the one where the board spans half the photo's width, centres spread over
// the photo; each moved towards the centre (and away) until the board and its margin are wholly
// in the photo, seen through the lens.
std::vector<BoardPose> CameraViewPoses(const SynthScene& scene, int count);

// The photo of the board in `pose` (1 channel, linear reflectance, each pixel the mean of
// lib/synthetic/board.h's point samples), through the scene's camera and lens.
ImageF RenderCameraView(const SynthScene& scene, const BoardPose& pose, int threads = 1);

}  // namespace lumislab
