#include "export/report_uncertainty.h"

#include <cmath>
#include <filesystem>

#include "core/basis.h"
#include "core/command_line.h"
#include "core/json.h"
#include "core/log.h"
#include "lib/synthetic/scene.h"
#include "plan/plan.h"

namespace lumislab {
namespace {

// The planner's receiver for the far field: |1 - d/D| = 1 (D >> d).
constexpr double kFarAway = 1e300;

std::string Percent(double relative) { return Num(100 * relative, 2) + " %"; }

// Relative standard error of the mean of `values` (each photo's value at the reference point per
// unit exposure); 0 with fewer than two.
double MeanSpread(const JsonView& values, double* mean_out) {
  const size_t n = values.Size();
  double sum = 0, sum2 = 0;
  for (size_t k = 0; k < n; ++k) {
    const double v = values[k]["value"].Number();
    sum += v;
    sum2 += v * v;
  }
  *mean_out = n > 0 ? sum / n : 0;
  if (n < 2 || !(sum > 0)) return 0;
  const double mean = sum / n;
  const double var = std::max(0.0, (sum2 - n * mean * mean) / (n - 1));
  return std::sqrt(var / n) / mean;
}

// The scale calibration's bracket agreement: u(Y+ - Y-) / (Y+ - Y-) from each slide's standard
// error of the mean.
void AddScaleTerm(const std::string& dataset_dir, FarFieldUncertainty* u) {
  const std::string path = dataset_dir + "/calib/scale.json";
  if (dataset_dir.empty() || !std::filesystem::is_regular_file(path)) {
    u->notes.push_back(
        "no calib/scale.json: the slab's scale is the dataset's stated one (or a synthetic "
        "truth), its uncertainty not included");
    return;
  }
  const JsonDocument doc = JsonDocument::Load(path);
  const JsonView report = doc.root()["report"];
  if (!report.Has("bracket_values_p") || !report.Has("bracket_values_n")) {
    u->notes.push_back(path + " records no bracket values: the scale's uncertainty not included");
    return;
  }
  double yp = 0, yn = 0;
  const double rp = MeanSpread(report["bracket_values_p"], &yp);
  const double rn = MeanSpread(report["bracket_values_n"], &yn);
  if (!(yp > yn)) return;
  const double relative = std::hypot(rp * yp, rn * yn) / (yp - yn);
  u->terms.push_back({"scale calibration: bracket agreement", relative,
                      "calib/scale.json: standard error of the mean of " +
                          std::to_string(report["bracket_values_p"].Size()) + " T+ and " +
                          std::to_string(report["bracket_values_n"].Size()) +
                          " T- photos' values at the reference point, through (Y+ - Y-)"});
  if (report["bracket_values_p"].Size() < 2 || report["bracket_values_n"].Size() < 2)
    u->notes.push_back("one photo per slide at the reference point: its spread is unknown");
}

}  // namespace

FarFieldUncertainty EstimateFarFieldUncertainty(const UncertaintyInput& in) {
  FarFieldUncertainty u;
  PlanInput plan;
  plan.distance_mm = in.info.distance_mm;
  plan.screen_w_mm = in.info.layout.window_w_mm;
  plan.screen_h_mm = in.info.layout.window_h_mm;
  plan.depth_mm = in.light_depth_mm;
  PlanSetting s;
  s.h_mm = in.info.grid.spacing_mm;
  s.nu = in.info.grid.nu;
  s.nv = in.info.grid.nv;
  s.k_max = std::max<int>(1, int(in.info.filter.dual_coefficients.size()) - 1);
  s.resolution = std::max(in.info.layout.res_x, in.info.layout.res_y);
  s.samples = in.far_field_samples;
  const ErrorTerms e = PredictError(plan, s, kFarAway);
  const std::string at = "plan/plan.h PredictError at h " + Num(s.h_mm, 4) + " mm, " +
                         std::to_string(s.nu) + " x " + std::to_string(s.nv) + ", K " +
                         std::to_string(s.k_max) + ", " + std::to_string(s.resolution) +
                         " texels, light " + Num(in.light_depth_mm, 4) + " mm behind S, D >> d";
  u.terms.push_back({"model: parallax (L2)", e.parallax, at, true, false});
  const double bound = ParallaxFirstOrderBound(in.light_depth_mm, plan.distance_mm, kFarAway,
                                               in.info.filter.Filter());
  u.terms.push_back({"model: parallax in one direction", bound / std::sqrt(3.0),
                     "core/basis.h ParallaxFirstOrderBound " + Percent(bound) +
                         " (2 a sum|c_m|, a = z / (d + z)) as the half-width of a rectangular "
                         "distribution",
                     false, true});
  u.terms.push_back({"model: slab fit", e.slab, at});
  u.terms.push_back({"model: quadrature", e.quadrature, at});
  u.terms.push_back({"noise floor (photos, screen calibration, lookups)", e.floor, at});
  AddScaleTerm(in.dataset_dir, &u);
  if (in.meter_relative > 0)
    u.terms.push_back({"reference meter", in.meter_relative, "--meter-uncertainty"});
  else
    u.notes.push_back("the reference meter's own calibration uncertainty: not given, not included");
  if (in.light_depth_mm == 0)
    u.notes.push_back("the light's depth behind S taken as 0 (no parallax term)");
  if (in.info.units == "relative")
    u.notes.push_back("relative units: the uncertainty is of the distribution's shape only");
  // The planner's relative L2 of the plane's irradiance stands for the flux (an integral of such
  // values: conservative) and, but for the parallax, for the peak.
  double flux2 = 0, peak2 = 0;
  for (const UncertaintyTerm& t : u.terms) {
    if (t.flux) flux2 += t.relative * t.relative;
    if (t.peak) peak2 += t.relative * t.relative;
  }
  u.flux_relative = std::sqrt(flux2);
  u.peak_relative = std::sqrt(peak2);
  return u;
}

void AddUncertaintyOptions(CLI::App* cmd, UncertaintyOptions* options) {
  cmd->add_option("--light-depth-mm", options->light_depth_mm,
                  "the light's depth behind S for the uncertainty's model terms (default: "
                  "truth/luminaire.json when there, else 0)")
      ->check(FiniteIn(0, 1e5));
  cmd->add_option("--meter-uncertainty", options->meter_uncertainty_percent,
                  "the reference meter's relative standard uncertainty (%)")
      ->check(FiniteIn(0, 100));
}

FarFieldUncertainty EstimateFarFieldUncertainty(const SlabInfo& info,
                                                const std::string& dataset_dir, int samples,
                                                const UncertaintyOptions& options) {
  UncertaintyInput in;
  in.info = info;
  in.dataset_dir = dataset_dir;
  in.far_field_samples = samples;
  in.meter_relative = options.meter_uncertainty_percent / 100;
  std::string source = "--light-depth-mm";
  in.light_depth_mm = options.light_depth_mm;
  const std::string truth = dataset_dir + "/truth/luminaire.json";
  if (in.light_depth_mm < 0) {
    in.light_depth_mm = 0;
    if (!dataset_dir.empty() && std::filesystem::is_regular_file(truth)) {
      double wz = 0, w = 0;
      for (const Emitter& e : LoadLuminaire(truth).emitters) {
        const double weight = e.intensity_w_sr.sum() / 3;
        wz += weight * -e.position_mm.z();
        w += weight;
      }
      in.light_depth_mm = w > 0 ? wz / w : 0;
      source = "truth/luminaire.json";
    }
  }
  FarFieldUncertainty u = EstimateFarFieldUncertainty(in);
  // A capture (no truth/) without the light's depth or the meter's uncertainty: the stated
  // figure leaves out known terms, which the lab must hear, not find in the small print.
  if (source != "truth/luminaire.json") {
    if (options.light_depth_mm < 0)
      u.missing.push_back(
          "the parallax terms (the light's depth behind S unknown: --light-depth-mm)");
    if (options.meter_uncertainty_percent <= 0)
      u.missing.push_back("the reference meter's uncertainty (--meter-uncertainty)");
    if (!u.missing.empty()) {
      std::string list;
      for (const std::string& m : u.missing) list += (list.empty() ? "" : "; ") + m;
      LogWarning("the stated uncertainty leaves out ", list);
    }
  }
  if (in.light_depth_mm > 0)
    u.notes.push_back("the light's depth behind S, " + Num(in.light_depth_mm, 4) + " mm, from " +
                      source);
  return u;
}

std::string UncertaintyKeyword(const FarFieldUncertainty& u) {
  std::string text = "flux +-" + Percent(u.FluxExpanded()) + ", peak intensity +-" +
                     Percent(u.PeakExpanded()) + " (expanded, k=" + Num(u.coverage_k, 2) +
                     "; terms:";
  for (const UncertaintyTerm& t : u.terms)
    text += " " + t.name +
            (t.flux && t.peak ? ""
             : t.flux         ? " (flux)"
                              : " (peak)") +
            " " + Percent(t.relative) + ",";
  text.back() = ')';
  if (!u.missing.empty()) {
    text += "; not included:";
    for (const std::string& m : u.missing) text += " " + m + ",";
    text.pop_back();
  }
  return text;
}

}  // namespace lumislab
