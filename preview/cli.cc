// lumislab-preview's command line: its options into a PreviewConfig, checked, then the window,
// the headless run or the CPU reference.
#include "preview/cli.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/log.h"
#include "core/luminaire_set.h"
#include "core/slab_light.h"
#include "core/stop_signal.h"
#include "lib/lightfield/light_field.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"
#include "preview/headless.h"
#include "preview/light_source.h"
#include "preview/reference_mode.h"
#include "preview/window.h"

namespace lumislab {
namespace {

// What the command line gives beyond PreviewConfig.
struct CommandLineExtras {
  std::string size = "400x400";
  std::string view = "normal";
  std::string false_colour_range = "auto";
  std::string false_colour_scale = "linear";
  bool write_test_slab = false;
  std::string tone_map = ToneCurveName(ToneMapping().curve);
  std::string auto_exposure = AutoExposureName(ToneMapping().auto_exposure);
  bool no_auto_exposure = false;
  std::string backend;  // empty: osmesa, or window with --window
  bool window = false;
  std::string texture_filter = TextureFilterName(TextureFilter::kBilinear);
};

void AddSceneOptions(CLI::App& app, PreviewConfig& config, CommandLineExtras& extras) {
  app.add_option("--slab", config.slab_dir,
                 "slab folder (slab.json + pos_<i>_<j>.exr), or a luminaire folder "
                 "(luminaire.json: every orientation's slab, posed into the luminaire frame)")
      ->required();
  app.add_option("--scene", config.scene.name, "crypt | cloister | plane | scene file (Assimp)")
      ->capture_default_str();
  app.add_option("--luminaire-pose", config.scene.pose,
                 "luminaire frame in the scene: x,y,z (mm),rx,ry,rz (degrees, R = Rz Ry Rx)")
      ->delimiter(',')
      ->expected(6);
  app.add_option("--camera", config.camera,
                 "orbit camera: yaw,pitch (degrees),distance,target x,y,z (mm, scene frame); "
                 "default: the scene's")
      ->delimiter(',')
      ->expected(6);
  app.add_option("--size", extras.size, "image size WxH")->capture_default_str();
  app.add_option("--out", config.out, "headless output: .exr (linear) or .png (tone-mapped)");
  app.add_option("--receiver-plane", config.scene.receiver_plane_mm,
                 "plane mode: D in mm (default: the slab's d)");
  app.add_option("--extent", config.scene.extent_mm,
                 "plane mode: side W in mm (default: window D/d)");
  app.add_option("--luminaire-depth-mm", config.luminaire_depth_mm,
                 "plane mode: how far behind S the deepest light sits, to check a receiver plane "
                 "near S (default: a synthetic dataset's truth/luminaire.json beside the slab)");
}

void AddRenderOptions(CLI::App& app, PreviewConfig& config, CommandLineExtras& extras) {
  app.add_option("--exposure", config.tone.exposure_stops, "exposure in stops (on top of auto)");
  app.add_option("--tone-map", extras.tone_map,
                 "PNG and window: linear (clip at 1) | filmic (ACES fit: a shoulder instead of "
                 "clipping)")
      ->capture_default_str();
  app.add_option("--auto-exposure", extras.auto_exposure,
                 "lit (log-average of the lit pixels to 0.18) | p99 (99th percentile to 0.8) | "
                 "off")
      ->capture_default_str();
  app.add_flag("--no-auto-exposure", extras.no_auto_exposure, "--auto-exposure off");
  app.add_option("--view", extras.view,
                 "normal (radiance, tone-mapped) | false-colour (the irradiance arriving at each "
                 "pixel, before albedo, in the slab's unit: viridis, colour bar, iso-lines at its "
                 "ticks; .png gets that picture, .exr the irradiance)")
      ->check(CLI::IsMember({"normal", "false-colour"}))
      ->capture_default_str();
  app.add_option("--false-colour-range", extras.false_colour_range,
                 "--view false-colour: min:max in the slab's unit, or auto (0 .. the 99.5th "
                 "percentile rounded up; log: 3 decades below it)")
      ->capture_default_str();
  app.add_option("--false-colour-scale", extras.false_colour_scale, "linear | log")
      ->check(CLI::IsMember({"linear", "log"}))
      ->capture_default_str();
  app.add_flag("!--no-shadows", config.shadows, "no shadow maps");
  app.add_flag("--srgbe", config.srgbe, "sRGBE-packed accumulation (paper §4.2)");
  app.add_flag("--srgbe-error", config.report_srgbe_error,
               "also render with the other accumulation format and report the difference");
  app.add_option("--shadow-size", config.shadow_size, "shadow-map size")->capture_default_str();
  app.add_flag("--shadow-pcf", config.shadow_pcf, "2x2 filtered shadow-map lookups");
  app.add_flag("!--no-shadow-cull", config.shadow_cull,
               "closed rooms: draw every face into the shadow maps, not only those turned to the "
               "light (the default: 22 - 30 % faster maps, crypt image within 0.6 %)");
  app.add_option("--texture-filter", extras.texture_filter,
                 "E' between its texel centres: bilinear (the hardware's, the paper's) | nearest "
                 "| cubic (Catmull-Rom, 16 texel reads)")
      ->check(CLI::IsMember({"bilinear", "nearest", "cubic"}))
      ->capture_default_str();
  app.add_option("--shadow-share", config.shadow_share,
                 "share one shadow map among g x g neighbouring positions, g the largest whose "
                 "shadow edges move by at most this many shadow texels (0: off)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("--merge-group", config.merge_group,
                 "merge blocks of N x N positions into one light for distant receivers (1: off; "
                 "0: auto, 2 without shadows, off with them)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--merge-error", config.merge_error,
                 "--merge-group: error bound of a merged light, relative to its block's peak "
                 "(sets the depth beyond which it is used)")
      ->check(CLI::Range(1e-6, 100.0))
      ->capture_default_str();
  app.add_option("--coarse-shading", config.coarse_tolerance,
                 "shade every second pixel of every second row and interpolate where four "
                 "samples on the pixel's surface agree within this fraction (0: off; default "
                 "auto: 0.1 in a room with shadows, off without them and on the plane, whose "
                 "irradiance is a measurement)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--reproject", config.reproject_tolerance,
                 "after a camera move, reuse the last frame shaded in full where four of its "
                 "pixels on the pixel's surface agree within this fraction (0: off)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
}

void AddModeOptions(CLI::App& app, PreviewConfig& config, CommandLineExtras& extras) {
  app.add_flag("--watch", config.watch, "poll the slab folder and add positions as they arrive");
  app.add_option("--poll", config.poll_s, "--watch polling interval (s)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--backend", extras.backend,
                 "osmesa (headless, llvmpipe; the default) | egl (headless on a GPU) | window "
                 "(GLFW with controls; needs a display)");
  app.add_flag("--window", extras.window, "--backend window");
  app.add_flag("!--no-ui", config.ui, "window: no controls panel (the picture only)");
  app.add_option("--screenshot", config.screenshot,
                 "--window: save the window to this PNG once all positions are in, then quit");
  app.add_flag("--bench", config.bench, "time frames with a moving camera");
  app.add_option("--bench-frames", config.bench_frames)->capture_default_str();
  auto* reference = app.add_flag(
      "--reference", config.reference,
      "exact CPU reference instead of OpenGL (docs/method.md §4.5): eq. 12 integrated over S with "
      "the exact model, --samples N per basis support, visibility by ray casting (Embree); slow, "
      "on --threads threads");
  app.add_option("--samples", config.samples,
                 "--reference: N x N samples per basis support (1 = the paper's eq. 14), 1..64")
      ->capture_default_str()
      ->needs(reference);
  app.add_option("--analytic", config.analytic,
                 "analytic image straight from a synthetic luminaire (no slab; the slab's d and "
                 "window only place the plane): default | dataset folder (its "
                 "truth/luminaire.json) | scene file")
      ->excludes(reference);
  app.add_flag("--write-test-slab", extras.write_test_slab,
               "first write the exact slab of the built-in synthetic luminaire (the default scene "
               "of lumislab-acquire synth: 9x7, h=5, "
               "d=750, window 1200 at 300) into --slab when it has no slab.json (demos, tests)");
}

Backend ParseBackend(const CommandLineExtras& extras) {
  if (extras.backend.empty()) return extras.window ? Backend::kWindow : Backend::kOsmesa;
  for (Backend b : {Backend::kOsmesa, Backend::kEgl, Backend::kWindow}) {
    if (extras.backend != BackendName(b)) continue;
    if (extras.window && b != Backend::kWindow)
      throw BadInput("--window is --backend window; it contradicts --backend " + extras.backend);
    return b;
  }
  throw InputError("--backend", "", "osmesa | egl | window", extras.backend);
}

void CheckCamera(const PreviewConfig& config) {
  if (config.camera.empty()) return;
  if (config.scene.name == "plane")
    throw BadInput("--camera: the plane view (--scene plane) has no orbit camera");
  const char* names[] = {"yaw", "pitch", "distance", "target x", "target y", "target z"};
  for (size_t k = 0; k < config.camera.size(); ++k) {
    const double v = config.camera[k];
    const bool ok = k < 2    ? std::abs(v) <= 36000
                    : k == 2 ? v >= 1 && v <= kMaxDistanceMm
                             : std::abs(v) <= kMaxCoordinateMm;
    if (!std::isfinite(v) || !ok)
      throw InputError("--camera", names[k],
                       k < 2    ? "an angle within 36000 degrees"
                       : k == 2 ? "a distance in [1, 1e5] mm"
                                : "a coordinate within 1e6 mm",
                       std::to_string(v));
  }
  if (std::abs(config.camera[1]) >= 90)
    throw InputError("--camera", "pitch", "within (-90, 90) degrees",
                     std::to_string(config.camera[1]));
}

// Checks what CLI11 cannot; fills the size.
void CheckOptions(const CommandLineExtras& extras, PreviewConfig& config) {
  if (!ParseSize(extras.size, &config.width, &config.height)) {
    throw InputError("--size", "size", "WxH, each 1..8192, e.g. 400x400", extras.size);
  }
  config.backend = ParseBackend(extras);
  const bool window = config.backend == Backend::kWindow;
  config.tone.curve = ParseToneCurve(extras.tone_map, "--tone-map");
  config.tone.auto_exposure = ParseAutoExposure(extras.auto_exposure, "--auto-exposure");
  if (extras.no_auto_exposure) config.tone.auto_exposure = AutoExposure::kOff;
  if (!std::isfinite(config.tone.exposure_stops) || std::abs(config.tone.exposure_stops) > 64)
    throw InputError("--exposure", "", "stops within [-64, 64]",
                     std::to_string(config.tone.exposure_stops));
  CheckCamera(config);
  // CLI11's ranges let NaN through (every comparison with it is false).
  for (const auto& [value, option] : {std::pair{config.shadow_share, "--shadow-share"},
                                      {config.merge_error, "--merge-error"},
                                      {config.reproject_tolerance, "--reproject"}}) {
    if (!std::isfinite(value)) throw InputError(option, "", "a finite number", "nan");
  }
  if (std::isnan(config.coarse_tolerance))
    throw InputError("--coarse-shading", "", "a finite number", "nan");
  if (config.shadow_size < 16 || config.shadow_size > 4096) {
    throw InputError("--shadow-size", "shadow-size", "16..4096",
                     std::to_string(config.shadow_size));
  }
  config.false_colour = extras.view == "false-colour";
  for (TextureFilter f : {TextureFilter::kBilinear, TextureFilter::kNearest, TextureFilter::kCubic})
    if (extras.texture_filter == TextureFilterName(f)) config.texture_filter = f;
  config.false_colour_scale.log = extras.false_colour_scale == "log";
  ParseFalseColourRange(extras.false_colour_range, "--false-colour-range",
                        &config.false_colour_scale);
  // A luminaire folder (docs/method.md §4.12): the shortcuts and the exact reference serve one
  // slab; --analytic renders the truth over the whole luminaire frame.
  config.luminaire_folder = IsLuminaireFolder(config.slab_dir);
  if (config.luminaire_folder) {
    for (const auto& [set, option] : {std::pair{config.reference, "--reference"},
                                      {config.shadow_share > 0, "--shadow-share"},
                                      {config.merge_group > 1, "--merge-group"},
                                      {extras.write_test_slab, "--write-test-slab"}})
      if (set)
        throw BadInput(std::string(option) + " serves one slab, not a luminaire folder (" +
                       config.slab_dir + ")");
  }
  if (config.reference || !config.analytic.empty()) {
    const char* mode = config.reference ? "--reference" : "--analytic";
    for (const auto& [set, option] : {std::pair{window, "--window"},
                                      {config.backend == Backend::kEgl, "--backend egl"},
                                      {config.watch, "--watch"},
                                      {config.bench, "--bench"},
                                      {config.srgbe, "--srgbe"},
                                      {config.report_srgbe_error, "--srgbe-error"},
                                      {config.shadow_pcf, "--shadow-pcf"},
                                      {!config.shadow_cull, "--no-shadow-cull"},
                                      {config.texture_filter != TextureFilter::kBilinear,
                                       "--texture-filter (it reads the slab bilinearly)"},

                                      {config.shadow_share > 0, "--shadow-share"},
                                      {config.merge_group > 1, "--merge-group"}})
      if (set)
        throw BadInput(std::string(mode) + " renders on the CPU: " + option + " is not for it");
    if (config.out.empty()) throw BadInput(std::string(mode) + " needs --out <file.exr|.png>");
    if (config.samples < 1 || config.samples > 64)
      throw InputError("--samples", "", "1 .. 64", std::to_string(config.samples));
  }
  if (!window && config.out.empty() && !config.bench) {
    throw BadInput("headless mode needs --out <file.exr|.png> (or --bench, or --window)");
  }
  if (!config.out.empty()) CheckOutputPath(config.out);
  // 0 means "the default" for the plane; anything else must be a distance a lab could mean.
  auto length = [](const char* option, double v) {
    if (v != 0 && !(v >= 1 && v <= kMaxDistanceMm))
      throw InputError(option, "", "0 (default) or a length in [1, 1e5] mm", std::to_string(v));
  };
  length("--receiver-plane", config.scene.receiver_plane_mm);
  if (config.luminaire_depth_mm != -1 &&
      !(config.luminaire_depth_mm >= 0 && config.luminaire_depth_mm <= kMaxDistanceMm))
    throw InputError("--luminaire-depth-mm", "", "a depth in [0, 1e5] mm",
                     std::to_string(config.luminaire_depth_mm));
  length("--extent", config.scene.extent_mm);
  for (size_t k = 0; k < config.scene.pose.size(); ++k) {
    const double v = config.scene.pose[k];
    const double limit = k < 3 ? kMaxCoordinateMm : 360.0 * 100;
    if (!std::isfinite(v) || std::abs(v) > limit)
      throw InputError("--luminaire-pose", "value " + std::to_string(k + 1),
                       k < 3 ? "a coordinate within 1e6 mm" : "an angle within 36000 degrees",
                       std::to_string(v));
  }
  if (!(config.poll_s > 0 && config.poll_s <= 60))
    throw InputError("--poll", "", "seconds in (0, 60]", std::to_string(config.poll_s));
  if (config.bench_frames < 1 || config.bench_frames > 100000)
    throw InputError("--bench-frames", "", "1 .. 100000", std::to_string(config.bench_frames));
}

// The light of the slab's positions there now, before anything is rendered of it
// ("slab.total_light", recorded in the dataset's checks.json under "preview"): a slab of negative
// light renders as a plausible dark scene. A --watch run checks the slab when it starts complete
// (positions that arrive later are the reconstruct's, which checks the complete slab).
void CheckSlabBeforeRendering(const PreviewConfig& config, const SlabInfo& info) {
  if (info.present.empty() || (config.watch && !info.Complete())) return;
  CheckLog checks(DatasetOfSlab(config.slab_dir), "preview");
  SlabLightSum sum(info);  // position by position: one image in memory
  for (const auto& [i, j] : info.present) sum.Add(ReadSlabPosition(config.slab_dir, info, i, j));
  CheckSlabLight(info, sum.Result(), config.slab_dir, checks);
  checks.Save();
}

// Runs the configured preview inside a stop-signal scope (Ctrl-C ends --watch cleanly).
int Run(const PreviewConfig& config, bool write_test_slab) {
  if (write_test_slab && !std::filesystem::exists(config.slab_dir + "/slab.json")) {
    const SynthScene scene = DefaultScene();
    WriteTruthSlab(scene.luminaire, TruthSlabInfo(scene, 300), config.slab_dir, config.threads);
    LogInfo("wrote the built-in test slab to ", config.slab_dir);
  }
  if (!config.out.empty()) {  // a killed --watch run may have left its output half-written
    const std::string folder = std::filesystem::absolute(config.out).parent_path().string();
    if (std::filesystem::is_directory(folder)) RemoveOrphanedTemporaries(folder);
  }
  const StopSignalScope stop_signals;
  const LightSource source = OpenLightSource(config.slab_dir, config.watch);
  const std::optional<SlabInfo> info = WaitForFirstSlab(config, source);
  if (!info) {
    LogInfo("stopped before ", config.slab_dir,
            source.luminaire ? "'s first slab.json" : "/slab.json", " appeared");
    return 0;
  }
  // One slab's checks (a luminaire folder's orientations are checked by their own stages).
  if (!source.luminaire) {
    CheckReceiverPlane(config, *info);
    if (config.analytic.empty()) CheckSlabBeforeRendering(config, *info);
  }
  if (config.reference || !config.analytic.empty()) return RunReferenceMode(config, *info);
  return config.backend == Backend::kWindow ? RunWindow(config, source, *info)
                                            : RunHeadless(config, source, *info);
}

}  // namespace

bool ParseSize(const std::string& text, int* width, int* height) {
  static const std::regex pattern("([0-9]{1,5})x([0-9]{1,5})");
  std::smatch match;
  if (!std::regex_match(text, match, pattern)) return false;
  *width = std::stoi(match[1].str());
  *height = std::stoi(match[2].str());
  return *width > 0 && *height > 0 && *width <= 8192 && *height <= 8192;
}

std::optional<int> ParsePreviewCommandLine(int argc, char** argv, PreviewConfig& config,
                                           bool* write_test_slab) {
  CLI::App app{
      "lumislab-preview: the measured luminaire lighting a scene (docs/method.md §4); headless "
      "(--backend osmesa or egl, --out) or in a window with controls (--backend window)"};
  app.footer(
      "--threads sizes lumislab's own CPU work (deriving E' of the slab positions as they are "
      "loaded; the whole render with --reference or --analytic). The OpenGL renderer's threads are "
      "llvmpipe's: set them with the LP_NUM_THREADS "
      "environment variable (default: all cores).");
  CommonOptions common;
  CommandLineExtras extras;
  AddCommonOptions(&app, &common);
  AddSceneOptions(app, config, extras);
  AddRenderOptions(app, config, extras);
  AddModeOptions(app, config, extras);
  if (const auto code = ParseCommandLine(app, argc, argv)) return code;
  config.threads = StartTool("preview", common);
  CheckOptions(extras, config);
  if (write_test_slab) *write_test_slab = extras.write_test_slab;
  return std::nullopt;
}

std::string HeadlessCommandLine(const PreviewConfig& config, const std::string& out) {
  std::ostringstream line;
  line.precision(6);
  auto arg = [&](const std::string& text) {
    const bool plain = !text.empty() && text.find_first_not_of(
                                            "abcdefghijklmnopqrstuvwxyz"
                                            "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                            "0123456789_-+=.,/:@%") == std::string::npos;
    if (plain) return " " + text;
    std::string quoted = " '";
    for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
  };
  auto values = [&](const std::vector<double>& v) {
    std::ostringstream list;
    list.precision(6);
    for (size_t k = 0; k < v.size(); ++k)
      list << (k ? "," : "") << (std::abs(v[k]) < 5e-7 ? 0.0 : v[k]);
    return list.str();
  };
  line << "lumislab-preview" << arg("--slab") << arg(config.slab_dir) << arg("--scene")
       << arg(config.scene.name);
  if (!config.scene.pose.empty()) line << arg("--luminaire-pose") << arg(values(config.scene.pose));
  if (config.scene.receiver_plane_mm != 0)
    line << arg("--receiver-plane") << arg(values({config.scene.receiver_plane_mm}));
  if (config.luminaire_depth_mm >= 0)
    line << arg("--luminaire-depth-mm") << arg(values({config.luminaire_depth_mm}));
  if (config.scene.extent_mm != 0) line << arg("--extent") << arg(values({config.scene.extent_mm}));
  if (!config.camera.empty()) line << arg("--camera") << arg(values(config.camera));
  line << arg("--size") << arg(std::to_string(config.width) + "x" + std::to_string(config.height));
  if (config.false_colour) {
    line << arg("--view") << arg("false-colour");
    if (config.false_colour_scale.log) line << arg("--false-colour-scale") << arg("log");
    if (config.false_colour_scale.max > config.false_colour_scale.min)
      line << arg("--false-colour-range")
           << arg(values({config.false_colour_scale.min}) + ":" +
                  values({config.false_colour_scale.max}));
  }
  line << arg("--exposure") << arg(values({config.tone.exposure_stops})) << arg("--tone-map")
       << arg(ToneCurveName(config.tone.curve)) << arg("--auto-exposure")
       << arg(AutoExposureName(config.tone.auto_exposure));
  if (!config.shadows) line << arg("--no-shadows");
  line << arg("--shadow-size") << arg(std::to_string(config.shadow_size));
  if (config.shadow_pcf) line << arg("--shadow-pcf");
  if (!config.shadow_cull) line << arg("--no-shadow-cull");
  if (config.shadow_share > 0) line << arg("--shadow-share") << arg(values({config.shadow_share}));
  if (config.merge_group != 0)
    line << arg("--merge-group") << arg(std::to_string(config.merge_group));
  if (config.merge_error != 0.05) line << arg("--merge-error") << arg(values({config.merge_error}));
  if (config.coarse_tolerance >= 0)
    line << arg("--coarse-shading") << arg(values({config.coarse_tolerance}));
  if (config.reproject_tolerance != 0.1)
    line << arg("--reproject") << arg(values({config.reproject_tolerance}));
  if (config.srgbe) line << arg("--srgbe");
  if (config.texture_filter != TextureFilter::kBilinear)
    line << arg("--texture-filter") << arg(TextureFilterName(config.texture_filter));
  line << arg("--out") << arg(out);
  return line.str();
}

int RunPreview(int argc, char** argv) {
  PreviewConfig config;
  bool write_test_slab = false;
  if (const auto code = ParsePreviewCommandLine(argc, argv, config, &write_test_slab)) return *code;
  return Run(config, write_test_slab);
}

}  // namespace lumislab
