#include "preview/renderer.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/srgbe.h"
#include "preview/renderer_gl.h"
#include "preview/shaders.h"

namespace lumislab {
namespace {

// shaders/shadow.vert for kShadowBatch maps per draw; layered: the instances draw into the layers
// and scissor rectangles they name (ARB_shader_viewport_layer_array).
std::string ShadowVertex(bool layered) {
  std::string text = WithDefines(
      shaders::kShadowVertex,
      layered ? "#extension GL_ARB_shader_viewport_layer_array : require\n#define LAYERED\n" : "");
  const std::string batch = "SHADOW_BATCH";
  text.replace(text.find(batch), batch.size(), std::to_string(kShadowBatch));
  return text;
}

}  // namespace

Renderer::Renderer(const SlabInfo& info, int width, int height, const RenderOptions& options,
                   const std::vector<LightOrientation>& orientations)
    : info_(info),
      orientations_(orientations.empty() ? std::vector<LightOrientation>(1) : orientations),
      posed_(!orientations.empty()),
      width_(width),
      height_(height),
      options_(options),
      gl_(new Gl) {
  if (int(orientations_.size()) > kMaxOrientations)
    throw BadInput("at most " + std::to_string(kMaxOrientations) + " orientations, got " +
                   std::to_string(orientations_.size()));
  CheckOrientationOptions(options_);
  orientation_present_.assign(orientations_.size(), false);
  const int lights = info_.grid.count() * int(orientations_.size());
  present_.assign(lights, false);
  shadow_valid_.assign(lights, false);
  accumulated_.assign(lights, false);
  support_.assign(lights, {0, 0, 0, 0});
  shadow_rect_.assign(lights, {0, 0, 0, 0});
  shadow_layer_.resize(lights);
  shadow_centre_.resize(lights);
  for (int l = 0; l < lights; ++l) {
    shadow_layer_[l] = l;
    const int p = GridIndexOf(l);
    shadow_centre_[l] = info_.grid.Centre(p % info_.grid.nu, p / info_.grid.nu);
  }
  intensity_.resize(lights);
  // Merged textures follow the positions' layers (one slab only): at most one per 2 x 2 block.
  const int merge_layers = ((info_.grid.nu + 1) / 2) * ((info_.grid.nv + 1) / 2);
  // The light program of these options now, so that a driver that refuses it fails here; the
  // others are linked when first used (the shortcuts' uniform arrays are larger: a driver that
  // refuses them then fails only the shortcuts, not the full render).
  LightProgram(false);
  gl_->geometry_program = LinkProgram(shaders::kSceneVertex, shaders::kGeometryFragment);
  // Layered maps need a viewport (scissor rectangle) per map of a draw.
  GLint viewports = 0;
  glGetIntegerv(GL_MAX_VIEWPORTS, &viewports);
  gl_->shadow_batch = std::min(kShadowBatch, int(viewports));
  gl_->layered_shadows = options_.layered_shadow_maps &&
                         HasExtension("GL_ARB_shader_viewport_layer_array") &&
                         gl_->shadow_batch >= 1;
  gl_->shadow_program = LinkProgram(ShadowVertex(gl_->layered_shadows), shaders::kEmptyFragment);
  gl_->display_program = LinkProgram(shaders::kQuadVertex, shaders::kDisplayFragment);
  glGenVertexArrays(1, &gl_->vao);
  glGenVertexArrays(1, &gl_->quad_vao);
  glGenBuffers(1, &gl_->vbo);

  // Every orientation's positions are layers of one texture array.
  GLint max_layers = 0;
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  if (lights + merge_layers > max_layers)
    throw BadInput(std::to_string(lights) + " positions (" + std::to_string(OrientationCount()) +
                   " orientations) exceed the driver's " + std::to_string(max_layers) +
                   " texture-array layers");
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
  glCreateBuffers(1, &gl_->dispatch_args);
  glNamedBufferStorage(gl_->dispatch_args, 3 * sizeof(GLuint), nullptr, 0);
  gl_->exact_args_program = LinkComputeProgram(shaders::kExactArgsCompute);
  const GLbitfield mapped = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
  glCreateBuffers(1, &gl_->reproject_count);
  glNamedBufferStorage(gl_->reproject_count, sizeof(GLuint), nullptr, mapped);
  gl_->reproject_count_map = static_cast<const GLuint*>(
      glMapNamedBufferRange(gl_->reproject_count, 0, sizeof(GLuint), mapped));
  glGenQueries(4, gl_->phase_queries);
  GLint timer_bits = 0;
  glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &timer_bits);
  gl_->timer_queries = timer_bits > 0;
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
  glDeleteBuffers(1, &gl_->dispatch_args);
  glDeleteProgram(gl_->exact_args_program);
  if (gl_->reproject_fence) glDeleteSync(gl_->reproject_fence);
  glUnmapNamedBuffer(gl_->reproject_count);
  glDeleteBuffers(1, &gl_->reproject_count);
  glDeleteQueries(4, gl_->phase_queries);
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
  glNamedBufferStorage(gl_->tile_lists, tiles * (2 + 2 * kShortcutLightsPerPass) * sizeof(GLuint),
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
  CheckOrientationOptions(options);
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

void Renderer::SetPosition(int i, int j, const ImageF& intensity, int orientation) {
  if (intensity.width != info_.layout.res_x || intensity.height != info_.layout.res_y ||
      intensity.channels != 3) {
    throw BadInput("slab position texture does not match the slab layout");
  }
  if (orientation < 0 || orientation >= OrientationCount())
    throw BadInput("orientation " + std::to_string(orientation) + " of " +
                   std::to_string(OrientationCount()));
  const int layer = orientation * info_.grid.count() + info_.grid.Index(i, j);
  if (!orientation_present_[orientation]) {
    orientation_present_[orientation] = true;
    // The others' blend weights change where its cone overlaps theirs: the sums are redone.
    if (OrientationCount() > 1) view_valid_ = source_valid_ = view_shaded_in_full_ = false;
  }
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

bool Renderer::HasPosition(int i, int j, int orientation) const {
  return present_[orientation * info_.grid.count() + info_.grid.Index(i, j)];
}

int Renderer::PositionCount() const {
  int n = 0;
  for (bool p : present_) n += p;
  return n;
}

int Renderer::Render() {
  // --profile (time_phases): each phase inside a GL_TIME_ELAPSED query, read after the frame's
  // last call; where the context has no timer queries, wall time with glFinish between phases.
  // Not profiling, the frame neither reads back nor waits (Finish() waits, for timing).
  using Clock = std::chrono::steady_clock;
  auto mark = Clock::now();
  times_ = PhaseTimes{};
  const bool timed = options_.time_phases, queries = timed && gl_->timer_queries;
  times_.gpu_timer = queries;
  double* phase_of_query[4] = {nullptr, nullptr, nullptr, nullptr};
  int query = 0;
  if (queries) glBeginQuery(GL_TIME_ELAPSED, gl_->phase_queries[0]);
  // Ends the phase running since the last mark, adding its time to *ms.
  auto lap = [&](double* ms) {
    if (!timed) return;
    if (queries) {
      glEndQuery(GL_TIME_ELAPSED);
      phase_of_query[query++] = ms;
      glBeginQuery(GL_TIME_ELAPSED, gl_->phase_queries[query]);
      return;
    }
    glFinish();
    const auto now = Clock::now();
    *ms += std::chrono::duration<double, std::milli>(now - mark).count();
    mark = now;
  };
  bool reprojected = false;
  if (!view_valid_) {
    if (options_.reproject_tolerance > 0 && view_shaded_in_full_) KeepViewAsSource();
    view_shaded_in_full_ = false;
    DrawView();
    lap(&times_.depth_ms);
    reprojected = TryReproject();
  }
  const std::vector<int> todo = PositionsToAdd();
  if (options_.shadows && !todo.empty()) {
    UpdateShadowMaps(todo);
    lap(&times_.shadow_ms);
  }
  LightPasses(todo);
  for (int l : todo) accumulated_[l] = true;
  if (reprojected || !todo.empty()) lap(&times_.light_ms);
  if (queries) {
    glEndQuery(GL_TIME_ELAPSED);  // the open one after the last phase: not a phase
    for (int k = 0; k < query; ++k) {
      GLuint64 ns = 0;
      glGetQueryObjectui64v(gl_->phase_queries[k], GL_QUERY_RESULT, &ns);
      *phase_of_query[k] += double(ns) * 1e-6;
    }
  }
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) throw Failure("GL error " + std::to_string(error) + " while rendering");
  return int(todo.size());
}

void Renderer::Finish() const { glFinish(); }

void Renderer::DrawView() {
  // Clear the sums, then draw the G-buffer (what each pixel sees; the light passes shade it).
  // Both targets share the float sum and the irradiance; the second target's packed sum is
  // read only in sRGBE mode. Of the G-buffer only the positions are cleared: w = 0 marks a
  // pixel without a surface, and no pass reads its normal or albedo there.
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
}

std::vector<int> Renderer::PositionsToAdd() const {
  std::vector<int> todo;
  for (size_t l = 0; l < present_.size(); ++l) {
    if (present_[l] && !accumulated_[l]) todo.push_back(int(l));
  }
  return todo;
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
