// The accumulation on the screen: float or sRGBE-decoded, times the exposure, clamped to [0, 1]
// and sRGB-encoded.
#version 450 core
in vec2 v_uv;
uniform sampler2D u_float;
uniform usampler2D u_packed;
uniform bool u_srgbe;
uniform float u_exposure;
out vec4 o_colour;

#include "srgbe.glsl"

void main() {
  vec3 c = u_srgbe ? DecodeSrgbe(texture(u_packed, v_uv).r) : texture(u_float, v_uv).rgb;
  c = clamp(c * u_exposure, 0.0, 1.0);
  c = mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
  o_colour = vec4(c, 1.0);
}
