// The one photo decoder of lumislab: every stage that reads a camera photo reads it here
// (docs/formats.md). It owns
//   - format detection from the file's content (lib/photo/photo_format.h),
//   - camera RAW and DNG through LibRaw (lib/photo/raw_decode.h): linear sensor values with the
//     file's black and white level, white balance unity or as shot, full or half size,
//   - the transfer curve: 8-bit photos are camera output and linearised through the sRGB curve
//     unless told otherwise, 16-bit and float photos are linear,
//   - black and white level: linear = (curve(code / code_max) - black) / (white - black),
//   - the saturation mask: a value curve(code / code_max) >= saturation_level is clipped,
//   - exposure normalisation: values are divided by the photo's relative exposure, so photos of
//     different exposures are comparable.
// Decoded images are allocated by lib/photo/photo_allocator.h; images are written by
// lib/photo/photo_write.h.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "lib/photo/photo_format.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

// kResponse: a camera response calibrated by lumislab-calibrate response (calib/response.json),
// used for 8-bit photos whenever PhotoSpec::corrections holds one; never asked for, only resolved.
enum class Transfer { kAuto, kLinear, kSrgb, kResponse };
// White balance of a camera RAW: kUnity keeps the sensor's channels as they are (the
// photometric default: one radiometric scale calibrates them), kAsShot applies the camera's
// recorded multipliers (DNG AsShotNeutral, LibRaw's cam_mul), normalised so that green = 1.
enum class RawWhiteBalance { kUnity, kAsShot };

// How to interpret a photo's codes (dataset.json radiometry and the photo's exposure).
struct PhotoSpec {
  Transfer transfer = Transfer::kAuto;  // kAuto: 8-bit -> sRGB, 16-bit and float -> linear
  double black_level = 0;               // in curve(code / code_max) units
  double white_level = 1;
  double saturation_level = 1;  // curve(code / code_max) at or above this is clipped
  double exposure = 1;          // relative exposure t ISO / N^2 (any consistent unit)
  // Camera RAW only. A RAW decodes to values in which the file's white level is 1 (black and
  // white level above then apply on top, defaults leave them alone).
  RawWhiteBalance raw_white_balance = RawWhiteBalance::kUnity;
  bool raw_half_size = false;  // one pixel per 2x2 Bayer quad (exact) instead of a demosaic
  // Radiometric calibration (calib/: dark map and hot pixels, response curve, flat field),
  // applied by LinearReader: the response replaces the transfer curve of 8-bit photos, the dark
  // level (offset + current x exposure) is subtracted before the exposure division, hot pixels
  // read as the mean of their neighbours, and the flat gain is divided out. Null: none.
  std::shared_ptr<const PhotoCorrections> corrections;
  void Check(const std::string& where) const;  // BadInput naming `where` and the field
};

struct Photo {
  std::string path;
  PhotoFormat format = PhotoFormat::kPng;
  // As stored: CV_8U or CV_16U with 1 or 3 channels (BGR order, OpenCV's convention), or CV_32FC3
  // in RGB order (EXR channels R, G, B; camera RAW with white level 1), or a colour JPEG's codes
  // with their fractions (fractional_codes: CV_16UC3 in RGB order, code x kFractionalCodeOne).
  cv::Mat pixels;
  // A colour JPEG (lib/photo/jpeg_decode.h): pixels are 8-bit codes in [0, 255] kept with the
  // fractions of the decoder's colour conversion in 8.8 fixed point, read through the transfer
  // curve between codes (ReadBetweenCodes).
  bool fractional_codes = false;
  bool rgb_order = false;
  Transfer transfer = Transfer::kLinear;  // resolved: never kAuto
  PhotoSpec spec;
  // Per-channel multipliers (R, G, B) LinearReader applies after the clipping test, so that a
  // channel is clipped where the sensor was, whatever the white balance (RAW kAsShot).
  std::array<float, 3> white_balance = {1, 1, 1};

