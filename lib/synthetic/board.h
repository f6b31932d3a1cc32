// The calibration board of the synthetic capture: its reflectance on the screen plane and a
// photo of it. One model for the capture (lumislab-acquire) and for the calibrate tests, which
// pass their own image -> screen mapping (with lens distortion) and look.
//
// Pixels are area averages of point samples on a Fibonacci lattice: sharp, anti-aliased edges.
// A lattice, not an n x n grid: an n x n grid quantises axis-aligned edges to 1/n pixel, which
// showed up as corner errors of up to 1/(2n) pixel.
#pragma once

#include <Eigen/Core>
#include <functional>

#include "core/dataset.h"
#include "core/image.h"

namespace lumislab {

struct BoardLook {
  double white = 0.8;   // reflectance of the white squares and the screen around the board
  double black = 0.05;  // black squares; square (0, 0) is black with a white dot of diameter
  bool dot = true;      // 0.4 square at its centre (the orientation mark); false leaves it out
  // Beyond `quiet_zone_squares` squares of white around the board the screen has reflectance
  // `surround`; quiet_zone_squares < 0: white all the way to the screen edge.
  int quiet_zone_squares = -1;
  double surround = 0.8;
  // Half extent of the screen (lab mm, centred on the origin); reflectance 0 outside it.
  // Zero: an unbounded screen.
  Eigen::Vector2d screen_half_mm{0, 0};
};

// Reflectance at lab point (x, y) mm on the screen plane.
double BoardReflectance(const CalibrationTarget& target, const Eigen::Vector2d& lab_mm,
                        const BoardLook& look = {});

// Where a point of the photo (pixel coordinates, OpenCV centres) sees the screen plane, in lab
// mm; false when it does not see the plane.
using ScreenOfPixel = std::function<bool(const Eigen::Vector2d& pixel, Eigen::Vector2d* lab_mm)>;

// Photo of the board (1 channel, linear reflectance) of width x height pixels, each the mean of
// kBoardSamples point samples; computed on `threads` threads.
constexpr int kBoardSamples = 34, kBoardSampleStride = 21;
ImageF RenderBoardPhoto(const CalibrationTarget& target, int width, int height,
                        const ScreenOfPixel& screen_of_pixel, const BoardLook& look,
                        int threads = 1);

}  // namespace lumislab
