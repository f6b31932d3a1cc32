// The radiometric calibration captures of the synthetic camera (docs/formats.md §10, scene
// block `calibration_captures`): dark frames, flat frames, a bracketed response series and the
// reading of a radiometer at a screen point, made through the same camera effects as the slide
// photos (only those that apply to each), with the truth they must recover.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/json.h"
#include "lib/synthetic/effects.h"

namespace lumislab {

struct SynthScene;

struct CalibrationCaptures {
  int dark_frames = 0;                   // per dark stop
  std::vector<double> dark_stops = {0};  // dark frames at camera.exposure x 2^stop
  int flat_frames = 0;
  double flat_level = 0.5;             // uniform screen irradiance, normalised value at exposure
  std::vector<double> response_stops;  // empty: no response series
  bool reference = false;              // a radiometer reading at `point_mm` for position (i, j)
  int reference_i = 0, reference_j = 0;
  Eigen::Vector2d point_mm{0, 0};  // lab, on the screen
  // "D50" or "D65": a photo of a ColorChecker Classic 24 under that illuminant
  // (lib/synthetic/spectral.h) for lumislab-calibrate colour; empty: none.
  std::string colour_chart;
};

// Parses and checks the block (unknown members refused; errors name the scene file and field).
// `scene` holds everything parsed before it (setup, camera, effects).
CalibrationCaptures ParseCalibrationCaptures(const JsonView& block, const SynthScene& scene);

// What a calibration photo is of, and so which effects apply to it.
enum class CaptureKind {
  kDark,        // lens capped: no light; the sensor's effects only (no vignetting, screen, ambient)
  kFlat,        // the screen under uniform irradiance, room lights off: every effect but ambient
  kResponse,    // the unfiltered luminaire lighting the screen: every effect
  kCameraView,  // a board in the room (camera_views.h), not the screen: all but screen_gain,
                // ambient
  kColourChart,  // a ColorChecker in the room, lit by its own lamp: as kCameraView
};
// Applies the scene's effects that act on a photo of `kind`, in list order.
void ApplyCaptureEffects(const SynthScene& scene, CaptureKind kind, const PhotoContext& context,
                         ImageF* photo);

// Photos before effects (normalised linear RGB at `exposure`): a flat frame (flat_level x
// exposure on every pixel that sees the screen), and the response scene: the luminaire without
// slide at the centre grid position, scaled so that its brightest pixel is 0.5 at exposure 1.
ImageF FlatFrameRender(const SynthScene& scene, double exposure);
ImageF ResponseSceneRender(const SynthScene& scene, double exposure);

// Truth: the per-pixel gain the slide photos carry (vignetting x screen gain; 1 channel), and
// the dark signal in normalised sensor units (channels black, current per unit exposure, hot).
ImageF TruthFlatGain(const SynthScene& scene);
ImageF TruthDarkMap(const SynthScene& scene);

// The radiometer's reading at the reference point through T+ and T- (W/m^2, RGB): the
// luminaire's irradiance as rendered (stage error included) plus the ambient light.
void ReferenceIrradiance(const SynthScene& scene, double radiometric_scale, Eigen::Vector3d* plus,
                         Eigen::Vector3d* minus);

}  // namespace lumislab
