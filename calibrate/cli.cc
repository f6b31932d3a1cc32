// lumislab-calibrate: the tool's command line; each subcommand's options and run are in
// cli_<subcommand>.cc.
#include "calibrate/cli.h"

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "calibrate/cli_camera.h"
#include "calibrate/cli_colour.h"
#include "calibrate/cli_orientations.h"
#include "calibrate/cli_radiometric.h"
#include "calibrate/cli_screen.h"
#include "core/command_line.h"

namespace lumislab {

int RunCalibrate(int argc, char** argv) {
  CLI::App app{
      "lumislab-calibrate: camera, screen and radiometric calibration into <dataset>/calib/ "
      "(docs/formats.md §5, §12 - §16). Order: response, dark, screen, flat, scale (flat "
      "and scale need the screen; colour, from a ColorChecker photo, any time); each later step "
      "decodes its frames with the earlier steps' "
      "corrections; orientations registers a luminaire folder's orientations (§19)"};
  app.require_subcommand(1);
  CommonOptions common;
  AddCommonOptions(&app, &common);
  ScreenCommand screen;
  AddScreenCommand(&app, &common, &screen);
  CameraCommand camera;
  AddCameraCommand(&app, &common, &camera);
  RadiometricCommand radiometric;
  AddRadiometricCommands(&app, &common, &radiometric);
  ColourCommand colour;
  AddColourCommand(&app, &common, &colour);
  OrientationsCommand orientations;
  AddOrientationsCommand(&app, &common, &orientations);
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  const int threads = StartTool("calibrate", common);
  cv::setNumThreads(threads);
  if (camera.sub->parsed()) return RunCameraCommand(&camera, threads);
  if (colour.sub->parsed()) return RunColourCommand(&colour);
  if (orientations.sub->parsed()) return RunOrientationsCommand(&orientations, threads);
  if (!screen.sub->parsed()) return RunRadiometricCommand(radiometric);
  return RunScreenCommand(&screen, threads);
}

}  // namespace lumislab
