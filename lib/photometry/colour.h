// Colorimetry of the light (docs/method.md, "Colour"): spectra sampled 380 - 780 nm every 5 nm,
// CIE 1931 XYZ, chromaticity, correlated colour temperature and Duv, and the camera's colour
// calibration <dataset>/calib/colour.json (docs/formats.md §17, "colour.json"), which maps the
// slab's linear RGB channels to XYZ.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "lib/photometry/colour_tables.h"

namespace lumislab {

// A spectral distribution: sample k at WavelengthNm(k).
using Spectrum = Eigen::Matrix<double, kSpectralSamples, 1>;

inline double WavelengthNm(int k) { return kSpectralFirstNm + kSpectralStepNm * k; }

// The CIE 1931 2-degree colour matching functions: columns x-bar, y-bar, z-bar (y-bar = V).
const Eigen::Matrix<double, kSpectralSamples, 3>& Cmf1931();
// Planck's law: the spectral radiance of a blackbody at `kelvin` (second radiation constant
// c2 = 1.4388e-2 m K, CIE 15), relative: 1 at its largest sample.
Spectrum Blackbody(double kelvin);
// CIE standard illuminants, relative (560 nm = 100).
Spectrum IlluminantD50();
Spectrum IlluminantD65();
// "D50" or "D65": that illuminant; none for any other name.
std::optional<Spectrum> IlluminantByName(const std::string& name);
// Spectral reflectance of ColorChecker Classic patch k (0: dark skin ... 23: black), Ohta 1997.
Spectrum ColorCheckerReflectance(int k);
const char* ColorCheckerPatchName(int k);

// XYZ = sum of s x (x-bar, y-bar, z-bar) x 5 nm: the units of s times nm.
Eigen::Vector3d SpectrumToXyz(const Spectrum& s);
// Luminous efficacy of radiation of s, lm/W: 683 x sum(V s) / sum(s) over 380 - 780 nm.
double LuminousEfficacy(const Spectrum& s);

// Chromaticity (x, y) = (X, Y) / (X + Y + Z); NaN when X + Y + Z <= 0.
Eigen::Vector2d XyzToXy(const Eigen::Vector3d& xyz);
// CIE 1960 (u, v) of (x, y).
Eigen::Vector2d XyToUv1960(const Eigen::Vector2d& xy);
// Chromaticity of the blackbody at `kelvin` (computed from Blackbody and Cmf1931).
Eigen::Vector2d PlanckianXy(double kelvin);

// CCT is defined only near the Planckian locus: CIE 15:2018 §9.5 and ANSI C78.377 use it within
// |Duv| <= 0.05 of the locus; farther away no temperature "correlates" and `kelvin` is NaN.
constexpr double kCctMaxAbsDuv = 0.05;

struct Cct {
  // Correlated colour temperature; NaN outside [1000, 25000] K or for |duv| > kCctMaxAbsDuv.
  double kelvin = 0;
  double duv = 0;  // signed distance to the Planckian locus in CIE 1960 (u, v), + above it; kept
                   // (finite) for any finite xy, also where kelvin is NaN
};
// The CCT of (x, y) by its definition (CIE 15): the temperature of the Planckian point nearest in
// CIE 1960 (u, v), found on a 1-mired table of the locus and refined by golden-section search.
// Exact to well below 1 K against PlanckianXy (the locus computed from the 5 nm tables). Off the
// locus by more than kCctMaxAbsDuv: kelvin NaN, duv the distance (say "no CCT (Duv ...)").
Cct CctFromXy(const Eigen::Vector2d& xy);

// CIE 1976 L*a*b* of xyz against the white `white_xyz` (same units), and Delta E*ab.
Eigen::Vector3d XyzToLab(const Eigen::Vector3d& xyz, const Eigen::Vector3d& white_xyz);
double DeltaE76(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2);

constexpr int kColourSchemaVersion = 1;

// calib/colour.json: the camera's linear RGB -> CIE 1931 XYZ, fitted to a colour chart.
struct ColourCalibration {
  std::string file;  // where it was read from (empty when built in memory)
  // Rows X, Y, Z from the linear RGB channels (the slab's, or a photo's values per unit
  // exposure). Its scale is the chart photo's: chromaticity and CCT do not depend on it; luminance
  // in cd/m^2 needs the lux calibration (calib/scale.json).
  Eigen::Matrix3d rgb_to_xyz = Eigen::Matrix3d::Identity();
  std::string chart;        // "ColorChecker Classic 24"
  std::string illuminant;   // the light the chart was photographed under: "D50", "D65"
  std::string photo;        // the chart photo's path as given
  double mean_delta_e = 0;  // fit residual over the patches, CIE 1976 Delta E*ab
  double max_delta_e = 0;

  // The Y row scaled to sum 1: the luminance weights of the channels.
  Eigen::Vector3d LuminanceWeights() const;
  Eigen::Vector3d Xyz(const Eigen::Vector3d& rgb) const { return rgb_to_xyz * rgb; }

  // Validates the file: "file: field: expected X, got Y" (exit 2).
  static ColourCalibration Load(const std::string& path);
  // <dataset_dir>/calib/colour.json when it exists (it is optional), else none.
  static std::optional<ColourCalibration> LoadFor(const std::string& dataset_dir);
};

// The colour of some light in linear camera RGB, through a calibration.
struct LightColour {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  Cct cct;
};
LightColour ColourOfRgb(const ColourCalibration& calibration, const Eigen::Vector3d& rgb);

}  // namespace lumislab
