// cone_taper.glsl at a list of directions, for the test that pins it equal to core's ConeTaper
// (Renderer-free: ShaderConeTaper in renderer_orientations.cc).
#version 450 core
layout(local_size_x = 64) in;
uniform vec3 u_cone;  // d, half-width, half-height (mm)
uniform float u_taper_deg;
uniform int u_count;
layout(std430, binding = 0) readonly buffer Directions { vec4 directions[]; };
layout(std430, binding = 1) writeonly buffer Tapers { float tapers[]; };

#include "cone_taper.glsl"

void main() {
  const int k = int(gl_GlobalInvocationID.x);
  if (k >= u_count) return;
  tapers[k] = ConeTaper(u_cone, directions[k].xyz, u_taper_deg);
}
