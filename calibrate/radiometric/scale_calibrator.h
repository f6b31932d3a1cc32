// lumislab-calibrate scale: a radiometer (or lux meter) reading at a known screen point for one
// grid position, through T+ and T- -> calib/scale.json (docs/formats.md §16).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "core/checks.h"
#include "core/dataset.h"
#include "core/screen_calibration.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

struct ScaleReference {
  std::string source;                   // the JSON file, or "command line"
  int i = -1, j = -1;                   // grid position
  Eigen::Vector2d point_mm{0, 0};       // lab, on the screen
  double reading_p = 0, reading_n = 0;  // with slide T+ / T- in, ambient light included
  std::string unit = "W/m^2";           // "W/m^2" or "lux"
  // BadInput naming the source and field: position outside the grid, point off the screen,
  // readings not finite, reading_p not > 0, reading_n < 0, reading_p not above reading_n.
  void Check(const Dataset& dataset) const;
};

// {"position": [i, j], "point_mm": [x, y], "reading_p": num, "reading_n": num,
//  "unit": "W/m2" | "W/m^2" | "lux"} (truth/reference.json of a synthetic capture has this form).
ScaleReference LoadScaleReference(const std::string& path);
// "W/m2", "W/m^2" -> "W/m^2", "lux" -> "lux"; BadInput naming `where` otherwise.
std::string CanonicalUnit(const std::string& unit, const std::string& where);

struct ScaleOptions {
  // Pixels within this distance of the point give the quadratic fit its value at the point
  // (at least 2: six coefficients).
  int radius_px = 3;
  // RGB -> the one channel matched to the reading (weights summing to 1): the colour
  // calibration's luminance (ColourCalibration::LuminanceWeights, `from_colour`) or Rec. 709's.
  Eigen::Vector3d channel_weights = Rec709Weights();
  bool channel_weights_from_colour = false;
};

// scale = (reading_p - reading_n) / (Y+ - Y-), Y options.channel_weights . RGB of the position's
// corrected linear values (decoded with `corrections`, exposure-weighted over the unclipped
// photos of each slide) at the point (a quadratic fit to the pixels within radius_px); ambient
// light cancels in both
// differences.
RadiometricScale CalibrateScale(const Dataset& dataset, const ScreenCalibration& screen,
                                const ScaleReference& reference,
                                const std::shared_ptr<const PhotoCorrections>& corrections,
                                const ScaleOptions& options, nlohmann::json* report,
                                CheckLog* checks = nullptr);

}  // namespace lumislab
