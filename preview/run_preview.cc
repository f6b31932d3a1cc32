#include "preview/run_preview.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <thread>

#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/tone_map.h"
#include "preview/gl_context.h"
#include "preview/point_emitters.h"
#include "preview/window.h"

namespace lumislab {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Waits for slab.json (a live reconstruct writes it with its first position).
SlabInfo LoadInfo(const PreviewConfig& config) {
  const std::string json = config.slab_dir + "/slab.json";
  while (config.watch && !std::filesystem::exists(json) && !StopRequested()) {
    std::this_thread::sleep_for(std::chrono::duration<double>(config.poll_s));
  }
  return SlabInfo::Load(config.slab_dir);
}

int RunHeadless(const PreviewConfig& config) {
  SlabInfo info = LoadInfo(config);
  OffscreenContext context(16, 16);
  LogDebug("GL renderer: ", context.Renderer());
  const SceneSetup setup = MakeSceneSetup(config.scene, info);
  RenderOptions options = MakeRenderOptions(config, setup);
  const int width = config.width;  // plane mode is square
  const int height = setup.plane ? config.width : config.height;
  Renderer renderer(info, width, height, options);
  renderer.SetScene(setup.mesh);
  renderer.SetPose(setup.pose);
  renderer.SetCamera(setup.plane ? PlaneView(setup.plane_z, setup.extent)
                                 : OrbitCamera(setup, double(width) / height));
  auto write = [&] {
    if (config.out.empty()) return;
    const ImageF image = renderer.Read();
    WriteImage(config.out, image,
               ExposureFactor(image, config.exposure_stops, config.auto_exposure));
  };
  std::vector<std::pair<int, int>> loaded =
      LoadNewPositions(config.slab_dir, info, renderer, config.threads);
  renderer.Render();
  write();
  LogInfo("rendered ", renderer.PositionCount(), "/", info.grid.count(), " positions, ",
          setup.mesh.triangles(), " triangles, ", width, "x", height,
          config.out.empty() ? "" : " -> " + config.out);
  if (config.report_srgbe_error || config.srgbe) {
    RenderOptions other = options;
    other.srgbe = !options.srgbe;
    const ImageF a = renderer.Read();
    renderer.SetOptions(other);
    renderer.Render();
    const ImageF b = renderer.Read();
    renderer.SetOptions(options);
    renderer.Render();
    const ImageDifference error = options.srgbe ? CompareImages(a, b) : CompareImages(b, a);
    LogInfo("sRGBE accumulation vs float: relative L2 error ", error.relative_l2,
            ", max per pixel (relative to its largest channel, pixels above 1e-3 of the peak) ",
            error.worst_pixel);
  }
  if (config.bench) {
    std::vector<double> seconds;
    SceneSetup moving = setup;
    for (int frame = 0; frame < config.bench_frames; ++frame) {
      moving.camera_yaw_deg += 1.0;
      if (!setup.plane) renderer.SetCamera(OrbitCamera(moving, double(width) / height));
      const auto start = std::chrono::steady_clock::now();
      renderer.Render();
      seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    const double median = Median(seconds);
    LogInfo("bench: ", config.bench_frames, " frames (camera moving, shadow maps cached), median ",
            median * 1000, " ms = ", 1.0 / median, " fps");
  }
  while (config.watch && renderer.PositionCount() < info.grid.count() && !StopRequested()) {
    std::this_thread::sleep_for(std::chrono::duration<double>(config.poll_s));
    try {
      info = SlabInfo::Load(config.slab_dir);
    } catch (const Error&) {
      continue;  // slab.json being replaced: try again at the next poll
    }
    const auto added = LoadNewPositions(config.slab_dir, info, renderer, config.threads);
    if (added.empty()) continue;
    renderer.Render();
    write();
    LogInfo("positions ", renderer.PositionCount(), "/", info.grid.count(), " (new: ", added.size(),
            ")");
    if (renderer.PositionCount() == info.grid.count()) break;
  }
  return 0;
}

}  // namespace

RenderOptions MakeRenderOptions(const PreviewConfig& config, const SceneSetup& setup) {
  RenderOptions options;
  options.shadows = config.shadows;
  options.srgbe = config.srgbe;
  options.shadow_size = config.shadow_size;
  options.shadow_pcf = config.shadow_pcf;
  if (setup.plane) options.radiance_scale = 1.0;
  options.cull_back_faces = setup.closed_room;
  return options;
}

std::vector<std::pair<int, int>> LoadNewPositions(const std::string& slab_dir, const SlabInfo& info,
                                                  Renderer& renderer, int threads) {
  std::vector<std::pair<int, int>> added;
  for (const auto& [i, j] : ScanSlabPositions(slab_dir, info.grid)) {
    if (!renderer.HasPosition(i, j)) added.emplace_back(i, j);
  }
  // E' of a batch on `threads` threads, then uploaded on this one (the GL context's); batches
  // bound the memory held for a large slab.
  const size_t batch = size_t(std::max(16, 2 * threads));
  for (size_t start = 0; start < added.size(); start += batch) {
    const std::vector<std::pair<int, int>> part(
        added.begin() + start, added.begin() + std::min(added.size(), start + batch));
    const std::vector<ImageF> intensities = ReadIntensities(slab_dir, info, part, threads);
    for (size_t k = 0; k < part.size(); ++k) {
      renderer.SetPosition(part[k].first, part[k].second, intensities[k]);
    }
  }
  return added;
}

bool ParseSize(const std::string& text, int* width, int* height) {
  static const std::regex pattern("([0-9]{1,5})x([0-9]{1,5})");
  std::smatch match;
  if (!std::regex_match(text, match, pattern)) return false;
  *width = std::stoi(match[1].str());
  *height = std::stoi(match[2].str());
  return *width > 0 && *height > 0 && *width <= 8192 && *height <= 8192;
}

void WriteImage(const std::string& path, const ImageF& image, double exposure_factor) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".exr") {
    WriteExr(path, image, {"R", "G", "B"});
    return;
  }
  if (ext != ".png") throw BadInput(path + ": output must end in .exr or .png");
  const std::vector<uint8_t> rgb = EncodeSrgb8(image, exposure_factor);
  cv::Mat out(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        out.at<cv::Vec3b>(y, x)[2 - c] = rgb[(size_t(y) * image.width + x) * 3 + c];
      }
    }
  }
  WriteAtomically(path, [&](const std::string& tmp) {
    if (!cv::imwrite(tmp, out)) throw IoError(path, "cannot write PNG");
  });
}

