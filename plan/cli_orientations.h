// The `orientations` subcommand of lumislab-plan: the orientations that cover the sphere or the
// hemisphere (plan/orientations.h) from a dataset's setup or the setup given by options; a table
// on stdout and luminaire.json's format in --out.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "core/command_line.h"
#include "plan/orientations.h"

namespace lumislab {

struct OrientationsCommand {
  std::string dataset_setup;  // dataset.json or setup.json
  double distance_mm = 0;
  std::vector<double> screen_mm;  // W H
  std::vector<double> grid;       // nu nv h
  int k_max = 1;
  bool hemisphere = false;
  std::string axis = "y";
  double luminaire_radius_mm = kDefaultLuminaireRadiusMm;
  double centre_depth_mm = 0;  // 0: luminaire_radius_mm + kCentreDepthMarginMm
  double min_coverage = 0.999;
  int max_orientations = 40;
  std::string out;
};

CLI::App* AddOrientationsCommand(CLI::App& app, OrientationsCommand* c, CommonOptions* common);
// Plans, prints the table, writes --out; BadInput (exit 2) with the reason when the coverage
// cannot be reached or the set does not connect.
int RunOrientationsCommand(const OrientationsCommand& c, int threads);
// The planner's input from the command (exposed for tests).
OrientationPlanInput OrientationPlanInputOf(const OrientationsCommand& c);

}  // namespace lumislab
