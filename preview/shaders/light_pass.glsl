// The light pass: a full-screen pass that shades what the G-buffer holds (geometry.frag), one
// fragment per pixel (drawing the scene again instead would run the light loop for every 4 x 4
// block each visible triangle touches). Compiled with the options as #defines after the first
// line (Renderer::LightProgram): a fragment shader, or with EXACT_LIST a compute shader that
// shades the pixels coarse shading's resolve or reprojection listed.
#version 450 core
uniform sampler2D u_gbuffer_position;  // luminaire frame, w = 1 where a surface was seen
uniform sampler2D u_gbuffer_normal;    // unit normal, luminaire frame
uniform sampler2D u_gbuffer_albedo;
uniform sampler2DArray u_intensity;
uniform sampler2DArrayShadow u_shadow;
uniform int u_count;
// Light k of this pass: u_lights[k].xy its centre c, .zw the centre its shadow map was rendered
// from; u_light_layers[k].x its E' layer, .y its shadow map's layer, .z and .w its shadow span
// (below). Packed in vec4s: an array of vec2 or int may take a vec4 slot per element, and a
// driver's uniform limit for compute shaders can be 2048 components (128 lights: 1024 here).
uniform vec4 u_lights[LIGHTS_PER_PASS];
uniform ivec4 u_light_layers[LIGHTS_PER_PASS];
#if FAST
// Shortcuts: each light's shadow map (a shared map lies in another layer and was rendered from
// its block's centre); lights [0, u_near_end) shade receivers nearer than u_z_far, lights
// [u_far_begin, u_count) the others (the merged lights replace their members there).
// A merged light's visibility is the mean of its members' (entries u_light_layers[k].z ..
// + .w - 1; a single light: its own entry).
uniform int u_near_end;
uniform int u_far_begin;
uniform float u_z_far;
#endif
uniform float u_offset_scale;  // normal offset per mm of distance (1.5 shadow texels)
uniform float u_radiance_scale;
uniform bool u_unit_albedo;  // irradiance view (false colour): E before the materials
uniform usampler2D u_previous;
uniform vec2 u_grid_half;  // half extent of the filter centres: the union of all spot cones
#if COARSE
// Coarse shading, first pass: the lights' sum at every second pixel of every second row (pixel
// 2 gl_FragCoord), before albedo and radiance scale; 0 where nothing is lit.
layout(location = 0) out vec4 o_coarse;
#elif !EXACT_LIST
layout(location = 0) out vec4 o_float;
layout(location = 1) out uint o_packed;
#endif
#if RESOLVE || REPROJECT
uniform sampler2D u_source;       // the sums reused: the coarse samples, or the last full frame's
uniform float u_reuse_tolerance;  // largest spread of four sums, relative to their peak
#endif
#if REPROJECT
uniform sampler2D u_source_position;  // the last full frame's G-buffer
uniform sampler2D u_source_normal;
uniform mat4 u_source_from_luminaire;  // its clip coordinates of a luminaire-frame point
#endif
#if RESOLVE || REPROJECT
// Row 4 of the sources' view's clip-from-luminaire matrix: a point's depth (clip w) there.
uniform vec4 u_depth_row;
#endif
#if !COARSE && !EXACT_LIST
layout(location = 2) out vec4 o_irradiance;  // the sum alone (before albedo), reused by REPROJECT
#endif
#if RESOLVE || REPROJECT || EXACT_LIST
// The pixels that coarse shading's resolve pass or reprojection do not take from their samples:
// those passes list them (x | y << 16) and a compute pass (EXACT_LIST) shades them, all its
// invocations busy (a fragment pass would run the light loop for every 4 x 4 block holding one
// such pixel).
layout(std430, binding = 0) buffer ExactCount { uint count; };
layout(std430, binding = 1) buffer ExactList { uint exact_pixels[]; };
#endif
#if TILED
// Light culling by tiles of TILE x TILE pixels (tile_lists.comp): per tile, this pass's lights
// whose E' can be non-zero at one of its pixels, [near count, far count, near ..., far ...] from
// tile_lists[u_tile_stride * tile]; the far list is empty without the shortcuts.
layout(std430, binding = 2) readonly buffer TileLightLists { uint tile_lists[]; };
uniform int u_tiles_x;
uniform int u_tile_stride;
#endif
#if EXACT_LIST
layout(local_size_x = 64) in;
layout(rgba32f, binding = 0) uniform image2D u_accumulation;  // float mode
layout(r32ui, binding = 1) uniform uimage2D u_packed_sum;     // sRGBE mode: the new sum
layout(rgba32f, binding = 2) uniform image2D u_irradiance;    // o_irradiance's target
#endif

