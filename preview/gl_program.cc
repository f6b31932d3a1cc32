#include "preview/gl_program.h"

#include <cstring>
#include <initializer_list>
#include <utility>
#include <vector>

#include "core/error.h"

namespace lumislab {
namespace {

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

}  // namespace

GLuint LinkProgram(const std::string& vertex, const std::string& fragment) {
  return LinkStages({{GL_VERTEX_SHADER, &vertex}, {GL_FRAGMENT_SHADER, &fragment}});
}

GLuint LinkComputeProgram(const std::string& compute) {
  return LinkStages({{GL_COMPUTE_SHADER, &compute}});
}

std::string WithDefines(const std::string& source, const std::string& defines) {
  std::string f = source;
  f.insert(f.find('\n') + 1, defines);
  return f;
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

}  // namespace lumislab
