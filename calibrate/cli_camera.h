// The `camera` subcommand of lumislab-calibrate: its options and its run (cli.cc
// only adds it to the tool and hands over when it was chosen).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "calibrate/camera/camera_calibrator.h"
#include "core/command_line.h"

namespace lumislab {

struct CameraCommand {
  CLI::App* sub = nullptr;  // set by AddCameraCommand
  std::vector<std::string> photos;
  std::string board_size;  // "<cols>x<rows>" inner corners
  CameraBoard board;
  std::string dataset_dir;  // writes <dataset>/calib/camera.json and camera.yaml
  std::string out;          // or <out>.json and the YAML beside it
  bool force = false;
  CameraCalibratorOptions options;
};

void AddCameraCommand(CLI::App* app, CommonOptions* common, CameraCommand* command);
// Checks the options, calibrates, writes camera.json and camera.yaml (skipped when they exist,
// unless --force).
int RunCameraCommand(CameraCommand* command, int threads);

}  // namespace lumislab
