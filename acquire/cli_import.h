// The `import` and `watch` subcommands of lumislab-acquire (a folder of camera photos, all at
// once or as they arrive, into a dataset): their options and their runs (cli.cc only adds them
// to the tool and hands over to the one chosen).
#pragma once

#include <CLI/CLI.hpp>

#include "acquire/import.h"
#include "acquire/watch.h"
#include "core/command_line.h"

namespace lumislab {

CLI::App* AddImportCommand(CLI::App& app, ImportOptions* o, CommonOptions* common);
CLI::App* AddWatchCommand(CLI::App& app, WatchOptions* w, CommonOptions* common);
int RunImportCommand(ImportOptions o);
// Exit 1 when the watch ends before the capture is complete (stop signal, --idle-timeout).
int RunWatchCommand(WatchOptions w);

}  // namespace lumislab
