#include "preview/config.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/lightfield/light_field.h"
#include "lib/synthetic/truth.h"

namespace lumislab {

const char* BackendName(Backend backend) {
  switch (backend) {
    case Backend::kOsmesa:
      return "osmesa";
    case Backend::kEgl:
      return "egl";
    case Backend::kWindow:
      return "window";
  }
  return "?";
}

double CheckReceiverPlane(const PreviewConfig& config, const SlabInfo& info) {
  const double d = info.distance_mm;
  const double D = config.scene.receiver_plane_mm;
  if (config.scene.name != "plane" || D == 0 || D >= d) return -1;
  double z = config.luminaire_depth_mm;
  std::string source = "--luminaire-depth-mm";
  std::filesystem::path slab = std::filesystem::absolute(config.slab_dir).lexically_normal();
  if (slab.filename().empty()) slab = slab.parent_path();  // "dataset/slab/"
  const std::filesystem::path truth = slab.parent_path() / "truth" / "luminaire.json";
  if (z < 0 && std::filesystem::exists(truth)) {
    z = 0;
    for (const Emitter& e : LoadLuminaire(truth.string()).emitters)
      z = std::max(z, -e.position_mm.z());
    source = truth.string();
  }
  if (z < 0) {
    LogInfo("the receiver plane at D = ", D, " mm is nearer S than d = ", d,
            " mm: the error there grows with the luminaire's depth behind S (z |1 - d/D|); give "
            "--luminaire-depth-mm to have it checked");
    return -1;
  }
  const double bound = ParallaxFirstOrderBound(z, d, D, info.filter.Filter());
  if (bound >= 1)
    LogWarning("the receiver plane at D = ", D,
               " mm is too close to S for the method: the "
               "first-order parallax bound 2 a sum|c_m| is ",
               bound, " (>= 1) for light ", z, " mm behind S (", source,
               "), so no error bound holds for this image");
  else
    LogInfo("receiver plane at D = ", D, " mm, light up to ", z, " mm behind S (", source,
            "): first-order parallax bound ", bound);
  return bound;
}

const char* TextureFilterName(TextureFilter filter) {
  switch (filter) {
    case TextureFilter::kBilinear:
      return "bilinear";
    case TextureFilter::kNearest:
      return "nearest";
    case TextureFilter::kCubic:
      return "cubic";
  }
  return "?";
}

SceneSetup MakePreviewSetup(const PreviewConfig& config, const SlabInfo& info) {
  SceneSetup setup = MakeSceneSetup(config.scene, info);
  if (!config.camera.empty()) SetCameraValues(config.camera, setup);
  return setup;
}

std::vector<double> CameraValues(const SceneSetup& setup) {
  return {setup.camera_yaw_deg,    setup.camera_pitch_deg,  setup.camera_distance,
          setup.camera_target.x(), setup.camera_target.y(), setup.camera_target.z()};
}

void SetCameraValues(const std::vector<double>& values, SceneSetup& setup) {
  if (values.size() != 6) throw BadInput("--camera needs yaw,pitch,distance,x,y,z");
  setup.camera_yaw_deg = values[0];
  setup.camera_pitch_deg = values[1];
  setup.camera_distance = values[2];
  setup.camera_target = Eigen::Vector3d(values[3], values[4], values[5]);
}

int MergeGroup(const PreviewConfig& config) {
  if (config.merge_group > 0) return config.merge_group;
  return config.shadows || config.luminaire_folder ? 1 : 2;
}

double CoarseTolerance(const PreviewConfig& config, const SceneSetup& setup) {
  if (config.coarse_tolerance >= 0) return config.coarse_tolerance;
  return config.shadows && !setup.plane ? 0.1 : 0;
}

bool IsSoftwareRenderer(const std::string& gl_renderer) {
  for (const char* name : {"llvmpipe", "softpipe", "swrast", "Software Rasterizer"})
    if (gl_renderer.find(name) != std::string::npos) return true;
  return false;
}

std::string ShortcutChoice(const PreviewConfig& config, const RenderOptions& options,
                           const std::string& gl_renderer) {
  const bool software = IsSoftwareRenderer(gl_renderer);
  auto tolerance = [](double t) {
    char text[32];
    std::snprintf(text, sizeof(text), "%g", t);
    return t > 0 ? std::string(text) : std::string("off");
  };
  std::string line =
      std::string("shortcuts (") + (software ? "software" : "hardware") +
      " renderer): coarse shading " + tolerance(options.coarse_tolerance) +
      (config.coarse_tolerance < 0 ? " (auto)" : " (--coarse-shading)") + ", reprojection " +
      tolerance(options.reproject_tolerance) + ", shadow-map sharing " +
      tolerance(options.shadow_share_texels) + ", merging " +
      (options.merge_group > 1
           ? std::to_string(options.merge_group) + "x" + std::to_string(options.merge_group)
           : std::string("off")) +
      (config.merge_group > 0 ? " (--merge-group)" : " (auto)") + "; why: ";
  if (software) {
    line += "the defaults measured to pay on llvmpipe (docs/results.md, Table 1)";
  } else {
    line +=
        "the same as on llvmpipe: on the one GPU measured (issue 32) they still paid (1080p "
        "camera move 168 fps with both, 131 without reprojection, 94 with neither); a GPU path "
        "without them is unmeasured";
  }
  return line;
}

RenderOptions MakeRenderOptions(const PreviewConfig& config, const SceneSetup& setup) {
  RenderOptions options;
  options.shadows = config.shadows;
  options.srgbe = config.srgbe;
  options.shadow_size = config.shadow_size;
  options.shadow_pcf = config.shadow_pcf;
  options.texture_filter = config.texture_filter;
  options.shadow_share_texels = config.shadow_share;
  options.merge_group = MergeGroup(config);
  options.merge_error = config.merge_error;
  options.coarse_tolerance = CoarseTolerance(config, setup);
  options.reproject_tolerance = config.reproject_tolerance;
  if (setup.plane || config.false_colour) options.radiance_scale = 1.0;
  options.unit_albedo = config.false_colour;
  options.cull_back_faces = setup.closed_room;
  options.shadow_cull = setup.closed_room && config.shadow_cull;
  return options;
}

std::vector<std::pair<int, int>> LoadNewPositions(const std::string& slab_dir, const SlabInfo& info,
                                                  Renderer& renderer, int threads,
                                                  int orientation) {
  std::vector<std::pair<int, int>> added;
  for (const auto& [i, j] : ScanSlabPositions(slab_dir, info)) {
    if (!renderer.HasPosition(i, j, orientation)) added.emplace_back(i, j);
  }
  // E' of a batch on `threads` threads, then uploaded on this one (the GL context's); batches
  // bound the memory held for a large slab.
  const size_t batch = size_t(std::max(16, 2 * threads));
  for (size_t start = 0; start < added.size(); start += batch) {
    const std::vector<std::pair<int, int>> part(
        added.begin() + start, added.begin() + std::min(added.size(), start + batch));
    const std::vector<ImageF> intensities = ReadIntensities(slab_dir, info, part, threads);
    for (size_t k = 0; k < part.size(); ++k) {
      renderer.SetPosition(part[k].first, part[k].second, intensities[k], orientation);
    }
  }
  return added;
}

Rgb8Image FalseColourView(const PreviewConfig& config, const SceneSetup& setup,
                          const SlabInfo& info, const ImageF& irradiance) {
  const double mm_per_pixel = setup.plane ? setup.extent / irradiance.width : 0;
  const std::string title =
      setup.plane ? "plane at " + FormatTick(setup.plane_z, 1) + " mm" : std::string();
  return FalseColourPicture(irradiance, info.channel_weights, config.false_colour_scale,
                            IrradianceUnitLabel(info.units), mm_per_pixel, title);
}

}  // namespace lumislab
