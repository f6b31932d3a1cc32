#include "plan/cli_orientations.h"

#include <filesystem>
#include <iostream>

#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/json.h"
#include "core/log.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// The setup whose cone one capture sees: a dataset.json or setup.json (photos not read), or
// the options.
Dataset SetupOf(const OrientationsCommand& c) {
  const bool by_options = c.distance_mm > 0 || !c.screen_mm.empty() || !c.grid.empty();
  if (!c.dataset_setup.empty()) {
    if (by_options)
      throw BadInput(
          "--dataset-setup: give the setup by a file or by --distance-mm, --screen-mm and "
          "--grid, not both");
    return Dataset::Parse(JsonDocument::Load(c.dataset_setup),
                          fs::path(c.dataset_setup).parent_path().string(), false);
  }
  if (!(c.distance_mm > 0)) throw BadInput("--distance-mm: required without --dataset-setup");
  if (c.screen_mm.size() != 2) throw BadInput("--screen-mm: required without --dataset-setup");
  if (c.grid.size() != 3) throw BadInput("--grid: required without --dataset-setup");
  Dataset ds;
  ds.distance_mm = c.distance_mm;
  ds.screen_w_mm = c.screen_mm[0];
  ds.screen_h_mm = c.screen_mm[1];
  for (int k : {0, 1})
    if (c.grid[size_t(k)] != std::floor(c.grid[size_t(k)]))
      throw BadInput("--grid: expected whole numbers of positions nu nv, got " +
                     std::to_string(c.grid[size_t(k)]));
  ds.grid.nu = int(c.grid[0]);
  ds.grid.nv = int(c.grid[1]);
  ds.grid.spacing_mm = c.grid[2];
  ds.filter = FilterInfo::Of(DualFilter::Truncated(c.k_max), ds.grid.spacing_mm);
  return ds;
}

// luminaire.json's content under any file name, its datasets relative to the file's folder.
void WritePlanFile(LuminaireSet set, const std::string& file) {
  const fs::path path(file);
  set.folder = path.has_parent_path() ? path.parent_path().string() : ".";
  WriteLuminaireSetFile(set, file);
}

}  // namespace

CLI::App* AddOrientationsCommand(CLI::App& app, OrientationsCommand* c, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand(
      "orientations",
      "the orientations to capture a luminaire in so that the captures together see the whole "
      "sphere (or the hemisphere z >= 0 of the luminaire frame), each connected to the first "
      "through overlaps of at least 0.03 sr (docs/method.md §4.12): a table on stdout and, with "
      "--out, the plan in luminaire.json's format (acquire synth --orientations, the lab "
      "driver). Exit 2 with the reason when the coverage cannot be reached or the set does not "
      "connect.");
  cmd->add_option("--dataset-setup", c->dataset_setup,
                  "dataset.json or setup.json of the capture setup (d, screen, grid, filter)");
  cmd->add_option("--distance-mm", c->distance_mm, "d, S to the screen (mm)")
      ->check(FiniteIn(kMinDistanceMm, kMaxDistanceMm));
  cmd->add_option("--screen-mm", c->screen_mm, "screen width and height (mm)")
      ->expected(2)
      ->check(FiniteIn(kMinScreenMm, kMaxScreenMm));
  cmd->add_option("--grid", c->grid, "positions nu nv and spacing h (mm)")
      ->expected(3)
      ->check(FiniteIn(kMinSpacingMm, kMaxGridSide));
  cmd->add_option("--k-max", c->k_max, "filter truncation K")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  cmd->add_flag("--hemisphere", c->hemisphere,
                "cover the hemisphere z >= 0 of the luminaire frame only (the first "
                "orientation's view of it at the screen's centre)");
  cmd->add_option("--axis", c->axis,
                  "y: a rotation axis (the stage's A axis) turns the luminaire about the capture "
                  "frame's +y through its centre, hand remounts tilt it on the axis; none: every "
                  "orientation a hand mount")
      ->check(CLI::IsMember({"y", "none"}))
      ->capture_default_str();
  cmd->add_option("--luminaire-radius-mm", c->luminaire_radius_mm,
                  "radius of a sphere about the luminaire's origin that holds it (mm)")
      ->check(FiniteIn(0, 1e4))
      ->capture_default_str();
  cmd->add_option("--centre-depth-mm", c->centre_depth_mm,
                  "L: the luminaire's origin at [0, 0, -L] of every capture frame, so that it "
                  "stays behind S turned any way (mm, > --luminaire-radius-mm; default the "
                  "radius + " +
                      std::to_string(int(kCentreDepthMarginMm)) + " mm)")
      ->check(FiniteIn(0, 1e5));
  cmd->add_option("--coverage", c->min_coverage,
                  "the fraction of the sphere / hemisphere to cover (AnalyseCoverage's samples)")
      ->check(FiniteIn(0.01, 1))
      ->capture_default_str();
  cmd->add_option("--max-orientations", c->max_orientations, "the most orientations to propose")
      ->check(CLI::Range(1, 200))
      ->capture_default_str();
  cmd->add_option("--out", c->out, "write the plan here (luminaire.json's format)");
  AddCommonOptions(cmd, common);
  return cmd;
}

OrientationPlanInput OrientationPlanInputOf(const OrientationsCommand& c) {
  OrientationPlanInput in;
  in.cone = ConeOfDataset(SetupOf(c));
  in.hemisphere = c.hemisphere;
  in.rotation_axis = c.axis == "y";
  const double depth =
      c.centre_depth_mm > 0 ? c.centre_depth_mm : c.luminaire_radius_mm + kCentreDepthMarginMm;
  if (!(depth > c.luminaire_radius_mm))
    throw BadInput("--centre-depth-mm: expected more than --luminaire-radius-mm (" +
                   std::to_string(c.luminaire_radius_mm) + " mm) so that the luminaire stays " +
                   "behind S, got " + std::to_string(depth));
  in.centre_mm = {0, 0, -depth};
  in.min_coverage = c.min_coverage;
  in.max_orientations = c.max_orientations;
  return in;
}

int RunOrientationsCommand(const OrientationsCommand& c, int threads) {
  if (!c.out.empty()) CheckOutputPath(c.out);
  OrientationPlanInput in = OrientationPlanInputOf(c);
  in.threads = threads;
  LogInfo("parameters: setup=", c.dataset_setup.empty() ? "options" : c.dataset_setup, " cone=+-",
          in.cone.half_w_mm, "x+-", in.cone.half_h_mm, " mm at d=", in.cone.distance_mm,
          " coverage=", c.hemisphere ? "hemisphere" : "sphere", " axis=", c.axis,
          " centre_z=", in.centre_mm.z(), " min_coverage=", in.min_coverage,
          " max_orientations=", in.max_orientations);
  if (!(in.cone.half_w_mm > 0 && in.cone.half_h_mm > 0))
    throw BadInput("the setup: a capture sees no direction (the screen, " +
                   std::to_string(2 * in.cone.half_w_mm) + " x " +
                   std::to_string(2 * in.cone.half_h_mm) +
                   " mm less the positions' support, is empty)");
  const OrientationPlan plan = PlanOrientations(in);
  std::cout << OrientationPlanTable(in, plan);
  if (!plan.problem.empty()) throw BadInput("no plan: " + plan.problem);
  if (!c.out.empty()) {
    WritePlanFile(OrientationPlanSet(in, plan), c.out);
    std::cout << "plan: " << c.out << '\n';
  }
  return 0;
}

}  // namespace lumislab
