#include "preview/renderer.h"

#include <glad/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "core/srgbe.h"

namespace lumislab {
namespace {

constexpr double kShadowNear = 10.0;  // mm: occluders nearer to c_ij than this are ignored
constexpr double kShadowFar = 100000.0;
// The shadow maps' depth mapping (u_depth in LightClip): NDC z = A + B / z between those planes.
constexpr double kShadowDepthA = (kShadowFar + kShadowNear) / (kShadowFar - kShadowNear);
constexpr double kShadowDepthB = -2 * kShadowFar * kShadowNear / (kShadowFar - kShadowNear);

const char* kSceneVertex = R"(#version 450 core
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
)";

const char* kEmptyFragment = R"(#version 450 core
void main() {}
)";

// Clip coordinates of luminaire-frame point x seen from c (z = 0): xy of NDC = slab texture
// coordinates 2u-1, 2v-1 (u from -W/2, v from +H/2), so shadow maps share the slab texel layout.
const char* kLightClip = R"(
uniform float u_d;
uniform vec2 u_window;  // W, H (mm)
uniform vec2 u_depth;   // A, B of the depth mapping
vec4 LightClip(vec3 x, vec2 c) {
  vec3 rel = x - vec3(c, 0.0);
  return vec4(2.0 * u_d / u_window.x * rel.x + 2.0 * c.x / u_window.x * rel.z,
              -2.0 * u_d / u_window.y * rel.y - 2.0 * c.y / u_window.y * rel.z,
              u_depth.x * rel.z + u_depth.y, rel.z);
}
)";

// Shadow maps drawn in one instanced draw: instance k draws into layer u_maps[k].z the map seen
// from centre u_maps[k].xy, inside scissor rectangle k (gl_Layer and gl_ViewportIndex written by
// the vertex shader, which needs ARB_shader_viewport_layer_array; one draw instead of one per map
// saved ~1 ms of ~17 on llvmpipe, more where a draw costs more). Without the extension (LAYERED
// undefined) each map is its own draw of one instance into the layer attached.
constexpr int kShadowBatch = 32;  // maps per draw (the size of u_maps)
std::string ShadowVertex(bool layered) {
  return std::string("#version 450 core\n") +
         (layered ? "#extension GL_ARB_shader_viewport_layer_array : require\n#define LAYERED\n"
                  : "") +
         R"(layout(location = 0) in vec3 a_position;
uniform mat4 u_scene_to_luminaire;
uniform vec4 u_maps[)" +
         std::to_string(kShadowBatch) + "];\n" + kLightClip + R"(
void main() {
  vec4 map = u_maps[gl_InstanceID];
#ifdef LAYERED
  gl_Layer = int(map.z);
  gl_ViewportIndex = gl_InstanceID;  // its scissor rectangle
#endif
  gl_Position = LightClip((u_scene_to_luminaire * vec4(a_position, 1.0)).xyz, map.xy);
}
)";
}

bool HasExtension(const char* name) {
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint k = 0; k < n; ++k) {
    const char* e = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(k)));
    if (e && std::strcmp(e, name) == 0) return true;
  }
  return false;
}

const char* kSrgbeCode = R"(
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
)";

// Deferred: a full-screen pass that shades what the G-buffer holds (kGeometryFragment), one
// fragment per pixel. (Drawing the scene again instead runs the light loop for every 4 x 4 block
// each visible triangle touches: on llvmpipe the cloister's light pass then cost nearly as much
// at 400 x 400 as at 800 x 800.)
const std::string kLightFragment = std::string(R"(#version 450 core
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
uniform float u_offset_scale;  // normal offset per mm of distance (one shadow texel)
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
// Light culling by tiles of kTile x kTile pixels (TileLists below): per tile, this pass's lights
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
)") + kLightClip + kSrgbeCode + R"(
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
bool Dark(vec3 x) {
  vec2 reach = 0.5 * u_window + u_grid_half * abs(1.0 - u_d / max(x.z, 1e-6));
  return x.z <= 0.0 || any(greaterThan(abs(x.xy) * (u_d / max(x.z, 1e-6)), reach));
}

// The sum over this pass's lights at surface point x (normal n), luminaire frame. Every c_ij
// lies at z = 0, so what depends on x alone is computed once: rel.z = x.z for every light, the
// point's projection through the window st = c + (x.xy - c) d / z = x.xy d / z + c (1 - d / z)
// is linear in c, and cos_emit cos_recv / delta^2 = z (n . (c - x)) / delta^4 needs no root.
vec3 ShadeLights(vec3 x, vec3 n, ivec2 pixel) {
  vec3 sum = vec3(0.0);
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
)";

// Light culling by tiles (RenderOptions::tiled_lights). A point x (z > 0) is seen from centre c
// through the window at st = c + (x.xy - c) d / z = a + c t, with a = x.xy d / z and
// t = 1 - d / z; TileBounds keeps, per tile of the G-buffer, the ranges of a and t over its
// points (once per view), and TileLists, per light pass, lists the lights whose E' support can
// meet a + c t over those ranges. llvmpipe runs a branch's both sides masked, so a light is
// saved only by leaving it out of the loop; a tile's pixels share one list.
constexpr int kTile = 16;
const std::string kTileBoundsCompute = R"(#version 450 core
layout(local_size_x = 64) in;
uniform sampler2D u_gbuffer_position;
uniform float u_d;
uniform ivec2 u_tiles;
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
      const vec4 p = texelFetch(u_gbuffer_position, min(origin + ivec2(x, y), last), 0);
      if (p.w == 0.0 || p.z <= 0.0) continue;
      const float s = u_d / p.z;
      const vec3 v = vec3(p.xy * s, 1.0 - s);
      lo = min(lo, v);
      hi = max(hi, v);
    }
  tile_bounds[2 * tile] = vec4(lo, 0.0);
  tile_bounds[2 * tile + 1] = vec4(hi, 0.0);
}
)";
const std::string kTileListsCompute = R"(#version 450 core
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
)";

// The G-buffer: what each pixel sees, in the luminaire frame (redrawn when the view, the scene or
// the pose changes; the light passes read it).
const char* kGeometryFragment = R"(#version 450 core
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
)";

const char* kQuadVertex = R"(#version 450 core
out vec2 v_uv;
void main() {
  vec2 p = vec2((gl_VertexID & 1) * 4.0 - 1.0, (gl_VertexID & 2) * 2.0 - 1.0);
  v_uv = 0.5 * p + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

const std::string kDisplayFragment = std::string(R"(#version 450 core
in vec2 v_uv;
uniform sampler2D u_float;
uniform usampler2D u_packed;
uniform bool u_srgbe;
uniform float u_exposure;
out vec4 o_colour;
)") + kSrgbeCode + R"(
void main() {
  vec3 c = u_srgbe ? DecodeSrgbe(texture(u_packed, v_uv).r) : texture(u_float, v_uv).rgb;
  c = clamp(c * u_exposure, 0.0, 1.0);
  c = mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
  o_colour = vec4(c, 1.0);
}
)";

GLuint Compile(GLenum type, const std::string& source) {
  const GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    throw Failure(std::string("GLSL compile error: ") + log);
  }
  return shader;
}

// Compiles and links one program from (stage, source) pairs.
GLuint LinkStages(std::initializer_list<std::pair<GLenum, const std::string*>> stages) {
  const GLuint program = glCreateProgram();
  std::vector<GLuint> shaders;
  for (const auto& [stage, source] : stages) {
    shaders.push_back(Compile(stage, *source));
    glAttachShader(program, shaders.back());
  }
  glLinkProgram(program);
  for (GLuint shader : shaders) glDeleteShader(shader);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetProgramInfoLog(program, sizeof(log), nullptr, log);
    throw Failure(std::string("GLSL link error: ") + log);
  }
  return program;
}

GLuint Link(const std::string& vertex, const std::string& fragment) {
  return LinkStages({{GL_VERTEX_SHADER, &vertex}, {GL_FRAGMENT_SHADER, &fragment}});
}

GLuint LinkCompute(const std::string& compute) {
  return LinkStages({{GL_COMPUTE_SHADER, &compute}});
}

GLint Loc(GLuint program, const char* name) { return glGetUniformLocation(program, name); }

