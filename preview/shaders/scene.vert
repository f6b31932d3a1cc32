// The scene as the camera sees it, for the G-buffer (geometry.frag): clip position from the
// camera, and the point's position, normal and albedo in the luminaire frame.
#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_albedo;
uniform mat4 u_view_projection;
uniform mat4 u_scene_to_luminaire;
out vec3 v_lum_position;
out vec3 v_lum_normal;
out vec3 v_albedo;
invariant gl_Position;
void main() {
  gl_Position = u_view_projection * vec4(a_position, 1.0);
  v_lum_position = (u_scene_to_luminaire * vec4(a_position, 1.0)).xyz;
  v_lum_normal = mat3(u_scene_to_luminaire) * a_normal;
  v_albedo = a_albedo;
}
