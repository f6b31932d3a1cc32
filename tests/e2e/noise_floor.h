// The noise floor predicted for a slab reconstructed from noisy photos: what the sensor's noise
// (and the rounding of its codes, dithered by that noise) leaves in the slab when every other
// step is exact. e2e_test (one 16-bit exposure per slide) and real_camera_test (brackets, a
// camera curve or a Bayer RAW, a flat field and a scale reading, each with their own noise)
// compare their slab error with it (issue 8: within 1.5x of the floor).
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/image.h"
#include "jpeg_coding_model.h"

namespace lumislab::testing {

// The camera's noise, in sensor values (the synthetic capture's normalised value before its
// curve or its RAW codes; 1 = full well).
struct SensorNoiseModel {
  double full_well_e = 20000;  // electrons at 1 (sensor_noise's full_well_e)
  double read_noise_e = 3;     // rms electrons
  // One code of the stored photo, in sensor values, at sensor value s: the rounding adds
  // q(s)^2 / 12 (the noise dithers it). Through a camera curve C: (1 / 255) / C'(s).
  std::function<double(double)> code_step = [](double) { return 1.0 / 65535; };
  // Sensor value at or above which the photo's value is clipped (left out of the merge).
  double saturation = std::numeric_limits<double>::infinity();
  // The photos are Bayer RGGB mosaics (a DNG), demosaiced by lib/photo: a pixel keeps its own
  // sample and takes the mean of the channel's samples in its 3 x 3 for the others. False: every
  // pixel samples every channel.
  bool bayer_rggb = false;
  // A JPEG camera: the quality its photos were written at (libjpeg through OpenCV: 4:2:0 chroma)
  // and its curve, code_of(s) = 255 C(s) before the rounding. 0: not a JPEG; the coding is then
  // only the rounding in code_step. With a quality, JpegCodingModel predicts what the coding
  // leaves instead (the photos' noise as it passes the quantiser, the roundings and chroma).
  int jpeg_quality = 0;
  std::function<double(double)> code_of;
  // Variance of one sensor value s: shot noise, read noise, the code's rounding.
  double Variance(double s) const;
};

// The calibrated chain's own noise sources (all optional).
struct ChainNoiseModel {
  // truth/flat.exr: the per-pixel gain (vignetting x screen gain) the flat divides out; the
  // merged variance is divided by its square. Empty: gain 1.
  std::string gain_exr;
  // truth/dark.exr: the dark signal (black + current x exposure) under the flat frames' and the
  // reference's values. Empty: none.
  std::string dark_exr;
  // The flat frames: their count (0: no flat), level at exposure 1 and exposure. Their mean per
  // pixel divides every photo, so its relative noise multiplies the slab texel's value.
  int flat_frames = 0;
  double flat_level = 0.5, flat_exposure = 1;
  // The scale's reading: position, lab point, radius of calibrate scale's quadratic fit; its
  // relative noise scales every texel alike. reference_radius_px 0: no scale step.
  int reference_i = 0, reference_j = 0;
  Eigen::Vector2d reference_mm = Eigen::Vector2d::Zero();
  int reference_radius_px = 0;
};

struct PositionNoiseFloor {
  int i = 0, j = 0;
  double relative = 0;  // predicted relative L2 of the position
};
struct NoiseFloor {
  double overall = 0;         // predicted relative L2 over the lit texels of all positions
  double scale_relative = 0;  // of which the scale reading's part (relative, every texel)
  std::vector<PositionNoiseFloor> positions;
};

// Predicts the relative L2 error (as core/slab_compare.h measures it: lit texels, >= 1 % of the
// position's peak, inside the slab's mask) that noise leaves in `slab_dir`. `clean` is the
// same capture without noise, its photos float EXR sensor values (the expected values of the
// noisy ones); `screen_json` maps texels to photo pixels; `truth_dir` holds the exact slab.
// Per photo pixel and channel, each slide's brackets are merged with inverse-variance weights
// (reconstruct's merge): var = 1 / sum_k (t_k^2 / var(s_k)) over the unclipped exposures k,
// divided by the gain^2 the flat divides out, times (filter peak x radiometric scale)^2. A
// texel's value is a weighted mean of the sensor's samples: the demosaic (Bayer), the mean of
// F x F pixels (F = round(side / 3), reconstruct's downsample) and K x K bilinear samples over
// the texel (reconstruct/rectify.cc); the sum of its squared weights is computed for a square
// texel of the area the screen calibration gives (N = texel area / pixel area, side sqrt(N)),
// averaged over 16 sub-pixel offsets and the mosaic's phases. The deconvolution with the
// stencil [b, a, b] (a = 5/6, b = 1/12) multiplies white noise's variance by
// (a / (a^2 - 4 b^2)^1.5)^2 in 2D. The flat's noise adds truth^2 x its relative variance
// through the same averaging and deconvolution, the scale reading's truth^2 x its relative
// variance.
NoiseFloor PredictNoiseFloor(const std::string& slab_dir, const std::string& clean,
                             const std::string& screen_json, const std::string& truth_dir,
                             const SensorNoiseModel& sensor, const ChainNoiseModel& chain = {});

}  // namespace lumislab::testing
