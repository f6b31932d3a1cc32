// lumislab-acquire synth: the synthetic capture of a scene into a dataset folder (docs/formats.md,
// docs/testing.md).
#pragma once

#include <string>

#include "core/image.h"
#include "lib/synthetic/render.h"
#include "lib/synthetic/scene.h"

namespace lumislab {

constexpr int kMaxCalibrationViews = 100;

struct SynthOptions {
  std::string scene = "default";  // scene file or "default"
  std::string out_dir;
  double interval_s = -1;  // >= 0: live acquisition, positions one by one with this pause
  bool force = false;      // redo a complete dataset
  int threads = 0;         // 0: all cores
  int truth_resolution = 300;
  // Photos of a scene without a quantization effect (which makes them 16-bit PNG): "half"
  // (half-float EXR, RLE: lossless for half, ~1 MB a photo) or "float" (32-bit float EXR).
  std::string photo_format = "half";
  bool compress_float = false;  // "float" photos PIZ-compressed (smaller, slower)
  // The capture as a camera leaves it (acquire/photo_store.h): camera/IMG_0001.<EXT> ... with
  // EXIF, camera/BOARD.PNG, setup.json and truth/, no dataset.json (`acquire import` makes it).
  bool camera_folder = false;
  // Photos of a free-standing board for lumislab-calibrate camera (calibration/camera/).
  int calibration_views = 0;
  // The meter of truth/reference.json: "radiometer" (W/m2, written for a scene whose
  // calibration_captures ask for a reference reading) or "lux" (a lux meter, lux = K x W/m2 with
  // K = SynthScene::LuminousEfficacy(), always written; truth/ then holds lux too), so that
  // `lumislab-calibrate scale --reference <out>/truth/reference.json` gives a photometric slab.
  std::string meter = "radiometer";

  void Check() const;  // BadInput naming the option
};

struct SynthReport {
  bool skipped = false;  // the folder already held a complete dataset
  double radiometric_scale = 0;
  int photos_written = 0;
};

// Runs the whole capture; callable from tests without a process.
SynthReport RunSynth(const SynthOptions& options);
SynthReport RunSynth(const SynthScene& scene, const SynthOptions& options);

// Radiometric scale (W/m^2 per unit value at exposure 1) that puts the brightest pixel of all
// photos at about 0.85, or the scene camera's explicit one.
double ChooseRadiometricScale(const SynthScene& scene, int threads);

// Applies the scene's effects, in list order, to the photo of `context` (photo_index as in
// PhotoIndex, the photo's exposure).
void ApplyEffects(const SynthScene& scene, const PhotoContext& context, ImageF* photo);
// The photo of a slide at stop `stop_index` of the scene's bracket (0 without brackets) before
// the effects: `render` (at camera.exposure) times 2^stop; the render itself without brackets.
ImageF ExposedPhoto(const SynthScene& scene, const ImageF& render, int stop_index);
// The finished photo of one slide as stored: render, exposure, effects. Exposed for tests.
ImageF SynthPhoto(const SynthScene& scene, const ScreenView& view, double scale, int i, int j,
                  bool positive, int stop_index = 0);

// True when `dir` holds a dataset.json whose photos, calibration photo and truth all exist.
bool DatasetComplete(const std::string& dir);

}  // namespace lumislab
