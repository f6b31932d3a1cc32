// The radiometric calibration captures of `acquire synth` (scene block calibration_captures,
// docs/formats.md §10): dark, flat and response frames under calibration/ with their manifest
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

// truth/reference.json: the meter's readings at the reference point through T+ and T-, for
// `lumislab-calibrate scale --reference`. A radiometer (W/m2) where the scene's
// calibration_captures ask for a reading; a lux meter (`meter` "lux": lux = K x W/m2, K =
// SynthScene::LuminousEfficacy()) always, at the scene's reference point or else at the screen's
// centre (lab (0, 0)) for the grid position of the largest signal there (T+ minus T-).
void WriteReferenceReading(const SynthScene& scene, const Dataset& dataset, const std::string& dir,
                           const std::string& meter);

// `acquire synth --calibration-views N`: N photos of a free-standing board
// (lib/synthetic/camera_views.h) in calibration/camera/view_<kk>.<ext>, stored like the slide
// photos (every effect but screen_gain and ambient; noise streams after the slide photos' and
// the calibration captures'), and their poses in truth/camera_views.json.
std::string CameraViewFile(const SynthScene& scene, const PhotoStore& store, int k);
void WriteCameraViews(const SynthScene& scene, const Dataset& dataset, const std::string& dir,
                      const PhotoStore& store, int count, int threads);
// True when `dir` holds the N views and truth/camera_views.json (true for N = 0).
bool CameraViewsComplete(const SynthScene& scene, const PhotoStore& store, const std::string& dir,
                         int count);

}  // namespace lumislab
