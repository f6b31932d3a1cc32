// lumislab-preview's configuration (PreviewConfig: from the command line, cli.h, and changed by
// the window) and the steps the headless run and the window share (scene set-up, renderer
// options, waiting for the slab, loading new positions, the false-colour picture).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/slab.h"
#include "lib/lightfield/false_colour.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/lightfield/tone_map.h"
#include "preview/renderer.h"

namespace lumislab {

// Where the preview's OpenGL runs (--backend): OSMesa (llvmpipe, headless, everywhere), EGL
// (headless on a GPU; refused when EGL offers only a software renderer) or a GLFW window.
enum class Backend { kOsmesa, kEgl, kWindow };
const char* BackendName(Backend backend);
// --texture-filter's names: bilinear, nearest, cubic.
const char* TextureFilterName(TextureFilter filter);

struct PreviewConfig {
  std::string slab_dir;           // a slab folder, or a luminaire folder (preview/light_source.h)
  bool luminaire_folder = false;  // slab_dir holds luminaire.json (set by the command line)
  SceneRequest scene;             // name, pose, receiver plane D and extent
  // --luminaire-depth-mm: how far behind S the deepest light sits, to check a receiver plane
  // near S (CheckReceiverPlane); < 0: a synthetic dataset's truth/luminaire.json beside the slab,
  // else unknown.
  double luminaire_depth_mm = -1;
  int width = 400, height = 400;
  std::string out;   // headless output (.exr linear, .png tone-mapped)
  ToneMapping tone;  // PNG / window: exposure stops, automatic exposure, tone curve
  // Orbit camera yaw, pitch (degrees), distance (mm), target x, y, z (mm, scene frame); empty:
  // the scene's default. The window's orbit and fly moves both change these six.
  std::vector<double> camera;
  // --view false-colour: the irradiance arriving at each pixel (W/m^2 or lux, before albedo and
  // tone mapping) through lib/lightfield/false_colour.h, with colour bar and iso-lines; the
  // window's toggle flips `false_colour` (MakeRenderOptions then gives unit albedo).
  bool false_colour = false;
  FalseColourRequest false_colour_scale;  // --false-colour-range, --false-colour-scale
  bool shadows = true;
  bool srgbe = false;
  int shadow_size = 512;
  bool shadow_pcf = false;
  // Shadow maps of a closed room hold only the faces turned to the light (RenderOptions::
  // shadow_cull); --no-shadow-cull draws every face.
  bool shadow_cull = true;
  TextureFilter texture_filter = TextureFilter::kBilinear;  // --texture-filter
  // Faster frames (RenderOptions): shadow-map sharing (largest edge shift in shadow texels, 0:
  // off), merged lights (block side, 1: off; 0: auto, MergeGroup) and their error bound. On by
  // default only where the image stays within 1 % of the full per-position render on the
  // default rooms (docs/method.md §4.2): merging 2 x 2 without shadows; sharing never.
  double shadow_share = 0;
  int merge_group = 0;
  double merge_error = 0.05;
  // Coarse shading's and reprojection's tolerances (RenderOptions; 0: off). Coarse shading: < 0
  // is auto, CoarseTolerance (0.1 in a room with shadows, where full frames wait on the light
  // passes). Both keep the default rooms within 1 % of the full render (docs/method.md §4.2).
  double coarse_tolerance = -1;
  double reproject_tolerance = 0.1;
  bool watch = false;
  double poll_s = 0.5;
  Backend backend = Backend::kOsmesa;  // --backend; --window is --backend window
  bool ui = true;                      // window: the controls panel (--no-ui: the picture only)
  bool bench = false;
  int bench_frames = 10;
  std::string screenshot;  // window: save this file after the first complete frame, then quit
  bool report_srgbe_error = false;
  int threads = 1;  // lumislab's own CPU work (E' of the positions loaded), resolved --threads
  // CPU reference instead of OpenGL (preview/reference_mode.h): the exact model from the slab
  // with N x N samples per basis support, or the analytic image of a synthetic luminaire.
  bool reference = false;
  int samples = 4;
  std::string analytic;  // default | dataset folder | scene or truth/luminaire.json file
};

// Plane mode with D < d: the parallax error of the method grows as z |1 - d/D| for light z mm
// behind S (docs/method.md §4.5). With z known (the flag, or truth/luminaire.json of the
// dataset holding the slab) it logs the first-order bound, and warns that no bound holds once
// it reaches 1; without z it says that the error there depends on it. Returns the bound (-1:
// not computed).
double CheckReceiverPlane(const PreviewConfig& config, const SlabInfo& info);

// The scene of the configuration: MakeSceneSetup, then --camera.
SceneSetup MakePreviewSetup(const PreviewConfig& config, const SlabInfo& info);
// The orbit camera of `setup` as the six --camera values, and back.
std::vector<double> CameraValues(const SceneSetup& setup);
void SetCameraValues(const std::vector<double>& values, SceneSetup& setup);

// Renderer options from the command line, for the scene it sets up (one place for both contexts).
RenderOptions MakeRenderOptions(const PreviewConfig& config, const SceneSetup& setup);
// --merge-group resolved: 0 (auto) is 2 without shadows, 1 (off) with them or for a luminaire
// folder (merging serves one slab).
int MergeGroup(const PreviewConfig& config);
// Coarse shading's tolerance: --coarse-shading, or auto: 0.1 in a room with shadows; 0 without
// them and on the plane (its irradiance is a measurement, written in W/m^2).
double CoarseTolerance(const PreviewConfig& config, const SceneSetup& setup);
// A software rasteriser by its GL_RENDERER string (llvmpipe, softpipe, swrast): the shortcuts'
// defaults were measured to pay there (docs/results.md, Table 1).
bool IsSoftwareRenderer(const std::string& gl_renderer);
// The log line that says which shortcuts `options` hold for the context's GL_RENDERER and why
// (docs/method.md §4.2, "Shortcuts by backend"). The choice is the same on every backend: the
// one GPU measured (issue 32) still ran faster with them; whether a GPU path without them is
// faster there is unmeasured.
std::string ShortcutChoice(const PreviewConfig& config, const RenderOptions& options,
                           const std::string& gl_renderer);

// Loads every slab position present on disk that the renderer lacks into it, as positions of
// `orientation` (E' derived on `threads` threads); returns the positions loaded. (--slab's
// waiting and loading for one slab or a luminaire folder: preview/light_source.h.)
std::vector<std::pair<int, int>> LoadNewPositions(const std::string& slab_dir, const SlabInfo& info,
                                                  Renderer& renderer, int threads,
                                                  int orientation = 0);
// The picture --out gets in false colour: `irradiance` (the renderer's image with unit albedo and
// radiance scale 1, or the reference's irradiance) with the bar in the slab's unit; on the plane
// a scale bar (its extent over `width` pixels) and the plane's distance as the title.
Rgb8Image FalseColourView(const PreviewConfig& config, const SceneSetup& setup,
                          const SlabInfo& info, const ImageF& irradiance);

}  // namespace lumislab
