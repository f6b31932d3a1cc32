// lumislab-reconstruct's command line and its batch and --watch drivers (cli.cc) around
// ReconstructPosition (reconstructor.h).
#pragma once

namespace lumislab {

// lumislab-reconstruct --dataset <dir> [--resolution N] [--watch] [--force] [--threads N]
// [--lambda x] [--verbose]
int RunReconstruct(int argc, char** argv);

}  // namespace lumislab
