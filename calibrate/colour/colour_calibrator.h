// lumislab-calibrate colour: a photo of a ColorChecker Classic 24 -> calib/colour.json, the 3x3
// matrix from the camera's linear RGB to CIE 1931 XYZ (docs/method.md, "Colour"; docs/formats.md
// §17, "colour.json").
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/checks.h"
#include "lib/photo/photo_io.h"
#include "lib/photometry/colour.h"

namespace lumislab {

struct ColourOptions {
  std::string illuminant = "D65";  // the light on the chart: "D50" or "D65"
  // A fit whose residual exceeds these (CIE 1976 Delta E*ab) is not of a ColorChecker under the
  // stated illuminant: refused (exit 2). A camera's 3x3 fit to the chart is typically 1 - 4 mean.
  double max_mean_delta_e = 8;
  double max_delta_e = 25;
  void Check() const;  // BadInput naming the option
};

// The 24 patches as found in a photo, in the chart's order (0: dark skin ... 23: black).
struct ChartPatches {
  std::vector<Eigen::Vector3d> rgb;      // mean linear RGB of each patch's central half
  std::vector<double> clipped_fraction;  // of each patch's pixels with a clipped channel
  std::vector<Eigen::Vector2d> centre_px;
};

// The reference XYZ of the 24 patches under the illuminant ("D50", "D65"): Ohta's reflectances
// x the illuminant x the CIE 1931 functions, scaled so a perfect white has Y = 1; the white.
std::vector<Eigen::Vector3d> ChartReferenceXyz(const std::string& illuminant);
Eigen::Vector3d ReferenceWhite(const std::string& illuminant);

// Least squares: the 3x3 matrix m minimising sum |m rgb_k - xyz_k|^2.
Eigen::Matrix3d FitRgbToXyz(const std::vector<Eigen::Vector3d>& rgb,
                            const std::vector<Eigen::Vector3d>& xyz);

// Finds the chart with OpenCV's mcc detector (cv::mcc::CCheckerDetector, MCC24) on an 8-bit
// rendering of the photo, then averages the photo's own linear values over the middle of each
// patch (half its side). The box's corner order is taken from the colours: of the 8 ways round,
// the one whose patches fit `reference` best. BadInput naming the photo when no chart is found.
ChartPatches FindColourChart(const Photo& photo, const std::vector<Eigen::Vector3d>& reference,
                             const Eigen::Vector3d& white);

// Least-squares 3x3 fit of the patches' RGB to their reference XYZ, its residuals, the checks
// (colour.fit: clipped patches and a residual above the options' limits fail, exit 2), and the
// calibration with `report` (per patch RGB, reference, Delta E).
ColourCalibration CalibrateColour(const ChartPatches& patches, const ColourOptions& options,
                                  const std::string& photo, nlohmann::json* report,
                                  CheckLog* checks);

// Writes calib/colour.json (schema 1) atomically.
void SaveColourCalibration(const std::string& path, const ColourCalibration& calibration,
                           const nlohmann::json& report);

}  // namespace lumislab
