// grbl_emulator --link <path> [--speed-factor x] [--seconds N] [--require-homing]: a GRBL 1.1
// controller on a pseudo-terminal (tests/acquire/grbl_emulator.h) with a symbolic link to it at
// <path>, so that `grbl:<path>` can be driven without a stage. Serves until --seconds (600 by
// default) have passed or SIGINT/SIGTERM arrives.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>

#include "core/stop_signal.h"
#include "grbl_emulator.h"

int main(int argc, char** argv) {
  std::string link;
  lumislab::GrblEmulatorOptions options;
  double seconds = 600;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--link" && has_value) {
      link = argv[++i];
    } else if (arg == "--speed-factor" && has_value) {
      options.speed_factor = std::atof(argv[++i]);
    } else if (arg == "--seconds" && has_value) {
      seconds = std::atof(argv[++i]);
    } else if (arg == "--require-homing") {
      options.require_homing = true;
    } else {
      std::fprintf(stderr,
                   "usage: grbl_emulator --link <path> [--speed-factor x] [--seconds N] "
                   "[--require-homing]\n");
      return 2;
    }
  }
  if (link.empty() || !(options.speed_factor > 0) || !(seconds > 0)) {
    std::fprintf(stderr, "grbl_emulator: --link is required; --speed-factor and --seconds > 0\n");
    return 2;
  }
  try {
    const lumislab::StopSignalScope stop_scope;
    lumislab::GrblEmulator emulator(options);
    emulator.Link(link);
    std::printf("grbl_emulator: %s -> %s\n", link.c_str(), emulator.SlavePath().c_str());
    std::fflush(stdout);
    lumislab::PauseUnlessStopped(seconds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "grbl_emulator: %s\n", e.what());
    return 1;
  }
  return 0;
}