int RunPreview(int argc, char** argv) {
  PreviewConfig config;
  CommonOptions common;
  std::string size = "400x400";
  CLI::App app{
      "lumislab-preview: the measured luminaire lighting a scene (DESIGN §4); headless "
      "(OSMesa, --out) or in a window (--window)"};
  AddCommonOptions(&app, &common);
  app.footer(
      "--threads sizes lumislab's own CPU work (deriving E' of the slab positions as they are "
      "loaded). The renderer's threads are llvmpipe's: set them with the LP_NUM_THREADS "
      "environment variable (default: all cores).");
  app.add_option("--slab", config.slab_dir, "slab folder (slab.json + pos_<i>_<j>.exr)")
      ->required();
  app.add_option("--scene", config.scene.name, "crypt | cloister | plane | scene file (Assimp)")
      ->capture_default_str();
  app.add_option("--luminaire-pose", config.scene.pose,
                 "luminaire frame in the scene: x,y,z (mm),rx,ry,rz (degrees, R = Rz Ry Rx)")
      ->delimiter(',')
      ->expected(6);
  app.add_option("--size", size, "image size WxH")->capture_default_str();
  app.add_option("--out", config.out, "headless output: .exr (linear) or .png (tone-mapped)");
  app.add_option("--receiver-plane", config.scene.receiver_plane_mm,
                 "plane mode: D in mm (default: the slab's d)");
  app.add_option("--extent", config.scene.extent_mm,
                 "plane mode: side W in mm (default: window D/d)");
  app.add_option("--exposure", config.exposure_stops, "exposure in stops (on top of auto)");
  app.add_flag("!--no-auto-exposure", config.auto_exposure, "no automatic exposure");
  app.add_flag("!--no-shadows", config.shadows, "no shadow maps");
  app.add_flag("--srgbe", config.srgbe, "sRGBE-packed accumulation (paper §4.2)");
  app.add_flag("--srgbe-error", config.report_srgbe_error,
               "also render with the other accumulation format and report the difference");
  app.add_option("--shadow-size", config.shadow_size, "shadow-map size")->capture_default_str();
  app.add_flag("--shadow-pcf", config.shadow_pcf, "2x2 filtered shadow-map lookups");
  app.add_flag("--watch", config.watch, "poll the slab folder and add positions as they arrive");
  app.add_option("--poll", config.poll_s, "--watch polling interval (s)")->capture_default_str();
  app.add_flag("--window", config.window, "interactive GLFW window (needs a display)");
  app.add_option("--screenshot", config.screenshot,
                 "--window: save the window to this PNG once all positions are in, then quit");
  app.add_flag("--bench", config.bench, "time frames with a moving camera");
  app.add_option("--bench-frames", config.bench_frames)->capture_default_str();
  bool write_test_slab = false;
  app.add_flag("--write-test-slab", write_test_slab,
               "first write the exact slab of the built-in point-emitter luminaire (9x7, h=5, "
               "d=750, window 1200 at 300) into --slab when it has no slab.json (demos, tests)");
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  config.threads = StartTool("preview", common);
  if (!ParseSize(size, &config.width, &config.height)) {
    throw InputError("--size", "size", "WxH, each 1..8192, e.g. 400x400", size);
  }
  if (config.shadow_size < 16 || config.shadow_size > 4096) {
    throw InputError("--shadow-size", "shadow-size", "16..4096",
                     std::to_string(config.shadow_size));
  }
  if (write_test_slab && !std::filesystem::exists(config.slab_dir + "/slab.json")) {
    WriteTruthSlab(DefaultPointEmitters(), MakeSlabInfo(750, 9, 7, 5, 1200, 300), config.slab_dir);
    LogInfo("wrote the built-in test slab to ", config.slab_dir);
  }
  const StopSignalScope stop_signals;  // Ctrl-C ends the --watch loops cleanly
  if (config.window) {
    SlabInfo info = LoadInfo(config);
    return RunWindow(config, info);
  }
  if (config.out.empty() && !config.bench) {
    throw BadInput("headless mode needs --out <file.exr|.png> (or --bench, or --window)");
  }
  return RunHeadless(config);
}

}  // namespace lumislab
