// The registration of a luminaire's orientations (docs/method.md §4.12, "Registration"): the
// rotations of every orientation but the first (the gauge) refined so that the directions two
// orientations both see have the same intensity in both far fields, with Ceres; their
// uncertainty; and how well each overlapping pair agrees after the fit.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "calibrate/orientations/far_field_grid.h"
#include "core/luminaire_set.h"

namespace lumislab {

// A pair whose relative RMS disagreement over its overlap stays above this after the fit is
// refused (docs/method.md §4.12, "Registration", derives it: three times the RMS difference of
// two slabs each within the single-slab far-field error).
constexpr double kMaxOverlapRelativeRms = 0.10;

struct RegistrationOptions {
  int directions = 40000;     // luminaire-frame directions sampled (Fibonacci sphere)
  double margin_deg = 3;      // a sample must lie this far inside both cones
  double nodes_per_tan = 30;  // far-field grid density (nodes per unit of x/z)
  double loss_scale = 0.05;   // Huber scale of the relative residuals
  double max_relative_rms = kMaxOverlapRelativeRms;
  // Fit the gain profile g(theta) shared by every orientation (overlap_cost.h) with the
  // rotations, where at least three pairs are compared; false, or fewer pairs, holds g = 1.
  // Off by default: the slabs' far-field error that limits the registration is not shared
  // (docs/method.md §4.12, "Registration", and docs/results.md §13 measure it).
  bool fit_gain_profile = false;
  int max_iterations = 100;
  int threads = 1;
  void Check() const;  // BadInput naming the field
};

// One orientation's input: its nominal pose, cone and far field.
struct RegistrationInput {
  std::string name;
  Eigen::Matrix3d nominal = Eigen::Matrix3d::Identity();  // capture_from_luminaire
  OrientationCone cone;
  FarFieldGrid far_field;
};

struct RegisteredOrientation {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();     // refined capture_from_luminaire
  Eigen::Vector3d correction_deg = Eigen::Vector3d::Zero();   // rotation vector, capture frame
  double angle_deg = 0;                                       // |correction|
  Eigen::Vector3d sigma_deg = Eigen::Vector3d::Zero();        // 1 sigma per component
  std::array<bool, 3> unconstrained = {false, false, false};  // components the overlaps leave free
  // The luminaire-frame axes about which the overlaps do not fix the orientation (unit vectors).
  std::vector<Eigen::Vector3d> free_axes;
  bool gauge = false;  // the first: held at its nominal pose
};

struct RegisteredPair {
  int a = 0, b = 0;
  double overlap_sr = 0;  // AnalyseCoverage's, at the nominal poses
  int samples = 0;        // directions compared after the fit
  double rms_before = 0;  // relative RMS of I_a - I_b over the pair's mean intensity, nominal
  double rms_after = 0;   // the same at the refined poses, each I divided by the gain profile
  double ratio = 0;       // sum I_a / sum I_b over the samples, refined poses and gain profile
                          // (checked, not fitted)
};

struct Registration {
  std::vector<RegisteredOrientation> orientations;
  std::vector<RegisteredPair> pairs;
  // The gain profile g(theta) = 1 + p_1 (1 - cos theta) + p_2 (1 - cos theta)^2 fitted with the
  // rotations (overlap_cost.h; zeros when not fitted), its 1 sigma, and the largest angle theta
  // from a capture axis among the samples compared (the profile is known up to there).
  bool gain_profile_fitted = false;
  std::array<double, 2> gain_profile = {0.0, 0.0};
  std::array<double, 2> gain_profile_sigma = {0.0, 0.0};
  double gain_profile_theta_max_deg = 0;
  double Gain(double theta_deg) const;  // g(theta)
  double residual_sigma = 0;            // the relative residuals' standard deviation after the fit
  int residuals = 0;
  int iterations = 0;
  bool converged = false;
  // "" or why the set is refused: the pairs whose overlap disagrees beyond the threshold, with
  // their numbers.
  std::string disagreement;
};

// Registers the orientations (at least two; the first is the gauge). `coverage` is
// AnalyseCoverage's report for the nominal poses (its pairs of overlap >= kMinOverlapSr are
// the pairs compared).
Registration RegisterOrientations(const std::vector<RegistrationInput>& inputs,
                                  const CoverageReport& coverage,
                                  const RegistrationOptions& options);

}  // namespace lumislab
