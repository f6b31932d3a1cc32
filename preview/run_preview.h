// lumislab-preview: command line, headless (OSMesa) renders, slab loading and --watch polling.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/slab.h"
#include "lib/lightfield/scene_setup.h"
#include "preview/renderer.h"

namespace lumislab {

struct PreviewConfig {
  std::string slab_dir;
  SceneRequest scene;  // name, pose, receiver plane D and extent
  int width = 400, height = 400;
  std::string out;            // headless output (.exr linear, .png tone-mapped)
  double exposure_stops = 0;  // PNG / window exposure; NaN-free: 0 + auto
  bool auto_exposure = true;
  bool shadows = true;
  bool srgbe = false;
  int shadow_size = 512;
  bool shadow_pcf = false;
  bool watch = false;
  double poll_s = 0.5;
  bool window = false;
  bool bench = false;
  int bench_frames = 10;
  std::string screenshot;  // window: save this file after the first complete frame, then quit
  bool report_srgbe_error = false;
  int threads = 1;  // lumislab's own CPU work (E' of the positions loaded), resolved --threads
};

int RunPreview(int argc, char** argv);

// Renderer options from the command line, for the scene it sets up (one place for both contexts).
RenderOptions MakeRenderOptions(const PreviewConfig& config, const SceneSetup& setup);

// Loads every slab position present on disk that the renderer lacks into it (E' derived on
// `threads` threads); returns the positions loaded.
std::vector<std::pair<int, int>> LoadNewPositions(const std::string& slab_dir, const SlabInfo& info,
                                                  Renderer& renderer, int threads);
// Strict "WxH" (digits only, each 1..8192): false for anything else ("400x400junk").
bool ParseSize(const std::string& text, int* width, int* height);

// Writes .exr (linear RGB) or .png (tone-mapped, sRGB 8-bit) atomically.
void WriteImage(const std::string& path, const ImageF& image, double exposure_factor);

}  // namespace lumislab
