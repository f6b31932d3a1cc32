// The radiometric calibration captures of `acquire synth` (scene block calibration_captures,
// docs/design.md §5.10): dark, flat and response frames under calibration/ with their manifest
// calibration/captures.json, and their truth (truth/flat.exr, truth/dark.exr,
// truth/reference.json).
#pragma once

#include <string>

#include "acquire/photo_store.h"
#include "core/dataset.h"
#include "lib/photo/photo_io.h"
#include "lib/synthetic/scene.h"

namespace lumislab {

// Writes the captures of scene.captures (nothing when absent) into the dataset folder `dir`,
// stored like the slide photos (StoreSlidePhoto: DNG with `raw`, camera-style files with EXIF in a
// camera folder). Their noise streams follow the slide photos' (photo index
// dataset.photos.size() + k), so adding them changes no slide photo.
void WriteCalibrationCaptures(const SynthScene& scene, const Dataset& dataset,
                              const std::string& dir, const PhotoStore& store, int threads);

}  // namespace lumislab
