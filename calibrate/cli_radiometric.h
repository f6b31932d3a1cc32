// lumislab-calibrate dark | response | flat | scale: the command lines of the radiometric
// calibration (docs/formats.md §13 - §16) around the calibrators of radiometric/.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "calibrate/radiometric/dark_calibrator.h"
#include "calibrate/radiometric/response_calibrator.h"
#include "calibrate/radiometric/scale_calibrator.h"

namespace lumislab {

struct RadiometricCommand {
  CLI::App* dark = nullptr;
  CLI::App* response = nullptr;
  CLI::App* flat = nullptr;
  CLI::App* scale = nullptr;
  std::string dataset_dir;
  std::vector<std::string> frames;
  std::string exposures;  // "e1,e2,..."
  bool force = false;
  DarkOptions dark_options;
  ResponseOptions response_options;
  ScaleOptions scale_options;
  double flat_smooth_px = 0;  // flat: Gaussian sigma of the gain map, pixels (0: none)
  // scale: a reference file, or its fields as options.
  std::string reference_file;
  std::string position, point_mm;  // "i,j", "x,y"
  double reading_p = std::nan(""), reading_n = std::nan("");
  std::string unit = "W/m2";
};

// Adds the four subcommands to `app` (each with the common options bound to `common`).
void AddRadiometricCommands(CLI::App* app, struct CommonOptions* common,
                            RadiometricCommand* command);
// Runs the one that was parsed; -1 when none of them was.
int RunRadiometricCommand(RadiometricCommand& command);

}  // namespace lumislab
