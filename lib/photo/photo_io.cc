#include "lib/photo/photo_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/exr_io.h"
#include "lib/photo/image_codecs.h"
#include "lib/photo/jpeg_decode.h"
#include "lib/photo/raw_decode.h"

namespace lumislab {
namespace {

float SrgbToLinear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// Checks a PNG's chunk structure before libpng decodes it: the size in IHDR (refused beyond
// kMaxPhotoPixels, which the decoder would allocate first) and a chunk sequence that ends in IEND
// within the file (a truncated copy does not). Walks the chunk headers only.
void CheckPng(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  auto be32 = [](const unsigned char* b) {
    return (uint32_t(b[0]) << 24) | (uint32_t(b[1]) << 16) | (uint32_t(b[2]) << 8) | uint32_t(b[3]);
  };
  unsigned char h[24] = {};
  in.read(reinterpret_cast<char*>(h), sizeof h);
  if (in.gcount() < 24 || std::memcmp(h + 12, "IHDR", 4) != 0)
    throw BadInput(path + ": truncated or corrupt PNG (no image header)");
  const uint64_t w = be32(h + 16), ht = be32(h + 20);
  if (w == 0 || ht == 0 || w * ht > uint64_t(kMaxPhotoPixels))
    throw InputError(path, "IHDR",
                     "an image of 1 .. " + std::to_string(kMaxPhotoPixels) + " pixels",
                     std::to_string(w) + "x" + std::to_string(ht));
  std::error_code ec;
  const uint64_t file_size = std::filesystem::file_size(path, ec);
  uint64_t at = 8;  // after the signature
  for (;;) {
    unsigned char chunk[8];
    in.seekg(std::streamoff(at));
    in.read(reinterpret_cast<char*>(chunk), 8);
    if (in.gcount() < 8) throw BadInput(path + ": truncated PNG (no IEND chunk)");
    at += 12 + uint64_t(be32(chunk));  // length, type, data, CRC
    if (at > file_size) throw BadInput(path + ": truncated PNG (a chunk runs past the end)");
    if (std::memcmp(chunk + 4, "IEND", 4) == 0) return;
  }
}

}  // namespace

void PhotoSpec::Check(const std::string& where) const {
  auto finite = [&](double v, const char* field, bool positive) {
    if (!std::isfinite(v) || (positive && !(v > 0)))
      throw BadInput(where + ": " + field + ": expected a finite number" +
                     (positive ? " > 0" : "") + ", got " + std::to_string(v));
  };
  finite(black_level, "black_level", false);
  finite(white_level, "white_level", true);
  finite(saturation_level, "saturation_level", true);
  finite(exposure, "exposure", true);
  if (!(white_level > black_level))
    throw BadInput(where + ": white_level: expected > black_level (" + std::to_string(black_level) +
                   "), got " + std::to_string(white_level));
}

PhotoSpec PhotoSpecOf(const Dataset& dataset, const PhotoEntry& entry) {
  PhotoSpec spec;
  spec.transfer = dataset.photo_transfer == "linear" ? Transfer::kLinear
                  : dataset.photo_transfer == "srgb" ? Transfer::kSrgb
                                                     : Transfer::kAuto;
  spec.black_level = dataset.black_level;
  spec.white_level = dataset.white_level;
  spec.saturation_level = dataset.saturation_level;
  spec.exposure = entry.exposure;
  return spec;
}

PhotoSpec CalibrationPhotoSpec(const Dataset& dataset) {
  PhotoEntry entry;
  PhotoSpec spec = PhotoSpecOf(dataset, entry);
  spec.saturation_level = 1e30;  // the board's contrast is what counts, not clipping
  return spec;
}

double Photo::CodeMax() const {
  if (fractional_codes) return 255.0;
  switch (pixels.depth()) {
    case CV_8U:
      return 255.0;
    case CV_16U:
      return 65535.0;
    default:
      return 1.0;
  }
}

bool Photo::UnityWhiteBalance() const {
  return white_balance[0] == 1 && white_balance[1] == 1 && white_balance[2] == 1;
}

double Photo::Gain() const {
  return 1.0 / (CodeMax() * (spec.white_level - spec.black_level) * spec.exposure);
}

double Photo::Offset() const {
  return spec.black_level / ((spec.white_level - spec.black_level) * spec.exposure);
}

bool Photo::PixelCorrections() const {
  return spec.corrections && (spec.corrections->dark || spec.corrections->flat);
}

double Photo::SaturationCode() const {
  if (fractional_codes) return spec.saturation_level * CodeMax();
  if (pixels.depth() == CV_32F) return spec.saturation_level;
  return std::ceil(spec.saturation_level * CodeMax() - 1e-9);
}

std::vector<float> FractionalCodeTable(const float* table) {
  constexpr int kTop = 255 * kFractionalCodeOne;
  std::vector<float> entries(kFractionalCodeTable, table[255]);
  for (int c = 0; c <= kTop; ++c) entries[c] = ReadBetweenCodes(table, uint16_t(c));
  return entries;
}

Photo DecodePhoto(const std::string& path, const PhotoSpec& spec) {
  spec.Check(path);
  Photo photo;
  photo.path = path;
  photo.spec = spec;
  photo.format = DetectPhotoFormat(path);
  if (photo.format == PhotoFormat::kExr) {
    const ImageF rgb = ReadExr(path, {"R", "G", "B"});  // BadInput naming file and channel
    // A camera never writes NaN or Inf: such a photo is corrupt, not dark or clipped.
    for (float v : rgb.data)
      if (!std::isfinite(v)) throw InputError(path, "pixel data", "finite values", "NaN or Inf");
    photo.pixels =
        cv::Mat(rgb.height, rgb.width, CV_32FC3, const_cast<float*>(rgb.data.data())).clone();
    photo.rgb_order = true;
  } else if (photo.format == PhotoFormat::kRaw) {
    RawImage raw = DecodeRaw(path, spec.raw_half_size);
    photo.pixels = raw.rgb;
    photo.rgb_order = true;
    if (spec.raw_white_balance == RawWhiteBalance::kAsShot)
      photo.white_balance = raw.as_shot_white_balance;
  } else {
    if (photo.format == PhotoFormat::kJpeg) {
      DecodedJpeg jpeg = DecodeJpeg(path);
      photo.pixels = jpeg.pixels;
      photo.fractional_codes = photo.rgb_order = jpeg.fractional;
    } else if (photo.format == PhotoFormat::kPng) {
      CheckPng(path);
      photo.pixels = DecodePng(path);
    } else {
      photo.pixels = DecodeTiff(path);
    }
  }
  photo.transfer = spec.transfer != Transfer::kAuto ? spec.transfer
                   : photo.EightBitCodes()          ? Transfer::kSrgb
                                                    : Transfer::kLinear;
  if (photo.format == PhotoFormat::kRaw) photo.transfer = Transfer::kLinear;  // sensor values
  if (const PhotoCorrections* c = spec.corrections.get()) {
    // The calibrated camera curve is what an 8-bit code means, whatever the dataset says.
    if (c->response && photo.EightBitCodes()) photo.transfer = Transfer::kResponse;
    auto check_size = [&](const ImageF& map, const std::string& file) {
      if (map.width != photo.pixels.cols || map.height != photo.pixels.rows)
        throw InputError(
            path, "image size",
            std::to_string(map.width) + "x" + std::to_string(map.height) + " as the map of " + file,
            std::to_string(photo.pixels.cols) + "x" + std::to_string(photo.pixels.rows));
    };
    if (c->dark) check_size(c->dark->offset, c->dark->file);
    if (c->flat) check_size(c->flat->gain, c->flat->file);
  }
  return photo;
}

LinearReader::LinearReader(const Photo& photo) : photo_(photo) {
  channels_ = photo.pixels.channels();
  r_ = photo.rgb_order || channels_ == 1 ? 0 : 2;
  b_ = channels_ == 1 ? 0 : 2 - r_;
  const PhotoCorrections* corrections = photo.spec.corrections.get();
  const bool srgb = photo.transfer == Transfer::kSrgb;
  for (int c = 0; c < 3; ++c) {
    for (int v = 0; v < 256; ++v)
      curve8_[c][v] = photo.transfer == Transfer::kResponse
                          ? corrections->response->linear_of_code[c][v]
                      : srgb ? SrgbToLinear(v / 255.f)
                             : v / 255.f;
    curve8_[c][256] = curve8_[c][255];
  }
  inv_max_ = float(1.0 / photo.CodeMax());
  black_ = float(photo.spec.black_level);
  inv_range_ = float(1.0 / (photo.spec.white_level - photo.spec.black_level));
  exposure_ = float(photo.spec.exposure);
  inv_exposure_ = float(1.0 / photo.spec.exposure);
  inv_range_exposure_ =
      float(1.0 / ((photo.spec.white_level - photo.spec.black_level) * photo.spec.exposure));
  saturation_ = float(photo.spec.saturation_level);
  for (int c = 0; c < 3; ++c) white_balance_[c] = photo.white_balance[c];
  if (corrections) {
    dark_ = corrections->dark.get();
    flat_ = corrections->flat.get();
  }
}

void LinearReader::Read(int y, int x, float rgb[3], bool clipped[3]) const {
  const cv::Mat& m = photo_.pixels;
  const int offsets[3] = {r_, channels_ == 1 ? 0 : 1, b_};
  const bool srgb = photo_.transfer == Transfer::kSrgb;
  const size_t pixel = size_t(y) * m.cols + x;
  // A hot pixel's value is its own dark current, not light: it reads as its neighbours do.
  if (dark_ && dark_->hot[pixel]) return ReadHot(y, x, rgb, clipped);
  for (int c = 0; c < 3; ++c) {
    float v;
    if (photo_.fractional_codes) {
      // Between two codes the curve is read linearly; the code counts as clipped when the next
      // whole code up does (the merge's code tables have the same rule).
      const uint16_t code = m.ptr<uint16_t>(y)[size_t(x) * channels_ + offsets[c]];
      v = ReadBetweenCodes(curve8_[c], code);
      clipped[c] = !(curve8_[c][CodeAtOrAbove(code)] < saturation_);
    } else if (m.depth() == CV_32F) {
      v = m.ptr<float>(y)[size_t(x) * channels_ + offsets[c]];
    } else if (m.depth() == CV_16U) {
      v = m.ptr<uint16_t>(y)[size_t(x) * channels_ + offsets[c]] * inv_max_;
      if (srgb) v = SrgbToLinear(v);
    } else {
      v = curve8_[c][m.ptr<uint8_t>(y)[size_t(x) * channels_ + offsets[c]]];
    }
    if (!photo_.fractional_codes) clipped[c] = !(v < saturation_);  // NaN counts as clipped
    // Linear value before the exposure division, less the sensor's dark signal at this exposure;
    // then per unit exposure, less the pixel's gain.
    float linear;
    if (dark_) {
      linear = (v - black_) * inv_range_ - dark_->offset.data[pixel * 3 + c];
      if (!dark_->current.empty()) linear -= dark_->current.data[pixel * 3 + c] * exposure_;
      linear *= inv_exposure_;
    } else {
      linear = (v - black_) * inv_range_exposure_;
    }
    if (flat_) linear /= flat_->gain.data[pixel * 3 + c];
    rgb[c] = linear * white_balance_[c];
  }
}

void LinearReader::ReadHot(int y, int x, float rgb[3], bool clipped[3]) const {
  // The defect correction of a camera's pipeline: the mean of the fully corrected values of the
  // nearest pixels that are not hot themselves: the 8 neighbours, or when all of them are hot
  // (a demosaic spreads a hot Bayer site into its 3 x 3 neighbourhood) the 16 around them.
  // Light varies little over a few pixels, so the texels around a hot pixel stay in the fit
  // instead of leaving a hole (mask 0). A channel is clipped when one of those pixels' is, or
  // when there is none.
  const cv::Mat& m = photo_.pixels;
  double sum[3] = {0, 0, 0};
  int n = 0;
  for (int c = 0; c < 3; ++c) clipped[c] = false;
  for (int ring = 1; ring <= 2 && n == 0; ++ring)
    for (int dy = -ring; dy <= ring; ++dy)
      for (int dx = -ring; dx <= ring; ++dx) {
        const int yy = y + dy, xx = x + dx;
        if (std::max(std::abs(dx), std::abs(dy)) != ring || yy < 0 || xx < 0 || yy >= m.rows ||
            xx >= m.cols || dark_->hot[size_t(yy) * m.cols + xx])
          continue;
        float v[3];
        bool clip[3];
        Read(yy, xx, v, clip);
        for (int c = 0; c < 3; ++c) sum[c] += v[c], clipped[c] = clipped[c] || clip[c];
        ++n;
      }
  for (int c = 0; c < 3; ++c) {
    rgb[c] = n ? float(sum[c] / n) : 0.f;
    if (n == 0) clipped[c] = true;
  }
}

cv::Mat Codes8(const Photo& photo) {
  LUMISLAB_CHECK(photo.EightBitCodes(), "Codes8: a photo of 8-bit codes");
  if (!photo.fractional_codes) return photo.pixels;
  cv::Mat codes;
  photo.pixels.convertTo(codes, CV_8U, 1.0 / kFractionalCodeOne);  // the nearest code
  return codes;
}

cv::Mat LinearGray(const Photo& photo) {
  const LinearReader reader(photo);
  cv::Mat gray(photo.pixels.rows, photo.pixels.cols, CV_32FC1);
  for (int y = 0; y < gray.rows; ++y) {
    float* row = gray.ptr<float>(y);
    for (int x = 0; x < gray.cols; ++x) {
      float rgb[3];
      bool clipped[3];
      reader.Read(y, x, rgb, clipped);
      row[x] = 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
      if (!std::isfinite(row[x])) throw BadInput(photo.path + ": photo holds non-finite values");
    }
  }
  return gray;
}

}  // namespace lumislab
