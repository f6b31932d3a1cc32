#include "acquire/cli_capture.h"

#include "core/log.h"

namespace lumislab {

CLI::App* AddCaptureCommand(CLI::App& app, CaptureOptions* o, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand(
      "capture",
      "run a capture: move the luminaire over the grid on a stage, photograph every position "
      "through both slides, write the dataset as it grows (resumable: the same command goes on)");
  cmd->add_option("--setup", o->setup_file,
                  "setup file: dataset.json without photos, with the lab block (stage axes, "
                  "origin, travel, slides, camera; docs/formats.md)")
      ->required();
  cmd->add_option("--stage", o->stage_uri,
                  "grbl:<serial port>[?baud=115200], command:<program> or manual")
      ->required();
  cmd->add_option("--camera", o->camera_uri,
                  "gphoto2[:<model>][@<port>], command:<program> or folder:<dir>")
      ->required();
  cmd->add_option("--out", o->out_dir,
                  "dataset folder to write (with --orientations: the luminaire folder)")
      ->required();
  cmd->add_option("--orientations", o->orientations_file,
                  "capture a luminaire from several orientations: a plan in luminaire.json "
                  "format (lumislab-plan orientations), each orientation into its own dataset "
                  "folder of --out; a rotation axis (lab.rotation_axis) turns the luminaire and "
                  "the operator is asked to remount it, else to turn it (docs/formats.md §19)");
  cmd->add_option("--order", o->order,
                  "slide-pass (every position through T+, then T-), position (both slides at "
                  "each position) or auto (position with a slide axis, else slide-pass)")
      ->capture_default_str();
  cmd->add_option("--operator", o->operator_program,
                  "a program that carries out the operator's steps (slides, board; with "
                  "--orientations remounts and turns) instead of the terminal: called as "
                  "<program> <action> <argument> <request>");
  cmd->add_flag("--dry-run", o->dry_run,
                "print the plan, the travel, the photo count and the predicted lab time; touch "
                "no device");
  cmd->add_flag("--force", o->force, "capture again over a complete or started dataset");
  AddLabModelOptions(cmd, &o->lab, false);
  (void)common;
  return cmd;
}

int RunCaptureCommand(const CaptureOptions& o) {
  const CaptureReport report = RunCapture(o);
  if (report.dry_run || report.skipped) return 0;
  if (!o.orientations_file.empty()) {
    LogInfo("capture complete: ", report.orientations_done, " orientation(s) now, ",
            report.orientations_resumed, " before; ", report.photos, " photos (", report.shots_done,
            " shots now, ", report.shots_resumed, " before)");
    std::printf("%s/luminaire.json\n", o.out_dir.c_str());
    return 0;
  }
  LogInfo("capture complete: ", report.photos, " photos in ", o.out_dir, "/dataset.json (",
          report.shots_done, " shots now, ", report.shots_resumed, " before",
          report.reshots ? ", " + std::to_string(report.reshots) + " taken again shorter" : "",
          ")");
  std::printf("%s/dataset.json\n", o.out_dir.c_str());
  return 0;
}

}  // namespace lumislab
