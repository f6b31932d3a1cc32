#include "reconstruct/merge_exposure.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <utility>

namespace lumislab::merge {
namespace {

// d(curve value) / d(code / code_max) of the photo's transfer curve at curve value l: the size
// of one code step in curve units is this / code_max.
float TransferSlope(Transfer transfer, float l) {
  if (transfer != Transfer::kSrgb) return 1.f;  // (kResponse: ResponseSlope)
  // sRGB decoding: l = c / 12.92 below c = 0.04045 (l = 0.0031308), else ((c + 0.055) / 1.055)^2.4,
  // whose slope is 2.4 / 1.055 * l^(1.4 / 2.4).
  return l <= 0.0031308f ? 1.f / 12.92f : 2.4f / 1.055f * std::pow(l, 1.4f / 2.4f);
}

// The slope d linear / d (code / 255) of a calibrated 8-bit response (green) at linear value l:
// central differences of the table at the code whose value is nearest above l.
float ResponseSlope(const ResponseCurve& response, float l) {
  const auto& g = response.linear_of_code[1];
  const int k = int(std::lower_bound(g.begin(), g.end(), l) - g.begin());
  const int a = std::clamp(k - 1, 0, 254), b = std::clamp(k + 1, 1, 255);
  return std::max(0.f, (g[b] - g[a]) * 255.f / float(b - a));
}

// The merge's readers: `pixels` pixels of row y from x0 into uk as the recorded value above black
// u (R, G, B; NaN where clipped). 16-bit or float linear codes (CodesAreLinear):
template <typename T>
void ReadLinear(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  const Photo& photo = *e.source;
  const T* __restrict row = photo.pixels.ptr<T>(y) + 3 * x0;
  const float gain = e.u_gain, offset = e.u_offset, saturation = e.saturation_code;
  // In storage order first (a plain loop that vectorises), then blue and red swapped.
  for (int j = 0; j < 3 * pixels; ++j) {
    const float code = float(row[j]);
    const float value = code * gain - offset;
    const bool ok = (code < saturation) & (std::abs(value) <= FLT_MAX);  // NaN: clipped
    uk[j] = ok ? value : kClipped;
  }
  if (!photo.rgb_order)
    for (int j = 0; j < 3 * pixels; j += 3) std::swap(uk[j], uk[j + 2]);
}

// 8-bit codes (1 or 3 channels) through the exposure's per-code tables:
void ReadCodes(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  const cv::Mat& m = e.source->pixels;
  const float* __restrict table = e.code_u.data();
  if (m.channels() == 1) {
    const uint8_t* __restrict row = m.ptr<uint8_t>(y) + x0;
    for (int x = 0; x < pixels; ++x)
      for (int c = 0; c < 3; ++c) uk[3 * x + c] = table[c * 256 + row[x]];
    return;
  }
  const uint8_t* __restrict row = m.ptr<uint8_t>(y) + 3 * x0;
  const int ri = e.source->rgb_order ? 0 : 2;  // storage position of red (blue: 2 - ri)
  for (int x = 0; x < pixels; ++x, row += 3, uk += 3) {
    uk[0] = table[row[ri]];
    uk[1] = table[256 + row[1]];
    uk[2] = table[512 + row[2 - ri]];
  }
}

// A JPEG's fractional codes (RGB order) through the same tables, read linearly between codes;
// NaN (clipped) when the next whole code up is, as LinearReader has it:
void ReadFractionalCodes(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  const uint16_t* __restrict row = e.source->pixels.ptr<uint16_t>(y) + 3 * x0;
  const float* __restrict r = e.fractional_u[0]->data();
  const float* __restrict g = e.fractional_u[1]->data();
  const float* __restrict b = e.fractional_u[2]->data();
  if (r == g && g == b) {
    for (int j = 0; j < 3 * pixels; ++j) uk[j] = r[row[j]];
    return;
  }
  for (int x = 0; x < pixels; ++x, row += 3, uk += 3) {
    uk[0] = r[row[0]];
    uk[1] = g[row[1]];
    uk[2] = b[row[2]];
  }
}

// Any other photo (calib/'s dark map, hot pixels or flat field), pixel by pixel:
void ReadPixels(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  for (int x = 0; x < pixels; ++x) {
    float v[3];
    bool c[3];
    e.reader.Read(y, x0 + x, v, c);
    for (int ch = 0; ch < 3; ++ch) {
      const float value = v[ch] * e.recorded;
      uk[x * 3 + ch] = !c[ch] && std::isfinite(value) ? value : kClipped;
    }
  }
}

}  // namespace

bool CodesAreLinear(const Photo& photo) {
  const int type = photo.pixels.type();
  // A dark map, hot pixels or a flat field (calib/) differ per pixel: only LinearReader has them.
  return photo.transfer == Transfer::kLinear && photo.UnityWhiteBalance() &&
         !photo.PixelCorrections() && !photo.fractional_codes &&
         (type == CV_16UC3 || type == CV_32FC3);
}

Exposure::Exposure(const DecodedPhoto& p, const NoiseModel& noise, double near_black_codes)
    : reader(p.photo) {
  const Photo& photo = p.photo;
  slide = p.entry.positive ? 0 : 1;
  recorded = effective = float(photo.spec.exposure);
  source = &photo;
  linear_codes = CodesAreLinear(photo);
  // The tables assume a code means the same at every pixel: not so with calib/'s dark map,
  // hot pixels or flat field (such photos are read through the reader, pixel by pixel).
  if (photo.EightBitCodes() && !photo.PixelCorrections()) {
    Photo codes = photo;
    codes.pixels.create(1, 256, photo.pixels.type());
    for (int v = 0; v < 256; ++v)
      for (int c = 0; c < codes.pixels.channels(); ++c) {
        const int i = v * codes.pixels.channels() + c;
        if (photo.fractional_codes)
          codes.pixels.ptr<uint16_t>(0)[i] = uint16_t(v * kFractionalCodeOne);
        else
          codes.pixels.ptr<uint8_t>(0)[i] = uint8_t(v);
      }
    const LinearReader code_reader(codes);
    code_u.resize(3 * 256);
    for (int v = 0; v < 256; ++v) {
      float rgb[3];
      bool clipped[3];
      code_reader.Read(0, v, rgb, clipped);
      for (int c = 0; c < 3; ++c) {
        const float value = rgb[c] * recorded;
        const bool ok = !clipped[c] && std::isfinite(value);
        code_u[c * 256 + v] = ok ? value : kClipped;
      }
    }
  }
  u_gain = float(photo.Gain() * photo.spec.exposure);
  u_offset = float(photo.Offset() * photo.spec.exposure);
  saturation_code = float(photo.SaturationCode());
  transfer = photo.transfer;
  black = float(photo.spec.black_level);
  range = float(photo.spec.white_level - photo.spec.black_level);
  code_step = photo.CodeBits() == 32 ? 0.f : float(1.0 / (photo.CodeMax() * range));
  read_var = float(std::pow(noise.read_noise_e / noise.full_well_e, 2));
  // n codes above black (the curve's slope at black: exact for sRGB up to code 10), or three
  // read-noise sigmas, whichever is larger.
  const ResponseCurve* response = transfer == Transfer::kResponse && photo.spec.corrections
                                      ? photo.spec.corrections->response.get()
                                      : nullptr;
  auto slope = [&](float l) {
    return response ? ResponseSlope(*response, l) : TransferSlope(transfer, l);
  };
  floor_u = std::max(float(near_black_codes) * code_step * slope(black), 3.f * std::sqrt(read_var));
  if (photo.EightBitCodes()) {  // code kTrustedCode through the curve, without per-pixel maps
    Photo code = photo;
    if (photo.spec.corrections) {
      auto curve_only = std::make_shared<PhotoCorrections>();
      curve_only->response = photo.spec.corrections->response;
      code.spec.corrections = curve_only;
    }
    code.pixels.create(1, 1, photo.pixels.type());
    code.pixels.setTo(
        cv::Scalar::all(photo.fractional_codes ? kTrustedCode * kFractionalCodeOne : kTrustedCode));
    float rgb[3];
    bool clipped[3];
    LinearReader(code).Read(0, 0, rgb, clipped);
    for (int c = 0; c < 3; ++c) trusted_u[c] = rgb[c] * recorded;
  }
  curved = transfer == Transfer::kSrgb || response != nullptr;
  for (int k = 0; k < kQuantTable; ++k) {
    const float q = code_step * slope(float(k) / (kQuantTable - 1));
    quant_var[k] = q * q / 12;
  }
}

std::vector<Exposure> MakeExposures(const std::vector<DecodedPhoto>& photos,
                                    const MergeOptions& options) {
  std::vector<Exposure> exposures;
  exposures.reserve(photos.size());
  for (const auto& p : photos) exposures.emplace_back(p, options.noise, options.near_black_codes);
  // The fractional-code tables, one per distinct per-code table: with sRGB and no calibration the
  // channels' tables are equal, and so are the exposures' where the exposures' ratios are powers
  // of 2 (u = value / exposure x exposure). One table (256 kB) stays in the cache, and is built
  // once.
  std::vector<std::pair<const float*, std::shared_ptr<const std::vector<float>>>> built;
  for (Exposure& e : exposures) {
    if (e.code_u.empty() || !e.source->fractional_codes) continue;
    for (int c = 0; c < 3; ++c) {
      const float* table = e.code_u.data() + c * 256;
      for (const auto& [other, entries] : built)
        if (std::memcmp(other, table, 256 * sizeof(float)) == 0) e.fractional_u[c] = entries;
      if (e.fractional_u[c]) continue;
      e.fractional_u[c] = std::make_shared<const std::vector<float>>(FractionalCodeTable(table));
      built.emplace_back(table, e.fractional_u[c]);
    }
  }
  return exposures;
}

std::vector<size_t> SlideOrder(const std::vector<Exposure>& exposures, int slide) {
  std::vector<size_t> order;
  for (size_t k = 0; k < exposures.size(); ++k)
    if (exposures[k].slide == slide) order.push_back(k);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return exposures[a].recorded < exposures[b].recorded;
  });
  return order;
}

void ReadRow(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  if (e.linear_codes && e.source->pixels.depth() == CV_16U)
    ReadLinear<uint16_t>(e, y, x0, pixels, uk);
  else if (e.linear_codes)
    ReadLinear<float>(e, y, x0, pixels, uk);
  else if (!e.code_u.empty() && e.source->fractional_codes)
    ReadFractionalCodes(e, y, x0, pixels, uk);
  else if (!e.code_u.empty())
    ReadCodes(e, y, x0, pixels, uk);
  else
    ReadPixels(e, y, x0, pixels, uk);
}

}  // namespace lumislab::merge
