// The preview of a luminaire folder against its number of orientations (docs/results.md §13):
// lib/synthetic's full-sphere luminaire turned into 1, 2 and 6 cube-face orientations (truth
// slabs, 2000 mm screen at d = 750 mm), lighting the crypt through OSMesa. Per row: the median
// frame time with a moving camera (shadow maps cached), with every shadow map redrawn (a pose
// change), the time to load the lights, the renderer's texture memory (E' and shadow-map arrays,
// from their sizes) and the process's resident-memory growth. Prints a table, writes CSV.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"
#include "core/log.h"
#include "core/luminaire_set.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"
#include "preview/gl_context.h"
#include "preview/renderer.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Resident memory of this process (MiB), from /proc/self/status.
double ResidentMiB() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kib = 0;
      status >> kib;
      return kib / 1024;
    }
  }
  return 0;
}

// The cube's faces as orientations (rotation_deg [rx, ry, rz] turning the face's normal to +z).
const double kFaceRotations[6][3] = {{0, 0, 0},  {0, -90, 0}, {180, 0, 0},
                                     {0, 90, 0}, {90, 0, 0},  {-90, 0, 0}};

int Run(int argc, char** argv) {
  int frames = 5, size = 400, shadow_size = 512, grid = 7, resolution = 300;
  std::string csv = "preview_orientations.csv";
  CLI::App app{
      "preview_orientations: the preview's frame time and memory against the number of "
      "orientations of a luminaire folder (docs/results.md §13)"};
  app.add_option("--frames", frames, "frames per row (median)")->capture_default_str();
  app.add_option("--size", size, "image side")->capture_default_str();
  app.add_option("--shadow-size", shadow_size, "shadow-map side")->capture_default_str();
  app.add_option("--grid", grid, "positions per side of each orientation's grid")
      ->capture_default_str();
  app.add_option("--resolution", resolution, "slab texels per side")->capture_default_str();
  app.add_option("--csv", csv, "CSV output")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::kBadInput);
  }
  SetLogTool("preview_orientations");
  OffscreenContext context(16, 16);
  SlabInfo info = DefaultSlabInfo(grid, grid, 12, resolution);
  info.layout.window_w_mm = info.layout.window_h_mm = 2000;
  const Luminaire luminaire = LoadScene("full-sphere").luminaire;
  double reach = 0;
  for (const Emitter& e : luminaire.emitters)
    reach = std::max(reach, (e.position_mm - luminaire.centre_mm).norm());
  const Eigen::Vector3d centre(0, 0, -(reach + 6));  // behind S in every orientation
  const OrientationCone cone = ConeOfSlab(info);
  // Every face's E' (the six faces once; rows take the first K).
  std::vector<std::vector<ImageF>> faces(6);
  for (int k = 0; k < 6; ++k) {
    const Luminaire turned = luminaire.Turned(
        RotationZyxDegrees({kFaceRotations[k][0], kFaceRotations[k][1], kFaceRotations[k][2]}),
        centre);
    for (int j = 0; j < grid; ++j)
      for (int i = 0; i < grid; ++i)
        faces[k].push_back(
            IntensityFromIrradiance(info, i, j, TruthPosition(turned, info, i, j).irradiance));
  }
  const SceneSetup setup = MakeSceneSetup("crypt", info);
  std::printf(
      "renderer: %s, crypt %dx%d, %dx%d positions per orientation at %d texels, shadow "
      "maps %d^2, median of %d frames\n",
      context.Renderer().c_str(), size, size, grid, grid, resolution, shadow_size, frames);
  std::printf("%-12s %6s %10s %10s %9s %11s %10s\n", "orientations", "lights", "camera ms",
              "full ms", "load s", "texture MiB", "RSS +MiB");
  std::ofstream out(csv);
  out << "orientations,lights,frame_camera_ms,frame_full_ms,load_s,texture_mib,rss_growth_mib\n";
  for (int count : {1, 2, 6}) {
    std::vector<LightOrientation> orientations;
    for (int k = 0; k < count; ++k) {
      LightOrientation o;
      o.capture_from_luminaire =
          RotationZyxDegrees({kFaceRotations[k][0], kFaceRotations[k][1], kFaceRotations[k][2]});
      o.centre_mm = centre;
      o.cone = cone;
      orientations.push_back(o);
    }
    RenderOptions options;
    options.shadow_size = shadow_size;
    options.cull_back_faces = setup.closed_room;
    options.shadow_cull = setup.closed_room;
    options.merge_group = 1;
    options.coarse_tolerance = 0.1;   // lumislab-preview's default in a room with shadows
    options.reproject_tolerance = 0;  // every frame shaded: the cost of the lights
    const double rss_before = ResidentMiB();
    auto start = Clock::now();
    Renderer renderer(info, size, size, options, orientations);
    renderer.SetScene(setup.mesh);
    renderer.SetPose(setup.pose);
    for (int k = 0; k < count; ++k)
      for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i)
          renderer.SetPosition(i, j, faces[k][info.grid.Index(i, j)], k);
    renderer.SetCamera(OrbitCamera(setup, 1.0));
    renderer.Render();
    const double load_s = Seconds(start);
    const double rss_growth = ResidentMiB() - rss_before;
    std::vector<double> camera, full;
    SceneSetup moving = setup;
    for (int f = 0; f < frames; ++f) {
      moving.camera_yaw_deg = setup.camera_yaw_deg + 2.0 * (2 * f + 1);
      renderer.SetCamera(OrbitCamera(moving, 1.0));
      start = Clock::now();
      renderer.Render();
      renderer.Finish();
      camera.push_back(Seconds(start) * 1000);
      moving.camera_yaw_deg += 2;
      renderer.SetCamera(OrbitCamera(moving, 1.0));
      renderer.SetPose(setup.pose);  // every shadow map redrawn
      start = Clock::now();
      renderer.Render();
      renderer.Finish();
      full.push_back(Seconds(start) * 1000);
    }
    const int lights = renderer.LightCount();
    // RGBA32F E' layers (one slab: also the merged layers) and DEPTH32F shadow maps.
    const double texture_mib = (double(lights) * resolution * resolution * 16 +
                                double(lights) * shadow_size * shadow_size * 4) /
                               (1024.0 * 1024.0);
    std::printf("%-12d %6d %10.1f %10.1f %9.2f %11.1f %10.1f\n", count, lights, Median(camera),
                Median(full), load_s, texture_mib, rss_growth);
    out << count << "," << lights << "," << Median(camera) << "," << Median(full) << "," << load_s
        << "," << texture_mib << "," << rss_growth << "\n";
  }
  return 0;
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) {
  return lumislab::RunMain("preview_orientations", [&] { return lumislab::Run(argc, argv); });
}
