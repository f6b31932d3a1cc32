// The photos a radiometric calibration step reads (dark, flat or response frames, named on the
// command line), decoded by the one decoder with the dataset's radiometry and the corrections
// calibrated before the step (docs/formats.md §13 - §16).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "lib/photo/photo_io.h"

namespace lumislab {

struct CalibrationFrame {
  Photo photo;          // decoded with spec.exposure = 1: values before the exposure division
  double exposure = 1;  // relative exposure (t ISO / N^2): --exposures, EXIF, or 1
  bool exposure_known = false;  // from --exposures or EXIF
};

struct FrameOptions {
  std::vector<std::string> files;
  std::vector<double> exposures;                        // empty, or one per file
  std::shared_ptr<const PhotoCorrections> corrections;  // applied by the decoder; may be null
  int min_frames = 1;
  // Decode with the frame's exposure (values per unit exposure, the dark current of that
  // exposure subtracted) instead of exposure 1.
  bool per_unit_exposure = false;
  const char* what = "frames";  // for messages: "dark frames", ...
};

// Decodes every frame. Bad input (exit 2) naming the option or file and field: fewer than
// min_frames files, --exposures not one positive number per file, a frame that is not a photo,
// frames of different sizes or bit depths, or a size other than calib/screen.json's.
std::vector<CalibrationFrame> DecodeCalibrationFrames(const Dataset& dataset,
                                                      const FrameOptions& options);

// Parses "e1,e2,..." (each finite and > 0); BadInput naming --exposures otherwise.
std::vector<double> ParseExposureList(const std::string& text);

// Logs (info) that `photo`'s codes went through the sRGB curve when they did (8- or 16-bit codes
// without a calibrated response); `step` starts the line. Linear RAW and float photos: nothing.
void NoteSrgbCurve(const char* step, const Photo& photo);

}  // namespace lumislab
