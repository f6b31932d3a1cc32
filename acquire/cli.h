// Command line of lumislab-acquire (subcommands synth and filter).
#pragma once

namespace lumislab {

int RunAcquire(int argc, char** argv);

}  // namespace lumislab
