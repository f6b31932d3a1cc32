// lumislab-export's file-format subcommands (docs/architecture.md §7.8):
//   info <file> [--json]                 what an IES, EULUMDAT or TM-25 file holds
//   ies | ldt --slab <dir> --out <file>  the slab's far-field intensity as IES LM-63-2019 or
//                                        EULUMDAT
//   tm25 --slab <dir> --out <f.ray>      rays drawn from the slab's light field
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>

#include "core/command_line.h"

namespace lumislab {

// Runs the subcommand of a set that was parsed, with the tool's resolved thread count; nothing
// when none of the set's subcommands was on the command line.
using ParsedCommand = std::function<std::optional<int>(int threads)>;

// Adds info, ies, ldt and tm25 to `app` (each with the common options bound to `common`).
ParsedCommand AddFormatCommands(CLI::App& app, CommonOptions* common);

}  // namespace lumislab
