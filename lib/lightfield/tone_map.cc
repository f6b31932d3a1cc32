#include "lib/lightfield/tone_map.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.h"

namespace lumislab {

namespace {

// Rec. 709 luminance of pixel k of a 3-channel image: the brightness a display tone maps, not
// a photometric quantity (whose weights are the slab's, SlabInfo::channel_weights).
double Luminance(const ImageF& image, size_t k) {
  return 0.2126 * image.data[3 * k] + 0.7152 * image.data[3 * k + 1] +
         0.0722 * image.data[3 * k + 2];
}

double LitFactor(const ImageF& image) {
  const size_t pixels = image.data.size() / 3;
  double peak = 0;
  for (size_t k = 0; k < pixels; ++k) peak = std::max(peak, Luminance(image, k));
  if (!(peak > 0) || !std::isfinite(peak)) return 1.0;
  double log_sum = 0;
  size_t lit = 0;
  for (size_t k = 0; k < pixels; ++k) {
    const double y = Luminance(image, k);
    if (y > kLitFraction * peak) {
      log_sum += std::log(y);
      ++lit;
    }
  }
  return kLitKey / std::exp(log_sum / double(lit));  // lit >= 1: the peak pixel
}

double P99Factor(const ImageF& image) {
  std::vector<float> values;
  values.reserve(size_t(image.width) * image.height);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      values.push_back(std::max({image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)}));
    }
  }
  std::nth_element(values.begin(), values.begin() + values.size() * 99 / 100, values.end());
  const double p99 = values[values.size() * 99 / 100];
  return p99 > 0 ? 0.8 / p99 : 1.0;
}

}  // namespace

const char* ToneCurveName(ToneCurve curve) {
  return curve == ToneCurve::kFilmic ? "filmic" : "linear";
}

const char* AutoExposureName(AutoExposure mode) {
  switch (mode) {
    case AutoExposure::kOff:
      return "off";
    case AutoExposure::kLit:
      return "lit";
    case AutoExposure::kP99:
      return "p99";
  }
  return "?";
}

ToneCurve ParseToneCurve(const std::string& name, const std::string& option) {
  for (ToneCurve c : {ToneCurve::kLinear, ToneCurve::kFilmic})
    if (name == ToneCurveName(c)) return c;
  throw InputError(option, "", "linear | filmic", name);
}

AutoExposure ParseAutoExposure(const std::string& name, const std::string& option) {
  for (AutoExposure m : {AutoExposure::kOff, AutoExposure::kLit, AutoExposure::kP99})
    if (name == AutoExposureName(m)) return m;
  throw InputError(option, "", "lit | p99 | off", name);
}

double AutoExposureFactor(const ImageF& image, AutoExposure mode) {
  if (mode == AutoExposure::kOff || image.empty()) return 1.0;
  if (image.channels != 3) throw BadInput("automatic exposure needs a 3-channel image");
  return mode == AutoExposure::kLit ? LitFactor(image) : P99Factor(image);
}

double ExposureFactor(const ImageF& image, const ToneMapping& tone) {
  return std::pow(2.0, tone.exposure_stops) * AutoExposureFactor(image, tone.auto_exposure);
}

double ApplyToneCurve(double x, ToneCurve curve) {
  if (!(x > 0)) return 0.0;  // negatives and NaN
  if (curve == ToneCurve::kLinear) return std::min(x, 1.0);
  // Narkowicz's fit of the ACES reference rendering transform, "ACES Filmic Tone Mapping
  // Curve" (2015): (x (2.51 x + 0.03)) / (x (2.43 x + 0.59) + 0.14), clamped to [0, 1].
  return std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

namespace {

// The sRGB encoding's code boundaries: code k (1..255) starts at the linear value whose encoded
// value is (k - 0.5) / 255, so SrgbByte(v) is the number of boundaries <= v: the rounded code of
// the exact curve. To find it without a pow() or a search per value (the window tone-maps each
// new image: a 1080p picture is six million values), a table gives the code at the start of
// each of 4096 equal steps of [0, 1]; no step holds more than one boundary (the curve's steepest
// slope, 12.92 * 255 codes per unit, is 0.8 codes per step), so one or two comparisons finish.
constexpr int kSteps = 4096;

struct SrgbTables {
  std::array<double, 256> bounds{};  // bounds[k - 1]: where code k starts; bounds[255] = inf
  std::array<uint8_t, kSteps + 1> step_code{};
  SrgbTables() {
    for (int k = 1; k <= 255; ++k) {
      const double c = (k - 0.5) / 255.0;
      bounds[k - 1] = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    }
    bounds[255] = INFINITY;
    for (int i = 0; i <= kSteps; ++i)
      step_code[i] =
          uint8_t(std::upper_bound(bounds.begin(), bounds.begin() + 255, double(i) / kSteps) -
                  bounds.begin());
  }
};

const SrgbTables& Tables() {
  static const SrgbTables tables;
  return tables;
}

}  // namespace

uint8_t SrgbByte(double linear) {
  if (!(linear > 0)) return 0;  // negatives and NaN
  if (linear >= 1) return 255;
  const SrgbTables& t = Tables();
  int code = t.step_code[int(linear * kSteps)];
  while (linear >= t.bounds[code]) ++code;  // bounds[255] = inf stops it
  return uint8_t(code);
}

std::vector<uint8_t> EncodeSrgb8(const ImageF& image, double exposure_factor, ToneCurve curve) {
  if (image.channels != 3) throw BadInput("sRGB encoding needs a 3-channel image");
  std::vector<uint8_t> out(image.data.size());
  for (size_t k = 0; k < image.data.size(); ++k) {
    out[k] = SrgbByte(ApplyToneCurve(image.data[k] * exposure_factor, curve));
  }
  return out;
}

std::vector<uint8_t> ToneMapToSrgb8(const ImageF& image, const ToneMapping& tone) {
  return EncodeSrgb8(image, ExposureFactor(image, tone), tone.curve);
}

ImageDifference CompareImages(const ImageF& image, const ImageF& reference) {
  if (image.data.size() != reference.data.size() || reference.channels != 3) {
    throw BadInput("images to compare differ in size or are not 3-channel");
  }
  ImageDifference out;
  if (reference.empty()) return out;
  double diff = 0, norm = 0;
  const double floor = 1e-3 * *std::max_element(reference.data.begin(), reference.data.end());
  for (size_t px = 0; px < reference.data.size() / 3; ++px) {
    double peak = 0, error = 0;
    for (size_t c = 3 * px; c < 3 * px + 3; ++c) {
      const double e = double(image.data[c]) - reference.data[c];
      diff += e * e;
      norm += double(reference.data[c]) * reference.data[c];
      peak = std::max(peak, std::abs(double(reference.data[c])));
      error = std::max(error, std::abs(e));
    }
    if (peak > floor) out.worst_pixel = std::max(out.worst_pixel, error / peak);
  }
  out.relative_l2 = norm > 0 ? std::sqrt(diff / norm) : (diff > 0 ? INFINITY : 0.0);
  return out;
}

}  // namespace lumislab
