// sRGBE packing (core/srgbe.h): signed RGB with a shared 8-bit exponent in 32 bits, each channel
// a sign bit and a 7-bit mantissa. The sRGBE accumulation decodes the sum so far, adds and encodes.
uint EncodeChannel(float x, int e) {
  uint m = uint(min(floor(ldexp(abs(x), -e) * 128.0 + 0.5), 127.0));
  return (x < 0.0 && m > 0u) ? (m | 0x80u) : m;
}
uint EncodeSrgbe(vec3 c) {
  c = clamp(c, vec3(-1.7e38), vec3(1.7e38));
  float m = max(max(abs(c.r), abs(c.g)), abs(c.b));
  if (!(m > 0.0)) return 0u;
  int e;
  frexp(m, e);
  e = max(e, -128);
  if (floor(ldexp(m, -e) * 128.0 + 0.5) > 127.0) e += 1;
  e = min(e, 127);
  uint word = EncodeChannel(c.r, e) | (EncodeChannel(c.g, e) << 8) |
                (EncodeChannel(c.b, e) << 16) | (uint(e + 128) << 24);
  return (word & 0x007f7f7fu) == 0u ? 0u : word;
}
vec3 DecodeSrgbe(uint p) {
  int e = int(p >> 24) - 128;
  vec3 rgb;
  for (int k = 0; k < 3; ++k) {
    uint b = (p >> (8 * k)) & 0xffu;
    float v = ldexp(float(b & 0x7fu) / 128.0, e);
    rgb[k] = (b & 0x80u) != 0u ? -v : v;
  }
  return rgb;
}
