// Writing images and synthetic photos: every PNG, JPEG or TIFF a tool writes goes through
// WriteImageFile (atomically: a temporary name renamed into place), and the synthetic camera's
// photos through WritePhoto.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/image.h"

namespace lumislab {

// Writes `image` (8-bit or 16-bit, 1, 3 or 4 channels in OpenCV's B, G, R (A) order) under a
// temporary name, then renames it into place, as PNG, JPEG (8-bit, 1 or 3 channels, at
// `jpeg_quality`) or uncompressed TIFF by the path's extension (.png, .jpg/.jpeg, .tif/.tiff;
// lib/photo/image_codecs.h).
void WriteImageFile(const std::string& path, const cv::Mat& image, int jpeg_quality = 95);
// 8-bit RGB (width * height * 3 bytes, RGB interleaved, row 0 on top: lib/lightfield's Rgb8Image
// and the preview's tone-mapped frames) through WriteImageFile (PNG by the path's ending).
void WriteRgb8File(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

// How the synthetic camera stores a photo of normalised linear RGB values (ImageF, 3 channels).
enum class PhotoEncoding {
  kLinear16Png,  // round(v * 65535), clipped: a 16-bit camera (values already quantised)
  kSrgb8Png,     // through the sRGB curve, 8 bit: a camera's PNG/JPEG-like output
  kHalfExr,      // half-float EXR, RLE (lossless for half; ~5e-4 relative precision)
  kFloatExr,     // 32-bit float EXR, uncompressed
  kFloatExrPiz,  // 32-bit float EXR, PIZ
  // Not linear: the values are a camera response's output in [0, 1] (the synthetic `response`
  // effect), written as round(v * 255) in an 8-bit JPEG at `jpeg_quality`.
  kCurve8Jpeg,
};
void WritePhoto(const std::string& path, const ImageF& linear, PhotoEncoding encoding,
                int jpeg_quality = 95);
// The codes an 8- or 16-bit encoding (kLinear16Png, kSrgb8Png, kCurve8Jpeg) stores, in
// OpenCV's BGR order: what WritePhoto writes, for writers with EXIF (lib/photo/camera_write.h).
cv::Mat PhotoCodes(const ImageF& linear, PhotoEncoding encoding);

}  // namespace lumislab
