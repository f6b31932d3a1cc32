// preview_gpu_check: the preview renderer on a real GPU through EGL, against OSMesa (llvmpipe).
// Renders the crypt lit by the exact slab of the built-in point-emitter luminaire (9x7, 300^2),
// with shadows, and prints the GL renderer, frame times and the relative difference between the
// two contexts' images. Both GL libraries are opened at run time (dlopen), so this binary runs on
// machines that have only one of them (a GPU node has libEGL, not OSMesa).
// --size takes a list of WxH (default 400x400; issue 32's GPU check: 400x400,1920x1080,3840x2160),
// each rendered by its own renderer; --out and --reference need a single size.
//   preview_gpu_check --context egl|osmesa [--size WxH[,WxH...]] [--out image.exr]
//                     [--reference other.exr] [--frames N]
#include <dlfcn.h>
#include <glad/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/exr_io.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/synthetic/truth.h"
#include "preview/egl_context.h"
#include "preview/renderer.h"

namespace lumislab {
namespace {

using Proc = void (*)();

Proc (*g_get_proc)(const char*) = nullptr;  // OSMesa's, for glad
GLADapiproc LoadProc(const char* name) { return reinterpret_cast<GLADapiproc>(g_get_proc(name)); }

template <typename F>
F Sym(void* lib, const char* name) {
  void* p = dlsym(lib, name);
  if (!p) throw Failure(std::string("missing symbol ") + name);
  return reinterpret_cast<F>(p);
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

// "WxH[,WxH...]": the sizes to render (each side 1..8192).
std::vector<std::pair<int, int>> ParseSizes(const std::string& text) {
  std::vector<std::pair<int, int>> sizes;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    int w = 0, h = 0;
    char x = 0;
    std::stringstream one(item);
    if (!(one >> w >> x >> h) || x != 'x' || w < 1 || h < 1 || w > 8192 || h > 8192 || !one.eof())
      throw InputError("--size", "size", "WxH[,WxH...], e.g. 1920x1080,3840x2160", text);
    sizes.emplace_back(w, h);
  }
  if (sizes.empty()) throw InputError("--size", "size", "WxH[,WxH...]", text);
  return sizes;
}

// The crypt of the 9x7 slab at w x h with shadows, as lumislab-preview draws it (every position
// exact): the first frame and the median camera move printed; returns the first frame's image.
ImageF RenderCrypt(int w, int h, int frames) {
  const SlabInfo info = DefaultSlabInfo(9, 7, 5, 300);
  const Luminaire luminaire = DefaultScene().luminaire;
  // The crypt as lumislab-preview sets it up: mesh, luminaire pose, orbit camera, culling.
  SceneSetup setup = MakeSceneSetup("crypt", info);
  RenderOptions options;
  options.cull_back_faces = setup.closed_room;
  options.shadow_cull = setup.closed_room;  // as lumislab-preview
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
  renderer.Finish();
  const double first_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const ImageF image = renderer.Read();
  std::vector<double> moving;
  for (int f = 0; f < frames; ++f) {
    renderer.SetCamera(camera(start_yaw + 2.0 * (f + 1)));
    t0 = std::chrono::steady_clock::now();
    renderer.Render();
    renderer.Finish();
    moving.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::printf(
      "crypt 9x7 %dx%d shadows: first frame (63 shadow maps + lights) %.2f ms; camera "
      "moving median %.3f ms = %.1f fps (paper: 1.2 fps at 400x400)\n",
      w, h, first_ms, Median(moving), 1000 / Median(moving));
  return image;
}

int Run(int argc, char** argv) {
  std::string context = "egl", out, reference;
  std::string size_text = "400x400";
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
    else if (a == "--size" && k + 1 < argc)
      size_text = argv[++k];
    else
      throw BadInput(
          "usage: preview_gpu_check --context egl|osmesa [--size WxH[,WxH...]] [--out x.exr] "
          "[--reference y.exr] [--frames N]");
  }
  const std::vector<std::pair<int, int>> sizes = ParseSizes(size_text);
  if (sizes.size() > 1 && !(out.empty() && reference.empty()))
    throw BadInput("preview_gpu_check: --out and --reference need a single --size");
  // EGL: any device, Mesa's software one included, so that EGL and OSMesa can be compared
  // where there is no GPU.
  std::unique_ptr<EglContext> egl;
  if (context == "egl") {
    egl = std::make_unique<EglContext>(EglContext::Device::kAnyDevice);
    std::printf("%s\n", egl->Version().c_str());
  } else {
    MakeOsmesaContext();
    if (!gladLoadGL(LoadProc)) throw Failure("gladLoadGL failed");
  }
  std::printf("context %s: GL_RENDERER %s, GL_VERSION %s\n", context.c_str(),
              reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
              reinterpret_cast<const char*>(glGetString(GL_VERSION)));

  ImageF image;
  for (const auto& [w, h] : sizes) image = RenderCrypt(w, h, frames);
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
