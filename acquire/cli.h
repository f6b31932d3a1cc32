// Command line of lumislab-acquire (subcommands synth, import, watch and filter).
#pragma once

namespace lumislab {

// The whole tool: parses the command line and runs the subcommand chosen.
int RunAcquire(int argc, char** argv);

}  // namespace lumislab
