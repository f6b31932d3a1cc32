// lumislab-plan: the lab's question before a capture (docs/method.md §4.8). From the luminaire's
// size and depth, d, the screen and a target accuracy at a receiver distance D it recommends the
// grid (h, nu x nv), K and the slab resolution, with the predicted error per term and the lab
// time of lumislab-study's lab model. The error model is stated and calibrated in docs/method.md
// §4.8 against the study's measurements (docs/study/).
#pragma once

#include <string>
#include <vector>

#include "core/lab_model.h"

namespace lumislab {

struct SynthScene;

// Where the light leaves the luminaire: |x| <= ax, |y| <= ay at depth z behind S (mm, z > 0).
struct LightPoint {
  double ax = 0, ay = 0, z = 0;
};

struct PlanInput {
  std::vector<LightPoint> light;  // coverage: the grid must cover the rays from every point
  double depth_mm = 0;            // the light's (intensity-weighted) depth: the error terms
  double distance_mm = 750;       // d
  double screen_w_mm = 1200, screen_h_mm = 1200;
  double receiver_mm = 0;             // D (0: d)
  double roi_w_mm = 0, roi_h_mm = 0;  // region of interest on the plane z = D (0: window x D/d)
  double target = 0.01;               // relative L2 of the receiver-plane irradiance at D
  int k_max = 1;
  int samples = 1;           // N of the reference render (docs/method.md §4.5)
  double h_max_mm = 10;      // largest h considered (the study's measured range)
  int resolution_min = 48;   // smallest slab resolution considered (see docs/method.md §4.8)
  int resolution_max = 512;  // largest slab resolution considered
  LabModel lab;  // the lab time of a setting (core/lab_model.h, shared with lumislab-study)

  double D() const { return receiver_mm > 0 ? receiver_mm : distance_mm; }
};

// d, the screen, K and the light of a synthetic scene: every emitter for coverage, the
// intensity-weighted mean depth for the error terms (docs/method.md §4.8).
PlanInput PlanInputFromScene(const SynthScene& scene);

struct PlanSetting {
  double h_mm = 0;
  int nu = 0, nv = 0, k_max = 1, resolution = 0, samples = 1;
  int positions() const { return nu * nv; }
};

// Predicted relative L2 of the receiver-plane irradiance at one distance, per term, for a grid
// that covers (coverage is a condition, not a term: SettingCovers, RequiredPositions).
struct ErrorTerms {
  double parallax = 0;    // exact model's first-order parallax at D != d (independent of h)
  double slab = 0;        // the bell fit's own error, (a / footprint)^2
  double quadrature = 0;  // N samples per support at D != d, (h / d)^2
  double floor = 0;       // photos, screen calibration, bilinear lookups (measured)
  double total = 0;       // root sum of squares
};

// Half-extents on S (mm) the duals must sum to 1 over: where rays from the light to the screen's
// edges (D = d) and to the region of interest at D cross S.
struct Coverage {
  double u_mm = 0, v_mm = 0;
};
Coverage RequiredCoverage(const PlanInput& in);
// The largest region of interest (full width, height; mm) on the plane z = D whose rays from the
// light all meet M inside the window less the spread |1 - d/D| (K + 2) h of the supports the
// reconstruction draws from (GridCovers' window condition): light beyond it is lost whatever
// the grid. At D = d it is the window itself.
Coverage ScreenHoldsRoi(const PlanInput& in, const PlanSetting& s);
// Fewest positions per axis with ((n - 1)/2 - K) h >= half_extent (GridCovers' condition).
int RequiredPositions(double half_extent_mm, double h_mm, int k_max);
// True when the setting's grid covers `RequiredCoverage`.
bool SettingCovers(const PlanInput& in, const PlanSetting& s);

ErrorTerms PredictError(const PlanInput& in, const PlanSetting& s, double receiver_mm);

struct Plan {
  PlanSetting setting;
  Coverage coverage;
  bool covers = true;
  Coverage roi_max;  // ScreenHoldsRoi
  ErrorTerms at_d, at_D;
  double lab_s = 0;
  bool reachable = true;              // the prediction at D meets the target
  std::vector<std::string> warnings;  // printed on stderr, listed in the JSON
};

// The cheapest (fewest positions, then coarsest slab) covering setting whose predicted error at D
// meets the target; when none does, reachable = false with a warning and the cheapest setting
// within 5 % of the least predicted error.
Plan MakePlan(const PlanInput& in);
// The prediction for a given setting (evaluate mode: --h, --nu, --nv, --resolution).
Plan EvaluatePlan(const PlanInput& in, const PlanSetting& s);

std::string PlanTable(const PlanInput& in, const Plan& plan);
std::string PlanJson(const PlanInput& in, const Plan& plan);

}  // namespace lumislab
