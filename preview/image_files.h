// Image files of lumislab-preview, written atomically: linear EXR, or PNG tone-mapped by
// lib/lightfield/tone_map.h and written by lib/photo (the one image-file writer).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "lib/lightfield/raster.h"
#include "lib/lightfield/tone_map.h"

namespace lumislab {

// 8-bit RGB, rows top first (width * height * 3 bytes), as a PNG.
void WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);
// .exr (linear RGB, `image`) or .png (`picture`, e.g. a false-colour view); BadInput for other
// endings.
void WriteImageOrPicture(const std::string& path, const ImageF& image, const Rgb8Image& picture);
// .exr (linear RGB) or .png (ToneMapToSrgb8 under `tone`); BadInput for other endings.
void WriteImage(const std::string& path, const ImageF& image, const ToneMapping& tone);

}  // namespace lumislab
