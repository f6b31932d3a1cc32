// Tone mapping of the preview's linear images (radiance or irradiance) for PNG files and the
// window, and the comparison of two renders; plain buffers, no image library. The window shows
// exactly what a headless PNG of the same settings holds: both go through EncodeSrgb8 with the
// factor of ExposureFactor (docs/method.md §4.4).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"

namespace lumislab {

// How a linear value becomes a display value in [0, 1] before the sRGB curve.
enum class ToneCurve {
  kLinear,  // clamp to [0, 1]: highlights above 1 clip
  kFilmic,  // ACES filmic fit (Narkowicz 2015): a toe, and a shoulder that reaches 1 near x = 10
};
// How the automatic part of the exposure is metered.
enum class AutoExposure {
  kOff,  // 2^stops only
  kLit,  // lit pixels (luminance above 1e-4 of the peak): their log-average maps to 0.18
  kP99,  // all pixels: the 99th percentile of each pixel's largest channel maps to 0.8
};

struct ToneMapping {
  double exposure_stops = 0;  // on top of the automatic factor
  AutoExposure auto_exposure = AutoExposure::kLit;
  ToneCurve curve = ToneCurve::kFilmic;
};

// Command-line names ("linear", "filmic"; "off", "lit", "p99") and back; BadInput naming
// `option` for an unknown name.
const char* ToneCurveName(ToneCurve curve);
const char* AutoExposureName(AutoExposure mode);
ToneCurve ParseToneCurve(const std::string& name, const std::string& option);
AutoExposure ParseAutoExposure(const std::string& name, const std::string& option);

// Luminance of the lit pixels' log-average that kLit maps to (Reinhard's "key", middle grey).
constexpr double kLitKey = 0.18;
// A pixel is lit when its luminance exceeds this fraction of the image's largest luminance.
constexpr double kLitFraction = 1e-4;

// The automatic factor alone (1 for kOff, and for an image without light).
double AutoExposureFactor(const ImageF& image, AutoExposure mode);
// 2^stops times the automatic factor.
double ExposureFactor(const ImageF& image, const ToneMapping& tone);

// The curve applied to one exposed linear value; result in [0, 1] (0 for NaN and negatives).
double ApplyToneCurve(double exposed, ToneCurve curve);
// The sRGB transfer function of one linear value, clamped to [0, 1], as an 8-bit code.
uint8_t SrgbByte(double linear);
// A 3-channel linear image times `exposure_factor`, through `curve` (per channel), sRGB-encoded:
// width * height * 3 bytes, RGB interleaved, row 0 on top (the image's own order).
std::vector<uint8_t> EncodeSrgb8(const ImageF& image, double exposure_factor,
                                 ToneCurve curve = ToneCurve::kLinear);

// The picture of `image` under `tone`: EncodeSrgb8 with ExposureFactor and the curve. Headless
// PNGs and the window both show this.
std::vector<uint8_t> ToneMapToSrgb8(const ImageF& image, const ToneMapping& tone);

// How far `image` is from `reference` (same size, 3 channels).
struct ImageDifference {
  double relative_l2 = 0;  // ||image - reference|| / ||reference|| over all values
  // Largest per-pixel error relative to the pixel's largest reference channel, over pixels
  // brighter than 1e-3 of the reference's peak (a shared-exponent format's error is per pixel).
  double worst_pixel = 0;
};
ImageDifference CompareImages(const ImageF& image, const ImageF& reference);

}  // namespace lumislab
