#include "core/srgbe.h"

#include <algorithm>
#include <cmath>

namespace lumislab {
namespace {
constexpr int kBias = 128;           // stored exponent e encodes 2^(e - 128)
constexpr int kMantissaScale = 128;  // 7-bit magnitude m/128
}  // namespace

const float kSrgbeMax = std::ldexp(127.0f / 128.0f, 127);
const float kSrgbeMinNormal = std::ldexp(0.5f, -kBias);

namespace {
float Sanitise(float x) {
  if (std::isnan(x)) return 0.f;
  return std::clamp(x, -kSrgbeMax, kSrgbeMax);  // +-Inf and huge values saturate
}
uint32_t Channel(float x, int exponent) {
  const int m = int(std::lround(std::ldexp(std::abs(x), -exponent) * kMantissaScale));
  return (x < 0 && m > 0 ? 0x80u : 0u) | uint32_t(std::min(m, 127));
}
}  // namespace

uint32_t EncodeSrgbe(float r, float g, float b) {
  r = Sanitise(r);
  g = Sanitise(g);
  b = Sanitise(b);
  const float max_abs = std::max({std::abs(r), std::abs(g), std::abs(b)});
  // Smallest exponent E with round(max_abs / 2^E * 128) <= 127, E in [-128, 127].
  int exponent = 0;
  std::frexp(max_abs, &exponent);  // max_abs in [2^(E-1), 2^E)
  if (max_abs == 0.f) return 0u;
  exponent = std::max(exponent, -kBias);
  if (std::lround(std::ldexp(max_abs, -exponent) * kMantissaScale) > 127) ++exponent;
  if (exponent > 255 - kBias) exponent = 255 - kBias;  // only reached by kSrgbeMax itself
  const uint32_t e = uint32_t(exponent + kBias);
  const uint32_t packed =
      Channel(r, exponent) | Channel(g, exponent) << 8 | Channel(b, exponent) << 16 | e << 24;
  // A triple entirely below the flush threshold encodes as exact zero.
  return (packed & 0x007f7f7fu) == 0 ? 0u : packed;
}

std::array<float, 3> DecodeSrgbe(uint32_t packed) {
  const int exponent = int(packed >> 24) - kBias;
  std::array<float, 3> rgb{};
  for (int c = 0; c < 3; ++c) {
    const uint32_t byte = (packed >> (8 * c)) & 0xffu;
    const float magnitude = std::ldexp(float(byte & 0x7fu) / kMantissaScale, exponent);
    rgb[c] = (byte & 0x80u) ? -magnitude : magnitude;
  }
  return rgb;
}

float SrgbeErrorBound(float r, float g, float b) {
  r = Sanitise(r);
  g = Sanitise(g);
  b = Sanitise(b);
  const float max_abs = std::max({std::abs(r), std::abs(g), std::abs(b)});
  // Rounding to nearest: half a step 2^(E-8), and max_abs >= 127.5 * 2^(E-8) once E is minimal.
  return std::max(max_abs / 127.5f, std::ldexp(1.0f, -kBias - 8));
}

}  // namespace lumislab