// The light pass's fragment shader, its options compiled in: llvmpipe runs both sides of a
// branch on a uniform, masked, so a run-time switch costs its untaken side in every light
// iteration (the cubic filter's 16 texel reads: a third of the light pass, measured).
std::string WithDefines(const std::string& source, const std::string& defines) {
  std::string f = source;
  f.insert(f.find('\n') + 1, defines);
  return f;
}
std::string LightFragment(const std::string& defines) {
  return WithDefines(kLightFragment, defines);
}

}  // namespace

struct Renderer::Gl {
  GLuint vao = 0, vbo = 0, quad_vao = 0;
  GLuint geometry_program = 0, shadow_program = 0, display_program = 0;
  // Light-pass programs by their #defines (Renderer::LightProgram), linked when first used.
  std::map<std::string, GLuint> light_programs;
  GLuint intensity = 0, shadow = 0, shadow_fbo = 0;
  bool layered_shadows = false;  // ShadowVertex(true): several maps per draw
  int shadow_batch = 1;          // maps per layered draw
  GLuint colour = 0, packed[2] = {0, 0}, fbo[2] = {0, 0};
  // The G-buffer (kGeometryFragment): position, normal, albedo and depth.
  GLuint gbuffer[3] = {0, 0, 0}, depth = 0, gbuffer_fbo = 0;
  // Coarse shading's samples (RGBA32F, every second pixel of every second row), and the list
  // of the pixels it shades exactly (ExactCount, ExactList in kLightFragment).
  GLuint coarse = 0, coarse_fbo = 0, exact_count = 0, exact_list = 0;
  // The lights' sum before albedo (o_irradiance) of the present view, and the last view shaded
  // in full: its sums, positions and normals (what reprojection reuses).
  GLuint irradiance = 0, source[3] = {0, 0, 0};
  // Light culling by tiles: the tiles' bounds (per view) and light lists (per light pass), and
  // the programs that make them (the lists' by lights per pass).
  GLuint tile_bounds = 0, tile_lists = 0, tile_bounds_program = 0;
  std::map<int, GLuint> tile_list_programs;
};

Renderer::Renderer(const SlabInfo& info, int width, int height, const RenderOptions& options)
    : info_(info), width_(width), height_(height), options_(options), gl_(new Gl) {
  const int lights = info_.grid.count();
  present_.assign(lights, false);
  shadow_valid_.assign(lights, false);
  accumulated_.assign(lights, false);
  support_.assign(lights, {0, 0, 0, 0});
  shadow_rect_.assign(lights, {0, 0, 0, 0});
  shadow_layer_.resize(lights);
  shadow_centre_.resize(lights);
  for (int l = 0; l < lights; ++l) {
    shadow_layer_[l] = l;
    shadow_centre_[l] = info_.grid.Centre(l % info_.grid.nu, l / info_.grid.nu);
  }
  intensity_.resize(lights);
  // Merged textures follow the positions' layers: at most one per 2 x 2 block.
  const int merge_layers = ((info_.grid.nu + 1) / 2) * ((info_.grid.nv + 1) / 2);
  // The light program of these options now, so that a driver that refuses it fails here; the
  // others are linked when first used (the shortcuts' uniform arrays are larger: a driver that
  // refuses them then fails only the shortcuts, not the full render).
  LightProgram(false);
  gl_->geometry_program = Link(kSceneVertex, kGeometryFragment);
  // Layered maps need a viewport (scissor rectangle) per map of a draw.
  GLint viewports = 0;
  glGetIntegerv(GL_MAX_VIEWPORTS, &viewports);
  gl_->shadow_batch = std::min(kShadowBatch, int(viewports));
  gl_->layered_shadows = options_.layered_shadow_maps &&
                         HasExtension("GL_ARB_shader_viewport_layer_array") &&
                         gl_->shadow_batch >= 1;
  gl_->shadow_program = Link(ShadowVertex(gl_->layered_shadows), kEmptyFragment);
  gl_->display_program = Link(kQuadVertex, kDisplayFragment);
  glGenVertexArrays(1, &gl_->vao);
  glGenVertexArrays(1, &gl_->quad_vao);
  glGenBuffers(1, &gl_->vbo);

  glGenTextures(1, &gl_->intensity);
  glBindTexture(GL_TEXTURE_2D_ARRAY, gl_->intensity);
  glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA32F, info_.layout.res_x, info_.layout.res_y,
                 lights + merge_layers);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  glGenTextures(1, &gl_->shadow);
  glBindTexture(GL_TEXTURE_2D_ARRAY, gl_->shadow);
  glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_DEPTH_COMPONENT32F, options_.shadow_size,
                 options_.shadow_size, lights);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glGenFramebuffers(1, &gl_->shadow_fbo);
  glCreateBuffers(1, &gl_->exact_count);
  glNamedBufferStorage(gl_->exact_count, sizeof(GLuint), nullptr, GL_DYNAMIC_STORAGE_BIT);
  AllocateTargets();
  if (glGetError() != GL_NO_ERROR) throw Failure("GL error while creating the renderer");
}

Renderer::~Renderer() {
  glDeleteFramebuffers(2, gl_->fbo);
  glDeleteFramebuffers(1, &gl_->gbuffer_fbo);
  glDeleteFramebuffers(1, &gl_->shadow_fbo);
  glDeleteFramebuffers(1, &gl_->coarse_fbo);
  glDeleteBuffers(1, &gl_->exact_count);
  glDeleteBuffers(1, &gl_->exact_list);
  glDeleteBuffers(1, &gl_->tile_bounds);
  glDeleteBuffers(1, &gl_->tile_lists);
  GLuint textures[] = {gl_->intensity,  gl_->shadow,   gl_->colour,     gl_->packed[0],
                       gl_->packed[1],  gl_->depth,    gl_->gbuffer[0], gl_->gbuffer[1],
                       gl_->gbuffer[2], gl_->coarse,   gl_->irradiance, gl_->source[0],
                       gl_->source[1],  gl_->source[2]};
  glDeleteTextures(14, textures);
  glDeleteBuffers(1, &gl_->vbo);
  glDeleteVertexArrays(1, &gl_->vao);
  glDeleteVertexArrays(1, &gl_->quad_vao);
  for (const auto& [defines, program] : gl_->light_programs) glDeleteProgram(program);
  for (const auto& [lights, program] : gl_->tile_list_programs) glDeleteProgram(program);
  for (GLuint p : {gl_->geometry_program, gl_->shadow_program, gl_->display_program,
                   gl_->tile_bounds_program}) {
    glDeleteProgram(p);
  }
  delete gl_;
}