  double CodeMax() const;  // 255 (8-bit codes, fractional or not), 65535 or 1 (float)
  // 8-bit camera codes (CV_8U, or a JPEG's fractional codes): linearised through the sRGB curve
  // or a calibrated response.
  bool EightBitCodes() const { return pixels.depth() == CV_8U || fractional_codes; }
  // Bits per stored code (8, 16; 32 for float values), for messages and consistency checks.
  int CodeBits() const { return fractional_codes ? 8 : int(pixels.elemSize1() * 8); }
  // For a linear transfer: linear value = code * Gain() - Offset(). (Fast paths that work on
  // the stored codes use these, and only when UnityWhiteBalance(); everything else uses
  // LinearReader.)
  bool UnityWhiteBalance() const;
  double Gain() const;
  double Offset() const;
  // Smallest stored code that counts as clipped (linear transfer).
  double SaturationCode() const;
  // True when a per-pixel correction (dark map, flat field) applies: only LinearReader does it.
  bool PixelCorrections() const;
};

// A fractional code's fixed point: the stored value is code x 256 (8.8 bits, codes [0, 255]: at
// most 65280), a step of 1/256 code, ~1/45 of the rounding a decoder's 8-bit output adds.
constexpr int kFractionalCodeOne = 256;
// The one reading of a fractional code through a per-code table (256 entries; the curve value
// of each whole code): the table's value read linearly between the two codes around it.
// Without a branch, which the merge's row loop mispredicted (f = 0 at every code 0 and 255 and
// at random elsewhere; a test loop measured it slower): at a whole code (f = 0) both reads are
// table[k] and the value is table[k] + 0 = table[k] exactly (the tables hold finite values or
// NaN, never an infinity).
inline float ReadBetweenCodes(const float* table, uint16_t fractional_code) {
  const int k = fractional_code >> 8, f = fractional_code & 255;
  // f > 0 only below code 255: table[k + 1] is in the table.
  const float a = table[k], b = table[k + (f != 0)];
  return a + float(f) * (1.f / kFractionalCodeOne) * (b - a);
}
// ReadBetweenCodes of every fractional code, precomputed: one load per value instead of two
// loads and a lerp, where one table reads many values (the merge reads ~200 M values of a
// 6000 x 4000 position with 3 brackets per slide). entry[c] == ReadBetweenCodes(table, c) bit
// for bit for every code c <= 255 x kFractionalCodeOne (the decoder's largest), table[255] above
// (never stored); kFractionalCodeTable floats, 256 kB.
constexpr int kFractionalCodeTable = 65536;
std::vector<float> FractionalCodeTable(const float* table);
// The whole code at or above a fractional code: its clipping decides the fractional code's.
inline int CodeAtOrAbove(uint16_t fractional_code) {
  return (fractional_code + kFractionalCodeOne - 1) >> 8;
}

// The spec of a dataset's slide photo (its radiometry and the photo's exposure), and of its
// calibration photo (exposure 1, nothing clipped).
PhotoSpec PhotoSpecOf(const Dataset& dataset, const PhotoEntry& entry);
PhotoSpec CalibrationPhotoSpec(const Dataset& dataset);

// Decodes a photo. A path that is not a regular file, an unknown or corrupt format, or an
// unsupported pixel layout is BadInput naming the photo (exit 2), as is a photo whose size
// differs from that of a calibration map in spec.corrections (naming both).
Photo DecodePhoto(const std::string& path, const PhotoSpec& spec = {});

// Linear, exposure-normalised RGB of a pixel, and which channels are clipped.
class LinearReader {
 public:
  explicit LinearReader(const Photo& photo);
  void Read(int y, int x, float rgb[3], bool clipped[3]) const;

 private:
  // A hot pixel (calib/dark.json): the mean of the nearest pixels that are not hot.
  void ReadHot(int y, int x, float rgb[3], bool clipped[3]) const;
  const Photo& photo_;
  int channels_;
  int r_, b_;             // offsets of red and blue in a pixel
  float curve8_[3][257];  // R, G, B: 8-bit code -> curve value (257: code 255 + 1 for lerps)
  float inv_max_, black_, inv_range_, inv_exposure_, exposure_, inv_range_exposure_, saturation_;
  float white_balance_[3];         // R, G, B
  const DarkMap* dark_ = nullptr;  // per-pixel corrections (PhotoSpec::corrections)
  const FlatMap* flat_ = nullptr;
};

// An 8-bit-code photo's codes as CV_8U in storage order (fractional codes rounded): what the
// detectors and the response fit look at.
cv::Mat Codes8(const Photo& photo);

// The whole photo as linear, exposure-normalised Rec. 709 luminance (CV_32FC1); BadInput when a
// value is not finite. A gray for detection, metering and levels against full scale, not a
// photometric quantity (that is the slab's, SlabInfo::channel_weights).
cv::Mat LinearGray(const Photo& photo);

}  // namespace lumislab
