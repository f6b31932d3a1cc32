#include "calibrate/radiometric/calibration_frames.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "core/log.h"
#include "core/screen_calibration.h"
#include "lib/photo/exif.h"

namespace lumislab {

std::vector<double> ParseExposureList(const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v) || !(v > 0))
      throw BadInput("--exposures: expected positive numbers separated by commas, got '" + text +
                     "'");
    out.push_back(v);
  }
  return out;
}

std::vector<CalibrationFrame> DecodeCalibrationFrames(const Dataset& dataset,
                                                      const FrameOptions& options) {
  if (int(options.files.size()) < options.min_frames)
    throw BadInput(std::string("--frames: expected at least ") +
                   std::to_string(options.min_frames) + " " + options.what + ", got " +
                   std::to_string(options.files.size()));
  if (!options.exposures.empty() && options.exposures.size() != options.files.size())
    throw BadInput("--exposures: expected one exposure per frame (" +
                   std::to_string(options.files.size()) + "), got " +
                   std::to_string(options.exposures.size()));
  // Frames must be of the camera that took the slide photos: calib/screen.json's size when the
  // screen is calibrated, else the first frame's.
  const std::string screen = dataset.Path("calib/screen.json");
  int width = 0, height = 0;
  std::string size_source;
  if (std::filesystem::exists(screen)) {
    const ScreenCalibration c = ScreenCalibration::Load(screen);
    width = c.image_width, height = c.image_height, size_source = screen;
  }
  std::vector<CalibrationFrame> frames;
  for (size_t k = 0; k < options.files.size(); ++k) {
    CalibrationFrame f;
    if (!options.exposures.empty()) {
      f.exposure = options.exposures[k];
      f.exposure_known = true;
    } else if (const auto e = ReadPhotoExif(options.files[k]).RelativeExposure()) {
      f.exposure = *e;
      f.exposure_known = true;
    }
    PhotoEntry entry;  // exposure 1 unless the values are wanted per unit exposure
    if (options.per_unit_exposure) entry.exposure = f.exposure;
    PhotoSpec spec = PhotoSpecOf(dataset, entry);
    spec.corrections = options.corrections;
    f.photo = DecodePhoto(options.files[k], spec);
    const cv::Mat& px = f.photo.pixels;
    if (width == 0) width = px.cols, height = px.rows, size_source = options.files[k];
    if (px.cols != width || px.rows != height)
      throw InputError(options.files[k], "image size",
                       std::to_string(width) + "x" + std::to_string(height) + " as " + size_source,
                       std::to_string(px.cols) + "x" + std::to_string(px.rows));
    if (!frames.empty() && f.photo.CodeBits() != frames[0].photo.CodeBits())
      throw InputError(
          options.files[k], "bit depth",
          std::to_string(frames[0].photo.CodeBits()) + " bits like " + options.files[0],
          std::to_string(f.photo.CodeBits()) + " bits");
    frames.push_back(std::move(f));
  }
  return frames;
}

// Says when the decoder linearised `photo`'s codes through the sRGB curve (8- or 16-bit codes,
// no calibrated response for them); RAW and float frames are linear and say nothing.
void NoteSrgbCurve(const char* step, const Photo& photo) {
  if (photo.transfer == Transfer::kSrgb && photo.CodeBits() < 32)
    LogInfo(step, ": ", photo.CodeBits(), "-bit ", PhotoFormatName(photo.format),
            " photos linearised through the sRGB curve (no calib/response.json for them)");
}

}  // namespace lumislab