void Renderer::AllocateTargets() {
  if (gl_->fbo[0]) {
    glDeleteFramebuffers(2, gl_->fbo);
    glDeleteFramebuffers(1, &gl_->gbuffer_fbo);
    glDeleteFramebuffers(1, &gl_->coarse_fbo);
    glDeleteBuffers(1, &gl_->exact_list);
    glDeleteBuffers(1, &gl_->tile_bounds);
    glDeleteBuffers(1, &gl_->tile_lists);
    GLuint textures[] = {gl_->colour,     gl_->packed[0],  gl_->packed[1],  gl_->depth,
                         gl_->gbuffer[0], gl_->gbuffer[1], gl_->gbuffer[2], gl_->coarse,
                         gl_->irradiance, gl_->source[0],  gl_->source[1],  gl_->source[2]};
    glDeleteTextures(12, textures);
  }
  auto make = [&](GLenum format, int width = 0, int height = 0) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, format, width ? width : width_, height ? height : height_);
    const GLint filter = (format == GL_R32UI) ? GL_NEAREST : GL_LINEAR;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    return t;
  };
  gl_->colour = make(GL_RGBA32F);
  gl_->packed[0] = make(GL_R32UI);
  gl_->packed[1] = make(GL_R32UI);
  gl_->depth = make(GL_DEPTH_COMPONENT32F);
  for (GLuint& t : gl_->gbuffer) t = make(GL_RGBA32F);  // 32-bit: the values the scene gives
  glGenFramebuffers(1, &gl_->gbuffer_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->gbuffer_fbo);
  for (int k = 0; k < 3; ++k) {
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + k, gl_->gbuffer[k], 0);
  }
  glFramebufferTexture(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, gl_->depth, 0);
  const GLenum gbuffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  glDrawBuffers(3, gbuffers);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw Failure("G-buffer framebuffer incomplete");
  }
  // Samples at pixels 0, 2, 4, ... up to the last pixel.
  gl_->coarse = make(GL_RGBA32F, (width_ + 1) / 2, (height_ + 1) / 2);
  glGenFramebuffers(1, &gl_->coarse_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->coarse_fbo);
  glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, gl_->coarse, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw Failure("coarse-shading framebuffer incomplete");
  }
  gl_->irradiance = make(GL_RGBA32F);
  for (GLuint& t : gl_->source) t = make(GL_RGBA32F);
  source_valid_ = view_shaded_in_full_ = false;  // new, undefined contents
  reproject_next_ = true;
  glCreateBuffers(1, &gl_->exact_list);
  glNamedBufferStorage(gl_->exact_list, GLsizeiptr(width_) * height_ * sizeof(GLuint), nullptr, 0);
  const GLsizeiptr tiles =
      GLsizeiptr((width_ + kTile - 1) / kTile) * ((height_ + kTile - 1) / kTile);
  glCreateBuffers(1, &gl_->tile_bounds);
  glNamedBufferStorage(gl_->tile_bounds, tiles * 8 * sizeof(GLfloat), nullptr, 0);
  glCreateBuffers(1, &gl_->tile_lists);
  glNamedBufferStorage(gl_->tile_lists, tiles * (2 + 2 * kFastLightsPerPass) * sizeof(GLuint),
                       nullptr, 0);
  tile_bounds_valid_ = false;
  glGenFramebuffers(2, gl_->fbo);
  for (int k = 0; k < 2; ++k) {
    glBindFramebuffer(GL_FRAMEBUFFER, gl_->fbo[k]);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, gl_->colour, 0);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, gl_->packed[k], 0);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT2, gl_->irradiance, 0);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glDrawBuffers(3, buffers);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw Failure("accumulation framebuffer incomplete");
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  view_valid_ = false;
}

void Renderer::SetScene(const Mesh& mesh) {
  std::vector<float> data;
  data.reserve(mesh.positions.size() * 9);
  for (size_t k = 0; k < mesh.positions.size(); ++k) {
    for (const Eigen::Vector3f* v : {&mesh.positions[k], &mesh.normals[k], &mesh.albedo[k]}) {
      data.insert(data.end(), {v->x(), v->y(), v->z()});
    }
  }
  vertex_count_ = int(mesh.positions.size());
  source_valid_ = view_shaded_in_full_ = false;
  glBindVertexArray(gl_->vao);
  glBindBuffer(GL_ARRAY_BUFFER, gl_->vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(),
               GL_STATIC_DRAW);
  for (int a = 0; a < 3; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, 9 * sizeof(float),
                          reinterpret_cast<void*>(size_t(a) * 3 * sizeof(float)));
  }
  glBindVertexArray(0);
  shadow_valid_.assign(shadow_valid_.size(), false);
  groups_valid_ = false;
  view_valid_ = false;
}

void Renderer::SetPose(const Eigen::Isometry3d& luminaire_to_scene) {
  pose_ = luminaire_to_scene;
  source_valid_ = view_shaded_in_full_ = false;
  shadow_valid_.assign(shadow_valid_.size(), false);
  groups_valid_ = false;
  view_valid_ = false;
}

void Renderer::SetCamera(const Eigen::Matrix4f& view_projection) {
  if (view_projection == view_projection_ && view_valid_) return;
  view_projection_ = view_projection;
  view_valid_ = false;
}

void Renderer::SetOptions(const RenderOptions& options) {
  if (options.shadow_size != options_.shadow_size ||
      options.layered_shadow_maps != options_.layered_shadow_maps) {
    throw BadInput("the shadow-map size and layering are fixed when the renderer is created");
  }
  if (options.merge_group < 1 || !(options.merge_error > 0) ||
      !(options.shadow_share_texels >= 0) || !(options.coarse_tolerance >= 0) ||
      !(options.reproject_tolerance >= 0)) {
    throw BadInput(
        "merge group must be >= 1, merge error > 0, shadow sharing >= 0 texels, coarse and "
        "reprojection tolerances >= 0");
  }
  // Maps drawn for the old options may be shared, or cover less than merged lights read.
  if (options.shadow_share_texels != options_.shadow_share_texels ||
      options.shadow_cull != options_.shadow_cull || options.merge_group != options_.merge_group ||
      options.shadow_scissor != options_.shadow_scissor) {
    shadow_valid_.assign(shadow_valid_.size(), false);
    groups_valid_ = false;
  }
  if (options.merge_group != options_.merge_group) {
    merged_valid_.clear();
  }
  options_ = options;
  view_valid_ = false;
  source_valid_ = view_shaded_in_full_ = false;
}

void Renderer::Resize(int width, int height) {
  if (width == width_ && height == height_) return;
  width_ = width;
  height_ = height;
  AllocateTargets();
}

void Renderer::SetPosition(int i, int j, const ImageF& intensity) {
  if (intensity.width != info_.layout.res_x || intensity.height != info_.layout.res_y ||
      intensity.channels != 3) {
    throw BadInput("slab position texture does not match the slab layout");
  }
  const int layer = info_.grid.Index(i, j);
  glBindTexture(GL_TEXTURE_2D_ARRAY, gl_->intensity);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, layer, intensity.width, intensity.height, 1, GL_RGB,
                  GL_FLOAT, intensity.data.data());
  if (accumulated_[layer]) view_valid_ = false;  // replaced: the sum must be redone
  if (accumulated_[layer] || (source_valid_ && source_lights_[layer])) {
    source_valid_ = view_shaded_in_full_ = false;  // the sums hold the texture replaced
  }
  // Where E' is not 0 (per row, the first and the last value not 0); a map drawn over a smaller
  // rectangle is redrawn.
  std::array<int, 4>& s = support_[layer];
  s = {intensity.width, intensity.height, 0, 0};
  const int row_values = intensity.width * 3;
  for (int y = 0; y < intensity.height; ++y) {
    const float* row = &intensity.data[size_t(y) * row_values];
    int first = 0, last = row_values - 1;
    while (first < row_values && row[first] == 0) ++first;
    if (first == row_values) continue;
    while (row[last] == 0) --last;
    s = {std::min(s[0], first / 3), std::min(s[1], y), std::max(s[2], last / 3 + 1), y + 1};
  }
  const ShadowJob job = ShadowJobFor(layer);
  if (shadow_valid_[job.layer]) {
    const std::array<int, 4>& drawn = shadow_rect_[job.layer];
    if (job.x1 > job.x0 &&
        (job.x0 < drawn[0] || job.y0 < drawn[1] || job.x1 > drawn[2] || job.y1 > drawn[3])) {
      shadow_valid_[job.layer] = false;
    }
  }
  present_[layer] = true;
  intensity_[layer] = intensity;
  merged_valid_.clear();  // the merged textures are rebuilt from the copies when next used
}

bool Renderer::HasPosition(int i, int j) const { return present_[info_.grid.Index(i, j)]; }

int Renderer::PositionCount() const {
  int n = 0;
  for (bool p : present_) n += p;
  return n;
}

Renderer::ShadowJob Renderer::ShadowJobFor(int l) const {
  const int size = options_.shadow_size;
  ShadowJob job{shadow_layer_[l], shadow_centre_[l], 0, 0, size, size};
  if (Fast() || !options_.shadow_scissor) return job;  // shared or merged maps: whole
  const std::array<int, 4>& s = support_[l];
  if (s[0] >= s[2] || s[1] >= s[3]) {
    job.x1 = job.y1 = 0;  // E' is 0 everywhere: the map is never read
    return job;
  }
  // A lookup for a point x reads E' at x's window coordinate st and the map at the coordinate of
  // x + n eps, eps = 1.5 W / (d S) delta (the normal offset, u_offset_scale). With
  // t = tan(theta) of the steepest ray through the window, st moves by at most
  // eps d / z (1 + t) = 1.5 (1 + t) / cos(theta) map texels along x, W/H times that along y.
  // The cubic filter reads 2 slab texels beyond a point, PCF one map texel, and one more for
  // rounding.
  const double w = info_.layout.window_w_mm, h = info_.layout.window_h_mm;
  const Eigen::Vector2d corner = info_.grid.Centre(info_.grid.nu - 1, info_.grid.nv - 1);
  const double t = (std::hypot(0.5 * w, 0.5 * h) + corner.norm()) / info_.distance_mm;
  const double offset = 1.5 * (1 + t) * std::sqrt(1 + t * t) * std::max(1.0, w / h);
  const double sx = double(size) / info_.layout.res_x, sy = double(size) / info_.layout.res_y;
  const int pad_x = int(std::ceil(2 * sx + offset)) + 2,
            pad_y = int(std::ceil(2 * sy + offset)) + 2;
  job.x0 = std::max(0, int(std::floor(s[0] * sx)) - pad_x);
  job.y0 = std::max(0, int(std::floor(s[1] * sy)) - pad_y);
  job.x1 = std::min(size, int(std::ceil(s[2] * sx)) + pad_x);
  job.y1 = std::min(size, int(std::ceil(s[3] * sy)) + pad_y);
  return job;
}

