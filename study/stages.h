// How lumislab-study runs the other tools (docs/method.md §4.7): as the executables beside its
// own, one subprocess per stage, so the time measured is what a user waits and a stage's own
// command line keeps its resumption, staging and validation (docs/architecture.md §2: a stage never
// links another).
#pragma once

#include <string>
#include <vector>

namespace lumislab {

// The executable `tool` beside lumislab-study (build/bin/ or an install's bin/); a failure naming
// the path when it is missing.
std::string ToolPath(const std::string& tool);

// Runs `tool args...` with stdout and stderr appended to `log`; returns its wall time (s). A
// tool that fails is a failure of the study (exit 1) naming the command and the log. A stop
// signal is passed on to the tool as SIGTERM and the study stops after it.
double RunStage(const std::string& tool, const std::vector<std::string>& args,
                const std::string& log);

}  // namespace lumislab
