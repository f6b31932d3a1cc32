#include "plan/plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/basis.h"
#include "core/error.h"
#include "core/geometry.h"
#include "lib/synthetic/scene.h"

namespace lumislab {

namespace {

// The model's constants (docs/method.md §4.8), each fitted to one measurement of the study
// (docs/study/default-quick) and checked against the others (tests/plan/plan_test.cc).
// Share of the first-order parallax bound 2 a sum|c_m| (docs/method.md §4.5) seen as relative L2 on
// the plane: 0.623 % at 2d on the default scene, whose bound is 4.46 %.
constexpr double kParallaxShare = 0.14;
// Receiver-plane error of the bell fit, kSlab (a / l)^2, a the texel, l = h (d + z) / z a
// position's bell footprint on M: 0.12 % at 48 texels, h = 5 mm, z = 20 mm (0.32 %, 0.026 % at 24
// and 96 texels).
constexpr double kSlab = 0.055;
// N-sample quadrature of the supports at D != d: 1.2e-4 at 2d for h = 5 mm, d = 750 mm, N = 1
// (docs/method.md §4.5), taken as kQuadrature (h / d)^2 |1 - d / D| / N.
constexpr double kQuadrature = 5.4;
// What the knobs above do not reach: photos, the screen calibration from the board photo,
// bilinear lookups (covered error at d 0.03 - 0.12 % whatever the photo size).
constexpr double kFloor = 7e-4;

// The largest h the model was checked at (the study's 10 mm points, the planner's own measured
// recommendation). Beyond it the error at d grows with h by a mechanism the model lacks
// (measured: 0.13 %, 0.32 %, 0.40 % at d for covering grids at h = 10, 20, 40 mm).
constexpr double kCalibratedHMax = 10;

// Candidate spacings and slab resolutions the recommendation searches.
const double kSpacings[] = {0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6, 7.5, 10, 12.5, 15, 20, 25, 30, 40, 50};
const int kResolutions[] = {16, 24, 32, 48, 64, 96, 128, 150, 192, 256, 384, 512, 768, 1000};

double SumAbsDual(int k_max) { return DualFilter::Truncated(k_max).SumAbs(); }

// Largest |u| where a ray from the light to |x| <= X on the plane z = D crosses S:
// u = e D / (D + z) + x z / (D + z), per point and axis.
double CrossingHalfExtent(const std::vector<LightPoint>& light, bool x_axis, double D, double X) {
  double u = 0;
  for (const LightPoint& p : light) {
    const double e = x_axis ? p.ax : p.ay;
    u = std::max(u, (e * D + X * p.z) / (D + p.z));
  }
  return u;
}

std::string Percent(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, x < 0.001 ? "%.3f %%" : "%.2f %%", 100 * x);
  return buf;
}

std::string Minutes(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  return buf;
}

}  // namespace

Coverage RequiredCoverage(const PlanInput& in) {
  const double d = in.distance_mm, D = in.D();
  const double roi_w = in.roi_w_mm > 0 ? in.roi_w_mm : in.screen_w_mm * D / d;
  const double roi_h = in.roi_h_mm > 0 ? in.roi_h_mm : in.screen_h_mm * D / d;
  Coverage c;
  c.u_mm = std::max(CrossingHalfExtent(in.light, true, d, in.screen_w_mm / 2),
                    CrossingHalfExtent(in.light, true, D, roi_w / 2));
  c.v_mm = std::max(CrossingHalfExtent(in.light, false, d, in.screen_h_mm / 2),
                    CrossingHalfExtent(in.light, false, D, roi_h / 2));
  return c;
}

Coverage ScreenHoldsRoi(const PlanInput& in, const PlanSetting& s) {
  const double d = in.distance_mm, D = in.D();
  const double spread = std::abs(1 - d / D) * (s.k_max + 2) * s.h_mm;
  // A ray from e (depth z) to x on z = D meets M at e (D - d)/(D + z) + x (d + z)/(D + z).
  auto limit = [&](bool x_axis, double half_window) {
    double X = 1e300;
    for (const LightPoint& p : in.light) {
      const double e = x_axis ? p.ax : p.ay;
      X = std::min(X, ((half_window - spread) * (D + p.z) - e * std::abs(D - d)) / (d + p.z));
    }
    return std::max(0.0, 2 * X);
  };
  return {limit(true, in.screen_w_mm / 2), limit(false, in.screen_h_mm / 2)};
}

