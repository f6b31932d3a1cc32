// The preamble every lumislab tool shares (docs/architecture.md §7): --verbose and --threads on the
// tool and on each of its subcommands, parsing with CLI11's messages mapped to exit code 2, the
// log prefix and level, and the thread count resolved once.
//   CLI::App app{"lumislab-x: ..."};
//   CommonOptions common;
//   AddCommonOptions(&app, &common);
//   if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
//   const int threads = StartTool("x", common);
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace lumislab {

struct CommonOptions {
  bool verbose = false;
  int threads = 0;  // 0: all cores
};

// Adds --verbose and --threads bound to `options` (call for the app and for each subcommand).
void AddCommonOptions(CLI::App* app, CommonOptions* options);
// Parses the command line. Returns the exit code when the tool must stop now (0 after --help,
// 2 for bad usage, with CLI11's message printed), nothing when it should go on.
std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv);
// Sets the log prefix ("lumislab-<tool>") and level; returns the resolved thread count
// (BadInput naming --threads when out of range).
int StartTool(const std::string& tool, const CommonOptions& options);
// A CLI11 check that a number is finite and in [lo, hi] (CLI::Range lets NaN through); the
// message names the option.
CLI::Validator FiniteIn(double lo, double hi);

// "out/ds///" -> "out/ds" (the root "/" stays).
std::string TrimTrailingSlashes(std::string path);

}  // namespace lumislab
