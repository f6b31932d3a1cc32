// Light culling by tiles (RenderOptions::tiled_lights). A point x (z > 0) is seen from centre c
// through the window at st = c + (x.xy - c) d / z = a + c t, with a = x.xy d / z and
// t = 1 - d / z; the tiles' bounds (shaders/tile_bounds.comp) keep, per tile of the G-buffer, the
// ranges of a and t over its points (once per view), and TileLists (shaders/tile_lists.comp), per
// light pass, lists the lights whose E' support can meet a + c t over those ranges. llvmpipe runs
// a branch's both sides masked, so a light is saved only by leaving it out of the loop; a tile's
// pixels share one list.
#include <array>
#include <string>
#include <vector>

#include "preview/renderer.h"
#include "preview/renderer_gl.h"
#include "preview/shaders.h"

namespace lumislab {

void Renderer::TileLists(int lights_per_pass, const float* lights,
                         const std::vector<LightEntry>& entries, int near_end, int far_begin) {
  const int tiles_x = (width_ + kTile - 1) / kTile, tiles_y = (height_ + kTile - 1) / kTile;
  const int count = int(entries.size());
  if (!tile_bounds_valid_ || tile_bounds_orientation_ != pass_orientation_) {
    if (!gl_->tile_bounds_program) {
      gl_->tile_bounds_program = LinkComputeProgram(
          WithDefines(shaders::kTileBoundsCompute, "#define TILE " + std::to_string(kTile) + "\n"));
    }
    const GLuint p = gl_->tile_bounds_program;
    glUseProgram(p);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, gl_->gbuffer[0]);
    glUniform1i(Loc(p, "u_gbuffer_position"), 3);
    glUniform1f(Loc(p, "u_d"), float(info_.distance_mm));
    glUniform2i(Loc(p, "u_tiles"), tiles_x, tiles_y);
    // The bounds are of the points in the pass's capture frame (the luminaire frame for a slab).
    const Eigen::Matrix4f capture_from_luminaire = CaptureFromLuminaire(pass_orientation_);
    glUniformMatrix4fv(Loc(p, "u_capture_from_luminaire"), 1, GL_FALSE,
                       capture_from_luminaire.data());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, gl_->tile_bounds);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);  // the G-buffer drawn before
    glDispatchCompute(GLuint(tiles_x * tiles_y + 63) / 64, 1, 1);
    glActiveTexture(GL_TEXTURE0);
    tile_bounds_valid_ = true;
    tile_bounds_orientation_ = pass_orientation_;
  }
  GLuint& p = gl_->tile_list_programs[lights_per_pass];
  if (!p) {
    p = LinkComputeProgram(
        WithDefines(shaders::kTileListsCompute,
                    "#define LIGHTS_PER_PASS " + std::to_string(lights_per_pass) + "\n"));
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

}  // namespace lumislab
