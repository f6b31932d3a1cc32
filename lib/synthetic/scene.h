// The synthetic scene: setup, luminaire, camera, calibration target and effects (docs/testing.md).
// Read from a JSON scene file (validated through core/json.h) or the built-in "default".
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "core/grid.h"
#include "lib/synthetic/calibration_captures.h"
#include "lib/synthetic/camera.h"
#include "lib/synthetic/effects.h"
#include "lib/synthetic/luminaire.h"

namespace lumislab {

constexpr int kSceneSchemaVersion = 1;

// The luminous efficacy of a scene without spectra: that of an equal-energy spectrum over 380 -
// 780 nm (lm/W, ~180), the light the synthetic camera's channels count in W (a flat spectrum of
// 1 W gives 1 W in every channel, lib/synthetic/spectral.h).
double DefaultLuminousEfficacy();

struct SynthScene {
  std::string source;      // scene file name, or "default"
  double distance_mm = 0;  // d, luminaire frame
  SamplingGrid grid;
  double screen_w_mm = 0;  // physical screen, lab frame, centred on the optical axis
  double screen_h_mm = 0;
  int k_max = 1;  // filter truncation (docs/method.md §2)
  Luminaire luminaire;
  CameraSpec camera;
  CalibrationTarget calibration;                       // photo = photos/calib_0.png
  std::vector<std::shared_ptr<const Effect>> effects;  // in the order listed
  // The radiometric calibration captures to write (scene block calibration_captures); none
  // when the block is absent.
  std::optional<CalibrationCaptures> captures;

  DualFilter Filter() const { return DualFilter::Truncated(k_max); }
  // Luminous efficacy of radiation of the luminaire's light, lm/W: the truth lux meter reads
  // lux = K x W/m^2 and the truth in lm = K x W. With a spectrum on every point emitter (cct_k)
  // and no ray source: 683 x sum(V S) / sum(S) of the emitters' spectra S weighted by their
  // radiant flux. Otherwise DefaultLuminousEfficacy().
  double LuminousEfficacy() const;
  bool Quantized() const;  // photos are 16-bit PNG (else float EXR, or JPEG with a response)
  // The listed effect of that type, or null (each is listed at most once).
  const BracketsEffect* Brackets() const;
  const ResponseEffect* Response() const;
  const DarkEffect* Dark() const;
  const RawEffect* Raw() const;
  // "dng" (raw), "jpg" (response), "png" (quantization) or "exr"
  std::string PhotoExtension() const;
  // The stops of each slide's exposure series: those of `brackets`, else {0}.
  std::vector<double> Stops() const;
  // Sum of the listed effects' stage offsets at position (i, j) (mm, lab frame; 0 without
  // stage_error).
  Eigen::Vector2d StageOffsetMm(int i, int j) const;
};

// "default", "full-sphere" (a luminaire lighting every direction, for luminaire folders,
// docs/formats.md §19) or a scene file; errors name the file and the field (exit 2).
SynthScene LoadScene(const std::string& path_or_default);
SynthScene ParseScene(const std::string& json_text, const std::string& name);
SynthScene ParseScene(const JsonDocument& doc, const std::string& name);
SynthScene DefaultScene();
std::string DefaultSceneJson();     // the built-in scene as a scene file
std::string FullSphereSceneJson();  // the built-in "full-sphere" scene as a scene file
// The luminaire of `source`: "default" or "full-sphere" (a built-in scene's), a synthetic dataset
// folder (its truth/luminaire.json), or a JSON file with a scene file's "luminaire" block and
// schema_version 1 (a scene file or truth/luminaire.json). Errors name the file and the field (exit
// 2).
Luminaire LoadLuminaire(const std::string& source);

// dataset.json without photos or radiometric scale: setup, filter, calibration, synthetic.
Dataset DatasetSkeleton(const SynthScene& scene);
// The full photo list (for every position j-major, i, then slides p, n, then the stops of a
// bracket); photo k of the list is the k passed to the effects. A bracket's photos carry the
// exposure camera.exposure x 2^stop and the stop's tag in their file name.
std::vector<PhotoEntry> PhotoList(const SynthScene& scene);
int PhotoIndex(const SynthScene& scene, int i, int j, bool positive, int stop_index = 0);

}  // namespace lumislab
