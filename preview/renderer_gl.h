// For the renderer's own files only (renderer*.cc): its GL objects and the constants and helpers
// they share.
#pragma once

#include <glad/gl.h>

#include <map>
#include <string>
#include <vector>

#include "core/slab.h"
#include "preview/gl_program.h"
#include "preview/renderer.h"

namespace lumislab {

// The shadow maps' near and far planes (mm from c_ij, luminaire frame): occluders nearer than
// kShadowNear are ignored.
constexpr double kShadowNear = 10.0;
constexpr double kShadowFar = 100000.0;
// The shadow maps' depth mapping (u_depth in LightClip): NDC z = A + B / z between those planes.
constexpr double kShadowDepthA = (kShadowFar + kShadowNear) / (kShadowFar - kShadowNear);
constexpr double kShadowDepthB = -2 * kShadowFar * kShadowNear / (kShadowFar - kShadowNear);
// Shadow maps per layered draw: the size of u_maps (shaders/shadow.vert).
constexpr int kShadowBatch = 32;
// Light culling's tiles: kTile x kTile pixels.
constexpr int kTile = 16;

struct Renderer::Gl {
  GLuint vao = 0, vbo = 0, quad_vao = 0;
  GLuint geometry_program = 0, shadow_program = 0, display_program = 0;
  // Light-pass programs by their #defines (Renderer::LightProgram), linked when first used.
  std::map<std::string, GLuint> light_programs;
  GLuint intensity = 0, shadow = 0, shadow_fbo = 0;
  bool layered_shadows = false;  // shadow.vert with LAYERED: several maps per draw
  int shadow_batch = 1;          // maps per layered draw
  GLuint colour = 0, packed[2] = {0, 0}, fbo[2] = {0, 0};
  // The G-buffer (geometry.frag): position, normal, albedo and depth.
  GLuint gbuffer[3] = {0, 0, 0}, depth = 0, gbuffer_fbo = 0;
  // Coarse shading's samples (RGBA32F, every second pixel of every second row), and the list
  // of the pixels shaded exactly (ExactCount, ExactList in light_pass.glsl).
  GLuint coarse = 0, coarse_fbo = 0, exact_count = 0, exact_list = 0;
  // The EXACT_LIST dispatch's size, written on the GPU from exact_count (exact_args.comp), so that
  // no frame reads the count back.
  GLuint dispatch_args = 0, exact_args_program = 0;
  // Reprojection's count of pixels listed, copied after its pass into a buffer mapped once
  // (persistent, coherent) and read when its fence has passed: the next camera move's choice
  // (reproject_next_) and shortcuts() without a read-back in a frame.
  GLuint reproject_count = 0;
  const GLuint* reproject_count_map = nullptr;
  GLsync reproject_fence = nullptr;
  // --profile: GL_TIME_ELAPSED queries, one per timed phase of a frame (Render()).
  GLuint phase_queries[4] = {0, 0, 0, 0};
  bool timer_queries = false;  // the context has them (GL_QUERY_COUNTER_BITS > 0)
  // The lights' sum before albedo (o_irradiance) of the present view, and the last view shaded
  // in full: its sums, positions and normals (what reprojection reuses).
  GLuint irradiance = 0, source[3] = {0, 0, 0};
  // Light culling by tiles: the tiles' bounds (per view) and light lists (per light pass), and
  // the programs that make them (the lists' by lights per pass).
  GLuint tile_bounds = 0, tile_lists = 0, tile_bounds_program = 0;
  std::map<int, GLuint> tile_list_programs;
};

// Blocks of g x g positions from the grid's corner (the last ones smaller): members of block
// (bi, bj) are i in [bi g, min(nu, bi g + g)), likewise j. Shadow-map sharing and light merging
// use them.
std::vector<int> BlockMembers(const SamplingGrid& grid, int g, int bi, int bj);
// The mean of the members' centres; *radius: the largest distance of a member's centre from it.
Eigen::Vector2d MeanCentre(const SamplingGrid& grid, const std::vector<int>& members,
                           double* radius);

}  // namespace lumislab
