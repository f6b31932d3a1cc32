#include "preview/light_source.h"

#include <chrono>
#include <filesystem>
#include <thread>

#include "core/dataset.h"
#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"

namespace lumislab {
namespace {

std::string SlabJson(const std::string& slab_dir) { return slab_dir + "/slab.json"; }

// The layout every orientation's slab must share with the first (the renderer's texture arrays
// and light program are of one layout).
bool SameLayout(const SlabInfo& a, const SlabInfo& b) {
  return a.distance_mm == b.distance_mm && a.grid.nu == b.grid.nu && a.grid.nv == b.grid.nv &&
         a.grid.spacing_mm == b.grid.spacing_mm && a.layout.res_x == b.layout.res_x &&
         a.layout.res_y == b.layout.res_y && a.layout.window_w_mm == b.layout.window_w_mm &&
         a.layout.window_h_mm == b.layout.window_h_mm &&
         a.filter.dual_coefficients == b.filter.dual_coefficients && a.units == b.units;
}

std::string LayoutText(const SlabInfo& s) {
  return "d " + std::to_string(s.distance_mm) + " mm, grid " + std::to_string(s.grid.nu) + "x" +
         std::to_string(s.grid.nv) + " at " + std::to_string(s.grid.spacing_mm) + " mm, " +
         std::to_string(s.layout.res_x) + "x" + std::to_string(s.layout.res_y) + " texels over " +
         std::to_string(s.layout.window_w_mm) + "x" + std::to_string(s.layout.window_h_mm) +
         " mm, " + s.units;
}

}  // namespace

LightSource OpenLightSource(const std::string& folder, bool watch) {
  LightSource source;
  source.folder = folder;
  // While the lab driver captures (acquire capture --orientations), luminaire.json lists only the
  // orientations already complete and capture/plan.json all of them: --watch follows the plan.
  const std::string plan = folder + "/capture/plan.json";
  std::error_code ec;
  const bool capturing = watch && std::filesystem::is_regular_file(plan, ec);
  source.luminaire = IsLuminaireFolder(folder) || capturing;
  if (!source.luminaire) {
    source.slab_dirs = {folder};
    return source;
  }
  if (capturing) {
    LuminaireSet planned = LoadLuminaireSetFile(plan, folder);
    source.set = IsLuminaireFolder(folder) ? LoadLuminaireSet(folder) : planned;
    if (planned.orientations.size() > source.set.orientations.size()) {
      LogInfo(plan, ": following the capture's plan of ", planned.orientations.size(),
              " orientations (", source.set.orientations.size(), " complete), nominal poses");
      source.set = std::move(planned);
    }
  } else {
    source.set = LoadLuminaireSet(folder);
  }
  if (int(source.set.orientations.size()) > kMaxOrientations)
    throw InputError(LuminaireJsonPath(folder), "orientations",
                     "at most " + std::to_string(kMaxOrientations) + " (the preview's limit)",
                     std::to_string(source.set.orientations.size()));
  for (size_t k = 0; k < source.set.orientations.size(); ++k)
    source.slab_dirs.push_back(source.set.DatasetFolder(k) + "/slab");
  return source;
}

std::vector<LightOrientation> RendererOrientations(const LightSource& source,
                                                   const SlabInfo& info) {
  std::vector<LightOrientation> out;
  if (!source.luminaire) return out;
  const OrientationCone cone = ConeOfSlab(info);
  for (const Orientation& o : source.set.orientations) {
    LightOrientation light;
    light.capture_from_luminaire = o.rotation;
    light.centre_mm = o.centre_mm;
    light.cone = cone;
    out.push_back(light);
  }
  return out;
}

std::optional<SlabInfo> WaitForFirstSlab(const PreviewConfig& config, const LightSource& source) {
  auto first = [&]() -> std::optional<std::string> {
    for (const std::string& dir : source.slab_dirs)
      if (std::filesystem::exists(SlabJson(dir))) return dir;
    return std::nullopt;
  };
  if (!config.watch) {
    // Every orientation's slab (one slab: its own) must be there.
    for (size_t k = 0; k < source.slab_dirs.size(); ++k)
      if (source.luminaire && !std::filesystem::exists(SlabJson(source.slab_dirs[k])))
        throw InputError(SlabJson(source.slab_dirs[k]), "",
                         "the slab of orientation " + source.set.orientations[k].name +
                             " (luminaire.json lists it; --watch waits for it)",
                         "no file");
    return SlabInfo::Load(source.slab_dirs[0]);
  }
  std::optional<std::string> dir = first();
  if (!dir)
    LogInfo("waiting for ", SlabJson(source.slab_dirs[0]),
            source.luminaire ? " (or another orientation's)" : "");
  while (!dir) {
    if (StopRequested()) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::duration<double>(config.poll_s));
    dir = first();
  }
  return SlabInfo::Load(*dir);
}

std::vector<std::pair<int, int>> LoadNewLights(const LightSource& source, const SlabInfo& info,
                                               Renderer& renderer, int threads) {
  if (!source.luminaire) return LoadNewPositions(source.folder, info, renderer, threads);
  std::vector<std::pair<int, int>> added;
  for (size_t k = 0; k < source.slab_dirs.size(); ++k) {
    const std::string& dir = source.slab_dirs[k];
    if (!std::filesystem::exists(SlabJson(dir))) continue;  // not captured yet
    const SlabInfo own = SlabInfo::Load(dir);
    if (!SameLayout(own, info))
      throw InputError(SlabJson(dir), "layout",
                       "the layout of the other orientations' slabs (" + LayoutText(info) + ")",
                       LayoutText(own));
    const auto loaded = LoadNewPositions(dir, own, renderer, threads, int(k));
    added.insert(added.end(), loaded.begin(), loaded.end());
  }
  return added;
}

void CheckListedLightsLoaded(const LightSource& source, const Renderer& renderer) {
  for (size_t k = 0; k < source.slab_dirs.size(); ++k) {
    const std::string& dir = source.slab_dirs[k];
    const SlabInfo info = SlabInfo::Load(dir);
    if (info.present.empty())
      throw InputError(SlabJson(dir), "present", "at least one position", "none");
    for (const auto& [i, j] : info.present)
      if (!renderer.HasPosition(i, j, int(k)))
        throw InputError(SlabPositionPath(dir, i, j), "",
                         "a complete EXR of " + std::to_string(info.layout.res_x) + "x" +
                             std::to_string(info.layout.res_y) +
                             " texels (slab.json lists the position)",
                         "a missing, truncated or other-sized file");
  }
}

}  // namespace lumislab
