// The stated uncertainty of a slab's far-field flux and peak intensity (docs/method.md §4.11):
// relative standard uncertainties from the terms that are known, combined in quadrature and
// expanded with k = 2. The report prints it; the IES/LDT writers put it in the `[_UNCERTAINTY]`
// keyword (UncertaintyKeyword).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "core/slab.h"

namespace lumislab {

struct UncertaintyTerm {
  std::string name;     // "planner: slab fit", "scale calibration: bracket agreement", ...
  double relative = 0;  // relative standard uncertainty (1 sigma)
  std::string basis;    // where the number comes from
  bool flux = true;     // enters the flux's uncertainty
  bool peak = true;     // enters the peak intensity's
};

struct FarFieldUncertainty {
  std::vector<UncertaintyTerm> terms;
  double flux_relative = 0;        // combined relative standard uncertainty of the total flux
  double peak_relative = 0;        // of the peak intensity
  double coverage_k = 2;           // the coverage factor of the expanded uncertainty
  std::vector<std::string> notes;  // what is not included, and why
  // Known terms left out because the lab did not give them (a capture without
  // --light-depth-mm or --meter-uncertainty): the keyword says so, the commands warn.
  std::vector<std::string> missing;
  double FluxExpanded() const { return coverage_k * flux_relative; }
  double PeakExpanded() const { return coverage_k * peak_relative; }
};

struct UncertaintyInput {
  SlabInfo info;
  std::string dataset_dir;    // "" when the slab is not in a dataset (no calib/scale.json)
  double light_depth_mm = 0;  // the light's depth behind S (the planner's z); 0: at S
  int far_field_samples = 4;  // N x N quadrature per position (FarFieldOptions::samples)
  double meter_relative = 0;  // the reference meter's own relative standard uncertainty (0: none)
};

// The terms: the planner's model error (plan/plan.h PredictError) at the slab's h, grid, K and
// resolution for a receiver far away (|1 - d/D| -> 1), its parallax, slab-fit, quadrature and
// floor (photos, screen calibration, lookups: the noise floor) terms, its parallax (a relative
// L2) for the flux only: the peak is one direction, which can be off by up to the first-order
// parallax bound (core/basis.h ParallaxFirstOrderBound), taken as a rectangular distribution of
// that half-width (u = bound / sqrt 3); the scale calibration's
// bracket agreement from <dataset>/calib/scale.json (the spread of the photos' values at the
// reference point, standard error of each slide's mean, propagated through (Y+ - Y-)); the
// meter's own uncertainty when given.
FarFieldUncertainty EstimateFarFieldUncertainty(const UncertaintyInput& in);

// What a lab gives for the uncertainty (report, ies, ldt: AddUncertaintyOptions).
struct UncertaintyOptions {
  double light_depth_mm = -1;  // -1: from truth/luminaire.json when there, else 0
  double meter_uncertainty_percent = 0;
};
void AddUncertaintyOptions(CLI::App* cmd, UncertaintyOptions* options);

// EstimateFarFieldUncertainty for a slab of `dataset_dir` ("" when in none) whose far field is
// computed with `samples` x `samples` points: the light's depth from the options, else the
// intensity-weighted depth of a synthetic dataset's truth/luminaire.json (as plan/plan.cc's
// PlanInputFromScene takes it), else 0; a note says which.
FarFieldUncertainty EstimateFarFieldUncertainty(const SlabInfo& info,
                                                const std::string& dataset_dir, int samples,
                                                const UncertaintyOptions& options);

// The `[_UNCERTAINTY]` keyword's text: "flux +-U % (k=2), peak intensity +-U % (k=2); <terms>".
std::string UncertaintyKeyword(const FarFieldUncertainty& u);

}  // namespace lumislab
