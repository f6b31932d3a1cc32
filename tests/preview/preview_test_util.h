// Shared by the preview tests.
#pragma once

#include <string>
#include <vector>

namespace lumislab {

// Runs lumislab-preview's command line in-process (RunMain: exit codes as the binary's).
int RunPreviewWith(std::vector<std::string> args);

}  // namespace lumislab