#include "light_clip.glsl"

#include "srgbe.glsl"

#if POSED
// A luminaire folder's orientations (docs/method.md §4.12): the G-buffer holds the luminaire
// frame; this pass's lights are orientation u_orientation's, shaded in its capture frame
// (x_capture = R x + centre), each sum weighted per direction w = x / |x| (luminaire frame, from
// its origin) by t_k / sum_j t_j, t_j = ConeTaper(cone_j, R_j w) over the orientations with a
// position present (.w of u_orientation_cone: 1). Where no cone holds w (all t_j = 0), the
// orientation with the largest margin (the first of equals) adds its light alone: continuous at
// the cones' edges, and never twice.
uniform mat4 u_capture_from_luminaire;
uniform int u_orientation;
uniform mat3 u_orientation_rotation[ORIENTATIONS];  // R_j
uniform vec4 u_orientation_cone[ORIENTATIONS];      // d, half-width, half-height (mm), present
uniform float u_taper_deg;

#include "cone_taper.glsl"

float BlendWeight(vec3 x) {
  const vec3 w = normalize(x);
  float own = 0.0, sum = 0.0, best = -1.0e30;
  int best_j = -1;
  for (int j = 0; j < ORIENTATIONS; ++j) {
    if (u_orientation_cone[j].w == 0.0) continue;
    const float margin = ConeMarginDeg(u_orientation_cone[j].xyz, u_orientation_rotation[j] * w);
    const float t = TaperOfMargin(margin, u_taper_deg);
    sum += t;
    if (j == u_orientation) own = t;
    if (margin > best) {
      best = margin;
      best_j = j;
    }
  }
  return sum > 0.0 ? own / sum : (best_j == u_orientation ? 1.0 : 0.0);
}
#endif

// E'_ij at texture coordinate uv of layer `layer`, reconstructed from the texel centres as
// --texture-filter says: bilinear through the hardware (the paper's), the nearest texel, or
// Catmull-Rom (4 x 4 texels, interpolating, cubic in each axis). Edges are clamped as the
// bilinear filter's CLAMP_TO_EDGE.
vec3 TexelClamped(ivec2 t, ivec2 size, int layer) {
  return texelFetch(u_intensity, ivec3(clamp(t, ivec2(0), size - 1), layer), 0).rgb;
}
vec4 CatmullRom(float f) {
  float f2 = f * f, f3 = f2 * f;
  return vec4(-0.5 * f3 + f2 - 0.5 * f, 1.5 * f3 - 2.5 * f2 + 1.0, -1.5 * f3 + 2.0 * f2 + 0.5 * f,
              0.5 * f3 - 0.5 * f2);
}
vec3 SampleIntensity(vec2 uv, int layer) {
#if TEXTURE_FILTER == 0
  return texture(u_intensity, vec3(uv, float(layer))).rgb;
#else
  ivec2 size = textureSize(u_intensity, 0).xy;
  vec2 p = uv * vec2(size) - 0.5;  // texel-centre coordinates
#if TEXTURE_FILTER == 1
  return TexelClamped(ivec2(floor(p + 0.5)), size, layer);
#else
  ivec2 base = ivec2(floor(p));
  vec2 f = p - vec2(base);
  vec4 wx = CatmullRom(f.x), wy = CatmullRom(f.y);
  vec3 sum = vec3(0.0);
  for (int b = 0; b < 4; ++b) {
    vec3 row = vec3(0.0);
    for (int a = 0; a < 4; ++a) row += wx[a] * TexelClamped(base + ivec2(a - 1, b - 1), size, layer);
    sum += wy[b] * row;
  }
  return sum;
#endif
#endif
}

