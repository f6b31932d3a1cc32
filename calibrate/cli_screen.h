// The `screen` subcommand of lumislab-calibrate: its options and its run (cli.cc only adds it to
// the tool and hands over when it was chosen).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "calibrate/screen/screen_calibrator.h"
#include "core/command_line.h"

namespace lumislab {

struct ScreenCommand {
  CLI::App* sub = nullptr;  // set by AddScreenCommand
  std::string dataset_dir;
  bool force = false;
  ScreenCalibratorOptions options;
};

void AddScreenCommand(CLI::App* app, CommonOptions* common, ScreenCommand* command);
// Checks the options, calibrates, writes calib/screen.json (skipped when it exists, unless
// --force).
int RunScreenCommand(ScreenCommand* command, int threads);

}  // namespace lumislab
