// The `colour` subcommand of lumislab-calibrate: a photo of a ColorChecker Classic 24 ->
// calib/colour.json (or a named file), the camera's RGB -> CIE XYZ.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "calibrate/colour/colour_calibrator.h"
#include "core/command_line.h"

namespace lumislab {

struct ColourCommand {
  CLI::App* sub = nullptr;  // set by AddColourCommand
  std::string photo;
  std::string out;  // a dataset folder (-> calib/colour.json) or a .json file
  bool force = false;
  ColourOptions options;
};

void AddColourCommand(CLI::App* app, CommonOptions* common, ColourCommand* command);
// Decodes the photo (with the dataset's response and dark calibration when --out is a dataset),
// fits, writes the file (exit 2 naming it when it exists, unless --force) and records colour.fit.
int RunColourCommand(ColourCommand* command);

}  // namespace lumislab
