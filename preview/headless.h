// Headless lumislab-preview (--backend osmesa, or egl on a GPU): one render into --out,
// optionally the sRGBE-vs-float report, a --bench timing and --watch polling that re-renders as
// positions arrive.
#pragma once

#include "core/slab.h"
#include "preview/config.h"

namespace lumislab {

int RunHeadless(const PreviewConfig& config, const SlabInfo& info);

}  // namespace lumislab
