// lumislab-calibrate's command line: the subcommands screen (cli_screen.h), camera
// (cli_camera.h) and dark, response, flat, scale (cli_radiometric.h).
#pragma once

namespace lumislab {

// The whole tool: parses the command line and runs the subcommand chosen.
int RunCalibrate(int argc, char** argv);

}  // namespace lumislab