// Outside every spot light's cone (behind S, or not through the window from any c_ij): no light.
// x: luminaire frame (POSED: taken to the pass's capture frame first).
bool Dark(vec3 x) {
#if POSED
  x = (u_capture_from_luminaire * vec4(x, 1.0)).xyz;
#endif
  vec2 reach = 0.5 * u_window + u_grid_half * abs(1.0 - u_d / max(x.z, 1e-6));
  return x.z <= 0.0 || any(greaterThan(abs(x.xy) * (u_d / max(x.z, 1e-6)), reach));
}

// The sum over this pass's lights at surface point x (normal n), luminaire frame (POSED: taken to
// the pass's capture frame, the sum weighted by BlendWeight). Every c_ij
// lies at z = 0, so what depends on x alone is computed once: rel.z = x.z for every light, the
// point's projection through the window st = c + (x.xy - c) d / z = x.xy d / z + c (1 - d / z)
// is linear in c, and cos_emit cos_recv / delta^2 = z (n . (c - x)) / delta^4 needs no root.
vec3 ShadeLights(vec3 x, vec3 n, ivec2 pixel) {
  vec3 sum = vec3(0.0);
#if POSED
  const float weight = BlendWeight(x);
  if (weight == 0.0) return sum;
  x = (u_capture_from_luminaire * vec4(x, 1.0)).xyz;
  n = mat3(u_capture_from_luminaire) * n;
#endif
  if (x.z <= 0.0) return sum;  // behind S: no light reaches it
  const float s = u_d / x.z;
  const vec2 uv_x = vec2(0.5, 0.5) + x.xy * s / vec2(u_window.x, -u_window.y);
  const vec2 uv_c = (1.0 - s) / vec2(u_window.x, -u_window.y);  // per mm of c
  const float n_dot_x = dot(n, x);
  const float z2 = x.z * x.z;
  const float z_scaled = x.z * 1.0e6;
#if FAST
  const bool far = x.z >= u_z_far;
#endif
#if TILED
  // The loop runs over the tile's list: the same count for the pixels shaded side by side (a
  // skipped light would add E' = 0, so the sum is the same bit for bit).
  const int base = ((pixel.y / TILE) * u_tiles_x + pixel.x / TILE) * u_tile_stride;
  const int near_count = int(tile_lists[base]);
#if FAST
  const int first = base + 2 + (far ? near_count : 0);
  const int last = first + (far ? int(tile_lists[base + 1]) : near_count);
#else
  const int first = base + 2, last = first + near_count;
#endif
  for (int i = first; i < last; ++i) {
    const int k = int(tile_lists[i]);
#elif FAST
  const int first = far ? u_far_begin : 0;
  const int last = far ? u_count : u_near_end;
  for (int k = first; k < last; ++k) {
#else
  for (int k = 0; k < u_count; ++k) {
#endif
    const vec2 c = u_lights[k].xy;
    const float recv = dot(n.xy, c) - n_dot_x;  // -n . rel, rel = x - c: delta cos_recv
    if (recv <= 0.0) continue;
    const vec2 uv = uv_x + c * uv_c;
    if (any(greaterThan(abs(uv - 0.5), vec2(0.5)))) continue;
    const vec2 rxy = x.xy - c;
    const float delta2 = dot(rxy, rxy) + z2;
    float visible = 1.0;
#if SHADOWS
    {
      // The map's coordinates of the offset point, as the maps were drawn (LightClip).
      const vec3 p = x + n * (u_offset_scale * sqrt(delta2));
#if FAST
      visible = 0.0;
      const int begin = u_light_layers[k].z, end = begin + u_light_layers[k].w;
      for (int m = begin; m < end; ++m) {
        const vec4 clip = LightClip(p, u_lights[m].zw);
        const vec3 ndc = clip.xyz / clip.w;
        visible += texture(u_shadow, vec4(0.5 * ndc.xy + 0.5, float(u_light_layers[m].y),
                                          0.5 * ndc.z + 0.5));
      }
      if (u_light_layers[k].w > 1) visible /= float(u_light_layers[k].w);
#else
      const vec4 clip = LightClip(p, c);
      const vec3 ndc = clip.xyz / clip.w;
      visible = texture(u_shadow, vec4(0.5 * ndc.xy + 0.5, float(u_light_layers[k].x),
                                       0.5 * ndc.z + 0.5));
#endif
    }
#endif
    vec3 intensity = SampleIntensity(uv, u_light_layers[k].x);
    sum += visible * intensity * (z_scaled * recv / (delta2 * delta2));
  }
#if POSED
  sum *= weight;
#endif
  return sum;
}

#if RESOLVE || REPROJECT
// The pixel's sum taken from four source samples around source coordinate q (texels, centres at
// integers), bilinear: when every sample with a weight saw a point of the pixel's own surface and
// their sums spread by at most u_reuse_tolerance of their largest magnitude in every channel, so
// the light varies smoothly there. Own surface: normals within 25 degrees, off the pixel's
// tangent plane by under a quarter of their distance, and the samples' 1/depth in the source
// view, interpolated at q (linear across a plane there), within 1 % of the pixel point's (so a
// surface in front of it, seen at a grazing angle, is not taken). False elsewhere (edges of
// objects, shadows and spots): the pixel is shaded exactly. Not seen: a lit or shadowed sliver
// narrower than the samples' spacing whose four samples agree. Sources: RESOLVE, the coarse
// samples (sample s at pixel 2 s of the G-buffer); REPROJECT, the last view shaded in full (its
// own G-buffer). depth: the pixel point's clip w in the source's view.
bool Reused(vec2 q, vec3 x, vec3 n, float depth, out vec3 sum) {
  sum = vec3(0.0);
  const ivec2 size = textureSize(u_source, 0);
  // In float first: a huge or NaN q has no defined integer conversion.
  if (!(all(greaterThanEqual(q, vec2(0.0))) && all(lessThanEqual(q, vec2(size - 1)))))
    return false;
  const ivec2 base = ivec2(floor(q));
  const vec2 f = q - vec2(base);
  vec3 lo = vec3(3.0e38), hi = vec3(-3.0e38);
  float inverse_depth = 0.0;
  for (int k = 0; k < 4; ++k) {
    const ivec2 corner = ivec2(k & 1, k >> 1);
    const float w = ((k & 1) != 0 ? f.x : 1.0 - f.x) * ((k & 2) != 0 ? f.y : 1.0 - f.y);
    if (w == 0.0) continue;
    const ivec2 s = base + corner;
    if (any(greaterThan(s, size - 1))) return false;
#if RESOLVE
    const vec4 p = texelFetch(u_gbuffer_position, 2 * s, 0);
    const vec3 ns = texelFetch(u_gbuffer_normal, 2 * s, 0).xyz;
#else
    const vec4 p = texelFetch(u_source_position, s, 0);
    const vec3 ns = texelFetch(u_source_normal, s, 0).xyz;
#endif
    const vec3 d = p.xyz - x;
    if (p.w == 0.0 || dot(n, ns) < 0.9 || abs(dot(n, d)) > 0.25 * length(d) + 1e-3) return false;
    inverse_depth += w / dot(u_depth_row, vec4(p.xyz, 1.0));
    const vec3 e = texelFetch(u_source, s, 0).rgb;
    lo = min(lo, e);
    hi = max(hi, e);
    sum += w * e;
  }
  if (!(abs(inverse_depth * depth - 1.0) <= 0.01)) return false;
  const vec3 peak = max(abs(lo), abs(hi));
  return all(lessThanEqual(hi - lo, u_reuse_tolerance * vec3(max(peak.r, max(peak.g, peak.b)))));
}
#endif

vec3 Radiance(vec3 sum, ivec2 pixel) {
  return sum * (u_unit_albedo ? vec3(1.0) : texelFetch(u_gbuffer_albedo, pixel, 0).rgb) *
         u_radiance_scale;
}

#if EXACT_LIST
void main() {
  // Work groups of 64 in rows of at most 65535 (the smallest GL_MAX_COMPUTE_WORK_GROUP_COUNT).
  const uint k = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u +
                 gl_LocalInvocationIndex;
  if (k >= count) return;
  const ivec2 pixel = ivec2(exact_pixels[k] & 0xffffu, exact_pixels[k] >> 16);
  const vec3 sum = ShadeLights(texelFetch(u_gbuffer_position, pixel, 0).xyz,
                               texelFetch(u_gbuffer_normal, pixel, 0).xyz, pixel);
  imageStore(u_irradiance, pixel, imageLoad(u_irradiance, pixel) + vec4(sum, 0.0));
  const vec3 radiance = Radiance(sum, pixel);
#if SRGBE
  // Carried by RESOLVE or REPROJECT.
  const vec3 previous = DecodeSrgbe(imageLoad(u_packed_sum, pixel).r);
  imageStore(u_packed_sum, pixel, uvec4(EncodeSrgbe(previous + radiance)));
#else
  imageStore(u_accumulation, pixel, imageLoad(u_accumulation, pixel) + vec4(radiance, 0.0));
#endif
}
#else
void main() {
#if COARSE
  const ivec2 pixel = 2 * ivec2(gl_FragCoord.xy);
  const vec4 surface = texelFetch(u_gbuffer_position, pixel, 0);
  if (surface.w == 0.0 || Dark(surface.xyz)) {
    o_coarse = vec4(0.0);
    return;
  }
  o_coarse =
      vec4(ShadeLights(surface.xyz, texelFetch(u_gbuffer_normal, pixel, 0).xyz, pixel), 1.0);
#else
  const ivec2 pixel = ivec2(gl_FragCoord.xy);
  const vec4 surface = texelFetch(u_gbuffer_position, pixel, 0);
  if (surface.w == 0.0) discard;  // no surface: both sRGBE targets keep their cleared 0
  const vec3 x = surface.xyz;
  const vec3 n = texelFetch(u_gbuffer_normal, pixel, 0).xyz;
  // In float mode a dark fragment is dropped before the light loop (it adds 0 anyway).
#if !SRGBE
  if (Dark(x)) discard;
#endif
  vec3 sum;
#if RESOLVE || REPROJECT
#if RESOLVE
  const vec2 q = 0.5 * vec2(pixel);
#else
  const vec4 clip = u_source_from_luminaire * vec4(x, 1.0);
  const vec2 q = clip.w > 0.0 ? (0.5 * clip.xy / clip.w + 0.5) * vec2(textureSize(u_source, 0)) - 0.5
                              : vec2(-1.0);
#endif
  if (!Reused(q, x, n, dot(u_depth_row, vec4(x, 1.0)), sum)) {
    exact_pixels[atomicAdd(count, 1u)] = uint(pixel.x) | (uint(pixel.y) << 16);
#if !SRGBE
    discard;
#endif
    sum = vec3(0.0);  // sRGBE: the previous sum is carried, the compute pass adds to it
  }
#else
  sum = ShadeLights(x, n, pixel);
#endif
  const vec3 radiance = Radiance(sum, pixel);
  o_float = vec4(radiance, 1.0);
  o_irradiance = vec4(sum, 1.0);
#if SRGBE
  vec3 previous = DecodeSrgbe(texelFetch(u_previous, ivec2(gl_FragCoord.xy), 0).r);
  o_packed = EncodeSrgbe(previous + radiance);
#else
  o_packed = 0u;
#endif
#endif
}
#endif
