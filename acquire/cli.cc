#include "acquire/cli.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <sstream>

#include "acquire/filter_print.h"
#include "acquire/import.h"
#include "acquire/synth.h"
#include "acquire/watch.h"
#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"

namespace lumislab {
namespace {

// "(0, 1) (2, 1) ..." for a log line: the first 8 positions, then how many more.
std::string PositionList(const std::vector<std::pair<int, int>>& positions) {
  std::ostringstream os;
  for (size_t k = 0; k < positions.size() && k < 8; ++k)
    os << (k ? " " : "") << "(" << positions[k].first << ", " << positions[k].second << ")";
  if (positions.size() > 8) os << " and " << positions.size() - 8 << " more";
  return os.str();
}

struct SynthCommand {
  SynthOptions options;
  bool print_scene = false;
};

CLI::App* AddSynthCommand(CLI::App& app, SynthCommand* c, CommonOptions* common) {
  SynthOptions& o = c->options;
  CLI::App* cmd = app.add_subcommand(
      "synth",
      "render the photos of a synthetic scene through both filter slides, a "
      "calibration photo, dataset.json and the analytic truth/ into a dataset folder");
  cmd->add_option("--scene", o.scene, "scene file (JSON) or \"default\"")->required();
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
                  "also write N photos of a free-standing 9x6 chessboard (30 mm squares) in "
                  "varied poses, for lumislab-calibrate camera, into calibration/camera/")
      ->check(CLI::Range(0, kMaxCalibrationViews))
      ->capture_default_str();
  cmd->add_flag("--print-scene", c->print_scene,
                "print the scene as JSON (the built-in one for --scene default) and exit");
  AddCommonOptions(cmd, common);
  return cmd;
}

// The options import and watch share: the folder, the setup, the dataset, and how the photos
// are named.
void AddPhotoOptions(CLI::App* cmd, ImportOptions* o) {
  cmd->add_option("--photos", o->photos_dir, "the camera's folder of photos")->required();
  cmd->add_option("--setup", o->setup_file,
                  "setup file: dataset.json without photos (setup, filter, radiometry, "
                  "calibration; calibration.photo relative to --photos)")
      ->required();
  cmd->add_option("--out", o->out_dir, "dataset folder to write")->required();
  cmd->add_option("--manifest", o->manifest, "CSV, one row per photo: i,j,slide,file[,exposure]");
  cmd->add_option("--pattern", o->pattern,
                  "file-name template, e.g. pos_{i}_{j}_{slide}_{exposure}.jpg ({bracket}: "
                  "index in the slide's bracket)");
  cmd->add_option("--order", o->order,
                  "name or capture (EXIF time): the order the photos were taken in (scan "
                  "positions, slide p then n, each bracket)");
  cmd->add_option("--scan", o->scan, "--order: rows, serpentine or columns")->capture_default_str();
  cmd->add_option("--exposures", o->exposures,
                  "--order: the relative exposures of each slide's bracket, in capture order")
      ->delimiter(',');
  cmd->add_option("--brackets", o->brackets,
                  "--order without --exposures, --pattern: photos per slide (each bracket's "
                  "exposures then from EXIF or the template)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--exposure", o->exposure,
                  "relative exposure of every photo that has none of its own")
      ->check(FiniteIn(1e-9, 1e9));
}

CLI::App* AddImportCommand(CLI::App& app, ImportOptions* o, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand(
      "import",
      "a folder of camera photos + a setup file -> dataset.json naming the photos where they are "
      "(nothing is copied)");
  AddPhotoOptions(cmd, o);
  cmd->add_flag("--partial", o->partial,
                "positions without all their photos are listed as missing_positions (with a "
                "warning) instead of refusing the folder");
  cmd->add_flag("--force", o->force, "write dataset.json again if it exists");
  AddCommonOptions(cmd, common);
  return cmd;
}

CLI::App* AddWatchCommand(CLI::App& app, WatchOptions* w, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand(
      "watch",
      "import while the photos arrive (tethered capture): dataset.json at once, rewritten as "
      "each position becomes complete; ends when the grid is, on --idle-timeout or Ctrl-C");
  AddPhotoOptions(cmd, &w->import);
  cmd->add_option("--settle", w->settle_s,
                  "seconds a file's size and time must stay unchanged before it is read")
      ->check(FiniteIn(0, 3600))
      ->capture_default_str();
  cmd->add_option("--poll", w->poll_s, "seconds between two looks at the folder")
      ->check(FiniteIn(0.01, 1))
      ->capture_default_str();
  cmd->add_option("--idle-timeout", w->idle_timeout_s,
                  "stop after this many seconds without a new file (0: wait until complete)")
      ->check(FiniteIn(0, 1e9))
      ->capture_default_str();
  cmd->add_flag("--force", w->import.force, "watch again over a complete dataset.json");
  AddCommonOptions(cmd, common);
  return cmd;
}

int RunImportCommand(ImportOptions o) {
  o.out_dir = TrimTrailingSlashes(o.out_dir);
  o.photos_dir = TrimTrailingSlashes(o.photos_dir);
  LogInfo("parameters: photos=", o.photos_dir, " setup=", o.setup_file, " out=", o.out_dir,
          " manifest=", o.manifest, " pattern=", o.pattern, " order=", o.order, " scan=", o.scan,
          " partial=", o.partial ? "yes" : "no", " force=", o.force ? "yes" : "no");
  const ImportReport r = RunImport(o);
  if (r.skipped) return 0;
  if (!r.unused.empty())
    LogWarning(r.unused.size(), " file(s) of ", o.photos_dir,
               " are not in the dataset (first: ", r.unused.front(), ")");
  if (!r.missing.empty())
    LogWarning("partial dataset: ", r.missing.size(), " position(s) missing (",
               PositionList(r.missing), "), listed in dataset.json missing_positions");
  LogInfo("imported ", r.photos, " photos, ", r.brackets, " exposure(s) per slide");
  std::printf("dataset: %s\n", o.out_dir.c_str());
  return 0;
}

int RunWatchCommand(WatchOptions w) {
  ImportOptions& o = w.import;
  o.out_dir = TrimTrailingSlashes(o.out_dir);
  o.photos_dir = TrimTrailingSlashes(o.photos_dir);
  LogInfo("parameters: photos=", o.photos_dir, " setup=", o.setup_file, " out=", o.out_dir,
          " manifest=", o.manifest, " pattern=", o.pattern, " order=", o.order, " scan=", o.scan,
          " settle=", w.settle_s, " s poll=", w.poll_s, " s idle_timeout=", w.idle_timeout_s,
          " s brackets=", o.brackets, " force=", o.force ? "yes" : "no");
  const StopSignalScope
      stop_signals;  // Ctrl-C: dataset.json stays as the last complete position left it
  const WatchReport r = RunWatch(w);
  if (r.skipped) return 0;
  if (!r.unused.empty())
    LogWarning(r.unused.size(), " file(s) of ", o.photos_dir,
               " are not in the dataset (first: ", r.unused.front(), ")");
  if (!r.complete) {
    LogWarning(
        r.stopped ? "interrupted" : "no new file for " + std::to_string(w.idle_timeout_s) + " s",
        ": the dataset is partial (", r.missing.size(), " position(s) missing",
        r.missing.empty() ? ", and the board photo" : "",
        "); run the same command again to go on watching");
    return 1;
  }
  LogInfo("complete: ", r.photos, " photos");
  std::printf("dataset: %s\n", o.out_dir.c_str());
  return 0;
}

CLI::App* AddFilterCommand(CLI::App& app, FilterPrintOptions* o, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand("filter",
                                     "write the printable filter slides T+ and T- as 16-bit PNG "
                                     "plus filter.json (coefficients, peak, cross-talk)");
  cmd->add_option("--spacing-mm", o->spacing_mm, "grid spacing h (mm)")->capture_default_str();
  cmd->add_option("--k-max", o->k_max, "truncation K of the dual: support +-(K+1)h")
      ->capture_default_str();
  cmd->add_option("--dpi", o->dpi, "print resolution")->capture_default_str();
  cmd->add_option("--out", o->out_dir, "output folder")->required();
  AddCommonOptions(cmd, common);
  return cmd;
}

int RunFilter(const FilterPrintOptions& filter) {
  LogInfo("parameters: spacing_mm=", filter.spacing_mm, " k_max=", filter.k_max,
          " dpi=", filter.dpi, " out=", filter.out_dir);
  const FilterPrintReport r = PrintFilter(filter);
  std::printf("filter slides (%d x %d px, %.3f mm, peak %.6f): %s %s %s\n", r.size_px, r.size_px,
              r.size_mm, r.peak, r.plus_png.c_str(), r.minus_png.c_str(), r.json.c_str());
  return 0;
}

int PrintScene(const std::string& scene) {
  if (scene == "default") {
    std::fputs(DefaultSceneJson().c_str(), stdout);
  } else {
    LoadScene(scene);  // validates
    std::fputs(ReadTextFile(scene).c_str(), stdout);
  }
  return 0;
}

int RunSynthCommand(SynthOptions synth, int threads) {
  synth.out_dir = TrimTrailingSlashes(synth.out_dir);
  synth.threads = threads;
  std::ostringstream params;
  params << "scene=" << synth.scene << " out=" << synth.out_dir << " interval="
         << (synth.interval_s >= 0 ? std::to_string(synth.interval_s) + " s" : "none")
         << " force=" << (synth.force ? "yes" : "no") << " photo_format=" << synth.photo_format
         << " camera_folder=" << (synth.camera_folder ? "yes" : "no")
         << " calibration_views=" << synth.calibration_views << " threads=" << synth.threads;
  LogInfo("parameters: ", params.str());
  const StopSignalScope stop_signals;  // Ctrl-C: finish the photos in hand, then stop
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

}  // namespace

int RunAcquire(int argc, char** argv) {
  CLI::App app{
      "lumislab-acquire: synthetic capture of a luminaire, import of a camera's photos, and "
      "filter-slide printing"};
  app.require_subcommand(1);
  CommonOptions common;
  AddCommonOptions(&app, &common);
  SynthCommand synth;
  FilterPrintOptions filter;
  CLI::App* synth_cmd = AddSynthCommand(app, &synth, &common);
  CLI::App* filter_cmd = AddFilterCommand(app, &filter, &common);
  ImportOptions import;
  CLI::App* import_cmd = AddImportCommand(app, &import, &common);
  WatchOptions watch;
  CLI::App* watch_cmd = AddWatchCommand(app, &watch, &common);
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  const int threads = StartTool("acquire", common);
  if (filter_cmd->parsed()) return RunFilter(filter);
  if (import_cmd->parsed()) return RunImportCommand(import);
  if (watch_cmd->parsed()) return RunWatchCommand(watch);
  if (synth_cmd->parsed() && synth.print_scene) return PrintScene(synth.options.scene);
  return RunSynthCommand(synth.options, threads);
}

}  // namespace lumislab
