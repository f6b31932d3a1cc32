// The `capture` subcommand of lumislab-acquire: its options and its run (acquire/capture.h).
#pragma once

#include <CLI/CLI.hpp>

#include "acquire/capture.h"
#include "core/command_line.h"

namespace lumislab {

CLI::App* AddCaptureCommand(CLI::App& app, CaptureOptions* o, CommonOptions* common);
// Exit 0 when the capture is complete (or was), or after --dry-run.
int RunCaptureCommand(const CaptureOptions& o);

}  // namespace lumislab