int RequiredPositions(double half_extent_mm, double h_mm, int k_max) {
  // ((n - 1)/2 - K) h >= u  <=>  n >= 2 (u / h + K) + 1; at least 2K + 1 (one covered point).
  const double n = 2 * (half_extent_mm / h_mm + k_max) + 1;
  return std::max(2 * k_max + 1, int(std::ceil(n - 1e-9)));
}

bool SettingCovers(const PlanInput& in, const PlanSetting& s) {
  const Coverage c = RequiredCoverage(in);
  return ((s.nu - 1) / 2.0 - s.k_max) * s.h_mm >= c.u_mm - 1e-9 &&
         ((s.nv - 1) / 2.0 - s.k_max) * s.h_mm >= c.v_mm - 1e-9;
}

ErrorTerms PredictError(const PlanInput& in, const PlanSetting& s, double D) {
  const double d = in.distance_mm, z = in.depth_mm;
  const double away = std::abs(1 - d / D);  // 0 at D = d: the exact model is exact there
  ErrorTerms e;
  e.parallax = kParallaxShare * 2 * (z / (d + z)) * away * SumAbsDual(s.k_max);
  const double texel = std::max(in.screen_w_mm, in.screen_h_mm) / s.resolution;
  const double footprint = s.h_mm * (d + z) / z;
  e.slab = kSlab * (texel / footprint) * (texel / footprint);
  e.quadrature = kQuadrature * (s.h_mm / d) * (s.h_mm / d) * away / s.samples;
  e.floor = kFloor;
  e.total = std::sqrt(e.parallax * e.parallax + e.slab * e.slab + e.quadrature * e.quadrature +
                      e.floor * e.floor);
  return e;
}

PlanInput PlanInputFromScene(const SynthScene& scene) {
  PlanInput in;
  in.distance_mm = scene.distance_mm;
  in.screen_w_mm = scene.screen_w_mm;
  in.screen_h_mm = scene.screen_h_mm;
  in.k_max = scene.k_max;
  // Coverage from every emitter; the error terms from the intensity-weighted depth (docs/method.md
  // §4.8).
  double wz = 0, w = 0;
  for (const Emitter& e : scene.luminaire.emitters) {
    const double z = -e.position_mm.z();
    in.light.push_back({std::abs(e.position_mm.x()), std::abs(e.position_mm.y()), z});
    const double weight = e.intensity_w_sr.sum() / 3;
    wz += weight * z;
    w += weight;
  }
  // A ray source (TM-25 file): the box of its rays' origins at their deepest, and its weight at
  // their flux-weighted depth; the weight flux / pi, a Lambertian source's axial intensity, to
  // compare with the point emitters' I0.
  for (const RaySource& r : scene.luminaire.ray_sources) {
    LightPoint box;
    double flux_z = 0;
    for (const SourceRay& ray : *r.rays) {
      box.ax = std::max(box.ax, std::abs(ray.origin_mm.x()));
      box.ay = std::max(box.ay, std::abs(ray.origin_mm.y()));
      box.z = std::max(box.z, -ray.origin_mm.z());
      flux_z += ray.flux * -ray.origin_mm.z();
    }
    in.light.push_back(box);
    const double weight = r.flux * r.rgb.sum() / 3 / kPi;
    wz += weight * flux_z / r.flux;
    w += weight;
  }
  in.depth_mm = w > 0 ? wz / w : in.light.front().z;
  return in;
}

