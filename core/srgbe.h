// sRGBE (paper §4.2, appendix A): signed RGB with a shared 8-bit exponent, packed into 32 bits.
// Each channel: sign bit + 7-bit mantissa; value = sign * m / 128 * 2^(e - 128).
//   0           -> all zero (decodes to +0)
//   denormals   -> flushed to 0 when below the smallest representable magnitude
//   huge / +-Inf-> clamped to +-kSrgbeMax (the largest finite value), sign kept
//   NaN         -> treated as 0 (never propagates into an accumulation)
// Error bound (rounded to nearest): every channel is within max(|r|,|g|,|b|)/127.5 of its input,
// or within 2^-136 (the flush-to-zero step) for tiny triples; sign is kept except for values that
// round to zero.
#pragma once

#include <array>
#include <cstdint>

namespace lumislab {

extern const float kSrgbeMax;
// 2^-129: the smallest magnitude of the largest channel that keeps a full 7-bit mantissa
// (m = 64 at the lowest exponent). Below it precision drops a bit per halving; the smallest
// nonzero magnitude is 2^-135 (m = 1), and a triple whose largest channel is under 2^-136
// encodes as zero.
extern const float kSrgbeMinNormal;

uint32_t EncodeSrgbe(float r, float g, float b);
std::array<float, 3> DecodeSrgbe(uint32_t packed);
// Absolute per-channel error bound for an encoded triple: max(max|x|/127.5, 2^-136).
float SrgbeErrorBound(float r, float g, float b);

}  // namespace lumislab
