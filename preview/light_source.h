// What lights the preview's scene (--slab): one slab folder, or a luminaire folder (docs/formats.md
// §19) whose orientations' slabs (<lum>/<dataset>/slab) all light it, each posed into the
// luminaire frame (docs/method.md §4.12, "The preview of a luminaire folder"). The steps the
// headless run and the window share: waiting for the first slab, loading the positions that
// arrived, and the renderer's orientations.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/luminaire_set.h"
#include "core/slab.h"
#include "preview/config.h"
#include "preview/renderer.h"

namespace lumislab {

struct LightSource {
  std::string folder;      // --slab as given
  bool luminaire = false;  // a luminaire folder (IsLuminaireFolder)
  LuminaireSet set;        // its orientations (registered poses where registration.json is)
  // Per orientation its slab folder (one slab: the folder itself).
  std::vector<std::string> slab_dirs;
};

// Opens --slab: a luminaire folder (luminaire.json read and checked, exit 2 naming the file and
// field) or a slab folder. With `watch`, a folder the lab driver is capturing into
// (capture/plan.json) is opened with all the plan's orientations, which join as they arrive.
LightSource OpenLightSource(const std::string& folder, bool watch = false);

// The renderer's orientations: none for one slab; a luminaire folder's poses and each one's cone
// (ConeOfDataset of the slab layout every orientation shares).
std::vector<LightOrientation> RendererOrientations(const LightSource& source, const SlabInfo& info);

// slab.json of the first orientation that has one (one slab: the slab's); with --watch, waits
// for one to appear; nothing when a stop signal arrives first. Without --watch every orientation
// of a luminaire folder must have its slab (exit 2 naming the missing slab.json).
std::optional<SlabInfo> WaitForFirstSlab(const PreviewConfig& config, const LightSource& source);

// Loads every position of every orientation present on disk that the renderer lacks (E' derived
// on `threads` threads). An orientation's slab must have `info`'s layout (d, grid, window,
// resolution, filter, units; exit 2 naming its slab.json). Returns the positions loaded.
std::vector<std::pair<int, int>> LoadNewLights(const LightSource& source, const SlabInfo& info,
                                               Renderer& renderer, int threads);

// Without --watch: every position each slab.json lists is in the renderer, and there is one.
void CheckListedLightsLoaded(const LightSource& source, const Renderer& renderer);

}  // namespace lumislab
