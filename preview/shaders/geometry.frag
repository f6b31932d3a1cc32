// The G-buffer: what each pixel sees, in the luminaire frame (position, with w = 1 where a
// surface was seen; unit normal; albedo). The light passes read it.
#version 450 core
in vec3 v_lum_position;
in vec3 v_lum_normal;
in vec3 v_albedo;
layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_albedo;
void main() {
  o_position = vec4(v_lum_position, 1.0);
  o_normal = vec4(normalize(v_lum_normal), 0.0);
  o_albedo = vec4(v_albedo, 1.0);
}
