// Colour JPEG photos decoded without the 8-bit rounding of the colour conversion (docs/formats.md
// §4), for DecodePhoto. A JPEG stores Y, Cb and Cr as 8-bit samples; a decoder's conversion to R, G
// and B (R = Y + 1.402 (Cr - 128), ...) lands between codes and every decoder then rounds it to an
// 8-bit code again, an error of up to half a code on top of the camera's own rounding that the
// response curve then magnifies (one code is 1-5 % of a dark value). Here libjpeg decodes to Y, Cb,
// Cr (its inverse DCT and chroma upsampling, as every decoder) and the conversion is done in
// floating point: the codes keep their fractions, and the curve is read between its codes.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace lumislab {

// Decodes a baseline or progressive JPEG, in the orientation its EXIF Orientation tag gives (as
// OpenCV's imread shows it). Components Y, Cb, Cr (JFIF, or EXIF without an Adobe transform) give
// CV_16UC3 in RGB order holding codes in [0, 255] with their fractions (Photo::fractional_codes:
// code x kFractionalCodeOne, rounded to 1/256 code), and `fractional` true. A grey JPEG gives its
// codes as CV_8UC1, one stored as RGB (Adobe) CV_8UC3 in B, G, R order, both as stored, and
// `fractional` false. Any other colour space (CMYK, YCCK) is InputError naming the file; a
// corrupt or truncated file, or one larger than kMaxPhotoPixels, is BadInput naming it.
struct DecodedJpeg {
  cv::Mat pixels;
  bool fractional = false;
};
DecodedJpeg DecodeJpeg(const std::string& path);

// An 8-bit image of 1 or 3 channels (B, G, R) as a baseline JFIF JPEG at `quality` (1 .. 100),
// with libjpeg's defaults (4:2:0 chroma, the islow DCT): the bytes OpenCV's imencode wrote.
std::vector<unsigned char> EncodeJpeg(const cv::Mat& image, int quality);

}  // namespace lumislab
