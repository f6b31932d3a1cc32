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

namespace lumislab {
namespace {

// Without --watch the slab is finished: every position slab.json lists must be there, complete
// and of its resolution (ScanSlabPositions leaves out any that is not), and there must be one.
void CheckListedPositionsLoaded(const std::string& slab_dir, const SlabInfo& info,
                                const Renderer& renderer) {
  if (info.present.empty())
    throw InputError(slab_dir + "/slab.json", "present", "at least one position", "none");
  for (const auto& [i, j] : info.present)
    if (!renderer.HasPosition(i, j))
      throw InputError(SlabPositionPath(slab_dir, i, j), "",
                       "a complete EXR of " + std::to_string(info.layout.res_x) + "x" +
                           std::to_string(info.layout.res_y) +
                           " texels (slab.json lists the position)",
                       "a missing, truncated or other-sized file");
}

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
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  const double median = Median(seconds);
  LogInfo("bench: ", config.bench_frames, " frames (camera moving, shadow maps cached), median ",
          median * 1000, " ms = ", 1.0 / median, " fps");
}

// --watch: polls the slab folder, re-rendering and rewriting --out as positions arrive, until
// all of them are in or a stop signal arrives.
void WatchSlab(const PreviewConfig& config, const SceneSetup& setup, SlabInfo info,
               Renderer& renderer) {
  while (renderer.PositionCount() < info.grid.count() && !StopRequested()) {
    std::this_thread::sleep_for(std::chrono::duration<double>(config.poll_s));
    try {
      info = SlabInfo::Load(config.slab_dir);
    } catch (const Error&) {
      continue;  // slab.json being replaced: try again at the next poll
    }
    const auto added = LoadNewPositions(config.slab_dir, info, renderer, config.threads);
    if (added.empty()) continue;
    // The last update sums every light afresh: the float sum of batches depends on how the
    // positions happened to arrive, and the final image should not (it then equals a render of
    // the finished slab, byte for byte).
    if (renderer.PositionCount() == info.grid.count()) renderer.SetOptions(renderer.options());
    renderer.Render();
    WriteOutput(config, setup, info, renderer);
    LogInfo("positions ", renderer.PositionCount(), "/", info.grid.count(), " (new: ", added.size(),
            ")");
  }
}

}  // namespace

int RunHeadless(const PreviewConfig& config, const SlabInfo& info) {
  const HeadlessContext context(config.backend == Backend::kEgl);
  LogInfo("backend ", BackendName(config.backend), ": ", context.Renderer());
  const SceneSetup setup = MakePreviewSetup(config, info);
  const int width = config.width;  // plane mode is square
  const int height = setup.plane ? config.width : config.height;
  const double aspect = double(width) / height;
  Renderer renderer(info, width, height, MakeRenderOptions(config, setup));
  renderer.SetScene(setup.mesh);
  renderer.SetPose(setup.pose);
  renderer.SetCamera(setup.plane ? PlaneView(setup.plane_z, setup.extent)
                                 : OrbitCamera(setup, aspect));
  LoadNewPositions(config.slab_dir, info, renderer, config.threads);
  if (!config.watch) CheckListedPositionsLoaded(config.slab_dir, info, renderer);
  renderer.Render();
  WriteOutput(config, setup, info, renderer);
  LogInfo("rendered ", renderer.PositionCount(), "/", info.grid.count(), " positions, ",
          setup.mesh.triangles(), " triangles, ", width, "x", height,
          config.out.empty() ? "" : " -> " + config.out);
  if (config.report_srgbe_error || config.srgbe) ReportSrgbeError(renderer);
  if (config.bench) RunBench(config, setup, aspect, renderer);
  if (config.watch) WatchSlab(config, setup, info, renderer);
  return 0;
}

}  // namespace lumislab
