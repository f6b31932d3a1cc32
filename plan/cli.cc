// lumislab-plan's command line: the planner's inputs from options or a scene file, then the
// plan (plan.h) as a table on stdout and, with --json, a file.
#include "plan/cli.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/error.h"
#include "core/log.h"
#include "lib/synthetic/scene.h"
#include "plan/cli_orientations.h"
#include "plan/plan.h"

namespace lumislab {

namespace {

// "3" or "3,2" (mm, both > 0 / >= 0): the value of a pair option, exit 2 naming it.
std::pair<double, double> ParsePair(const std::string& option, const std::string& text, double lo) {
  std::istringstream in(text);
  std::vector<double> v;
  for (std::string part; std::getline(in, part, ',');) {
    char* end = nullptr;
    const double x = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(x) || x < lo || x > 1e5)
      throw BadInput(option + ": expected one or two numbers in [" + std::to_string(lo) +
                     ", 1e5] mm separated by a comma, got \"" + text + "\"");
    v.push_back(x);
  }
  if (v.empty() || v.size() > 2)
    throw BadInput(option + ": expected one or two numbers separated by a comma, got \"" + text +
                   "\"");
  return {v[0], v.size() == 2 ? v[1] : v[0]};
}

}  // namespace

int RunPlan(int argc, char** argv) {
  CLI::App app{
      "lumislab-plan: before a capture, the grid (h, nu x nv), K and slab resolution that reach a "
      "target accuracy of the receiver-plane irradiance at distance D, with the predicted error "
      "per term and the lab time (docs/method.md §4.8). Give the luminaire by --scene or by "
      "--aperture-mm and --depth-mm. Prints a table; --json writes it for machines. A target out "
      "of reach is a warning (exit 0) with the cheapest setting near the least predicted error. "
      "`lumislab-plan orientations` plans the orientations of a luminaire measured from several "
      "(docs/method.md §4.12)."};
  PlanInput in;
  CommonOptions common;
  AddCommonOptions(&app, &common);
  std::string scene, aperture, screen, roi, json_out, target = "1%";
  double depth = 0, depth_max = 0, h = 0;
  int nu = 0, nv = 0, resolution = 0;
  app.add_option("--scene", scene,
                 "synthetic scene file (acquire synth's) or \"default\": the luminaire, d, the "
                 "screen and K from it");
  app.add_option("--aperture-mm", aperture,
                 "luminaire aperture half-extent on S, \"A\" or \"AX,AY\" (mm)");
  app.add_option("--depth-mm", depth, "depth of the light behind S (mm, > 0)")
      ->check(FiniteIn(1e-3, 1e5));
  app.add_option("--depth-max-mm", depth_max,
                 "deepest point of the light, for coverage (default --depth-mm)")
      ->check(FiniteIn(1e-3, 1e5));
  app.add_option("--distance-mm", in.distance_mm, "d, S to the screen (mm)")
      ->check(FiniteIn(1, 1e5));
  app.add_option("--screen-mm", screen, "screen size \"W,H\" or \"W\" (mm; default 1200,1200)");
  app.add_option("--target", target,
                 "target relative L2 error at D, a fraction (0.01) or a percentage (1%)")
      ->capture_default_str();
  app.add_option("--receiver-mm", in.receiver_mm,
                 "D, the receiver plane's distance (mm; default d)")
      ->check(FiniteIn(1, 1e6));
  app.add_option("--roi-mm", roi,
                 "region of interest on the receiver plane \"W,H\" (mm; default the screen x D/d)");
  app.add_option("--k-max", in.k_max, "filter truncation K")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  app.add_option("--samples", in.samples, "samples per support N of the render")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--h-max", in.h_max_mm,
                 "largest spacing considered (mm; the model is calibrated up to 10)")
      ->check(FiniteIn(0.5, 1000))
      ->capture_default_str();
  app.add_option("--resolution-max", in.resolution_max, "largest slab resolution considered")
      ->check(CLI::Range(16, 1000))
      ->capture_default_str();
  app.add_option("--resolution-min", in.resolution_min,
                 "smallest slab resolution considered (the model is calibrated from 24 up)")
      ->check(CLI::Range(16, 1000))
      ->capture_default_str();
  app.add_option("--h", h, "evaluate this spacing instead of recommending (mm)")
      ->check(FiniteIn(0.01, 1000));
  app.add_option("--nu", nu, "evaluate: positions along u (default: what covers)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--nv", nv, "evaluate: positions along v (default: what covers)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--resolution", resolution, "evaluate: slab resolution (default 150)")
      ->check(CLI::Range(8, 1000));
  AddLabModelOptions(&app, &in.lab, /*brackets_option=*/true);
  app.add_option("--json", json_out, "also write the plan as JSON to this file");
  OrientationsCommand orientations;
  CLI::App* orientations_cmd = AddOrientationsCommand(app, &orientations, &common);
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  const int threads = StartTool("plan", common);
  if (orientations_cmd->parsed()) return RunOrientationsCommand(orientations, threads);

  // The target: a fraction or a percentage in (0, 1).
  {
    std::string t = target;
    const bool percent = !t.empty() && t.back() == '%';
    if (percent) t.pop_back();
    char* end = nullptr;
    double x = std::strtod(t.c_str(), &end);
    if (percent) x /= 100;
    if (t.empty() || *end != '\0' || !std::isfinite(x) || !(x > 0) || !(x < 1))
      throw BadInput("--target: expected a fraction in (0, 1) or a percentage (\"1%\"), got \"" +
                     target + "\"");
    in.target = x;
  }
  if (in.resolution_min > in.resolution_max)
    throw BadInput("--resolution-min: must be at most --resolution-max");
  if (!scene.empty()) {
    if (!aperture.empty() || depth > 0)
      throw BadInput(
          "--scene: give the luminaire by --scene or by --aperture-mm/--depth-mm, "
          "not both");
    const SynthScene sc = LoadScene(scene);
    const PlanInput from_scene = PlanInputFromScene(sc);
    if (app.count("--distance-mm") == 0) in.distance_mm = sc.distance_mm;
    if (screen.empty()) {
      in.screen_w_mm = sc.screen_w_mm;
      in.screen_h_mm = sc.screen_h_mm;
    }
    if (app.count("--k-max") == 0) in.k_max = sc.k_max;
    in.light = from_scene.light;
    in.depth_mm = from_scene.depth_mm;
  } else {
    if (aperture.empty()) throw BadInput("--aperture-mm: required without --scene");
    if (!(depth > 0)) throw BadInput("--depth-mm: required without --scene");
    const auto [ax, ay] = ParsePair("--aperture-mm", aperture, 0);
    const double zmax = depth_max > 0 ? depth_max : depth;
    if (zmax < depth) throw BadInput("--depth-max-mm: must be at least --depth-mm");
    // The aperture's corner at the deepest point and at S itself bound every crossing
    // (the crossing is monotone in the depth, docs/method.md §4.8).
    in.light = {{ax, ay, zmax}, {ax, ay, 1e-9}};
    in.depth_mm = depth;
  }
  if (!screen.empty()) {
    const auto [w, hh] = ParsePair("--screen-mm", screen, 1);
    in.screen_w_mm = w;
    in.screen_h_mm = hh;
  }
  if (!roi.empty()) {
    const auto [w, hh] = ParsePair("--roi-mm", roi, 1);
    in.roi_w_mm = w;
    in.roi_h_mm = hh;
  }
  if (!json_out.empty()) CheckOutputPath(json_out);
  LogInfo("parameters: scene=", scene.empty() ? "-" : scene, " aperture=", aperture,
          " depth_mm=", in.depth_mm, " d=", in.distance_mm, " screen=", in.screen_w_mm, "x",
          in.screen_h_mm, " D=", in.D(), " target=", in.target, " k_max=", in.k_max);

  Plan plan;
  if (h > 0) {
    PlanSetting s;
    s.h_mm = h;
    s.k_max = in.k_max;
    s.samples = in.samples;
    const Coverage c = RequiredCoverage(in);
    s.nu = nu > 0 ? nu : RequiredPositions(c.u_mm, h, in.k_max);
    s.nv = nv > 0 ? nv : RequiredPositions(c.v_mm, h, in.k_max);
    s.resolution = resolution > 0 ? resolution : 150;
    plan = EvaluatePlan(in, s);
  } else {
    if (nu > 0 || nv > 0 || resolution > 0)
      throw BadInput("--h: --nu, --nv and --resolution evaluate a setting and need --h");
    plan = MakePlan(in);
  }
  if (!json_out.empty()) WriteTextAtomically(json_out, PlanJson(in, plan));
  std::cout << PlanTable(in, plan);
  for (const std::string& w : plan.warnings) LogWarning(w);
  return 0;
}

}  // namespace lumislab