void Renderer::RenderShadowMaps(const std::vector<ShadowJob>& jobs) {
  if (jobs.empty()) return;
  const int size = options_.shadow_size;
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->shadow_fbo);
  glDrawBuffer(GL_NONE);
  glViewport(0, 0, size, size);  // every viewport index
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  if (gl_->layered_shadows) {
    // Every layer attached; cleared in one go when no layer holds a map still in use (a full
    // frame), else each map's rectangle.
    glFramebufferTexture(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, gl_->shadow, 0);
    if (std::find(shadow_valid_.begin(), shadow_valid_.end(), true) == shadow_valid_.end()) {
      glClear(GL_DEPTH_BUFFER_BIT);
    } else {
      const float far = 1;
      for (const ShadowJob& job : jobs) {
        if (job.x1 <= job.x0 || job.y1 <= job.y0) continue;
        glClearTexSubImage(gl_->shadow, 0, job.x0, job.y0, job.layer, job.x1 - job.x0,
                           job.y1 - job.y0, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &far);
      }
    }
  }
  glEnable(GL_SCISSOR_TEST);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.5f, 2.0f);
  const GLuint p = gl_->shadow_program;
  glUseProgram(p);
  const Eigen::Matrix4f to_lum = pose_.inverse().matrix().cast<float>();
  glUniformMatrix4fv(Loc(p, "u_scene_to_luminaire"), 1, GL_FALSE, to_lum.data());
  glUniform1f(Loc(p, "u_d"), float(info_.distance_mm));
  glUniform2f(Loc(p, "u_window"), float(info_.layout.window_w_mm), float(info_.layout.window_h_mm));
  glUniform2f(Loc(p, "u_depth"), float(kShadowDepthA), float(kShadowDepthB));
  const GLint maps = Loc(p, "u_maps");
  glBindVertexArray(gl_->vao);
  // Faces turned to the light wind counter-clockwise in the map (LightClip), so GL_BACK, the
  // default, drops the faces turned away (culling GL_FRONT instead drops the room's walls: the
  // crypt then moves by 3.1 %, PreviewSlabFiles.ShadowCullKeepsTheImage).
  if (options_.shadow_cull) glEnable(GL_CULL_FACE);
  const size_t batch = gl_->layered_shadows ? size_t(gl_->shadow_batch) : 1;
  for (size_t b = 0; b < jobs.size(); b += batch) {
    const size_t n = std::min(batch, jobs.size() - b);
    float u[4 * kShadowBatch];
    for (size_t k = 0; k < n; ++k) {
      const ShadowJob& job = jobs[b + k];
      u[4 * k] = float(job.centre.x());
      u[4 * k + 1] = float(job.centre.y());
      u[4 * k + 2] = float(job.layer);
      u[4 * k + 3] = 0;
      glScissorIndexed(GLuint(k), job.x0, job.y0, std::max(0, job.x1 - job.x0),
                       std::max(0, job.y1 - job.y0));
    }
    if (!gl_->layered_shadows) {
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, gl_->shadow, 0, jobs[b].layer);
      glClear(GL_DEPTH_BUFFER_BIT);  // inside the scissor rectangle
    }
    glUniform4fv(maps, GLsizei(n), u);
    glDrawArraysInstanced(GL_TRIANGLES, 0, vertex_count_, GLsizei(n));
  }
  glDisable(GL_CULL_FACE);
  glDisable(GL_POLYGON_OFFSET_FILL);
  glDisable(GL_SCISSOR_TEST);
  for (const ShadowJob& job : jobs) {
    shadow_rect_[job.layer] = {job.x0, job.y0, job.x1, job.y1};
    shadow_texels_ += (long long)std::max(0, job.x1 - job.x0) * std::max(0, job.y1 - job.y0);
  }
  shadow_renders_ += int(jobs.size());
}

// Blocks of g x g positions from the grid's corner (the last ones smaller): members of block
// (bi, bj) are i in [bi g, min(nu, bi g + g)), likewise j.
std::vector<int> BlockMembers(const SamplingGrid& grid, int g, int bi, int bj) {
  std::vector<int> members;
  for (int j = bj * g; j < std::min(grid.nv, bj * g + g); ++j)
    for (int i = bi * g; i < std::min(grid.nu, bi * g + g); ++i)
      members.push_back(grid.Index(i, j));
  return members;
}

Eigen::Vector2d MeanCentre(const SamplingGrid& grid, const std::vector<int>& members,
                           double* radius) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int l : members) mean += grid.Centre(l % grid.nu, l / grid.nu);
  mean /= double(members.size());
  *radius = 0;
  for (int l : members)
    *radius = std::max(*radius, (grid.Centre(l % grid.nu, l / grid.nu) - mean).norm());
  return mean;
}

// Shadow-map sharing. A block of positions shares the map rendered from its centre c̄. Seen from
// c̄, the edge of an occluder at depth z_o (luminaire frame) cast onto a receiver at z_r lies
// where the ray from c_k past the edge meets the receiver: |c_k - c̄| (1/z_o - 1/z_r) radians
// away from where the shared map puts it. A shadow texel spans W/(d S) radians (the map's
// projection: x_ndc = 2 d x / (W z)), H/(d S) vertically. So over the depth range [z_min, z_max]
// of what the maps see, a block of half-diagonal r moves shadow edges by at most
//     r (1/z_min - 1/z_max) d S / min(W, H)  shadow texels,
// and g is the largest block side that keeps this within --shadow-share. The depth range is
// read back from the map of the grid's centre position (the surfaces the lights see first:
// occluders, and receivers at a shadow's edge, which the map also sees).
void Renderer::ChooseShadowGroups() {
  const SamplingGrid& grid = info_.grid;
  const int lights = grid.count();
  shadow_valid_.assign(lights, false);
  int g = 1;
  state_ = ShortcutState{};
  if (options_.shadow_share_texels > 0) {
    const int centre = grid.Index(grid.nu / 2, grid.nv / 2);
    const int size = options_.shadow_size;
    RenderShadowMaps({{centre, grid.Centre(grid.nu / 2, grid.nv / 2), 0, 0, size, size}});
    std::vector<float> depth(size_t(size) * size);
    glGetTextureSubImage(gl_->shadow, 0, 0, 0, centre, size, size, 1, GL_DEPTH_COMPONENT, GL_FLOAT,
                         GLsizei(depth.size() * sizeof(float)), depth.data());
    double z_min = kShadowFar, z_max = 0;
    for (float w : depth) {
      if (!(w < 1.0f)) continue;  // cleared: nothing seen through this texel
      const double z = kShadowDepthB / (2.0 * w - 1.0 - kShadowDepthA);
      z_min = std::min(z_min, z);
      z_max = std::max(z_max, z);
    }
    const double texel =
        std::min(info_.layout.window_w_mm, info_.layout.window_h_mm) / (info_.distance_mm * size);
    const double spread = z_max > 0 ? 1 / z_min - 1 / z_max : 0;  // nothing seen: any g is exact
    for (int t = 2; t <= std::max(grid.nu, grid.nv); ++t) {
      const double hu = 0.5 * (std::min(t, grid.nu) - 1), hv = 0.5 * (std::min(t, grid.nv) - 1);
      const double shift = grid.spacing_mm * std::hypot(hu, hv) * spread / texel;
      if (shift > options_.shadow_share_texels) break;
      g = t;
      state_.shadow_shift = shift;
    }
    state_.z_min = z_min;
    state_.z_max = z_max;
    if (g == 1) shadow_valid_[centre] = true;  // that map is the centre position's own
  }
  state_.shadow_group = g;
  state_.shadow_maps = 0;
  for (int bj = 0; bj * g < grid.nv; ++bj) {
    for (int bi = 0; bi * g < grid.nu; ++bi) {
      const std::vector<int> members = BlockMembers(grid, g, bi, bj);
      double radius = 0;
      const Eigen::Vector2d mean = MeanCentre(grid, members, &radius);
      // The map lies in the layer of the member nearest the centre (in an odd block, the
      // centre position itself, whose map is then its own).
      int rep = members[0];
      for (int l : members) {
        if ((grid.Centre(l % grid.nu, l / grid.nu) - mean).norm() <
            (grid.Centre(rep % grid.nu, rep / grid.nu) - mean).norm())
          rep = l;
      }
      for (int l : members) {
        shadow_layer_[l] = rep;
        shadow_centre_[l] = g == 1 ? grid.Centre(l % grid.nu, l / grid.nu) : mean;
      }
      ++state_.shadow_maps;
    }
  }
  groups_valid_ = true;
}

