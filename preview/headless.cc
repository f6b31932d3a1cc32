#include "preview/headless.h"

#include <algorithm>
#include <chrono>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/tone_map.h"
#include "preview/gl_context.h"
#include "preview/image_files.h"
#include "preview/light_source.h"

namespace lumislab {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

void WriteOutput(const PreviewConfig& config, const SceneSetup& setup, const SlabInfo& info,
                 const Renderer& renderer) {
  if (config.out.empty()) return;
  const ImageF image = renderer.Read();
  if (config.false_colour)
    WriteImageOrPicture(config.out, image, FalseColourView(config, setup, info, image));
  else
    WriteImage(config.out, image, config.tone);
}

// Renders again with the other accumulation format and logs how far sRGBE is from float.
void ReportSrgbeError(Renderer& renderer) {
  const RenderOptions options = renderer.options();
  RenderOptions other = options;
  other.srgbe = !options.srgbe;
  const ImageF current = renderer.Read();
  renderer.SetOptions(other);
  renderer.Render();
  const ImageF switched = renderer.Read();
  renderer.SetOptions(options);
  renderer.Render();
  const ImageDifference error =
      options.srgbe ? CompareImages(current, switched) : CompareImages(switched, current);
  LogInfo("sRGBE accumulation vs float: relative L2 error ", error.relative_l2,
          ", max per pixel (relative to its largest channel, pixels above 1e-3 of the peak) ",
          error.worst_pixel);
}

// --bench: frames with the camera orbiting 1 degree per frame (shadow maps stay cached).
void RunBench(const PreviewConfig& config, const SceneSetup& setup, double aspect,
              Renderer& renderer) {
  std::vector<double> seconds;
  SceneSetup moving = setup;
  for (int frame = 0; frame < config.bench_frames; ++frame) {
    moving.camera_yaw_deg += 1.0;
    if (!setup.plane) renderer.SetCamera(OrbitCamera(moving, aspect));
    const auto start = std::chrono::steady_clock::now();
    renderer.Render();
    renderer.Finish();  // the frame's GL work done, not only issued
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  const double median = Median(seconds);
  LogInfo("bench: ", config.bench_frames, " frames (camera moving, shadow maps cached), median ",
          median * 1000, " ms = ", 1.0 / median, " fps");
}

// --watch: polls the slab folder (a luminaire folder: every orientation's), re-rendering and
// rewriting --out as positions arrive (an orientation whose slab appears joins), until all of
// them are in or a stop signal arrives.
void WatchSlab(const PreviewConfig& config, const SceneSetup& setup, const LightSource& source,
               SlabInfo info, Renderer& renderer) {
  while (renderer.PositionCount() < renderer.LightCount() && !StopRequested()) {
    std::this_thread::sleep_for(std::chrono::duration<double>(config.poll_s));
    std::vector<std::pair<int, int>> added;
    try {
      if (!source.luminaire) info = SlabInfo::Load(config.slab_dir);
      added = LoadNewLights(source, info, renderer, config.threads);
    } catch (const Error& e) {
      LogDebug("poll: ", e.what());
      continue;  // slab.json being replaced: try again at the next poll
    }
    if (added.empty()) continue;
    // The last update sums every light afresh: the float sum of batches depends on how the
    // positions happened to arrive, and the final image should not (it then equals a render of
    // the finished slab, byte for byte).
    if (renderer.PositionCount() == renderer.LightCount()) renderer.SetOptions(renderer.options());
    renderer.Render();
    WriteOutput(config, setup, info, renderer);
    LogInfo("positions ", renderer.PositionCount(), "/", renderer.LightCount(),
            " (new: ", added.size(), ")");
  }
}

}  // namespace

int RunHeadless(const PreviewConfig& config, const LightSource& source, const SlabInfo& info) {
  const HeadlessContext context(config.backend == Backend::kEgl);
  LogInfo("backend ", BackendName(config.backend), ": ", context.Renderer());
  const SceneSetup setup = MakePreviewSetup(config, info);
  const int width = config.width;  // plane mode is square
  const int height = setup.plane ? config.width : config.height;
  const double aspect = double(width) / height;
  const RenderOptions options = MakeRenderOptions(config, setup);
  LogInfo(ShortcutChoice(config, options, context.Renderer()));
  Renderer renderer(info, width, height, options, RendererOrientations(source, info));
  renderer.SetScene(setup.mesh);
  renderer.SetPose(setup.pose);
  renderer.SetCamera(setup.plane ? PlaneView(setup.plane_z, setup.extent)
                                 : OrbitCamera(setup, aspect));
  LoadNewLights(source, info, renderer, config.threads);
  if (!config.watch) CheckListedLightsLoaded(source, renderer);
  renderer.Render();
  WriteOutput(config, setup, info, renderer);
  LogInfo("rendered ", renderer.PositionCount(), "/", renderer.LightCount(), " positions",
          source.luminaire
              ? " of " + std::to_string(renderer.OrientationCount()) + " orientations, "
              : std::string(", "),
          setup.mesh.triangles(), " triangles, ", width, "x", height,
          config.out.empty() ? "" : " -> " + config.out);
  if (config.report_srgbe_error || config.srgbe) ReportSrgbeError(renderer);
  if (config.bench) RunBench(config, setup, aspect, renderer);
  if (config.watch) WatchSlab(config, setup, source, info, renderer);
  return 0;
}

}  // namespace lumislab
