// The radiometric calibration files of calib/ (docs/formats.md §13 - §16) and the per-pixel
// corrections the one decoder applies with them (lib/photo/photo_io.h LinearReader):
//   calib/dark.json + dark.exr       per-pixel dark level (offset, optionally dark current per
//                                    unit exposure) and hot pixels, camera image space;
//   calib/response.json              per-channel camera response of 8-bit photos, code -> linear;
//   calib/flat.json + flat.exr       per-pixel gain (vignetting x screen non-uniformity), mean 1
//                                    over the pixels that see the screen;
//   calib/scale.json                 the absolute scale: irradiance (W/m^2 or lux) per unit of
//                                    corrected linear value at exposure 1.
// lumislab-calibrate writes them (its dark, flat, response and scale calibrators); reconstruct
// and the later calibration steps read them here. Maps are in the decoder's linear units before the
// division by the exposure: (curve(code) - black_level) / (white_level - black_level).
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/slab.h"  // Rec709Weights

namespace lumislab {

constexpr int kRadiometricCalibrationSchemaVersion = 1;

// The map of calib/dark.json (dark-<hash>.exr): value = offset + current * exposure (exposure as
// dataset.json's relative exposure, the photo's t ISO / N^2), RGB per pixel; a hot pixel reads as
// the mean of its neighbours that are not hot (LinearReader).
struct DarkMap {
  std::string file;          // the JSON it was read from (for messages)
  ImageF offset;             // 3 channels, RGB
  ImageF current;            // 3 channels per unit exposure; empty: a constant dark level
  std::vector<uint8_t> hot;  // width * height, 1 = hot (its neighbours' mean replaces it)
  int hot_count = 0;
};

// calib/response.json: linear_of_code[c][k] is the relative linear value of 8-bit code k in
// channel c (R, G, B), increasing, code 255 -> 1.
struct ResponseCurve {
  std::string file;
  std::array<std::array<float, 256>, 3> linear_of_code{};
};

// The map of calib/flat.json (flat-<hash>.exr): RGB gain per pixel, mean 1 over the pixels that see
// the screen (1 elsewhere).
struct FlatMap {
  std::string file;
  ImageF gain;
};

// calib/scale.json: what reconstruct uses instead of dataset.json's radiometry.scale_w_m2.
struct RadiometricScale {
  std::string file;
  double scale = 1;             // units per unit of corrected linear value at exposure 1
  std::string units = "W/m^2";  // "W/m^2" or "lux"
  // The weights that reduced the photos' RGB to the one channel the reading was matched to
  // (luminance; they sum to 1): the camera's Y row from calib/colour.json, or Rec. 709's when
  // the dataset had none (`from_colour` false; also when the file predates the member).
  // Reconstruct gives them to the slab (SlabInfo::channel_weights).
  Eigen::Vector3d channel_weights = Rec709Weights();
  bool from_colour = false;
};
// calib/scale.json is written as version 2 when its channel_weights come from a colour
// calibration (a version-1 reader would build a slab weighed with Rec. 709's), else as 1.
constexpr int kScaleSchemaVersion = 2;

// The corrections the decoder applies to every photo (each optional).
struct PhotoCorrections {
  std::shared_ptr<const DarkMap> dark;
  std::shared_ptr<const ResponseCurve> response;
  std::shared_ptr<const FlatMap> flat;
  bool Empty() const { return !dark && !response && !flat; }
};

// Readers: BadInput naming the file and field (exit 2) for anything out of place (schema,
// sizes, a map that does not match its JSON, non-finite or out-of-range values).
DarkMap LoadDarkMap(const std::string& json_path);
ResponseCurve LoadResponseCurve(const std::string& json_path);
FlatMap LoadFlatMap(const std::string& json_path);
RadiometricScale LoadRadiometricScale(const std::string& json_path);

// Writers (atomic). `report` members are added to the JSON under "report". The dark and flat
// JSON name their map, written beside them first under a name of its content
// (<stem>-<16 hex digits>.exr): the JSON's rename commits the pair, and the stem's other maps
// are then removed, so an interrupted rewrite leaves the previous pair whole.
void SaveDarkMap(const std::string& json_path, const DarkMap& map, const nlohmann::json& report);
void SaveResponseCurve(const std::string& json_path, const ResponseCurve& curve,
                       const nlohmann::json& report);
void SaveFlatMap(const std::string& json_path, const FlatMap& map, const nlohmann::json& report);
void SaveRadiometricScale(const std::string& json_path, const RadiometricScale& scale,
                          const nlohmann::json& report);

// Which of calib/dark.json, response.json, flat.json to load from `calib_dir` (when present).
struct CorrectionSet {
  bool dark = true, response = true, flat = true;
};
PhotoCorrections LoadPhotoCorrections(const std::string& calib_dir, CorrectionSet which = {});

}  // namespace lumislab