// The merged texture of a block G (centre c̄) for distant receivers: a receiver at depth z looks
// member k up at s_k = x d/z + c_k (1 - d/z) and the merged light at s̄ = x d/z + c̄ (1 - d/z), so
//     M_G(s) = Σ_k E'_k(s + (c_k - c̄))
// equals the members' sum at z = ∞ and is off by E'_k displaced by e_k = (c_k - c̄) d/z at z:
// |error| ≤ (r d / z) Σ_k max|∇E'_k| (r the block's radius). The spot factor cosθ cosθ'/δ² of
// c̄ instead of c_k changes by at most 5 r/δ ≤ 5 r/z of the largest term (cosθ and cosθ' by r/δ
// and 2r/δ, 1/δ² by 2r/δ). Relative to the block's peak P = max M_G the error is at most
//     (r / z) (d Σ_k max|∇E'_k| / P + 5),
// so receivers at z ≥ z_G = r (d Σ_k max|∇E'_k| / P + 5) / merge_error use the merged light
// (per channel, the largest z_G). The merged light's visibility is the mean of its members'
// shadow-map tests (each at its own map: soft shadows stay as soft), so
//     Σ_k V_k E'_k  ≈  (1/n Σ_k V_k) Σ_k E'_k,
// exact where the members see the receiver alike or their E' are alike.
void Renderer::MergedTexture(int group) {
  const SamplingGrid& grid = info_.grid;
  const int g = options_.merge_group, bu = (grid.nu + g - 1) / g;
  const std::vector<int> members = BlockMembers(grid, g, group % bu, group / bu);
  double radius = 0;
  const Eigen::Vector2d mean = MeanCentre(grid, members, &radius);
  const int rx = info_.layout.res_x, ry = info_.layout.res_y;
  const double w = info_.layout.window_w_mm, h = info_.layout.window_h_mm;
  ImageF merged(rx, ry, 3);
  double gradient[3] = {0, 0, 0};
  for (int l : members) {
    const ImageF& e = intensity_[l];
    const Eigen::Vector2d c = grid.Centre(l % grid.nu, l / grid.nu) - mean;
    // Texel shift of E'_k: u = s/W + 1/2 (columns), v = 1/2 - t/H (rows).
    const double du = c.x() / w * rx, dv = -c.y() / h * ry;
    for (int y = 0; y < ry; ++y) {
      const double qy = y + 0.5 + dv;   // in texels from the window's top edge
      if (qy < 0 || qy > ry) continue;  // outside the window: the member gives no light
      const double fy = std::clamp(qy - 0.5, 0.0, double(ry - 1));
      const int y0 = std::min(int(fy), ry - 1), y1 = std::min(y0 + 1, ry - 1);
      const double ty = fy - y0;
      for (int x = 0; x < rx; ++x) {
        const double qx = x + 0.5 + du;
        if (qx < 0 || qx > rx) continue;
        const double fx = std::clamp(qx - 0.5, 0.0, double(rx - 1));
        const int x0 = std::min(int(fx), rx - 1), x1 = std::min(x0 + 1, rx - 1);
        const double tx = fx - x0;
        for (int ch = 0; ch < 3; ++ch) {
          merged.at(x, y, ch) +=
              float((1 - ty) * ((1 - tx) * e.at(x0, y0, ch) + tx * e.at(x1, y0, ch)) +
                    ty * ((1 - tx) * e.at(x0, y1, ch) + tx * e.at(x1, y1, ch)));
        }
      }
    }
    // max |∇E'_k| per mm from neighbouring texels.
    for (int ch = 0; ch < 3; ++ch) {
      double m = 0;
      for (int y = 0; y < ry; ++y) {
        for (int x = 0; x < rx; ++x) {
          if (x + 1 < rx) m = std::max(m, std::abs(e.at(x + 1, y, ch) - e.at(x, y, ch)) * rx / w);
          if (y + 1 < ry) m = std::max(m, std::abs(e.at(x, y + 1, ch) - e.at(x, y, ch)) * ry / h);
        }
      }
      gradient[ch] += m;
    }
  }
  double z = 0;
  for (int ch = 0; ch < 3; ++ch) {
    double peak = 0;
    for (int y = 0; y < ry; ++y)
      for (int x = 0; x < rx; ++x) peak = std::max(peak, double(std::abs(merged.at(x, y, ch))));
    if (peak > 0) z = std::max(z, radius * (info_.distance_mm * gradient[ch] / peak + 5));
  }
  const int layer = grid.count() + group;
  glBindTexture(GL_TEXTURE_2D_ARRAY, gl_->intensity);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, layer, rx, ry, 1, GL_RGB, GL_FLOAT,
                  merged.data.data());
  merged_z_[group] = z;
  merged_valid_[group] = true;
}

// The shortcuts' light passes: with merging, the blocks whose members all are added now become
// a merged light for receivers at least z_far deep (the largest of their z_G) and their members
// shade the nearer ones; the other positions shade all.
void Renderer::FastPasses(const std::vector<int>& todo) {
  const SamplingGrid& grid = info_.grid;
  auto entry = [&](int l) {
    LightEntry e;
    e.centre = grid.Centre(l % grid.nu, l / grid.nu);
    e.layer = l;
    e.shadow_centre = shadow_centre_[l];
    e.shadow_layer = shadow_layer_[l];
    e.support = support_[l];
    return e;
  };
  std::vector<LightEntry> near_only, both, far_only;
  std::vector<bool> adding(grid.count(), false);
  for (int l : todo) adding[l] = true;
  std::vector<bool> merged(grid.count(), false);
  double z_far = 0;
  const int g = options_.merge_group;
  if (g > 1) {
    const int bu = (grid.nu + g - 1) / g, bv = (grid.nv + g - 1) / g;
    if (int(merged_valid_.size()) != bu * bv || merged_group_size_ != g) {
      merged_valid_.assign(bu * bv, false);
      merged_z_.assign(bu * bv, 0);
      merged_group_size_ = g;
    }
    for (int bj = 0; bj < bv; ++bj) {
      for (int bi = 0; bi < bu; ++bi) {
        const std::vector<int> members = BlockMembers(grid, g, bi, bj);
        if (members.size() < 2) continue;
        if (!std::all_of(members.begin(), members.end(), [&](int l) { return adding[l]; }))
          continue;
        const int group = bj * bu + bi;
        if (!merged_valid_[group]) MergedTexture(group);
        double radius = 0;
        LightEntry e;
        e.centre = MeanCentre(grid, members, &radius);
        e.layer = grid.count() + group;
        int nearest = members[0];
        for (int l : members) {
          if ((grid.Centre(l % grid.nu, l / grid.nu) - e.centre).norm() <
              (grid.Centre(nearest % grid.nu, nearest / grid.nu) - e.centre).norm())
            nearest = l;
        }
        e.shadow_centre = shadow_centre_[nearest];
        e.shadow_layer = shadow_layer_[nearest];
        e.span_begin = int(near_only.size());  // the members follow at this index
        e.span_count = int(members.size());
        // The summed texture's support: the members' (their rectangles' bounding box).
        e.support = {info_.layout.res_x, info_.layout.res_y, 0, 0};
        for (int l : members) {
          const std::array<int, 4>& m = support_[l];
          if (m[0] >= m[2] || m[1] >= m[3]) continue;
          e.support = {std::min(e.support[0], m[0]), std::min(e.support[1], m[1]),
                       std::max(e.support[2], m[2]), std::max(e.support[3], m[3])};
        }
        far_only.push_back(e);
        z_far = std::max(z_far, merged_z_[group] / options_.merge_error);
        for (int l : members) {
          near_only.push_back(entry(l));
          merged[l] = true;
        }
      }
    }
  }
  for (int l : todo)
    if (!merged[l]) both.push_back(entry(l));
  if (far_only.empty()) z_far = std::numeric_limits<double>::infinity();
  state_.merged_lights = int(far_only.size());
  state_.z_merge = z_far;
  const size_t total = near_only.size() + both.size() + far_only.size();
  if (total <= size_t(kFastLightsPerPass)) {
    std::vector<LightEntry> entries = near_only;
    entries.insert(entries.end(), both.begin(), both.end());
    entries.insert(entries.end(), far_only.begin(), far_only.end());
    EntriesPass(entries, true, int(near_only.size() + both.size()), int(near_only.size()), z_far);
    return;
  }
  // Too many for one pass: every position on its own, in passes of kFastLightsPerPass.
  state_.merged_lights = 0;
  for (size_t start = 0; start < todo.size(); start += kFastLightsPerPass) {
    const size_t end = std::min(todo.size(), start + kFastLightsPerPass);
    std::vector<LightEntry> entries;
    for (size_t k = start; k < end; ++k) entries.push_back(entry(todo[k]));
    EntriesPass(entries, true, int(entries.size()), int(entries.size()),
                std::numeric_limits<double>::infinity());
  }
}

