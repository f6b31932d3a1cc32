// lumislab-calibrate flat: frames of the screen under uniform irradiance -> calib/flat.json +
// flat.exr, the per-pixel gain of lens vignetting times screen non-uniformity
// (docs/formats.md §15).
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "calibrate/radiometric/calibration_frames.h"
#include "core/checks.h"
#include "core/dataset.h"
#include "core/screen_calibration.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

// The frames' mean (decoded per unit exposure, dark-subtracted and linearised by the decoder),
// per channel normalised to mean 1 over the pixels whose centre sees the physical screen
// (calib/screen.json); 1 on the other pixels and on hot ones. A pixel clipped in a frame
// (other than a hot one) keeps gain 1; more than 0.1 % of the screen clipped in one frame is bad
// input naming the frame (overexposed).
// smooth_px > 0: the gain is then smoothed with a Gaussian of that sigma (pixels), normalised
// over the screen pixels that count (hot and clipped ones and the pixels off the screen do not
// pull their neighbours): vignetting and a screen's non-uniformity vary over tens of pixels,
// while the frames' noise and a JPEG's compression error vary from pixel to pixel and would be
// divided into every photo.
// `checks` (optional): flat.has_signal is checked there before the gain is formed
// (calibration_checks.h); a frame without light fails it.
FlatMap CalibrateFlat(const std::vector<CalibrationFrame>& frames, const Dataset& dataset,
                      const ScreenCalibration& screen, nlohmann::json* report, double smooth_px = 0,
                      CheckLog* checks = nullptr);

}  // namespace lumislab
