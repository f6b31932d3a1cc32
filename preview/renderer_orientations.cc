// A luminaire folder's orientations in the renderer (docs/method.md §4.12, "The preview of a
// luminaire folder"): their capture frames, the light program's orientation uniforms, and the
// shader's blend taper on its own (for the test that pins it equal to core's ConeTaper).
#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"
#include "preview/renderer.h"
#include "preview/renderer_gl.h"
#include "preview/shaders.h"

namespace lumislab {

Eigen::Matrix4f Renderer::CaptureFromLuminaire(int k) const {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  if (!posed_) return m;
  const LightOrientation& o = orientations_[k];
  m.topLeftCorner<3, 3>() = o.capture_from_luminaire.cast<float>();
  m.topRightCorner<3, 1>() = o.centre_mm.cast<float>();
  return m;
}

void Renderer::SetOrientationUniforms(unsigned program) const {
  if (!posed_) return;
  const GLuint p = program;
  const Eigen::Matrix4f m = CaptureFromLuminaire(pass_orientation_);
  glUniformMatrix4fv(Loc(p, "u_capture_from_luminaire"), 1, GL_FALSE, m.data());
  glUniform1i(Loc(p, "u_orientation"), pass_orientation_);
  std::vector<float> rotations, cones;
  for (size_t k = 0; k < orientations_.size(); ++k) {
    const LightOrientation& o = orientations_[k];
    const Eigen::Matrix3f r = o.capture_from_luminaire.cast<float>();  // column-major
    rotations.insert(rotations.end(), r.data(), r.data() + 9);
    cones.insert(cones.end(), {float(o.cone.distance_mm), float(o.cone.half_w_mm),
                               float(o.cone.half_h_mm), orientation_present_[k] ? 1.0f : 0.0f});
  }
  const GLsizei n = GLsizei(orientations_.size());
  glUniformMatrix3fv(Loc(p, "u_orientation_rotation"), n, GL_FALSE, rotations.data());
  glUniform4fv(Loc(p, "u_orientation_cone"), n, cones.data());
  glUniform1f(Loc(p, "u_taper_deg"), float(kDefaultTaperDeg));
}

void Renderer::CheckOrientationOptions(const RenderOptions& options) const {
  if (orientations_.size() > 1 && options.SharesOrMergesLights())
    throw BadInput(
        "shadow-map sharing and light merging serve one slab: a luminaire folder of several "
        "orientations renders every position (--shadow-share 0, --merge-group 1)");
}

std::vector<double> ShaderConeTaper(const OrientationCone& cone,
                                    const std::vector<Eigen::Vector3d>& w_capture,
                                    double taper_deg) {
  std::vector<float> directions;
  for (const Eigen::Vector3d& w : w_capture)
    directions.insert(directions.end(), {float(w.x()), float(w.y()), float(w.z()), 0.0f});
  const GLuint program = LinkComputeProgram(shaders::kConeTaperCheckCompute);
  GLuint buffers[2];
  glCreateBuffers(2, buffers);
  const GLsizeiptr n = GLsizeiptr(w_capture.size());
  glNamedBufferStorage(buffers[0], std::max<GLsizeiptr>(1, n) * 4 * sizeof(float),
                       directions.empty() ? nullptr : directions.data(), 0);
  glNamedBufferStorage(buffers[1], std::max<GLsizeiptr>(1, n) * sizeof(float), nullptr, 0);
  glUseProgram(program);
  glUniform3f(Loc(program, "u_cone"), float(cone.distance_mm), float(cone.half_w_mm),
              float(cone.half_h_mm));
  glUniform1f(Loc(program, "u_taper_deg"), float(taper_deg));
  glUniform1i(Loc(program, "u_count"), GLint(n));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers[0]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers[1]);
  glDispatchCompute(GLuint((n + 63) / 64), 1, 1);
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  std::vector<float> tapers(static_cast<size_t>(n));
  if (n > 0) glGetNamedBufferSubData(buffers[1], 0, n * sizeof(float), tapers.data());
  glDeleteBuffers(2, buffers);
  glDeleteProgram(program);
  if (glGetError() != GL_NO_ERROR) throw Failure("GL error while evaluating the shader's taper");
  return std::vector<double>(tapers.begin(), tapers.end());
}

}  // namespace lumislab