void Renderer::TileLists(int lights_per_pass, const float* lights,
                         const std::vector<LightEntry>& entries, int near_end, int far_begin) {
  const int tiles_x = (width_ + kTile - 1) / kTile, tiles_y = (height_ + kTile - 1) / kTile;
  const int count = int(entries.size());
  if (!tile_bounds_valid_) {
    if (!gl_->tile_bounds_program) {
      gl_->tile_bounds_program = LinkCompute(
          WithDefines(kTileBoundsCompute, "#define TILE " + std::to_string(kTile) + "\n"));
    }
    const GLuint p = gl_->tile_bounds_program;
    glUseProgram(p);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, gl_->gbuffer[0]);
    glUniform1i(Loc(p, "u_gbuffer_position"), 3);
    glUniform1f(Loc(p, "u_d"), float(info_.distance_mm));
    glUniform2i(Loc(p, "u_tiles"), tiles_x, tiles_y);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, gl_->tile_bounds);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);  // the G-buffer drawn before
    glDispatchCompute(GLuint(tiles_x * tiles_y + 63) / 64, 1, 1);
    glActiveTexture(GL_TEXTURE0);
    tile_bounds_valid_ = true;
  }
  GLuint& p = gl_->tile_list_programs[lights_per_pass];
  if (!p) {
    p = LinkCompute(WithDefines(
        kTileListsCompute, "#define LIGHTS_PER_PASS " + std::to_string(lights_per_pass) + "\n"));
  }
  // Each light's support in window coordinates (mm), widened by 3 texels: the cubic filter
  // reads 2 texels beyond a point, the bilinear 1, and 1 more for rounding. A light whose E' is
  // 0 everywhere is in no list.
  const double w = info_.layout.window_w_mm, h = info_.layout.window_h_mm;
  const double rx = info_.layout.res_x, ry = info_.layout.res_y, pad = 3;
  std::vector<float> windows;
  for (const LightEntry& e : entries) {
    const std::array<int, 4>& s = e.support;
    if (s[0] >= s[2] || s[1] >= s[3]) {
      windows.insert(windows.end(), {1, 1, -1, -1});
      continue;
    }
    windows.insert(windows.end(),
                   {float(((s[0] - pad) / rx - 0.5) * w), float((0.5 - (s[3] + pad) / ry) * h),
                    float(((s[2] + pad) / rx - 0.5) * w), float((0.5 - (s[1] - pad) / ry) * h)});
  }
  tile_stride_ = 2 + near_end + (count - far_begin);
  tile_list_lights_ = tile_stride_ - 2;
  glUseProgram(p);
  glUniform1i(Loc(p, "u_tile_count"), tiles_x * tiles_y);
  glUniform1i(Loc(p, "u_tile_stride"), tile_stride_);
  glUniform1i(Loc(p, "u_count"), count);
  glUniform1i(Loc(p, "u_near_end"), near_end);
  glUniform1i(Loc(p, "u_far_begin"), far_begin);
  glUniform4fv(Loc(p, "u_lights"), count, lights);
  glUniform4fv(Loc(p, "u_support"), count, windows.data());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, gl_->tile_bounds);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, gl_->tile_lists);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  glDispatchCompute(GLuint(tiles_x * tiles_y + 63) / 64, 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

double Renderer::ListedLightFraction() const {
  if (!options_.tiled_lights || tile_list_lights_ == 0) return 1;
  const int tiles = ((width_ + kTile - 1) / kTile) * ((height_ + kTile - 1) / kTile);
  std::vector<GLuint> lists(size_t(tiles) * tile_stride_);
  glGetNamedBufferSubData(gl_->tile_lists, 0, GLsizeiptr(lists.size() * sizeof(GLuint)),
                          lists.data());
  double listed = 0;
  for (int t = 0; t < tiles; ++t)
    listed += lists[size_t(t) * tile_stride_] + lists[size_t(t) * tile_stride_ + 1];
  return listed / (double(tiles) * tile_list_lights_);
}

// Everything of a light pass but the lights: target, uniforms, textures.
void Renderer::SetCommonUniforms(unsigned program, Shading shading) {
  const GLuint p = program;
  if (shading == Shading::kCoarse) {
    glBindFramebuffer(GL_FRAMEBUFFER, gl_->coarse_fbo);
    glViewport(0, 0, (width_ + 1) / 2, (height_ + 1) / 2);
  } else {
    const int target = options_.srgbe ? 1 - ping_ : 0;
    glBindFramebuffer(GL_FRAMEBUFFER, gl_->fbo[target]);
    glViewport(0, 0, width_, height_);
  }
  glUseProgram(p);
  glUniform1f(Loc(p, "u_d"), float(info_.distance_mm));
  glUniform2f(Loc(p, "u_window"), float(info_.layout.window_w_mm), float(info_.layout.window_h_mm));
  glUniform2f(Loc(p, "u_depth"), float(kShadowDepthA), float(kShadowDepthB));
  glUniform1f(Loc(p, "u_radiance_scale"), float(options_.radiance_scale));
  glUniform1i(Loc(p, "u_unit_albedo"), options_.unit_albedo ? 1 : 0);
  if (options_.tiled_lights) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, gl_->tile_lists);
    glUniform1i(Loc(p, "u_tiles_x"), (width_ + kTile - 1) / kTile);
    glUniform1i(Loc(p, "u_tile_stride"), tile_stride_);
  }
  const Eigen::Vector2d corner = info_.grid.Centre(info_.grid.nu - 1, info_.grid.nv - 1);
  glUniform2f(Loc(p, "u_grid_half"), float(corner.x()), float(corner.y()));
  // One shadow texel seen at unit distance, times 1.5: normal offset against self-shadowing.
  glUniform1f(Loc(p, "u_offset_scale"),
              float(1.5 * info_.layout.window_w_mm / info_.distance_mm / options_.shadow_size));
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D_ARRAY, gl_->intensity);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D_ARRAY, gl_->shadow);
  const GLint shadow_filter = options_.shadow_pcf ? GL_LINEAR : GL_NEAREST;
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, shadow_filter);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, shadow_filter);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_2D, gl_->packed[ping_]);
  glUniform1i(Loc(p, "u_intensity"), 0);
  glUniform1i(Loc(p, "u_shadow"), 1);
  glUniform1i(Loc(p, "u_previous"), 2);
  const char* gbuffer[] = {"u_gbuffer_position", "u_gbuffer_normal", "u_gbuffer_albedo"};
  for (int k = 0; k < 3; ++k) {
    glActiveTexture(GL_TEXTURE3 + k);
    glBindTexture(GL_TEXTURE_2D, gl_->gbuffer[k]);
    glUniform1i(Loc(p, gbuffer[k]), 3 + k);
  }
  if (shading == Shading::kResolve || shading == Shading::kReproject) {
    const bool coarse = shading == Shading::kResolve;
    glActiveTexture(GL_TEXTURE6);
    glBindTexture(GL_TEXTURE_2D, coarse ? gl_->coarse : gl_->source[0]);
    glUniform1i(Loc(p, "u_source"), 6);
    glUniform1f(Loc(p, "u_reuse_tolerance"),
                float(coarse ? options_.coarse_tolerance : options_.reproject_tolerance));
    const Eigen::Matrix4f m =
        (coarse ? drawn_view_projection_ : source_view_projection_) * pose_.matrix().cast<float>();
    const Eigen::Vector4f depth_row = m.row(3).transpose();
    glUniform4fv(Loc(p, "u_depth_row"), 1, depth_row.data());
  }
  if (shading == Shading::kReproject) {
    for (int k = 1; k < 3; ++k) {
      glActiveTexture(GL_TEXTURE6 + k);
      glBindTexture(GL_TEXTURE_2D, gl_->source[k]);
    }
    glUniform1i(Loc(p, "u_source_position"), 7);
    glUniform1i(Loc(p, "u_source_normal"), 8);
    const Eigen::Matrix4f m = source_view_projection_ * pose_.matrix().cast<float>();
    glUniformMatrix4fv(Loc(p, "u_source_from_luminaire"), 1, GL_FALSE, m.data());
  }
  glActiveTexture(GL_TEXTURE0);
}

