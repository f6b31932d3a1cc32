// lumislab-acquire: the tool's command line; each subcommand's options and run are in
// cli_<subcommand>.cc (cli_import.cc: import and watch).
#include "acquire/cli.h"

#include <CLI/CLI.hpp>
#include <cstdio>

#include "acquire/cli_capture.h"
#include "acquire/cli_filter.h"
#include "acquire/cli_import.h"
#include "acquire/cli_synth.h"
#include "core/checks.h"
#include "core/command_line.h"
#include "core/error.h"

namespace lumislab {

int RunAcquire(int argc, char** argv) {
  CLI::App app{
      "lumislab-acquire: capture with a lab's stage and camera, synthetic capture of a luminaire, "
      "import of a camera's photos, and filter-slide printing"};
  app.require_subcommand(1);
  CommonOptions common;
  AddCommonOptions(&app, &common);
  SynthCommand synth;
  FilterPrintOptions filter;
  AddSynthCommand(app, &synth, &common);
  CLI::App* filter_cmd = AddFilterCommand(app, &filter, &common);
  ImportOptions import;
  CLI::App* import_cmd = AddImportCommand(app, &import, &common);
  WatchOptions watch;
  CLI::App* watch_cmd = AddWatchCommand(app, &watch, &common);
  CaptureOptions capture;
  CLI::App* capture_cmd = AddCaptureCommand(app, &capture, &common);
  std::string checks_dataset;
  CLI::App* checks_cmd = app.add_subcommand(
      "checks",
      "print a dataset's consistency report (checks.json: what each stage verified about the "
      "capture, docs/verifies.md)");
  checks_cmd->add_option("dataset", checks_dataset, "dataset folder")->required();
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  const int threads = StartTool("acquire", common);
  if (filter_cmd->parsed()) return RunFilter(filter);
  if (import_cmd->parsed()) return RunImportCommand(import);
  if (watch_cmd->parsed()) return RunWatchCommand(watch);
  if (capture_cmd->parsed()) return RunCaptureCommand(capture);
  if (checks_cmd->parsed()) {
    const std::string report = FormatCheckReport(checks_dataset);
    if (report.empty())
      throw BadInput(checks_dataset +
                     "/checks.json: not found (no stage has checked this dataset)");
    std::fputs(report.c_str(), stdout);
    return 0;
  }
  // CLI11 requires one subcommand: the one left is synth.
  return RunSynthCommand(synth, threads);
}

}  // namespace lumislab
