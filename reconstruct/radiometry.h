// What reconstruct takes from the radiometric calibration in calib/ (docs/formats.md §13 -
// §16): the per-pixel corrections the decoder applies (dark, response, flat) and the absolute
// scale (calib/scale.json before dataset.json's radiometry.scale_w_m2).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "core/dataset.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

struct ReconstructRadiometry {
  std::shared_ptr<const PhotoCorrections> corrections;  // null when calib/ holds none
  std::optional<double> scale;  // units per unit value at exposure 1; none: relative
  std::string units = "relative";
  std::string scale_source;  // the file it came from
  // calib/scale.json's: the weights its reading was matched to (Rec. 709's without one).
  Eigen::Vector3d channel_weights = Rec709Weights();
  bool channel_weights_from_colour = false;
};

// Reads whichever of calib/dark.json, response.json, flat.json, scale.json exist (BadInput
// naming the file and field when one is bad) and logs one line per correction it will apply.
ReconstructRadiometry LoadReconstructRadiometry(const Dataset& dataset);

}  // namespace lumislab