std::vector<Renderer::Shading> Renderer::ShadingPasses(int lights) const {
  if (list_only_) return {Shading::kExactList};
  if (options_.coarse_tolerance > 0 && lights >= kCoarseMinLights)
    return {Shading::kCoarse, Shading::kResolve, Shading::kExactList};
  return {Shading::kExact};
}

unsigned Renderer::LightProgram(bool fast, Shading shading) {
  const std::string defines =
      "#define LIGHTS_PER_PASS " + std::to_string(fast ? kFastLightsPerPass : kLightsPerPass) +
      "\n#define FAST " + std::to_string(fast) + "\n#define SHADOWS " +
      std::to_string(options_.shadows) + "\n#define SRGBE " + std::to_string(options_.srgbe) +
      "\n#define TEXTURE_FILTER " + std::to_string(int(options_.texture_filter)) +
      "\n#define COARSE " + std::to_string(shading == Shading::kCoarse) + "\n#define RESOLVE " +
      std::to_string(shading == Shading::kResolve) + "\n#define EXACT_LIST " +
      std::to_string(shading == Shading::kExactList) + "\n#define REPROJECT " +
      std::to_string(shading == Shading::kReproject) + "\n#define TILED " +
      std::to_string(options_.tiled_lights) + "\n#define TILE " + std::to_string(kTile) + "\n";
  GLuint& program = gl_->light_programs[defines];
  if (!program) {
    program = shading == Shading::kExactList ? LinkCompute(LightFragment(defines))
                                             : Link(kQuadVertex, LightFragment(defines));
  }
  return program;
}

void Renderer::LightPass(const std::vector<int>& lights) {
  std::vector<LightEntry> entries;
  for (int l : lights) {
    LightEntry e;
    e.centre = e.shadow_centre = info_.grid.Centre(l % info_.grid.nu, l / info_.grid.nu);
    e.layer = e.shadow_layer = l;
    e.support = support_[l];
    entries.push_back(e);
  }
  const int n = int(entries.size());
  EntriesPass(entries, false, n, n, std::numeric_limits<double>::infinity());
}

// The pass's lights as the shaders' u_lights (centre, shadow centre) and u_light_layers (E'
// layer, shadow layer, shadow span: a single light's is its own entry).
void Renderer::PackLights(const std::vector<LightEntry>& entries, std::vector<float>* lights,
                          std::vector<int>* layers) {
  for (size_t k = 0; k < entries.size(); ++k) {
    const LightEntry& e = entries[k];
    lights->insert(lights->end(), {float(e.centre.x()), float(e.centre.y()),
                                   float(e.shadow_centre.x()), float(e.shadow_centre.y())});
    layers->insert(layers->end(), {e.layer, e.shadow_layer,
                                   e.span_begin < 0 ? int(k) : e.span_begin, e.span_count});
  }
}

void Renderer::EntriesPass(const std::vector<LightEntry>& entries, bool fast, int near_end,
                           int far_begin, double z_far) {
  const GLsizei n = GLsizei(entries.size());
  std::vector<float> packed;
  std::vector<int> layers;
  PackLights(entries, &packed, &layers);
  if (options_.tiled_lights) {
    TileLists(fast ? kFastLightsPerPass : kLightsPerPass, packed.data(), entries, near_end,
              far_begin);
  }
  for (Shading shading : ShadingPasses(n)) {
    const GLuint p = LightProgram(fast, shading);
    SetCommonUniforms(p, shading);
    glUniform1i(Loc(p, "u_count"), n);
    glUniform4fv(Loc(p, "u_lights"), n, packed.data());
    glUniform4iv(Loc(p, "u_light_layers"), n, layers.data());
    // The shortcuts' near and far lists (absent from the plain program: location -1, ignored).
    glUniform1i(Loc(p, "u_near_end"), near_end);
    glUniform1i(Loc(p, "u_far_begin"), far_begin);
    glUniform1f(Loc(p, "u_z_far"), float(std::min(z_far, 3.0e38)));
    DrawLightPass(shading);
  }
}