Plan EvaluatePlan(const PlanInput& in, const PlanSetting& s) {
  Plan p;
  p.setting = s;
  p.coverage = RequiredCoverage(in);
  p.covers = SettingCovers(in, s);
  p.at_d = PredictError(in, s, in.distance_mm);
  p.at_D = PredictError(in, s, in.D());
  p.lab_s = in.lab.Seconds(s.positions());
  p.roi_max = ScreenHoldsRoi(in, s);
  p.reachable = p.at_D.total <= in.target;
  if ((in.roi_w_mm > 0 && in.roi_w_mm > p.roi_max.u_mm + 1e-9) ||
      (in.roi_h_mm > 0 && in.roi_h_mm > p.roi_max.v_mm + 1e-9)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.0f x %.0f mm", p.roi_max.u_mm, p.roi_max.v_mm);
    p.warnings.push_back(std::string("--roi-mm reaches beyond what the screen holds at D (") + buf +
                         "): rays from its edges meet the screen outside the window, light no "
                         "grid can capture; use a larger screen or a smaller region");
  }
  if (s.h_mm > kCalibratedHMax + 1e-12) {
    p.warnings.push_back(
        "h above " + std::to_string(int(kCalibratedHMax)) +
        " mm is outside the model's calibrated range: the study measured more error than it "
        "predicts there (h = 20 mm, 5 x 5, default scene: 0.32 % at d, 0.88 % at 2d; "
        "docs/method.md §4.8)");
  }
  // Receivers near S (D -> 0): the parallax error is first order in a = z/(d + z) |1 - d/D|,
  // bounded by 2 a sum|c_m| (docs/method.md §4.5) for the deepest light. Once that reaches 1 the
  // expansion the model rests on does not converge (measured on the default scene: 0.05 d, 2 a
  // sum|c_m| = 1.7; docs/testing.md §2): no prediction holds, whatever the grid.
  double z_max = 0;
  for (const LightPoint& l : in.light) z_max = std::max(z_max, l.z);
  const double first_order =
      ParallaxFirstOrderBound(z_max, in.distance_mm, in.D(), DualFilter::Truncated(s.k_max));
  if (first_order >= 1) {
    p.reachable = false;
    char buf[240];
    std::snprintf(buf, sizeof buf,
                  "the receiver plane at D = %.4g mm is too close to S for the method: the "
                  "first-order parallax bound 2 a sum|c_m| is %.2f (>= 1) for light %.4g mm "
                  "behind S, so no error prediction holds there (docs/testing.md §2)",
                  in.D(), first_order, z_max);
    p.warnings.push_back(buf);
  }
  if (!p.covers) {
    p.reachable = false;
    p.warnings.push_back(
        "the grid does not cover the rays to the screen and the region of interest: it needs " +
        std::to_string(RequiredPositions(p.coverage.u_mm, s.h_mm, s.k_max)) + " x " +
        std::to_string(RequiredPositions(p.coverage.v_mm, s.h_mm, s.k_max)) +
        " positions at this h and K; the light outside is missing from the slab and the error "
        "predicted here is only that of the covered part");
  } else if (p.at_D.total > in.target) {
    p.warnings.push_back("the predicted error at D, " + Percent(p.at_D.total) +
                         ", is above the target " + Percent(in.target));
  }
  return p;
}

Plan MakePlan(const PlanInput& in) {
  const Coverage c = RequiredCoverage(in);
  bool found = false;
  PlanSetting best, least_error;
  double least = 1e300;
  for (const double h : kSpacings) {
    if (h > in.h_max_mm + 1e-12) continue;
    PlanSetting s;
    s.h_mm = h;
    s.k_max = in.k_max;
    s.samples = in.samples;
    s.nu = RequiredPositions(c.u_mm, h, in.k_max);
    s.nv = RequiredPositions(c.v_mm, h, in.k_max);
    if (s.nu > 1000 || s.nv > 1000) continue;  // SamplingGrid's limit (docs/method.md §1.3)
    for (const int r : kResolutions) {
      if (r < in.resolution_min) continue;
      if (r > in.resolution_max) break;
      s.resolution = r;
      const double e = PredictError(in, s, in.D()).total;
      if (e < least - 1e-12 ||
          (std::abs(e - least) <= 1e-12 && s.positions() < least_error.positions())) {
        least = e;
        least_error = s;
      }
      if (e <= in.target) {
        // Fewest positions (the lab's time), then the coarsest slab (reconstruct's time), then
        // the larger h (same positions, smoother footprints).
        if (!found || s.positions() < best.positions() ||
            (s.positions() == best.positions() &&
             (r < best.resolution || (r == best.resolution && h > best.h_mm)))) {
          best = s;
        }
        found = true;
        break;  // a finer slab at this h only costs more
      }
    }
  }
  if (least_error.h_mm == 0)
    throw BadInput("--h-max: no spacing up to " + std::to_string(in.h_max_mm) +
                   " mm gives a grid of at most 1000 x 1000 positions");
  if (!found) {
    // Out of reach: the cheapest setting within 5 % of the least predicted error (the least
    // itself is typically the finest h, whose only gain is a smaller quadrature term).
    PlanInput closest = in;
    closest.target = 1.05 * least;
    Plan p = MakePlan(closest);
    p.reachable = false;  // closest's plan met closest's target: no "above the target" warning
    const ErrorTerms& e = p.at_D;
    std::string why = "the target " + Percent(in.target) +
                      " at D = " + std::to_string(int(std::lround(in.D()))) +
                      " mm is out of reach: the least predicted is " + Percent(least) +
                      " (this setting: " + Percent(e.total) + ")";
    if (e.parallax >= e.slab && e.parallax >= e.quadrature)
      why += ", most of it the exact model's parallax error at D != d (" + Percent(e.parallax) +
             ", docs/method.md §4.5), which neither h, the slab resolution nor N reduces";
    else
      why += "; raise --h-max or --resolution-max";
    why += ". The setting shown is the cheapest within 5 % of the least predicted error.";
    p.warnings.push_back(why);
    return p;
  }
  return EvaluatePlan(in, best);
}

