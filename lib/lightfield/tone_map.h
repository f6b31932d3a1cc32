// Tone mapping of the preview's linear images (radiance or irradiance) for PNG files and the
// window, and the comparison of two renders; plain buffers, no image library.
#pragma once

#include <cstdint>
#include <vector>

#include "core/image.h"

namespace lumislab {

// Exposure factor for `stops` (2^stops), times the automatic one when `automatic`: the 99th
// percentile of each pixel's largest channel maps to 0.8 (a black image keeps 2^stops).
double ExposureFactor(const ImageF& image, double stops, bool automatic);

// The sRGB transfer function of one linear value, clamped to [0, 1], as an 8-bit code.
uint8_t SrgbByte(double linear);
// A 3-channel linear image times `exposure_factor`, sRGB-encoded: width * height * 3 bytes, RGB
// interleaved, row 0 on top (the image's own order).
std::vector<uint8_t> EncodeSrgb8(const ImageF& image, double exposure_factor);

// How far `image` is from `reference` (same size, 3 channels).
struct ImageDifference {
  double relative_l2 = 0;  // ||image - reference|| / ||reference|| over all values
  // Largest per-pixel error relative to the pixel's largest reference channel, over pixels
  // brighter than 1e-3 of the reference's peak (a shared-exponent format's error is per pixel).
  double worst_pixel = 0;
};
ImageDifference CompareImages(const ImageF& image, const ImageF& reference);

}  // namespace lumislab
