// lumislab-preview: command line, headless (OSMesa) renders, slab loading and --watch polling.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/slab.h"
#include "preview/renderer.h"
#include "preview/scenes.h"

namespace lumislab {

struct PreviewConfig {
  std::string slab_dir;
  std::string scene = "crypt";  // crypt | cloister | plane | <file>
  std::vector<double> pose;     // x,y,z,rx,ry,rz; empty: the scene's default
  int width = 400, height = 400;
  std::string out;               // headless output (.exr linear, .png tone-mapped)
  double receiver_plane_mm = 0;  // plane mode: D (0: the slab's d)
  double extent_mm = 0;          // plane mode: W (0: window * D / d)
  double exposure_stops = 0;     // PNG / window exposure; NaN-free: 0 + auto
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
};

int RunPreview(int argc, char** argv);
// True once SIGINT/SIGTERM arrived (clean shutdown of --watch loops).
bool PreviewStopRequested();

// What a scene name resolves to: mesh, default luminaire pose and default camera.
struct SceneSetup {
  Mesh mesh;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Eigen::Vector3d camera_target{0, 0, 0};
  double camera_distance = 3000, camera_yaw_deg = 30, camera_pitch_deg = 20;
  bool plane = false;
  bool closed_room = false;  // built-in rooms: cull back faces so the camera sees in
  double plane_z = 0, extent = 0;
};
// Renderer options from the command line, for the scene it sets up (one place for both contexts).
RenderOptions MakeRenderOptions(const PreviewConfig& config, const SceneSetup& setup);
SceneSetup MakeSceneSetup(const PreviewConfig& config, const SlabInfo& info);
// Orbit camera: clip-from-scene matrix.
Eigen::Matrix4f OrbitCamera(const SceneSetup& setup, double aspect);

// Loads every slab position present on disk that `loaded` (grid index -> bool) lacks into the
// renderer (E' derived on load); returns the positions loaded.
std::vector<std::pair<int, int>> LoadNewPositions(const std::string& slab_dir, const SlabInfo& info,
                                                  Renderer& renderer);

// Tone mapping for PNG/window: factor for `stops` plus auto (99th percentile of max channel
// -> 0.8) when `automatic`.
double ExposureFactor(const ImageF& image, double stops, bool automatic);
// Writes .exr (linear RGB) or .png (tone-mapped, sRGB 8-bit) atomically.
void WriteImage(const std::string& path, const ImageF& image, double exposure_factor);

}  // namespace lumislab
