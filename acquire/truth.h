// Ground truth of a synthetic dataset (truth/): the exact E_ij at the slab texel centres and the
// true camera (truth/camera.json) for the calibration tests.
#pragma once

#include <string>

#include "acquire/scene.h"
#include "core/slab.h"

namespace lumislab {

// Exact E_ij(s,t) (W/m^2, luminaire frame) at the texel centres of `info`, mask 1 everywhere.
SlabPosition TruthPosition(const SynthScene& scene, const SlabInfo& info, int i, int j);

// truth/: slab.json + every position (SlabInfo::FromDataset(dataset, resolution)), written with
// `threads` workers.
void WriteTruthSlab(const SynthScene& scene, const Dataset& dataset, const std::string& truth_dir,
                    int resolution, int threads);

// truth/camera.json: intrinsics, pose (lab frame), and the exact homographies of the screen
// plane (screen_from_image: pixel -> lab mm, row-major, and its inverse).
void WriteTruthCamera(const SynthScene& scene, const std::string& path);

}  // namespace lumislab
