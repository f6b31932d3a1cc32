// Shadow maps: which rectangle of which map each position reads, drawing them (layered where the
// driver can), and shadow-map sharing (RenderOptions::shadow_share_texels).
#include <algorithm>
#include <cmath>
#include <vector>

#include "preview/renderer.h"
#include "preview/renderer_gl.h"

namespace lumislab {

Renderer::ShadowJob Renderer::ShadowJobFor(int l) const {
  const int size = options_.shadow_size;
  ShadowJob job{shadow_layer_[l], OrientationOf(l), shadow_centre_[l], 0, 0, size, size};
  if (options_.SharesOrMergesLights() || !options_.shadow_scissor)
    return job;  // shared or merged maps: whole
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
  // Each map is drawn in its light's capture frame (a luminaire folder's orientation).
  const Eigen::Matrix4f to_lum = pose_.inverse().matrix().cast<float>();
  auto set_frame = [&](int orientation) {
    const Eigen::Matrix4f to_capture =
        posed_ ? Eigen::Matrix4f(CaptureFromLuminaire(orientation) * to_lum) : to_lum;
    glUniformMatrix4fv(Loc(p, "u_scene_to_luminaire"), 1, GL_FALSE, to_capture.data());
  };
  int frame = jobs[0].orientation;
  set_frame(frame);
  glUniform1f(Loc(p, "u_d"), float(info_.distance_mm));
  glUniform2f(Loc(p, "u_window"), float(info_.layout.window_w_mm), float(info_.layout.window_h_mm));
  glUniform2f(Loc(p, "u_depth"), float(kShadowDepthA), float(kShadowDepthB));
  const GLint maps = Loc(p, "u_maps");
  glBindVertexArray(gl_->vao);
  // Faces turned to the light wind counter-clockwise in the map (LightClip), so GL_BACK, the
  // default, drops the faces turned away (culling GL_FRONT instead would drop the room's walls;
  // PreviewSlabFiles.ShadowCullKeepsTheImage checks that the crypt's image stays within 1 %).
  if (options_.shadow_cull) glEnable(GL_CULL_FACE);
  const size_t batch = gl_->layered_shadows ? size_t(gl_->shadow_batch) : 1;
  for (size_t b = 0, n = 0; b < jobs.size(); b += n) {
    // A draw's maps share one frame.
    n = 1;
    while (n < batch && b + n < jobs.size() && jobs[b + n].orientation == jobs[b].orientation) ++n;
    if (jobs[b].orientation != frame) set_frame(frame = jobs[b].orientation);
    // The draw's maps and their scissor rectangles, one call each (not one per map).
    float u[4 * kShadowBatch];
    GLint scissors[4 * kShadowBatch];
    for (size_t k = 0; k < n; ++k) {
      const ShadowJob& job = jobs[b + k];
      u[4 * k] = float(job.centre.x());
      u[4 * k + 1] = float(job.centre.y());
      u[4 * k + 2] = float(job.layer);
      u[4 * k + 3] = 0;
      scissors[4 * k] = job.x0;
      scissors[4 * k + 1] = job.y0;
      scissors[4 * k + 2] = std::max(0, job.x1 - job.x0);
      scissors[4 * k + 3] = std::max(0, job.y1 - job.y0);
    }
    glScissorArrayv(0, GLsizei(n), scissors);
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

void Renderer::UpdateShadowMaps(const std::vector<int>& todo) {
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
  // Every orientation's maps (sharing serves one slab: the others keep their own maps).
  shadow_valid_.assign(LightCount(), false);
  int g = 1;
  state_ = ShortcutState{};
  if (options_.shadow_share_texels > 0) {
    const int centre = grid.Index(grid.nu / 2, grid.nv / 2);
    const int size = options_.shadow_size;
    RenderShadowMaps({{centre, 0, grid.Centre(grid.nu / 2, grid.nv / 2), 0, 0, size, size}});
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

}  // namespace lumislab
