#include "core/srgbe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace lumislab {
namespace {

void ExpectWithinBound(float r, float g, float b) {
  const auto d = DecodeSrgbe(EncodeSrgbe(r, g, b));
  const float bound = SrgbeErrorBound(r, g, b);
  const float in[3] = {r, g, b};
  for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(d[c] - in[c]), bound) << r << " " << g << " " << b;
}

TEST(SrgbeTest, RoundTripWithinStatedBound) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> mantissa(-1.f, 1.f);
  std::uniform_int_distribution<int> exponent(-120, 120);
  for (int n = 0; n < 200000; ++n) {
    const int e = exponent(rng);
    // Channels spread over a few orders of magnitude around a common scale.
    ExpectWithinBound(std::ldexp(mantissa(rng), e), std::ldexp(mantissa(rng), e - 3),
                      std::ldexp(mantissa(rng), e + 2));
  }
}

TEST(SrgbeTest, BoundIsTight) {
  // The relative error of the largest channel reaches close to 1/255 somewhere, never above.
  float worst = 0;
  for (float x = 1.0f; x < 2.0f; x += 1e-4f) {
    const float y = DecodeSrgbe(EncodeSrgbe(x, 0, 0))[0];
    worst = std::max(worst, std::abs(y - x) / x);
  }
  EXPECT_LE(worst, 1 / 127.5f);
  EXPECT_GT(worst, 0.5f / 128);
}

TEST(SrgbeTest, ZeroIsExact) {
  EXPECT_EQ(EncodeSrgbe(0, 0, 0), 0u);
  EXPECT_EQ(EncodeSrgbe(-0.f, 0, -0.f), 0u);
  const auto d = DecodeSrgbe(0);
  EXPECT_EQ(d[0], 0.f);
  EXPECT_EQ(d[1], 0.f);
  EXPECT_EQ(d[2], 0.f);
}

TEST(SrgbeTest, DenormalsFlushOrKeepSign) {
  const float denorm = std::numeric_limits<float>::denorm_min();
  EXPECT_EQ(EncodeSrgbe(denorm, -denorm, denorm), 0u);  // below the flush threshold
  // The smallest denormal-range values that are representable keep their magnitude roughly.
  const float small = std::ldexp(1.0f, -129);  // 2^-129, a denormal
  const auto d = DecodeSrgbe(EncodeSrgbe(small, -small, 0));
  EXPECT_NEAR(d[0], small, SrgbeErrorBound(small, small, 0));
  EXPECT_LT(d[1], 0.f);
  ExpectWithinBound(small, -small, 0);
}

TEST(SrgbeTest, HugeAndInfinitySaturateWithSign) {
  const float inf = std::numeric_limits<float>::infinity();
  auto d = DecodeSrgbe(EncodeSrgbe(inf, -inf, 1.f));
  EXPECT_FLOAT_EQ(d[0], kSrgbeMax);
  EXPECT_FLOAT_EQ(d[1], -kSrgbeMax);
  EXPECT_EQ(d[2], 0.f);  // 1 is far below the shared exponent's resolution
  d = DecodeSrgbe(EncodeSrgbe(std::numeric_limits<float>::max(), 0, 0));
  EXPECT_FLOAT_EQ(d[0], kSrgbeMax);
  EXPECT_TRUE(std::isfinite(d[0]));
}

TEST(SrgbeTest, NanBecomesZeroAndDoesNotPoisonOtherChannels) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto d = DecodeSrgbe(EncodeSrgbe(nan, 2.f, -0.5f));
  EXPECT_EQ(d[0], 0.f);
  EXPECT_NEAR(d[1], 2.f, SrgbeErrorBound(0, 2, 0.5));
  EXPECT_NEAR(d[2], -0.5f, SrgbeErrorBound(0, 2, 0.5));
  EXPECT_EQ(EncodeSrgbe(nan, nan, nan), 0u);
}

TEST(SrgbeTest, SignsAreKept) {
  const auto d = DecodeSrgbe(EncodeSrgbe(-3.f, 1.5f, -0.25f));
  EXPECT_LT(d[0], 0.f);
  EXPECT_GT(d[1], 0.f);
  EXPECT_LT(d[2], 0.f);
}

}  // namespace
}  // namespace lumislab
