// GL contexts of the preview: OSMesa offscreen (headless renders, tests, benchmarks), EGL
// (headless on a GPU, preview/egl_context.h) and a GLFW window, all loading GL 4.5 core through
// the same glad loader (docs/architecture.md).
#pragma once

#include <memory>
#include <string>
#include <vector>

struct GLFWwindow;

namespace lumislab {

// An OSMesa core-profile 4.5 context with its own RGBA colour buffer; made current on creation.
// All rendering targets FBOs; the default buffer is only there to make the context current.
class OffscreenContext {
 public:
  OffscreenContext(int width, int height);
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;
  std::string Renderer() const;  // GL_RENDERER string

 private:
  void* context_ = nullptr;
  std::vector<unsigned char> buffer_;
};

class EglContext;

// The context of a headless run (--backend osmesa | egl), current from construction.
class HeadlessContext {
 public:
  explicit HeadlessContext(bool egl);
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;
  std::string Renderer() const;

 private:
  std::unique_ptr<OffscreenContext> osmesa_;
  std::unique_ptr<EglContext> egl_;
};

// A GLFW window with a GL 4.5 core context (needs a display; Xvfb works).
class WindowContext {
 public:
  WindowContext(int width, int height, const std::string& title);
  ~WindowContext();
  WindowContext(const WindowContext&) = delete;
  WindowContext& operator=(const WindowContext&) = delete;
  GLFWwindow* window() const { return window_; }

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace lumislab
