// The `synth` subcommand of lumislab-acquire (the photos of a synthetic scene into a dataset):
// its options and its run (cli.cc only adds it to the tool and hands over when it was chosen).
#pragma once

#include <CLI/CLI.hpp>

#include "acquire/synth.h"
#include "acquire/synth_orientations.h"
#include "core/command_line.h"

namespace lumislab {

struct SynthCommand {
  SynthOptions options;
  SynthOrientationsOptions orientations;  // orientations_file set: a luminaire folder
  bool print_scene = false;
};

CLI::App* AddSynthCommand(CLI::App& app, SynthCommand* c, CommonOptions* common);
// --print-scene prints the scene and returns; otherwise renders the dataset, or with
// --orientations the luminaire folder (exit 1 when a stop signal cut it short).
int RunSynthCommand(const SynthCommand& command, int threads);

}  // namespace lumislab
