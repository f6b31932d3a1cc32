// preview_gpu_check: the preview renderer on a real GPU through EGL, against OSMesa (llvmpipe).
// Renders the crypt lit by the exact slab of the built-in point-emitter luminaire (9x7, 300^2),
// with shadows, and prints the GL renderer, frame times and the relative difference between the
// two contexts' images. Both GL libraries are opened at run time (dlopen), so this binary runs on
// machines that have only one of them (a GPU node has libEGL, not OSMesa).
//   preview_gpu_check --context egl|osmesa [--out image.exr] [--reference other.exr] [--frames N]
#include <dlfcn.h>
#include <glad/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/exr_io.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/synthetic/truth.h"
#include "preview/renderer.h"

namespace lumislab {
namespace {

using Proc = void (*)();

// --- EGL (types from the EGL 1.5 headers, spelled out to need no headers at build time) ---
using EGLDisplay = void*;
using EGLConfig = void*;
using EGLContext = void*;
using EGLint = int32_t;
constexpr EGLint kEglNone = 0x3038, kEglSurfaceType = 0x3033, kEglPbufferBit = 0x0001,
                 kEglRenderableType = 0x3040, kEglOpenglBit = 0x0008, kEglOpenglApi = 0x30A2,
                 kEglContextMajor = 0x3098, kEglContextMinor = 0x30FB,
                 kEglContextProfileMask = 0x30FD, kEglCoreProfileBit = 0x1,
                 kEglPlatformDevice = 0x313F;

void* g_egl_proc_source = nullptr;
Proc (*g_get_proc)(const char*) = nullptr;
GLADapiproc LoadProc(const char* name) { return reinterpret_cast<GLADapiproc>(g_get_proc(name)); }

template <typename F>
F Sym(void* lib, const char* name) {
  void* p = dlsym(lib, name);
  if (!p) throw Failure(std::string("missing symbol ") + name);
  return reinterpret_cast<F>(p);
}

void MakeEglContext() {
  void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_GLOBAL);
  if (!lib) throw Failure(std::string("cannot open libEGL.so.1: ") + dlerror());
  g_egl_proc_source = lib;
  auto get_proc = Sym<Proc (*)(const char*)>(lib, "eglGetProcAddress");
  g_get_proc = get_proc;
  auto initialize = Sym<unsigned (*)(EGLDisplay, EGLint*, EGLint*)>(lib, "eglInitialize");
  auto choose = Sym<unsigned (*)(EGLDisplay, const EGLint*, EGLConfig*, EGLint, EGLint*)>(
      lib, "eglChooseConfig");
  auto bind_api = Sym<unsigned (*)(unsigned)>(lib, "eglBindAPI");
  auto create = Sym<EGLContext (*)(EGLDisplay, EGLConfig, EGLContext, const EGLint*)>(
      lib, "eglCreateContext");
  auto make_current =
      Sym<unsigned (*)(EGLDisplay, void*, void*, EGLContext)>(lib, "eglMakeCurrent");
  // A device display (no window system): first EGL device.
  using QueryDevices = unsigned (*)(EGLint, void**, EGLint*);
  using GetPlatformDisplay = EGLDisplay (*)(unsigned, void*, const EGLint*);
  auto query_devices = reinterpret_cast<QueryDevices>(get_proc("eglQueryDevicesEXT"));
  auto platform_display =
      reinterpret_cast<GetPlatformDisplay>(get_proc("eglGetPlatformDisplayEXT"));
  EGLDisplay display = nullptr;
  if (query_devices && platform_display) {
    void* devices[8];
    EGLint n = 0;
    if (query_devices(8, devices, &n) && n > 0)
      display = platform_display(kEglPlatformDevice, devices[0], nullptr);
  }
  if (!display) display = Sym<EGLDisplay (*)(void*)>(lib, "eglGetDisplay")(nullptr);
  EGLint major = 0, minor = 0;
  if (!display || !initialize(display, &major, &minor)) throw Failure("eglInitialize failed");
  const EGLint config_attribs[] = {kEglSurfaceType, kEglPbufferBit, kEglRenderableType,
                                   kEglOpenglBit, kEglNone};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (!choose(display, config_attribs, &config, 1, &count) || count < 1)
    throw Failure("eglChooseConfig found no OpenGL config");
  if (!bind_api(kEglOpenglApi)) throw Failure("eglBindAPI(OpenGL) failed");
  const EGLint context_attribs[] = {
      kEglContextMajor,   4,       kEglContextMinor, 5, kEglContextProfileMask,
      kEglCoreProfileBit, kEglNone};
  EGLContext context = create(display, config, nullptr, context_attribs);
  if (!context) throw Failure("eglCreateContext (GL 4.5 core) failed");
  // Surfaceless: the renderer draws only into its own framebuffers.
  if (!make_current(display, nullptr, nullptr, context)) throw Failure("eglMakeCurrent failed");
  std::printf("EGL %d.%d\n", major, minor);
}

std::vector<unsigned char> g_osmesa_buffer(16 * 16 * 4);
void MakeOsmesaContext() {
  void* lib = dlopen("libOSMesa.so.8", RTLD_NOW | RTLD_GLOBAL);
  if (!lib) throw Failure(std::string("cannot open libOSMesa.so.8: ") + dlerror());
  auto create = Sym<void* (*)(const int*, void*)>(lib, "OSMesaCreateContextAttribs");
  auto make_current =
      Sym<unsigned char (*)(void*, void*, unsigned, int, int)>(lib, "OSMesaMakeCurrent");
  g_get_proc = Sym<Proc (*)(const char*)>(lib, "OSMesaGetProcAddress");
  // OSMESA_FORMAT, OSMESA_RGBA, OSMESA_PROFILE, OSMESA_CORE_PROFILE, major, minor.
  const int attribs[] = {0x22, 0x1908, 0x33, 0x34, 0x36, 4, 0x37, 5, 0};
  void* context = create(attribs, nullptr);
  if (!context) throw Failure("OSMesaCreateContextAttribs failed");
  if (!make_current(context, g_osmesa_buffer.data(), 0x1401 /*GL_UNSIGNED_BYTE*/, 16, 16))
    throw Failure("OSMesaMakeCurrent failed");
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int Run(int argc, char** argv) {
  std::string context = "egl", out, reference;
  int frames = 10;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--context" && k + 1 < argc)
      context = argv[++k];
    else if (a == "--out" && k + 1 < argc)
      out = argv[++k];
    else if (a == "--reference" && k + 1 < argc)
      reference = argv[++k];
    else if (a == "--frames" && k + 1 < argc)
      frames = std::max(1, std::atoi(argv[++k]));
    else
      throw BadInput(
          "usage: preview_gpu_check --context egl|osmesa [--out x.exr] "
          "[--reference y.exr] [--frames N]");
  }
  context == "egl" ? MakeEglContext() : MakeOsmesaContext();
  if (!gladLoadGL(LoadProc)) throw Failure("gladLoadGL failed");
  std::printf("context %s: GL_RENDERER %s, GL_VERSION %s\n", context.c_str(),
              reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
              reinterpret_cast<const char*>(glGetString(GL_VERSION)));

  const SlabInfo info = DefaultSlabInfo(9, 7, 5, 300);
  const Luminaire luminaire = DefaultScene().luminaire;
  const int w = 400, h = 400;
  // The crypt as lumislab-preview sets it up: mesh, luminaire pose, orbit camera, culling.
  SceneSetup setup = MakeSceneSetup("crypt", info);
  RenderOptions options;
  options.cull_back_faces = setup.closed_room;
  Renderer renderer(info, w, h, options);
  renderer.SetScene(setup.mesh);
  renderer.SetPose(setup.pose);
  const double start_yaw = setup.camera_yaw_deg;
  auto camera = [&](double yaw_deg) {
    setup.camera_yaw_deg = yaw_deg;
    return OrbitCamera(setup, double(w) / h);
  };
  renderer.SetCamera(camera(start_yaw));
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i)
      renderer.SetPosition(
          i, j,
          IntensityFromIrradiance(info, i, j, TruthPosition(luminaire, info, i, j).irradiance));
  auto t0 = std::chrono::steady_clock::now();
  renderer.Render();  // includes all 63 shadow maps
  const double first_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const ImageF image = renderer.Read();
  std::vector<double> moving;
  for (int f = 0; f < frames; ++f) {
    renderer.SetCamera(camera(start_yaw + 2.0 * (f + 1)));
    t0 = std::chrono::steady_clock::now();
    renderer.Render();
    moving.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::printf(
      "crypt 9x7 400x400 shadows: first frame (63 shadow maps + lights) %.2f ms; camera "
      "moving median %.3f ms = %.1f fps (paper: 1.2 fps)\n",
      first_ms, Median(moving), 1000 / Median(moving));
  if (!out.empty()) WriteExr(out, image, {"R", "G", "B"});
  if (!reference.empty()) {
    const ImageF ref = ReadExr(reference, {"R", "G", "B"});
    double d2 = 0, r2 = 0;
    for (size_t k = 0; k < ref.data.size(); ++k) {
      const double d = double(image.data[k]) - ref.data[k];
      d2 += d * d;
      r2 += double(ref.data[k]) * ref.data[k];
    }
    std::printf("relative L2 difference to %s: %.4f %%\n", reference.c_str(),
                100 * std::sqrt(d2 / std::max(r2, 1e-300)));
  }
  return 0;
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) {
  return lumislab::RunMain("preview_gpu_check", [&] { return lumislab::Run(argc, argv); });
}
