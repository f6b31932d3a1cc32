// lumislab-export's command line: the subcommands come from cli_formats (info, ies, ldt, tm25),
// cli_plots (irradiance, polar) and report (the lab report).
#include "export/cli.h"

#include <CLI/CLI.hpp>

#include "core/command_line.h"
#include "export/cli_formats.h"
#include "export/cli_plots.h"
#include "export/report.h"

namespace lumislab {

int RunExport(int argc, char** argv) {
  CLI::App app{
      "lumislab-export: a light slab out to the files and pictures of the lighting "
      "industry"};
  app.require_subcommand(1);
  CommonOptions common;
  AddCommonOptions(&app, &common);
  const ParsedCommand formats = AddFormatCommands(app, &common);
  const ParsedCommand plots = AddPlotCommands(app, &common);
  const ParsedCommand report = AddReportCommand(app, &common);
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  const int threads = StartTool("export", common);
  if (const auto code = formats(threads)) return *code;
  if (const auto code = plots(threads)) return *code;
  // report: the lab report (export/report.h).
  if (const auto code = report(threads)) return *code;
  return 2;  // unreachable: CLI11 requires one subcommand
}

}  // namespace lumislab
