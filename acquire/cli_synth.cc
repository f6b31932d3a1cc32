#include "acquire/cli_synth.h"

#include <cstdio>
#include <sstream>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/synthetic/camera_views.h"

namespace lumislab {
namespace {

int PrintScene(const std::string& scene) {
  if (scene == "default") {
    std::fputs(DefaultSceneJson().c_str(), stdout);
  } else if (scene == "full-sphere") {
    std::fputs(FullSphereSceneJson().c_str(), stdout);
  } else {
    LoadScene(scene);  // validates
    std::fputs(ReadTextFile(scene).c_str(), stdout);
  }
  return 0;
}

int RunSynthOrientationsCommand(const SynthOrientationsOptions& o, const SynthOptions& synth) {
  LogInfo("parameters: orientations=", o.orientations_file, " mount_error_deg=", o.mount_error_deg,
          " seed=", o.seed);
  synth.Check();
  const SynthOrientationsReport r = RunSynthOrientations(LoadScene(synth.scene), synth, o);
  if (StopRequested()) {
    LogWarning(synth.interval_s >= 0
                   ? "interrupted: the luminaire folder is partial; run the same command again "
                     "to redo it"
                   : "interrupted: nothing was written (a previous folder there is unchanged)");
    return 1;
  }
  if (!r.skipped) {
    int photos = 0;
    for (const SynthReport& d : r.orientations) photos += d.photos_written;
    LogInfo("wrote ", r.orientations.size(), " orientation(s), ", photos, " photos");
  }
  std::printf("luminaire: %s\n", synth.out_dir.c_str());
  return 0;
}

}  // namespace

CLI::App* AddSynthCommand(CLI::App& app, SynthCommand* c, CommonOptions* common) {
  SynthOptions& o = c->options;
  CLI::App* cmd = app.add_subcommand(
      "synth",
      "render the photos of a synthetic scene through both filter slides, a "
      "calibration photo, dataset.json and the analytic truth/ into a dataset folder");
  cmd->add_option("--scene", o.scene,
                  "scene file (JSON), \"default\" or \"full-sphere\" (a luminaire lighting "
                  "every direction, for --orientations)")
      ->required();
  cmd->add_option("--out", o.out_dir, "dataset folder to write");
  cmd->add_option("--interval", o.interval_s,
                  "live acquisition: dataset.json and the calibration photo first, then "
                  "the positions one by one with this pause (s)")
      ->check(FiniteIn(0, 3600));
  cmd->add_flag("--force", o.force, "redo a dataset that is already complete");
  cmd->add_option("--truth-resolution", o.truth_resolution, "texels per side of the truth slab")
      ->capture_default_str();
  cmd->add_option("--photo-format", o.photo_format,
                  "photos of a scene without a quantization effect: half (half-float EXR, "
                  "RLE, lossless for half: ~1 MB a photo) or float (32-bit float EXR)")
      ->check(CLI::IsMember({"half", "float"}))
      ->capture_default_str();
  cmd->add_flag("--compress", o.compress_float,
                "--photo-format float: PIZ-compress the photos (smaller, slower)");
  cmd->add_flag("--camera-folder", o.camera_folder,
                "write the capture as a camera leaves it: camera/IMG_0001.TIF (JPG with a "
                "response, DNG with raw) ... in capture order with EXIF, camera/BOARD.PNG, "
                "setup.json and truth/, no dataset.json (acquire import makes it)");
  cmd->add_option("--calibration-views", o.calibration_views,
                  "also write N photos of a free-standing chessboard of " +
                      std::to_string(kViewBoardInnerCols) + "x" +
                      std::to_string(kViewBoardInnerRows) + " inner corners (" +
                      Num(kViewBoardSquareMm, 6) +
                      " mm squares) in varied poses, for lumislab-calibrate camera, into "
                      "calibration/camera/")
      ->check(CLI::Range(0, kMaxCalibrationViews))
      ->capture_default_str();
  cmd->add_option("--meter", o.meter,
                  "the meter of truth/reference.json: radiometer (W/m2, where the scene's "
                  "calibration_captures ask for a reading) or lux (a lux meter: lux = K x W/m2, K "
                  "the scene's luminous efficacy, " +
                      Num(DefaultLuminousEfficacy(), 4) +
                      " lm/W by default; truth/ in lux; for lumislab-calibrate scale --reference "
                      "and photometric exports)")
      ->check(CLI::IsMember({"radiometer", "lux"}))
      ->capture_default_str();
  cmd->add_option("--orientations", c->orientations.orientations_file,
                  "capture the scene's luminaire from several orientations (a file in "
                  "luminaire.json's format, lumislab-plan orientations --out): --out is then a "
                  "luminaire folder with luminaire.json, one dataset per orientation of the "
                  "luminaire turned by its pose, and truth/ (true poses, the luminaire in its own "
                  "frame; docs/formats.md §19)");
  cmd->add_option("--mount-error-deg", c->orientations.mount_error_deg,
                  "--orientations: turn every orientation but the first by a further rotation "
                  "of angle uniform in [A/2, A] degrees about a random axis (truth/"
                  "orientations.json holds the true poses)")
      ->check(FiniteIn(0, kMaxMountErrorDeg));
  cmd->add_option("--seed", c->orientations.seed, "--orientations: the seed of the mounting errors")
      ->capture_default_str();
  cmd->add_flag("--print-scene", c->print_scene,
                "print the scene as JSON (the built-in one for --scene default or full-sphere) "
                "and exit");
  AddCommonOptions(cmd, common);
  return cmd;
}

int RunSynthCommand(const SynthCommand& command, int threads) {
  if (command.print_scene) return PrintScene(command.options.scene);
  SynthOptions synth = command.options;
  synth.out_dir = TrimTrailingSlashes(synth.out_dir);
  synth.threads = threads;
  std::ostringstream params;
  params << "scene=" << synth.scene << " out=" << synth.out_dir << " interval="
         << (synth.interval_s >= 0 ? std::to_string(synth.interval_s) + " s" : "none")
         << " force=" << (synth.force ? "yes" : "no") << " photo_format=" << synth.photo_format
         << " camera_folder=" << (synth.camera_folder ? "yes" : "no")
         << " calibration_views=" << synth.calibration_views << " meter=" << synth.meter
         << " threads=" << synth.threads;
  LogInfo("parameters: ", params.str());
  const StopSignalScope stop_signals;  // Ctrl-C: finish the photos in hand, then stop
  if (!command.orientations.orientations_file.empty())
    return RunSynthOrientationsCommand(command.orientations, synth);
  if (command.orientations.mount_error_deg > 0)
    throw BadInput("--mount-error-deg: needs --orientations");
  const SynthReport r = RunSynth(synth);
  if (!r.skipped)
    LogInfo("wrote ", r.photos_written, " photos, radiometric scale ", r.radiometric_scale,
            " W/m^2 per unit");
  if (StopRequested()) {
    LogWarning(synth.interval_s >= 0
                   ? "interrupted: the dataset is partial; run the same command again to redo it"
                   : "interrupted: nothing was written (a previous dataset there is unchanged)");
    return 1;
  }
  std::printf("dataset: %s\n", synth.out_dir.c_str());
  return 0;
}

}  // namespace lumislab
