// Reprojection (RenderOptions::reproject_tolerance): after a camera move, the sums of the last
// view shaded in full reused where they may be.
#include <algorithm>
#include <utility>
#include <vector>

#include "preview/renderer.h"
#include "preview/renderer_gl.h"

namespace lumislab {

void Renderer::KeepViewAsSource() {
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

bool Renderer::ReadReprojectCount(bool wait) const {
  if (!reproject_count_pending_) return true;
  GLint status = GL_UNSIGNALED;
  if (wait) {
    while (glClientWaitSync(gl_->reproject_fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000) ==
           GL_TIMEOUT_EXPIRED) {
    }
  } else {
    glGetSynciv(gl_->reproject_fence, GL_SYNC_STATUS, 1, nullptr, &status);
    if (status != GL_SIGNALED) return false;
  }
  glDeleteSync(gl_->reproject_fence);
  gl_->reproject_fence = nullptr;
  reproject_count_pending_ = false;
  state_.reprojected_exact = double(*gl_->reproject_count_map) / (double(width_) * height_);
  reproject_next_ = state_.reprojected_exact <= 0.25;
  return true;
}

const ShortcutState& Renderer::shortcuts() const {
  ReadReprojectCount(true);
  return state_;
}

// A count still being copied is forgotten (its view is gone).
void Renderer::DropReprojectCount() {
  if (gl_->reproject_fence) glDeleteSync(gl_->reproject_fence);
  gl_->reproject_fence = nullptr;
  reproject_count_pending_ = false;
}

bool Renderer::TryReproject() {
  // The last reprojection's count, if its frame is done (a fence polled, not waited for): a
  // source whose reuse listed over a quarter of the pixels is replaced. Not done yet: this move
  // reprojects from it again (the pixels it cannot reuse are listed and shaded exactly).
  ReadReprojectCount(false);
  const bool source_lit =
      std::find(source_lights_.begin(), source_lights_.end(), true) != source_lights_.end();
  if (options_.reproject_tolerance > 0 && source_valid_ && source_lit && reproject_next_) {
    Reproject();
    return true;
  }
  view_shaded_in_full_ = options_.reproject_tolerance > 0;
  reproject_next_ = true;
  DropReprojectCount();
  state_.reprojected_exact = 0;
  return false;
}

// Reprojection: each pixel takes the source view's sums where its point lies between four source
// pixels of its own surface whose sums agree (Reused in shaders/light_pass.glsl); the pixels it
// lists are shaded by the source's lights. A source whose reuse listed over a quarter of the pixels
// (the view moved far) is replaced: the next view whose move finds that count done (TryReproject)
// is shaded in full, and becomes the source at the move after it.
void Renderer::Reproject() {
  const GLuint p = LightProgram(false, Shading::kReproject);
  SetCommonUniforms(p, Shading::kReproject);
  DrawLightPass(Shading::kReproject);
  // Its count, copied for ReadReprojectCount; the fence marks the copy, glFlush sends it off.
  DropReprojectCount();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  glCopyNamedBufferSubData(gl_->exact_count, gl_->reproject_count, 0, 0, sizeof(GLuint));
  glMemoryBarrier(GL_CLIENT_MAPPED_BUFFER_BARRIER_BIT);
  gl_->reproject_fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  glFlush();
  reproject_count_pending_ = true;
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
  accumulated_ = source_lights_;
}

}  // namespace lumislab
