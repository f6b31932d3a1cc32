// lumislab-preview's command line (cli.cc): its options into a PreviewConfig (config.h), and back
// into a headless command line for what the window shows.
#pragma once

#include <optional>
#include <string>

#include "preview/config.h"

namespace lumislab {

// The whole tool: command line, then the window or the headless run.
int RunPreview(int argc, char** argv);

// Parses the command line into `config` (help, version and CLI11 errors: the exit code to
// return; bad values: BadInput). `write_test_slab` receives --write-test-slab.
std::optional<int> ParsePreviewCommandLine(int argc, char** argv, PreviewConfig& config,
                                           bool* write_test_slab);
// The headless command line that renders what `config` describes into `out` (the window's
// "command line" line and its screenshot log): every setting the window changes is a flag.
std::string HeadlessCommandLine(const PreviewConfig& config, const std::string& out);

// Strict "WxH" (digits only, each 1..8192): false for anything else ("400x400junk").
bool ParseSize(const std::string& text, int* width, int* height);

}  // namespace lumislab
