// lumislab-plan's command line (cli.cc) around the planner of plan.h.
#pragma once

namespace lumislab {

// The whole tool: parses the command line, plans, prints the plan.
int RunPlan(int argc, char** argv);

}  // namespace lumislab
