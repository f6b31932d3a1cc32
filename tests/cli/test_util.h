// Helpers for tests that run the lumislab executables.
#pragma once

#include <string>

namespace lumislab::testing {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs build/bin/<tool> with the given argument string (shell-quoted by the caller).
CommandResult RunTool(const std::string& tool, const std::string& args);
// A fresh, empty folder under the system temp folder, named after the test.
std::string FreshDir(const std::string& name);
void WriteFile(const std::string& path, const std::string& text);
// Scene JSON of the default luminaire with the given grid, camera and effects (JSON fragments).
std::string SceneJson(int nu, int nv, const std::string& camera_json,
                      const std::string& effects_json);
// Files under `dir` (recursively) whose name does not start with '.', and those that do.
int CountFinalFiles(const std::string& dir);
int CountTemporaryFiles(const std::string& dir);

}  // namespace lumislab::testing
