// Rendering of the synthetic photos: the slide photos of each grid position and the
// checkerboard photo for the screen calibration.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "acquire/camera.h"
#include "acquire/scene.h"
#include "core/image.h"

namespace lumislab {

// Where each pixel's centre sees the physical screen (lab mm), computed once per camera; the
// pixels that see no screen are left out (their value is 0 in every photo).
struct ScreenView {
  int width = 0;
  int height = 0;
  std::vector<int> pixels;              // y * width + x
  std::vector<Eigen::Vector2d> lab_mm;  // parallel to `pixels`

  static ScreenView Of(const SynthScene& scene);
};

// Photos of position (i, j) through T+ and T- before any effect: normalised linear RGB values
// v = E / radiometric_scale * exposure (3 channels, RGB order). `stride` > 1 renders only every
// stride-th visible pixel (for the cheap pre-pass that sets the scale).
void RenderPosition(const SynthScene& scene, const ScreenView& view, int i, int j,
                    double radiometric_scale, ImageF* plus, ImageF* minus);
// Largest slide irradiance (W/m^2, any channel, either slide) over all positions, sampling every
// `stride`-th screen pixel; divides out to the radiometric scale.
double MaxSlideIrradiance(const SynthScene& scene, const ScreenView& view, int stride, int threads);

// The checkerboard of scene.calibration on the screen plane, 8-bit grayscale, 4x4 supersampled:
// white 0.8, black 0.05, white dot of diameter 0.4 square in square (0, 0); outside the board
// the white screen (0.8), outside the screen 0.
cv::Mat RenderCalibration(const SynthScene& scene);

// View an ImageF as a CV_32FC3 (no copy).
inline cv::Mat AsMat(ImageF& image) {
  return cv::Mat(image.height, image.width, CV_32FC(image.channels), image.data.data());
}

}  // namespace lumislab
