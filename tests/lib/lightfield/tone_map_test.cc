// Tone mapping to 8-bit sRGB buffers, automatic exposure, and the image comparison.
#include "lib/lightfield/tone_map.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace lumislab {
namespace {

TEST(LightFieldToneMap, SrgbBytesFollowTheTransferFunction) {
  EXPECT_EQ(SrgbByte(0), 0);
  EXPECT_EQ(SrgbByte(-3), 0);
  EXPECT_EQ(SrgbByte(1), 255);
  EXPECT_EQ(SrgbByte(7), 255);
  EXPECT_EQ(SrgbByte(0.002), 7);            // linear segment: 12.92 * 0.002 * 255 = 6.59
  EXPECT_EQ(SrgbByte(0.5), 188);            // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 187.5
  for (int code = 1; code < 256; ++code) {  // monotonic, and round-trips every code
    const double c = code / 255.0;
    const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    EXPECT_EQ(SrgbByte(linear), code);
    EXPECT_GE(SrgbByte(linear), SrgbByte(linear * 0.999));
  }
}

// SrgbByte's tables give the code of the exact curve, rounded: compared with the formula on a
// dense sweep of [0, 1] (values within 1e-9 of a rounding boundary may go either way).
TEST(LightFieldToneMap, SrgbByteTablesMatchTheFormula) {
  int compared = 0;
  for (int k = 0; k <= 200000; ++k) {
    const double v = std::pow(k / 200000.0, 2.2);  // denser near 0, where the curve is steep
    const double encoded = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    const double code = encoded * 255.0 + 0.5;
    if (std::abs(code - std::round(code)) < 1e-9) continue;
    EXPECT_EQ(SrgbByte(v), int(code)) << v;
    ++compared;
  }
  EXPECT_GT(compared, 199000);
}

TEST(LightFieldToneMap, EncodeSrgb8KeepsLayoutAndAppliesExposure) {
  ImageF image(3, 2, 3);
  image.at(2, 0, 0) = 0.25f;  // top row, right: red
  image.at(0, 1, 2) = 0.5f;   // bottom row, left: blue
  const std::vector<uint8_t> bytes = EncodeSrgb8(image, 2.0);
  ASSERT_EQ(bytes.size(), 18u);
  EXPECT_EQ(bytes[(0 * 3 + 2) * 3 + 0], 188);  // 0.25 * 2
  EXPECT_EQ(bytes[(1 * 3 + 0) * 3 + 2], 255);  // 0.5 * 2
  int lit = 0;
  for (uint8_t b : bytes) lit += b != 0;
  EXPECT_EQ(lit, 2);
}

ToneMapping Tone(double stops, AutoExposure mode) {
  ToneMapping tone;
  tone.exposure_stops = stops;
  tone.auto_exposure = mode;
  return tone;
}

TEST(LightFieldToneMap, P99ExposurePutsThe99thPercentileAt08) {
  ImageF image(100, 10, 3);
  for (int k = 0; k < 1000; ++k) image.data[3 * k + (k % 3)] = float(k + 1);  // max channel k+1
  // 99th percentile of 1..1000 (nth_element at index 990) is 991.
  EXPECT_NEAR(ExposureFactor(image, Tone(0, AutoExposure::kP99)), 0.8 / 991, 1e-12);
  EXPECT_NEAR(ExposureFactor(image, Tone(1, AutoExposure::kP99)), 2 * 0.8 / 991, 1e-12);
  EXPECT_EQ(ExposureFactor(image, Tone(-2, AutoExposure::kOff)), 0.25);
  for (AutoExposure mode : {AutoExposure::kP99, AutoExposure::kLit})  // black: stops only
    EXPECT_EQ(ExposureFactor(ImageF(4, 4, 3), Tone(1, mode)), 2.0);
}

// A room lit in a small patch: 995 of 1000 pixels black, the lit ones at luminances 2 and 8
// (grey) and one coloured pixel. The log-average of the lit pixels goes to 0.18; dark pixels and
// pixels below 1e-4 of the peak do not count. p99 sees only black and leaves the image as it is.
TEST(LightFieldToneMap, LitExposureMapsTheLitPixelsLogAverageToMiddleGrey) {
  ImageF image(100, 10, 3);
  auto grey = [&](int k, float v) {
    for (int c = 0; c < 3; ++c) image.data[3 * k + c] = v;
  };
  grey(10, 2.f);
  grey(11, 2.f);
  grey(12, 8.f);
  grey(13, 8.f);
  image.data[3 * 14 + 1] = 4.f / 0.7152f;  // pure green of luminance 4
  grey(15, 8e-4f * 0.99f);                 // just below 1e-4 of the peak (8): not lit
  // Log-average of 2, 2, 8, 8, 4 is 4.
  EXPECT_NEAR(AutoExposureFactor(image, AutoExposure::kLit), 0.18 / 4, 1e-6);
  EXPECT_NEAR(ExposureFactor(image, Tone(1, AutoExposure::kLit)), 2 * 0.18 / 4, 1e-6);
  EXPECT_EQ(AutoExposureFactor(image, AutoExposure::kP99), 1.0);
  // Scale invariance: ten times the light, a tenth of the factor.
  for (float& v : image.data) v *= 10;
  EXPECT_NEAR(AutoExposureFactor(image, AutoExposure::kLit), 0.18 / 40, 1e-7);
}

TEST(LightFieldToneMap, FilmicCurveHasAToeAndAShoulder) {
  EXPECT_EQ(ApplyToneCurve(0.5, ToneCurve::kLinear), 0.5);
  EXPECT_EQ(ApplyToneCurve(3, ToneCurve::kLinear), 1.0);
  EXPECT_EQ(ApplyToneCurve(-1, ToneCurve::kFilmic), 0.0);
  EXPECT_EQ(ApplyToneCurve(std::nan(""), ToneCurve::kFilmic), 0.0);
  // Narkowicz's published fit at a few points.
  EXPECT_NEAR(ApplyToneCurve(0.18, ToneCurve::kFilmic),
              0.18 * (2.51 * 0.18 + 0.03) / (0.18 * (2.43 * 0.18 + 0.59) + 0.14), 1e-12);
  EXPECT_NEAR(ApplyToneCurve(0.18, ToneCurve::kFilmic), 0.2669, 1e-4);
  EXPECT_NEAR(ApplyToneCurve(1.0, ToneCurve::kFilmic), 0.8038, 1e-4);
  EXPECT_EQ(ApplyToneCurve(20, ToneCurve::kFilmic), 1.0);  // clamped shoulder
  double previous = 0;
  for (double x = 1e-3; x < 12; x *= 1.1) {  // monotonic: no value overtakes a brighter one
    EXPECT_GE(ApplyToneCurve(x, ToneCurve::kFilmic), previous) << x;
    previous = ApplyToneCurve(x, ToneCurve::kFilmic);
  }
  // Through EncodeSrgb8: 1.0 is no longer white, 4.0 is not clipped, 50 is.
  ImageF image(3, 1, 3);
  image.at(0, 0, 0) = 1.f;
  image.at(1, 0, 0) = 4.f;
  image.at(2, 0, 0) = 50.f;
  const std::vector<uint8_t> bytes = EncodeSrgb8(image, 1.0, ToneCurve::kFilmic);
  EXPECT_EQ(bytes[0], SrgbByte(ApplyToneCurve(1.0, ToneCurve::kFilmic)));
  EXPECT_LT(bytes[0], 240);
  EXPECT_LT(bytes[3], 255);
  EXPECT_EQ(bytes[6], 255);
}

TEST(LightFieldToneMap, NamesRoundTripAndUnknownOnesAreRefused) {
  for (ToneCurve c : {ToneCurve::kLinear, ToneCurve::kFilmic})
    EXPECT_EQ(ParseToneCurve(ToneCurveName(c), "--tone-map"), c);
  for (AutoExposure m : {AutoExposure::kOff, AutoExposure::kLit, AutoExposure::kP99})
    EXPECT_EQ(ParseAutoExposure(AutoExposureName(m), "--auto-exposure"), m);
  try {
    ParseToneCurve("aces", "--tone-map");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--tone-map"), std::string::npos) << e.what();
    EXPECT_EQ(e.exit_code(), 2);
  }
}

TEST(LightFieldToneMap, CompareImagesGivesRelativeL2AndWorstPixel) {
  ImageF reference(2, 1, 3, 1.f);
  reference.at(1, 0, 1) = 4.f;  // pixel 1's peak is 4
  ImageF image = reference;
  EXPECT_EQ(CompareImages(image, reference).relative_l2, 0);
  image.at(0, 0, 0) += 0.1f;  // pixel 0: 0.1 / 1
  image.at(1, 0, 0) += 0.2f;  // pixel 1: 0.2 / 4
  const ImageDifference d = CompareImages(image, reference);
  EXPECT_NEAR(d.relative_l2, std::sqrt((0.01 + 0.04) / (5 + 16)), 1e-6);
  EXPECT_NEAR(d.worst_pixel, 0.1, 1e-6);
}

}  // namespace
}  // namespace lumislab
