// The interactive GLFW window of lumislab-preview (--backend window) with its Dear ImGui controls
// panel (docs/method.md §4.4): fps, positions arrived (a grid), exposure and tone map,
// shadows and their quality, float/sRGBE, the luminaire pose (fields; Ctrl+drag moves, Shift+drag
// aims), the camera (orbit: left drag, right drag pans, wheel zooms; fly: arrows, PgUp/PgDn),
// a screenshot button (P) and the headless command line of what is shown. Keys: +/- exposure,
// S shadows, F float/sRGBE, Q/Esc quit. With --watch, new slab positions are added as they
// arrive. The picture is the headless PNG's: ToneMapToSrgb8 of the read-back image.
#pragma once

#include "core/slab.h"
#include "preview/config.h"
#include "preview/light_source.h"

namespace lumislab {

int RunWindow(const PreviewConfig& config, const LightSource& source, const SlabInfo& info);

}  // namespace lumislab
