// PNG and TIFF decoding and encoding through libpng and libtiff directly, for lib/photo's decoder
// (photo_io.cc) and writers; JPEG through libjpeg is in jpeg_decode.h. Not through OpenCV's
// imgcodecs: Debian's libopencv_imgcodecs links GDAL and GDCM, and with them ~110 more shared
// libraries that every process loads at start, which multiplies the start-up time of a tool (its
// --help included). The tests start the tools thousands of times; a lab's batch conversion once
// per stage and dataset.
//
// Images are cv::Mat in OpenCV's conventions, so that the rest of lumislab sees what imread gave
// (the exceptions are said below):
// 8-bit or 16-bit codes, 1 or 3 channels, colour in B, G, R order, 16-bit samples in the host's
// byte order. Decoded images are allocated with NewPhotoImage (huge pages, kept for the next
// photo of the same size).
#pragma once

#include <tiffio.h>

#include <cstdio>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace lumislab {

// A PNG of any colour type and bit depth as stored codes: grey (1 .. 16 bits; below 8 bits
// scaled to 8) and grey + alpha as 1 channel (OpenCV gave 3 equal ones); RGB and palette as 3
// (B, G, R); alpha and a palette's transparency dropped; no gamma applied. An EXIF orientation
// in an eXIf chunk is not applied (OpenCV 4.6 applied it; cameras do not write PNG).
// A corrupt or truncated file is BadInput naming it and libpng's reason.
cv::Mat DecodePng(const std::string& path);

// A TIFF's first image of 8-bit or 16-bit unsigned samples, grey (MinIsBlack) as 1 channel or
// RGB (also JPEG-compressed YCbCr, converted by libtiff) as 3 (B, G, R); extra samples (alpha)
// dropped, not premultiplied; strips or tiles, contiguous or planar, any compression libtiff
// decodes; turned as its Orientation tag says. Another sample format, bit depth or photometric
// interpretation (palette, MinIsWhite, 1-bit), more than 16 samples or tiles larger than the
// image are InputError naming the file and the TIFF field; a corrupt file is BadInput with
// libtiff's reason.
cv::Mat DecodeTiff(const std::string& path);

// Turns `image` as EXIF or TIFF Orientation `orientation` (1-8) says, as OpenCV's imread does
// (modules/imgcodecs ExifTransform); other values leave it as it is.
void ApplyOrientation(int orientation, cv::Mat& image);

// Writes an 8-bit or 16-bit image of 1, 3 or 4 channels (B, G, R, A) to `file` as PNG (grey, RGB
// or RGBA), compressed for speed (OpenCV's defaults: the Sub filter, zlib level 1, RLE). IoError
// naming `path` when it cannot.
void EncodePng(const std::string& file, const cv::Mat& image, const std::string& path);

// A C file the codecs read or write through (libpng, libjpeg), closed with the pointer.
struct CloseCodecFile {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using CodecFile = std::unique_ptr<std::FILE, CloseCodecFile>;

// A libtiff handle whose error messages go into `error` (the first one) instead of stderr, and
// whose warnings are dropped. nullptr when libtiff cannot open the file; closed with the pointer.
using TiffFile = std::unique_ptr<TIFF, void (*)(TIFF*)>;
TiffFile OpenTiff(const std::string& path, const char* mode, std::string& error);

}  // namespace lumislab
