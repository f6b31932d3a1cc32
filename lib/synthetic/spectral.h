// The synthetic camera's colour (docs/testing.md, "Colour"): spectral sensitivities, the light of
// an emitter with a spectrum, and a photo of a ColorChecker Classic 24 under a CIE illuminant,
// so the colour calibration and the chromaticity / CCT of the light have a known truth.
#pragma once

#include <Eigen/Core>
#include <string>

#include "core/image.h"
#include "lib/photometry/colour.h"

namespace lumislab {

// The synthetic camera's spectral sensitivities, columns R, G, B. A model, not a real camera's
// data: each channel a sum of Gaussians placed like a CMOS sensor's behind a Bayer filter and an
// IR-cut filter (R: 600 nm with a secondary lobe at 450 nm, G: 535 nm, B: 460 nm). They are not a
// linear combination of the CIE colour matching functions, so a 3x3 RGB -> XYZ matrix fits them
// only approximately, as it does a real camera. Each column is scaled so that an equal-energy
// spectrum of mean 1 gives 1 in every channel.
const Eigen::Matrix<double, kSpectralSamples, 3>& SyntheticSensitivities();

// The camera's RGB of spectrum s: sum over samples of s x sensitivity / sum of the sensitivity
// (a flat spectrum of value v gives v in every channel).
Eigen::Vector3d CameraRgb(const Spectrum& s);

// An emitter's "cct_k" (scene file): its RGB intensity per W/sr of radiant intensity (380 - 780
// nm) for a blackbody at `kelvin`, i.e. CameraRgb of the spectrum scaled to mean 1.
Eigen::Vector3d BlackbodyRgbPerWatt(double kelvin);

// A synthetic photo of a ColorChecker Classic 24 (docs/testing.md): the chart (the detector's
// model geometry, cv::mcc's classic chart: 16.75 x 11.25 units, patches 2.5 units at a pitch of
// 2.75, a black frame of reflectance 0.03) on a grey card (0.18), lit uniformly by `illuminant`
// ("D50" or "D65"), seen slightly in perspective. Values: CameraRgb of reflectance x illuminant
// (illuminant scaled to mean 1) x `exposure`, normalised linear (3 channels, RGB).
struct ColourChartPhotoSpec {
  int width = 800, height = 600;  // px
  std::string illuminant = "D65";
  double exposure = 0.8;        // the white patch (~0.9 reflectance) comes out ~0.7
  double chart_fraction = 0.7;  // chart width / photo width
  double rotation_deg = 3;      // in the image plane
  double noise = 0.002;         // Gaussian, relative to the value, deterministic seed
};
ImageF RenderColourChartPhoto(const ColourChartPhotoSpec& spec);

}  // namespace lumislab
