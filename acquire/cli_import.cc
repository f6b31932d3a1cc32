#include "acquire/cli_import.h"

#include <cstdio>
#include <sstream>

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

}  // namespace

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

}  // namespace lumislab
