#include "preview/egl_context.h"

#include <dlfcn.h>
#include <glad/gl.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/log.h"

namespace lumislab {
namespace {

// EGL 1.5 types and enums, spelled out so that no EGL header is needed at build time.
using Proc = void (*)();
using EGLDisplay = void*;
using EGLConfig = void*;
using EGLContext = void*;
using EGLDeviceEXT = void*;
using EGLint = int32_t;
constexpr EGLint kEglNone = 0x3038, kEglSurfaceType = 0x3033, kEglPbufferBit = 0x0001,
                 kEglRenderableType = 0x3040, kEglOpenglBit = 0x0008, kEglOpenglApi = 0x30A2,
                 kEglContextMajor = 0x3098, kEglContextMinor = 0x30FB,
                 kEglContextProfileMask = 0x30FD, kEglCoreProfileBit = 0x1,
                 kEglPlatformDevice = 0x313F, kEglExtensions = 0x3055;

Proc (*g_get_proc)(const char*) = nullptr;  // glad's loader reads it (one EGL context at a time)
GLADapiproc LoadProc(const char* name) { return reinterpret_cast<GLADapiproc>(g_get_proc(name)); }

template <typename F>
F Sym(void* lib, const char* name) {
  void* p = dlsym(lib, name);
  if (!p) throw Failure(std::string("libEGL.so.1 lacks ") + name);
  return reinterpret_cast<F>(p);
}

bool IsSoftwareDevice(EGLDeviceEXT device) {
  using QueryString = const char* (*)(EGLDeviceEXT, EGLint);
  auto query = reinterpret_cast<QueryString>(g_get_proc("eglQueryDeviceStringEXT"));
  const char* extensions = query ? query(device, kEglExtensions) : nullptr;
  return extensions &&
         std::string(extensions).find("EGL_MESA_device_software") != std::string::npos;
}

// The display of the first device that qualifies; nullptr with `offered` describing the devices
// when none does.
EGLDisplay DeviceDisplay(EglContext::Device which, std::string* offered) {
  using QueryDevices = unsigned (*)(EGLint, EGLDeviceEXT*, EGLint*);
  using GetPlatformDisplay = EGLDisplay (*)(unsigned, void*, const EGLint*);
  auto query_devices = reinterpret_cast<QueryDevices>(g_get_proc("eglQueryDevicesEXT"));
  auto platform_display =
      reinterpret_cast<GetPlatformDisplay>(g_get_proc("eglGetPlatformDisplayEXT"));
  if (!query_devices || !platform_display) {
    *offered = "no device enumeration (EGL_EXT_device_enumeration)";
    return nullptr;
  }
  EGLDeviceEXT devices[16];
  EGLint n = 0;
  if (!query_devices(16, devices, &n) || n < 1) {
    *offered = "no EGL device";
    return nullptr;
  }
  int software = 0;
  for (EGLint k = 0; k < n; ++k) {
    if (which == EglContext::Device::kGpu && IsSoftwareDevice(devices[k])) {
      ++software;
      continue;
    }
    if (EGLDisplay display = platform_display(kEglPlatformDevice, devices[k], nullptr))
      return display;
  }
  *offered = std::to_string(n) + " EGL device(s), " + std::to_string(software) +
             " of them Mesa's software renderer";
  return nullptr;
}

}  // namespace

EglContext::EglContext(Device which) {
  library_ = dlopen("libEGL.so.1", RTLD_NOW | RTLD_GLOBAL);
  if (!library_)
    throw Failure(std::string("EGL: cannot open libEGL.so.1 (Debian: libegl1, and the GPU "
                              "driver's EGL library): ") +
                  dlerror());
  g_get_proc = Sym<Proc (*)(const char*)>(library_, "eglGetProcAddress");
  auto initialize = Sym<unsigned (*)(EGLDisplay, EGLint*, EGLint*)>(library_, "eglInitialize");
  auto choose = Sym<unsigned (*)(EGLDisplay, const EGLint*, EGLConfig*, EGLint, EGLint*)>(
      library_, "eglChooseConfig");
  auto bind_api = Sym<unsigned (*)(unsigned)>(library_, "eglBindAPI");
  auto create = Sym<EGLContext (*)(EGLDisplay, EGLConfig, EGLContext, const EGLint*)>(
      library_, "eglCreateContext");
  auto make_current =
      Sym<unsigned (*)(EGLDisplay, void*, void*, EGLContext)>(library_, "eglMakeCurrent");
  std::string offered;
  display_ = DeviceDisplay(which, &offered);
  if (!display_)
    throw Failure("EGL found no GPU (" + offered +
                  "); on this machine use --backend osmesa (llvmpipe) instead");
  if (!initialize(display_, &major_, &minor_)) throw Failure("EGL: eglInitialize failed");
  const EGLint config_attribs[] = {kEglSurfaceType, kEglPbufferBit, kEglRenderableType,
                                   kEglOpenglBit, kEglNone};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (!choose(display_, config_attribs, &config, 1, &count) || count < 1)
    throw Failure("EGL: eglChooseConfig found no OpenGL config");
  if (!bind_api(kEglOpenglApi)) throw Failure("EGL: eglBindAPI(OpenGL) failed");
  const EGLint context_attribs[] = {
      kEglContextMajor,   4,       kEglContextMinor, 5, kEglContextProfileMask,
      kEglCoreProfileBit, kEglNone};
  context_ = create(display_, config, nullptr, context_attribs);
  if (!context_) throw Failure("EGL: eglCreateContext (GL 4.5 core) failed");
  if (!make_current(display_, nullptr, nullptr, context_))
    throw Failure("EGL: eglMakeCurrent (surfaceless) failed");
  const int version = gladLoadGL(LoadProc);
  if (!version) throw Failure("EGL: gladLoadGL failed");
  if (GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version) < 45)
    throw Failure("EGL: OpenGL 4.5 core is needed, the context gives " +
                  std::to_string(GLAD_VERSION_MAJOR(version)) + "." +
                  std::to_string(GLAD_VERSION_MINOR(version)));
  LogDebug("EGL ", major_, ".", minor_, " context: ", Renderer());
}

EglContext::~EglContext() {
  if (!library_) return;
  if (context_) {
    auto make_current = reinterpret_cast<unsigned (*)(EGLDisplay, void*, void*, EGLContext)>(
        dlsym(library_, "eglMakeCurrent"));
    auto destroy = reinterpret_cast<unsigned (*)(EGLDisplay, EGLContext)>(
        dlsym(library_, "eglDestroyContext"));
    if (make_current) make_current(display_, nullptr, nullptr, nullptr);
    if (destroy) destroy(display_, context_);
  }
  // libEGL stays loaded: drivers register exit handlers that must find their code.
}

std::string EglContext::Renderer() const {
  const GLubyte* renderer = glGetString(GL_RENDERER);
  return renderer ? reinterpret_cast<const char*>(renderer) : "?";
}

std::string EglContext::Version() const {
  return "EGL " + std::to_string(major_) + "." + std::to_string(minor_);
}

}  // namespace lumislab
