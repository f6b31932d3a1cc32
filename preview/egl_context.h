// A headless GL 4.5 core context through EGL (docs/method.md §4.2, docs/architecture.md §5):
// lumislab-preview
// --backend egl and bench/preview_gpu_check. libEGL is opened at run time (dlopen) and nothing
// is linked, so binaries that carry this run where libEGL is missing (OSMesa only) and on GPU
// nodes without OSMesa. Surfaceless: the renderer draws only into its own framebuffers.
#pragma once

#include <string>

namespace lumislab {

class EglContext {
 public:
  // kGpu: the first EGL device that is not Mesa's software device (EGL_MESA_device_software);
  // Failure naming what EGL offered when there is none. kAnyDevice: the first device, software
  // included (benchmarks comparing EGL and OSMesa on machines without a GPU).
  enum class Device { kGpu, kAnyDevice };
  explicit EglContext(Device device = Device::kGpu);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  std::string Renderer() const;  // GL_RENDERER
  std::string Version() const;   // "EGL 1.5"

 private:
  void* library_ = nullptr;
  void* display_ = nullptr;
  void* context_ = nullptr;
  int major_ = 0, minor_ = 0;
};

}  // namespace lumislab