// Runs the bound light program over the image: float adds into the accumulation, sRGBE packs
// the new sum into the other target; coarse shading's first pass writes its samples.
void Renderer::DrawLightPass(Shading shading) {
  glDisable(GL_DEPTH_TEST);
  glBindVertexArray(gl_->quad_vao);
  if (shading == Shading::kExactList) {
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, gl_->exact_count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, gl_->exact_list);
    glBindImageTexture(0, gl_->colour, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(1, gl_->packed[ping_], 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindImageTexture(2, gl_->irradiance, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    // Work groups of 64 in rows of at most 65535, the smallest GL_MAX_COMPUTE_WORK_GROUP_COUNT.
    const GLuint groups = (exact_listed_ + 63) / 64, row = std::min<GLuint>(groups, 65535);
    if (groups > 0) glDispatchCompute(row, (groups + row - 1) / row, 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    return;
  }
  const bool listing = shading == Shading::kResolve || shading == Shading::kReproject;
  if (listing) {
    const GLuint zero = 0;
    glNamedBufferSubData(gl_->exact_count, 0, sizeof(zero), &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, gl_->exact_count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, gl_->exact_list);
  }
  if (shading == Shading::kCoarse) {
    glDisablei(GL_BLEND, 0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    return;
  }
  if (options_.srgbe) {
    glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDisable(GL_BLEND);
  } else {
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnablei(GL_BLEND, 0);
    glBlendFunci(0, GL_ONE, GL_ONE);
  }
  // The sums alone, kept only where reprojection will reuse them: in a view being shaded in full
  // (a reprojected one never becomes a source).
  const GLboolean keep =
      options_.reproject_tolerance > 0 && view_shaded_in_full_ ? GL_TRUE : GL_FALSE;
  glColorMaski(2, keep, keep, keep, keep);
  glEnablei(GL_BLEND, 2);
  glBlendFunci(2, GL_ONE, GL_ONE);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDisablei(GL_BLEND, 0);
  glDisablei(GL_BLEND, 2);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glColorMaski(2, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  if (options_.srgbe) ping_ = 1 - ping_;
  if (listing) {  // how many it listed (sizes the compute passes' dispatch)
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    glGetNamedBufferSubData(gl_->exact_count, 0, sizeof(exact_listed_), &exact_listed_);
  }
}

// The light passes that add `lights`: with the shortcuts, FastPasses; otherwise batches of
// kLightsPerPass.
void Renderer::LightPasses(const std::vector<int>& lights) {
  if (lights.empty()) return;
  if (Fast()) {
    FastPasses(lights);
    return;
  }
  for (size_t start = 0; start < lights.size(); start += kLightsPerPass) {
    const size_t end = std::min(lights.size(), start + kLightsPerPass);
    LightPass(std::vector<int>(lights.begin() + start, lights.begin() + end));
  }
}

// Reprojection: each pixel takes the source view's sums where its point lies between four source
// pixels of its own surface whose sums agree (Reused in kLightFragment); the pixels it lists are
// shaded by the source's lights. A source whose reuse listed over a quarter of the pixels (the
// view moved far) is replaced: the next view is shaded in full, and becomes the source at the
// move after it.
void Renderer::Reproject() {
  const GLuint p = LightProgram(false, Shading::kReproject);
  SetCommonUniforms(p, Shading::kReproject);
  DrawLightPass(Shading::kReproject);
  std::vector<int> lights;
  for (size_t l = 0; l < source_lights_.size(); ++l) {
    if (source_lights_[l]) lights.push_back(int(l));
  }
  // The light passes run only EXACT_LIST over the list while this lives (also if one throws).
  struct ListOnly {
    bool& flag;
    explicit ListOnly(bool& f) : flag(f) { flag = true; }
    ~ListOnly() { flag = false; }
  } list_only(list_only_);
  LightPasses(lights);
  state_.reprojected_exact = double(exact_listed_) / (double(width_) * height_);
  reproject_next_ = state_.reprojected_exact <= 0.25;
  accumulated_ = source_lights_;
}

int Renderer::Render() {
  using Clock = std::chrono::steady_clock;
  auto mark = Clock::now();
  times_ = PhaseTimes{};
  // Adds the time since the last mark to *ms (after glFinish) when phases are timed.
  auto lap = [&](double* ms) {
    if (!options_.time_phases) return;
    glFinish();
    const auto now = Clock::now();
    *ms += std::chrono::duration<double, std::milli>(now - mark).count();
    mark = now;
  };
  bool reprojected = false;
  if (!view_valid_) {
    // The view shaded in full so far becomes reprojection's source before the G-buffer changes.
    if (options_.reproject_tolerance > 0 && view_shaded_in_full_) {
      // Its textures change roles with the source's (no copies); the targets take the others.
      std::swap(gl_->irradiance, gl_->source[0]);
      std::swap(gl_->gbuffer[0], gl_->source[1]);
      std::swap(gl_->gbuffer[1], gl_->source[2]);
      glBindFramebuffer(GL_FRAMEBUFFER, gl_->gbuffer_fbo);
      for (int k = 0; k < 2; ++k) {
        glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + k, gl_->gbuffer[k], 0);
      }
      for (GLuint fbo : gl_->fbo) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT2, gl_->irradiance, 0);
      }
      source_view_projection_ = drawn_view_projection_;
      source_lights_ = accumulated_;
      source_valid_ = true;
    }
    view_shaded_in_full_ = false;
    // Clear the sums, then draw the G-buffer (what each pixel sees; the light passes shade it).
    // Both targets share the float sum and the irradiance; the second target's packed sum is
    // read only in sRGBE mode. Of the G-buffer only the positions are cleared: w = 0 marks a
    // pixel without a surface, and no pass reads its normal or albedo there. (The crypt's G-buffer
    // phase went from ~4.6 to ~3.5 ms at 400 x 400 on llvmpipe.)
    const float zero[4] = {0, 0, 0, 0};
    const GLuint zero_u[4] = {0, 0, 0, 0};
    glBindFramebuffer(GL_FRAMEBUFFER, gl_->fbo[0]);
    glClearBufferfv(GL_COLOR, 0, zero);
    glClearBufferuiv(GL_COLOR, 1, zero_u);
    glClearBufferfv(GL_COLOR, 2, zero);
    if (options_.srgbe) {
      glBindFramebuffer(GL_FRAMEBUFFER, gl_->fbo[1]);
      glClearBufferuiv(GL_COLOR, 1, zero_u);
    }
    ping_ = 0;
    glBindFramebuffer(GL_FRAMEBUFFER, gl_->gbuffer_fbo);
    glViewport(0, 0, width_, height_);
    glClearBufferfv(GL_COLOR, 0, zero);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    if (options_.cull_back_faces) glEnable(GL_CULL_FACE);
    const GLuint p = gl_->geometry_program;
    glUseProgram(p);
    const Eigen::Matrix4f to_lum = pose_.inverse().matrix().cast<float>();
    glUniformMatrix4fv(Loc(p, "u_view_projection"), 1, GL_FALSE, view_projection_.data());
    glUniformMatrix4fv(Loc(p, "u_scene_to_luminaire"), 1, GL_FALSE, to_lum.data());
    glBindVertexArray(gl_->vao);
    glDrawArrays(GL_TRIANGLES, 0, vertex_count_);
    glDisable(GL_CULL_FACE);
    drawn_view_projection_ = view_projection_;
    accumulated_.assign(accumulated_.size(), false);
    view_valid_ = true;
    tile_bounds_valid_ = false;
    lap(&times_.depth_ms);
    const bool source_lit =
        std::find(source_lights_.begin(), source_lights_.end(), true) != source_lights_.end();
    if (options_.reproject_tolerance > 0 && source_valid_ && source_lit && reproject_next_) {
      Reproject();
      reprojected = true;
    } else {
      view_shaded_in_full_ = options_.reproject_tolerance > 0;
      reproject_next_ = true;
      state_.reprojected_exact = 0;
    }
  }
  std::vector<int> todo;
  for (size_t l = 0; l < present_.size(); ++l) {
    if (present_[l] && !accumulated_[l]) todo.push_back(int(l));
  }
  if (options_.shadows && !todo.empty()) {
    if (!groups_valid_) ChooseShadowGroups();
    // Each position's map (with sharing, its block's, in the layer shadow_layer_ names).
    std::vector<ShadowJob> jobs;
    std::vector<bool> listed(shadow_valid_.size(), false);
    for (int l : todo) {
      const int layer = shadow_layer_[l];
      if (shadow_valid_[layer] || listed[layer]) continue;
      listed[layer] = true;
      jobs.push_back(ShadowJobFor(l));
    }
    RenderShadowMaps(jobs);
    for (const ShadowJob& job : jobs) shadow_valid_[job.layer] = true;
    lap(&times_.shadow_ms);
  }
  LightPasses(todo);
  for (int l : todo) accumulated_[l] = true;
  if (reprojected || !todo.empty()) lap(&times_.light_ms);
  glFinish();
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) throw Failure("GL error " + std::to_string(error) + " while rendering");
  return int(todo.size());
}

ImageF Renderer::Read() const {
  ImageF out(width_, height_, 3);
  if (options_.srgbe) {
    std::vector<uint32_t> packed(size_t(width_) * height_);
    glBindTexture(GL_TEXTURE_2D, gl_->packed[ping_]);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, packed.data());
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        const auto rgb = DecodeSrgbe(packed[size_t(height_ - 1 - y) * width_ + x]);
        for (int c = 0; c < 3; ++c) out.at(x, y, c) = rgb[c];
      }
    }
    return out;
  }
  std::vector<float> rgba(size_t(width_) * height_ * 4);
  glBindTexture(GL_TEXTURE_2D, gl_->colour);
  glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, rgba.data());
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      for (int c = 0; c < 3; ++c) {
        out.at(x, y, c) = rgba[(size_t(height_ - 1 - y) * width_ + x) * 4 + c];
      }
    }
  }
  return out;
}

void Renderer::Display(double exposure, int viewport_w, int viewport_h) const {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, viewport_w, viewport_h);
  glDisable(GL_DEPTH_TEST);
  const GLuint p = gl_->display_program;
  glUseProgram(p);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, gl_->colour);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, gl_->packed[ping_]);
  glUniform1i(Loc(p, "u_float"), 0);
  glUniform1i(Loc(p, "u_packed"), 1);
  glUniform1i(Loc(p, "u_srgbe"), options_.srgbe);
  glUniform1f(Loc(p, "u_exposure"), float(exposure));
  glBindVertexArray(gl_->quad_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace lumislab
