// Tone mapping to 8-bit sRGB buffers, automatic exposure, and the image comparison.
#include "lib/lightfield/tone_map.h"

#include <gtest/gtest.h>

#include <cmath>

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

TEST(LightFieldToneMap, AutomaticExposurePutsThe99thPercentileAt08) {
  ImageF image(100, 10, 3);
  for (int k = 0; k < 1000; ++k) image.data[3 * k + (k % 3)] = float(k + 1);  // max channel k+1
  // 99th percentile of 1..1000 (nth_element at index 990) is 991.
  EXPECT_NEAR(ExposureFactor(image, 0, true), 0.8 / 991, 1e-12);
  EXPECT_NEAR(ExposureFactor(image, 1, true), 2 * 0.8 / 991, 1e-12);
  EXPECT_EQ(ExposureFactor(image, -2, false), 0.25);
  EXPECT_EQ(ExposureFactor(ImageF(4, 4, 3), 1, true), 2.0);  // black: stops only
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
