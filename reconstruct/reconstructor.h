// The reconstruct stage: photos of one grid position -> fitted E_ij in the slab layout.
#pragma once

#include <memory>
#include <string>

#include "core/dataset.h"
#include "core/screen_calibration.h"
#include "core/slab.h"
#include "reconstruct/bell_fit.h"
#include "reconstruct/photo_merge.h"
#include "reconstruct/radiometry.h"
#include "reconstruct/rectify.h"

namespace lumislab {

struct ReconstructOptions {
  int resolution = 300;       // slab texels per side
  double lambda = 1e-4;       // regulariser of the fit (relative to B^T B, diagonal ~0.5)
  int samples_per_texel = 0;  // K; 0 = automatic (at least as dense as the photo pixels)
  // calib/'s corrections and scale (LoadReconstructRadiometry); null: dataset.json's radiometry
  // only, no per-pixel correction.
  std::shared_ptr<const ReconstructRadiometry> radiometry;
  MergeOptions merge;  // brackets: noise model, near-black floor, exposure ratios
  void Check() const;  // throws BadInput naming the option
};

// Above this PositionReport::bell_correction the light varies within a texel. For a Gaussian
// spot of sigma texels, c - b ~ -(1/12) lap c and the integral of |lap G| is 4 / (e sigma^2)
// times G's, so the ratio is 0.123 / sigma^2: 5 % at sigma = 1.57 texels, where the bell
// model's own error at the spot's centre, (1/24) |lap E| / E = 1 / (12 sigma^2), reaches 3 %.
//
constexpr double kUnresolvedLight = 0.05;

struct PositionReport {
  int i = 0, j = 0;
  // Photo pixels clipped in every exposure of a slide, of those the merge reads (the pixels
  // that reach the slab, RectifyMap::read_region). calib/dark.json's hot pixels are not among
  // them: the decoder reads them as their neighbours' mean.
  int saturated_pixels = 0;
  int saturated_texels = 0;  // texels dropped because a sample touched a saturated pixel
  // Brackets (MergedPosition): exposures per slide, pixels near-black in every exposure of a
  // slide, the merged image's dynamic range, the exposure ratios found in the pixels.
  int exposures = 1;
  int near_black_pixels = 0;
  double brightest = 0, faintest = 0, dynamic_range_stops = 0;
  std::vector<BracketRatio> bracket_ratios;
  int seen_texels = 0;
  int samples_per_texel = 0;
  int downsample = 1;  // photo box-averaged F x F before the remap
  int fit_iterations = 0;
  double fit_residual = 0;
  // How much the fit moved the texel box averages b to the bell coefficients c,
  // sum |c - b| / sum |b| over the seen texels and channels: about (1/12) |lap E| a^2 / |E|
  // for light smooth over several texels (docs/method.md §3.6), of order 1 for light that
  // varies within a texel, which the slab cannot hold (its flux stays right, not its shape).
  double bell_correction = 0;
  // Nothing measured: every seen texel is 0, or the brightest stored code of the position's
  // (linear, integer) photos lies below the near-black floor (MergeOptions::near_black_codes).
  bool no_light = false;
  // That code above black where it lies below the floor; else a code at or above the floor (the
  // first row maximum met: a lit position is told without reading every photo); -1 for float or
  // curved photos.
  double brightest_codes = -1;
  // Seconds per stage.
  double decode_s = 0, rectify_s = 0, fit_s = 0, write_s = 0;
  // rectify_s split: building the map, merging the photos, remap + area average.
  double map_s = 0, merge_s = 0, remap_s = 0;
};

// Photos of (i, j), decoded (both slides, all exposures) with `corrections` (calib/'s dark,
// response, flat; null: none); checks that both slides exist and that the sizes match the
// calibration.
std::vector<DecodedPhoto> DecodePosition(
    const Dataset& dataset, const ScreenCalibration& calibration, int i, int j,
    const std::shared_ptr<const PhotoCorrections>& corrections = nullptr);
// From decoded photos (the bench times decoding on its own).
SlabPosition ReconstructDecoded(const Dataset& dataset, const ScreenCalibration& calibration,
                                const SlabInfo& info, int i, int j,
                                const std::vector<DecodedPhoto>& photos,
                                const ReconstructOptions& options, PositionReport* report);
SlabPosition ReconstructPosition(const Dataset& dataset, const ScreenCalibration& calibration,
                                 const SlabInfo& info, int i, int j,
                                 const ReconstructOptions& options, PositionReport* report);

}  // namespace lumislab
