// Rendering of the synthetic photos: the slide photos of each grid position and the
// checkerboard photo for the screen calibration (normalised linear values, before effects).
#pragma once

#include <vector>

#include "core/image.h"
#include "lib/synthetic/camera.h"
#include "lib/synthetic/scene.h"

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

// The light the screen gets through the slides of the filter centred at c (luminaire frame, the
// stage's actual position): the physical screen, lab [-W/2, W/2] x [-H/2, H/2], is that window
// shifted by c in the luminaire frame.
PlaneLight ScreenLight(const SynthScene& scene, const DualFilter& filter, const Eigen::Vector2d& c);

// Photos of position (i, j) through T+ and T- before any effect: normalised linear RGB values
// v = E / radiometric_scale * exposure (3 channels, RGB order), with the luminaire at the grid
// centre plus scene.StageOffsetMm(i, j).
void RenderPosition(const SynthScene& scene, const ScreenView& view, int i, int j,
                    double radiometric_scale, ImageF* plus, ImageF* minus);
// The same with the luminaire at the filter centre c (luminaire frame, mm: wherever a stage put
// it, acquire capture's virtual lab) and values E x gain.
void RenderAt(const SynthScene& scene, const ScreenView& view, const Eigen::Vector2d& c,
              double gain, ImageF* plus, ImageF* minus);
// Largest slide irradiance (W/m^2, any channel, either slide) over all positions, sampling every
// `stride`-th screen pixel (a cheap pre-pass); divides out to the radiometric scale.
double MaxSlideIrradiance(const SynthScene& scene, const ScreenView& view, int stride, int threads);

// The checkerboard of scene.calibration on the screen as the scene's camera sees it (1 channel,
// linear reflectance, lib/synthetic/board.h's default look: white 0.8, black 0.05, the white
// screen around the board, 0 outside the screen).
ImageF RenderCalibration(const SynthScene& scene, int threads = 1);

}  // namespace lumislab
