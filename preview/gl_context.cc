#include "preview/gl_context.h"

// glad must come before any other GL header.
#include <glad/gl.h>
// Then OSMesa and GLFW (without its own GL header).
#include <GL/osmesa.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/error.h"
#include "core/log.h"
#include "preview/egl_context.h"

namespace lumislab {
namespace {

GLADapiproc OsMesaLoad(const char* name) {
  return reinterpret_cast<GLADapiproc>(OSMesaGetProcAddress(name));
}

GLADapiproc GlfwLoad(const char* name) {
  return reinterpret_cast<GLADapiproc>(glfwGetProcAddress(name));
}

void CheckVersion(int version) {
  if (GLAD_VERSION_MAJOR(version) < 4 ||
      (GLAD_VERSION_MAJOR(version) == 4 && GLAD_VERSION_MINOR(version) < 5)) {
    throw Failure("OpenGL 4.5 core is needed, the context gives " +
                  std::to_string(GLAD_VERSION_MAJOR(version)) + "." +
                  std::to_string(GLAD_VERSION_MINOR(version)));
  }
}

}  // namespace

OffscreenContext::OffscreenContext(int width, int height) {
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            24,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            4,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            5,
                            0};
  OSMesaContext context = OSMesaCreateContextAttribs(attributes, nullptr);
  if (!context) throw Failure("OSMesaCreateContextAttribs failed (core profile 4.5)");
  context_ = context;
  buffer_.resize(size_t(width) * height * 4);
  if (!OSMesaMakeCurrent(context, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
    OSMesaDestroyContext(context);
    throw Failure("OSMesaMakeCurrent failed");
  }
  const int version = gladLoadGL(OsMesaLoad);
  if (!version) throw Failure("gladLoadGL failed on the OSMesa context");
  CheckVersion(version);
  LogDebug("OSMesa context: ", Renderer());
}

OffscreenContext::~OffscreenContext() {
  if (context_) OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
}

std::string OffscreenContext::Renderer() const {
  const GLubyte* renderer = glGetString(GL_RENDERER);
  return renderer ? reinterpret_cast<const char*>(renderer) : "?";
}

HeadlessContext::HeadlessContext(bool egl) {
  if (egl)
    egl_ = std::make_unique<EglContext>(EglContext::Device::kGpu);
  else
    osmesa_ = std::make_unique<OffscreenContext>(16, 16);
}

HeadlessContext::~HeadlessContext() = default;

std::string HeadlessContext::Renderer() const {
  return egl_ ? egl_->Renderer() : osmesa_->Renderer();
}

WindowContext::WindowContext(int width, int height, const std::string& title) {
  if (!glfwInit()) throw Failure("glfwInit failed (is there a display? try xvfb-run)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    glfwTerminate();
    throw Failure("glfwCreateWindow failed (GL 4.5 core)");
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(0);
  const int version = gladLoadGL(GlfwLoad);
  if (!version) throw Failure("gladLoadGL failed on the GLFW context");
  CheckVersion(version);
}

WindowContext::~WindowContext() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

}  // namespace lumislab
