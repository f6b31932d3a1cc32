// Light culling by tiles, once per view (and per orientation of a luminaire folder): per tile of TILE x TILE pixels of the G-buffer, the
// ranges of a = x.xy d / z and t = 1 - d / z over its points (a point x is seen from centre c
// through the window at st = a + c t); tile_lists.comp lists the lights from them.
#version 450 core
layout(local_size_x = 64) in;
uniform sampler2D u_gbuffer_position;
uniform float u_d;
uniform ivec2 u_tiles;
// The light pass's capture frame from the luminaire frame (a luminaire folder's orientation; the
// identity for one slab).
uniform mat4 u_capture_from_luminaire;
// Per tile: (a.x, a.y, t) smallest, then largest; smallest > largest where no point has z > 0.
layout(std430, binding = 3) writeonly buffer TileBounds { vec4 tile_bounds[]; };
void main() {
  const int tile = int(gl_GlobalInvocationID.x);
  if (tile >= u_tiles.x * u_tiles.y) return;
  const ivec2 origin = TILE * ivec2(tile % u_tiles.x, tile / u_tiles.x);
  const ivec2 last = textureSize(u_gbuffer_position, 0) - 1;
  vec3 lo = vec3(3.0e38), hi = vec3(-3.0e38);
  for (int y = 0; y < TILE; ++y)
    for (int x = 0; x < TILE; ++x) {
      // Clamped to the image: an edge tile repeats its own last pixels.
      vec4 p = texelFetch(u_gbuffer_position, min(origin + ivec2(x, y), last), 0);
      if (p.w == 0.0) continue;
      p.xyz = (u_capture_from_luminaire * vec4(p.xyz, 1.0)).xyz;
      if (p.z <= 0.0) continue;
      const float s = u_d / p.z;
      const vec3 v = vec3(p.xy * s, 1.0 - s);
      lo = min(lo, v);
      hi = max(hi, v);
    }
  tile_bounds[2 * tile] = vec4(lo, 0.0);
  tile_bounds[2 * tile + 1] = vec4(hi, 0.0);
}
