// The `filter` subcommand of lumislab-acquire (the printable filter slides): its options and its
// run (cli.cc only adds it to the tool and hands over when it was chosen).
#pragma once

#include <CLI/CLI.hpp>

#include "acquire/filter_print.h"
#include "core/command_line.h"

namespace lumislab {

CLI::App* AddFilterCommand(CLI::App& app, FilterPrintOptions* o, CommonOptions* common);
int RunFilter(const FilterPrintOptions& filter);

}  // namespace lumislab
