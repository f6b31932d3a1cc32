// lumislab-export: the subcommands come from formats_cli (info, ies, ldt, tm25) and plots_cli
// (irradiance, polar).
#include <CLI/CLI.hpp>

#include "core/command_line.h"
#include "core/error.h"
#include "export/formats_cli.h"
#include "export/plots_cli.h"

namespace lumislab {
namespace {

int RunExport(int argc, char** argv) {
  CLI::App app{
      "lumislab-export: a light slab out to the files and pictures of the lighting "
      "industry"};
  app.require_subcommand(1);
  CommonOptions common;
  AddCommonOptions(&app, &common);
  const ParsedCommand formats = AddFormatCommands(app, &common);
  const ParsedCommand plots = AddPlotCommands(app, &common);
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  const int threads = StartTool("export", common);
  if (const auto code = formats(threads)) return *code;
  if (const auto code = plots(threads)) return *code;
  return 2;  // unreachable: CLI11 requires one subcommand
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) {
  return lumislab::RunMain("export", [&] { return lumislab::RunExport(argc, argv); });
}
