// lumislab-export's command line: the subcommands of cli_formats.h and cli_plots.h.
#pragma once

namespace lumislab {

// The whole tool: parses the command line and runs the subcommand chosen.
int RunExport(int argc, char** argv);

}  // namespace lumislab
