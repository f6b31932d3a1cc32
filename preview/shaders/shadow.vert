// Shadow maps drawn in one instanced draw: instance k draws into layer u_maps[k].z the map seen
// from centre u_maps[k].xy, inside scissor rectangle k (gl_Layer and gl_ViewportIndex written by
// the vertex shader, which needs ARB_shader_viewport_layer_array: the renderer inserts the
// extension and LAYERED after the first line where the driver has it). Without it (LAYERED
// undefined) each map is its own draw of one instance into the layer attached. The renderer
// replaces SHADOW_BATCH by kShadowBatch, the maps per draw, before compiling.
#version 450 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_scene_to_luminaire;
uniform vec4 u_maps[SHADOW_BATCH];

#include "light_clip.glsl"

void main() {
  vec4 map = u_maps[gl_InstanceID];
#ifdef LAYERED
  gl_Layer = int(map.z);
  gl_ViewportIndex = gl_InstanceID;  // its scissor rectangle
#endif
  gl_Position = LightClip((u_scene_to_luminaire * vec4(a_position, 1.0)).xyz, map.xy);
}
