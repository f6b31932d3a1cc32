// The interactive GLFW window of lumislab-preview: orbit (left drag), pan (right drag), zoom
// (wheel), exposure (+/-), shadows (S), accumulation format float/sRGBE (F), screenshot (P),
// quit (Q/Esc). With --watch, new slab positions are added as they arrive; the title shows how
// many and which arrived.
#pragma once

#include "core/slab.h"
#include "preview/run_preview.h"

namespace lumislab {

int RunWindow(const PreviewConfig& config, const SlabInfo& info);

}  // namespace lumislab
