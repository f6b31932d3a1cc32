// Headless lumislab-preview (--backend osmesa, or egl on a GPU): one render into --out,
// optionally the sRGBE-vs-float report, a --bench timing and --watch polling that re-renders as
// positions arrive.
#pragma once

#include "core/slab.h"
#include "preview/config.h"
#include "preview/light_source.h"

namespace lumislab {

// `info`: the layout of the slab (of every orientation's, for a luminaire folder).
int RunHeadless(const PreviewConfig& config, const LightSource& source, const SlabInfo& info);

}  // namespace lumislab