std::string PlanTable(const PlanInput& in, const Plan& p) {
  const PlanSetting& s = p.setting;
  std::ostringstream o;
  auto row = [&](const std::string& a, const std::string& b) {
    o << "| " << a << " | " << b << " |\n";
  };
  o << "| setting | value |\n|---|---|\n";
  row("h (spacing)",
      std::to_string(s.h_mm).substr(0, std::to_string(s.h_mm).find('.') + 3) + " mm");
  row("grid", std::to_string(s.nu) + " x " + std::to_string(s.nv) + " = " +
                  std::to_string(s.positions()) + " positions");
  row("K (filter truncation)", std::to_string(s.k_max));
  row("slab resolution", std::to_string(s.resolution) + " texels");
  row("samples N", std::to_string(s.samples));
  char cov[96];
  std::snprintf(cov, sizeof cov, "|u| <= %.1f mm, |v| <= %.1f mm (%s)", p.coverage.u_mm,
                p.coverage.v_mm, p.covers ? "covered" : "NOT covered");
  row("coverage needed on S", cov);
  char roi[96];
  std::snprintf(roi, sizeof roi, "%.0f x %.0f mm", p.roi_max.u_mm, p.roi_max.v_mm);
  row("largest region the screen holds at D", roi);
  row("lab time", Minutes(p.lab_s));
  o << "\n| predicted error | at d = " << std::lround(in.distance_mm)
    << " mm | at D = " << std::lround(in.D()) << " mm |\n|---|---|---|\n";
  auto err = [&](const std::string& name, double a, double b) {
    o << "| " << name << " | " << Percent(a) << " | " << Percent(b) << " |\n";
  };
  err("parallax (exact model, D != d)", p.at_d.parallax, p.at_D.parallax);
  err("slab resolution (bell fit)", p.at_d.slab, p.at_D.slab);
  err("quadrature (N)", p.at_d.quadrature, p.at_D.quadrature);
  err("floor (photos, screen, lookups)", p.at_d.floor, p.at_D.floor);
  err("total (root sum of squares)", p.at_d.total, p.at_D.total);
  o << "\ntarget " << Percent(in.target)
    << " at D: " << (p.reachable ? "met" : "NOT met (see the warning)") << "\n";
  return o.str();
}

std::string PlanJson(const PlanInput& in, const Plan& p) {
  auto terms = [](const ErrorTerms& e) {
    return nlohmann::json{{"parallax", e.parallax},
                          {"slab", e.slab},
                          {"quadrature", e.quadrature},
                          {"floor", e.floor},
                          {"total", e.total}};
  };
  const PlanSetting& s = p.setting;
  nlohmann::json j = {{"schema_version", 1},
                      {"input",
                       {{"distance_mm", in.distance_mm},
                        {"screen_mm", {in.screen_w_mm, in.screen_h_mm}},
                        {"receiver_mm", in.D()},
                        {"depth_mm", in.depth_mm},
                        {"target", in.target}}},
                      {"setting",
                       {{"spacing_mm", s.h_mm},
                        {"nu", s.nu},
                        {"nv", s.nv},
                        {"positions", s.positions()},
                        {"k_max", s.k_max},
                        {"resolution", s.resolution},
                        {"samples", s.samples}}},
                      {"coverage_mm", {p.coverage.u_mm, p.coverage.v_mm}},
                      {"covers", p.covers},
                      {"roi_max_mm", {p.roi_max.u_mm, p.roi_max.v_mm}},
                      {"error_at_d", terms(p.at_d)},
                      {"error_at_D", terms(p.at_D)},
                      {"lab_s", p.lab_s},
                      {"reachable", p.reachable},
                      {"warnings", p.warnings}};
  return j.dump(2) + "\n";
}

}  // namespace lumislab
