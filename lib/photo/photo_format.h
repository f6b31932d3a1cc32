// Which format a photo file is in, from its content (the extension is not trusted), and the
// largest photo any of the decoders accepts.
#pragma once

#include <string>

namespace lumislab {

// kRaw: a camera RAW or DNG (LibRaw). A TIFF container is a DNG when its first IFD holds the
// DNGVersion tag; a TIFF without it is a camera RAW (NEF, ARW, PEF, ...) when it names a camera
// maker and LibRaw identifies a Bayer mosaic in it, since a plain TIFF reader would decode
// only its small preview. Anything else in a TIFF container is a plain TIFF (libtiff).
enum class PhotoFormat { kPng, kJpeg, kTiff, kExr, kRaw };
// Largest photo decoded (pixels; a 100-megapixel camera fits), checked from the header.
constexpr long long kMaxPhotoPixels = 1LL << 27;

// The format from the file's first bytes; BadInput naming the file when it is none of ours (or
// not a regular file).
PhotoFormat DetectPhotoFormat(const std::string& path);
const char* PhotoFormatName(PhotoFormat format);

}  // namespace lumislab
