// The light passes: batching the positions, the light program for the options (compiled in),
// its uniforms and textures, and the passes of coarse shading (RenderOptions::coarse_tolerance).
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "preview/renderer.h"
#include "preview/renderer_gl.h"
#include "preview/shaders.h"

namespace lumislab {

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
  SetOrientationUniforms(p);
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

// shaders/light_pass.glsl with the options as #defines: llvmpipe runs both sides of a branch on
// a uniform, masked, so a run-time switch would cost its untaken side in every light iteration.
// FAST: the shortcuts' program.
unsigned Renderer::LightProgram(bool shortcuts, Shading shading) {
  const std::string defines =
      "#define LIGHTS_PER_PASS " +
      std::to_string(shortcuts ? kShortcutLightsPerPass : kLightsPerPass) + "\n#define FAST " +
      std::to_string(shortcuts) + "\n#define SHADOWS " + std::to_string(options_.shadows) +
      "\n#define SRGBE " + std::to_string(options_.srgbe) + "\n#define TEXTURE_FILTER " +
      std::to_string(int(options_.texture_filter)) + "\n#define COARSE " +
      std::to_string(shading == Shading::kCoarse) + "\n#define RESOLVE " +
      std::to_string(shading == Shading::kResolve) + "\n#define EXACT_LIST " +
      std::to_string(shading == Shading::kExactList) + "\n#define REPROJECT " +
      std::to_string(shading == Shading::kReproject) + "\n#define TILED " +
      std::to_string(options_.tiled_lights) + "\n#define TILE " + std::to_string(kTile) +
      "\n#define POSED " + std::to_string(posed_) + "\n#define ORIENTATIONS " +
      std::to_string(OrientationCount()) + "\n";
  GLuint& program = gl_->light_programs[defines];
  if (!program) {
    const std::string source = WithDefines(shaders::kLightPass, defines);
    program = shading == Shading::kExactList ? LinkComputeProgram(source)
                                             : LinkProgram(shaders::kQuadVertex, source);
  }
  return program;
}

void Renderer::LightPass(const std::vector<int>& lights) {
  std::vector<LightEntry> entries;
  for (int l : lights) {
    LightEntry e;
    const int p = GridIndexOf(l);
    e.centre = e.shadow_centre = info_.grid.Centre(p % info_.grid.nu, p / info_.grid.nu);
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

void Renderer::EntriesPass(const std::vector<LightEntry>& entries, bool shortcuts, int near_end,
                           int far_begin, double z_far) {
  const GLsizei n = GLsizei(entries.size());
  std::vector<float> packed;
  std::vector<int> layers;
  PackLights(entries, &packed, &layers);
  if (options_.tiled_lights) {
    TileLists(shortcuts ? kShortcutLightsPerPass : kLightsPerPass, packed.data(), entries, near_end,
              far_begin);
  }
  for (Shading shading : ShadingPasses(n)) {
    const GLuint p = LightProgram(shortcuts, shading);
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
// the new sum into the other target; coarse shading's first pass writes its samples; the resolve
// and reprojection passes also list the pixels they leave, and EXACT_LIST (a compute dispatch)
// shades those.
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
    // Sized on the GPU from the listing pass's count (exact_args.comp): no read-back.
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, gl_->dispatch_args);
    glDispatchComputeIndirect(0);
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
  if (listing) {  // how many it listed sizes the EXACT_LIST dispatch, on the GPU
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUseProgram(gl_->exact_args_program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, gl_->exact_count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, gl_->dispatch_args);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  }
}

// The light passes that add `lights` (ascending): with the shortcuts, ShortcutPasses (one
// orientation); otherwise batches of kLightsPerPass, each of one orientation (a pass shades in
// its capture frame).
void Renderer::LightPasses(const std::vector<int>& lights) {
  if (lights.empty()) return;
  pass_orientation_ = 0;
  if (options_.SharesOrMergesLights()) {
    ShortcutPasses(lights);
    return;
  }
  size_t start = 0;
  while (start < lights.size()) {
    pass_orientation_ = OrientationOf(lights[start]);
    size_t end = start;
    while (end < lights.size() && end - start < size_t(kLightsPerPass) &&
           OrientationOf(lights[end]) == pass_orientation_)
      ++end;
    LightPass(std::vector<int>(lights.begin() + start, lights.begin() + end));
    start = end;
  }
}

}  // namespace lumislab
