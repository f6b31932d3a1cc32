// lumislab-study's command line (cli.cc) around the sweep of study.h.
#pragma once

namespace lumislab {

// The whole tool: parses the command line, runs the sweep, prints its tables.
int RunStudy(int argc, char** argv);

}  // namespace lumislab
