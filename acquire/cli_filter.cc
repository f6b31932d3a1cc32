#include "acquire/cli_filter.h"

#include <cstdio>

#include "core/log.h"

namespace lumislab {

CLI::App* AddFilterCommand(CLI::App& app, FilterPrintOptions* o, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand("filter",
                                     "write the printable filter slides T+ and T- as 16-bit PNG "
                                     "plus filter.json (coefficients, peak, cross-talk)");
  cmd->add_option("--spacing-mm", o->spacing_mm, "grid spacing h (mm)")->capture_default_str();
  cmd->add_option("--k-max", o->k_max, "truncation K of the dual: support +-(K+1)h")
      ->capture_default_str();
  cmd->add_option("--dpi", o->dpi, "print resolution")->capture_default_str();
  cmd->add_option("--out", o->out_dir, "output folder")->required();
  AddCommonOptions(cmd, common);
  return cmd;
}

int RunFilter(const FilterPrintOptions& filter) {
  LogInfo("parameters: spacing_mm=", filter.spacing_mm, " k_max=", filter.k_max,
          " dpi=", filter.dpi, " out=", filter.out_dir);
  const FilterPrintReport r = PrintFilter(filter);
  std::printf("filter slides (%d x %d px, %.3f mm, peak %.6f): %s %s %s\n", r.size_px, r.size_px,
              r.size_mm, r.peak, r.plus_png.c_str(), r.minus_png.c_str(), r.json.c_str());
  return 0;
}

}  // namespace lumislab
