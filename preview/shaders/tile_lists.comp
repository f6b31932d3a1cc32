// Light culling by tiles, once per light pass: per tile, the pass's lights whose E' support can
// meet a + c t over the tile's ranges (tile_bounds.comp), as [near count, far count, near ...,
// far ...]; light_pass.glsl's loop runs over its tile's list.
#version 450 core
layout(local_size_x = 64) in;
uniform int u_tile_count;
uniform int u_tile_stride;
uniform int u_count;
uniform int u_near_end;   // lights [0, u_near_end) go to the near list
uniform int u_far_begin;  // lights [u_far_begin, u_count) to the far list
uniform vec4 u_lights[LIGHTS_PER_PASS];  // xy: the light's centre (as the light pass's)
// Where each light's E' may be non-zero, in window coordinates (mm): st.x in [x, z], st.y in
// [y, w] (the support widened by the filter's reach and a margin for rounding).
uniform vec4 u_support[LIGHTS_PER_PASS];
layout(std430, binding = 3) readonly buffer TileBounds { vec4 tile_bounds[]; };
layout(std430, binding = 2) writeonly buffer TileLightLists { uint tile_lists[]; };
bool Reaches(int k, vec3 lo, vec3 hi) {
  const vec2 c_lo = u_lights[k].xy * lo.z, c_hi = u_lights[k].xy * hi.z;  // c t at t's ends
  const vec2 st_lo = lo.xy + min(c_lo, c_hi), st_hi = hi.xy + max(c_lo, c_hi);
  return all(lessThanEqual(st_lo, u_support[k].zw)) &&
         all(greaterThanEqual(st_hi, u_support[k].xy));
}
void main() {
  const int tile = int(gl_GlobalInvocationID.x);
  if (tile >= u_tile_count) return;
  const vec3 lo = tile_bounds[2 * tile].xyz, hi = tile_bounds[2 * tile + 1].xyz;
  const int base = tile * u_tile_stride;
  int n = 0;
  if (lo.z <= hi.z) {
    for (int k = 0; k < u_near_end; ++k)
      if (Reaches(k, lo, hi)) tile_lists[base + 2 + n++] = uint(k);
  }
  const int near_count = n;
  if (lo.z <= hi.z) {
    for (int k = u_far_begin; k < u_count; ++k)
      if (Reaches(k, lo, hi)) tile_lists[base + 2 + n++] = uint(k);
  }
  tile_lists[base] = uint(near_count);
  tile_lists[base + 1] = uint(n - near_count);
}
