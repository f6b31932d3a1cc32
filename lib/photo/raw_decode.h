// Camera RAW and DNG photos through LibRaw (docs/formats.md §4), for DecodePhoto. Photometric
// rules: the sensor's values, linear, no gamma, no auto-brightening, no colour matrix; the
// file's black level (common, per-channel and repeat pattern) subtracted and its white level
// mapped to 1, per channel: value = (code - black) / (white - black).
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>

#include "lib/photo/exif.h"

namespace lumislab {

// Whether a file LibRaw identifies as a Bayer camera RAW (header only, nothing unpacked).
bool LibRawIdentifiesRaw(const std::string& path);

struct RawImage {
  cv::Mat rgb;  // CV_32FC3, RGB order, white level = 1, no white balance applied
  // As-shot white balance of the file, normalised so that green = 1 (R, G, B); 1 when the
  // file records none.
  std::array<float, 3> as_shot_white_balance = {1, 1, 1};
};

// Decodes a Bayer RAW/DNG. Full size: bilinear demosaic (each missing channel is the mean of
// the same-colour samples in the 3x3 window; exact for values that vary linearly). Half size:
// each 2x2 Bayer quad becomes one pixel (R, mean of the two G, B), exact for photometry. The
// image size is checked against kMaxPhotoPixels before anything is unpacked. A truncated or
// corrupt file, or a sensor that is not a 2x2 Bayer mosaic (X-Trans, Foveon, linear DNG), is
// BadInput naming the file.
RawImage DecodeRaw(const std::string& path, bool half_size);

// The EXIF LibRaw parses from a RAW/DNG header (exposure, f-number, ISO, make, model, lens,
// capture time); a file LibRaw cannot open is BadInput naming it. Make and model are LibRaw's
// normalised names (e.g. "Nikon" for "NIKON CORPORATION").
PhotoExif ReadRawExif(const std::string& path);

}  // namespace lumislab
