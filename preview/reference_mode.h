// lumislab-preview --reference / --analytic (docs/method.md §4.5): the same scene, pose, camera,
// size and output as a headless render, computed on the CPU by lib/lightfield's exact reference
// (Embree ray casting) instead of OpenGL: from the slab through the exact model, or straight from
// a synthetic luminaire's emitters (the analytic truth).
#pragma once

#include "core/slab.h"
#include "preview/config.h"

namespace lumislab {

// Renders and writes config.out; exit 1 (nothing written) when stopped by a signal (the caller
// holds the StopSignalScope).
int RunReferenceMode(const PreviewConfig& config, const SlabInfo& info);

}  // namespace lumislab
