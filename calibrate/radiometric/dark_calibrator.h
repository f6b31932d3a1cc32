// lumislab-calibrate dark: dark frames (lens capped) -> calib/dark.json + dark.exr
// (docs/formats.md §13).
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "calibrate/radiometric/calibration_frames.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

struct DarkOptions {
  // A pixel is hot when its dark level at the longest exposure (largest channel) exceeds the
  // median pixel's by more than this (decoder linear units: fraction of full scale).
  double hot_threshold = 0.02;
  void Check() const;  // BadInput naming --hot-threshold
};

// The per-pixel dark level: the mean of the frames (linear, before the exposure division) when
// they share one exposure, else per pixel and channel the least-squares line offset + current x
// exposure. `report` receives the numbers docs/formats.md §13 lists.
DarkMap CalibrateDark(const std::vector<CalibrationFrame>& frames, const DarkOptions& options,
                      nlohmann::json* report);

}  // namespace lumislab
