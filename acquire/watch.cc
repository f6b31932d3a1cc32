#include "acquire/watch.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "acquire/capture_list.h"
#include "acquire/photo_naming.h"
#include "acquire/settle_tracker.h"
#include "core/checks.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/photo/photo_io.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// A watch reads and decodes one photo after another for as long as the capture lasts. glibc
// serves a buffer above its mmap threshold (the file read, the pixels) from a mapping of its own,
// but raises that threshold to the largest such buffer freed: from then on the photo buffers come
// from the heap, and the small long-lived allocations made between two photos (the photo list,
// dataset.json) land in the holes they leave, so that the heap grows by about a photo per photo
// taken and is never given back (400 x 300 16-bit TIFFs: +0.19 MB a photo, 86 MB after 500). A
// fixed threshold keeps every buffer of 128 kB or more in its own mapping, returned when freed.
void KeepPhotoBuffersOutOfTheHeap() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
}

// The capture as it arrives: which files were taken, the photo list, and dataset.json.
class Watcher {
 public:
  explicit Watcher(const WatchOptions& w)
      : o_(w.import),
        ds_(ImportSkeleton(o_)),
        list_(o_, ds_.grid, "acquire watch"),
        tracker_(w.settle_s) {
    if (!o_.manifest.empty()) {
      // Rows that can never complete the grid are refused now, as import refuses them, rather
      // than waited for.
      const std::vector<NamedPhoto> rows = ManifestPhotos(o_.manifest);
      per_slide_ = CheckManifestCompletes(o_.manifest, rows, ds_.grid);
      for (const NamedPhoto& n : rows) by_file_[n.file].push_back(n);
    } else if (!o_.pattern.empty()) {
      pattern_.emplace(o_.pattern);
      per_slide_ = std::max(1, o_.brackets);
    } else {
      per_slide_ = int(OrderedPerSlide(o_));
    }
    ds_.photos.clear();
    list_.Entries(per_slide_, &ds_.missing_positions);
  }

  // One look at the folder: takes the files that have settled, rewrites dataset.json when a
  // position became complete. Returns whether the folder changed (a file new, growing or gone).
  bool Step() {
    const bool changed = tracker_.Scan(o_.photos_dir);
    for (const std::string& name : kept_)
      if (!tracker_.Has(name)) Gone(name);
    std::vector<std::string> arrived;
    for (const auto& [name, settled] : tracker_.Files()) {
      if (taken_.count(name) || IsDatasetFile(o_, name)) continue;
      // In name order a later name must wait for an earlier one still being copied.
      if (!settled && o_.order == "name") break;
      if (settled) arrived.push_back(name);
    }
    std::vector<std::string> ordered;
    for (const std::string& name : arrived) {
      taken_.insert(name);
      kept_.insert(name);
      if (name == ds_.calibration.photo) {
        DecodePhoto(Path(name));  // an image, whole: BadInput naming it otherwise
        board_ = true;
      } else if (!o_.manifest.empty()) {
        const auto it = by_file_.find(name);
        if (it == by_file_.end()) {
          kept_.erase(name);
          unused_.push_back(name);
          continue;
        }
        CheckPhoto(name);
        for (const NamedPhoto& n : it->second) Add(n);
      } else if (pattern_) {
        const auto n = pattern_->Match(name);
        if (!n) {
          kept_.erase(name);
          unused_.push_back(name);
          continue;
        }
        CheckPhoto(name);
        Add(*n);
      } else {
        CheckPhoto(name);
        ordered.push_back(name);
      }
    }
    AddInOrder(ordered);
    std::vector<std::pair<int, int>> missing;
    std::vector<PhotoEntry> entries = list_.Entries(per_slide_, &missing);
    if (missing != ds_.missing_positions) {
      ds_.photos = std::move(entries);
      ds_.missing_positions = std::move(missing);
      Write();
    }
    return changed;
  }

  void Write() const { WriteImportedDataset(ds_, o_.out_dir); }
  // Every photo taken is still in the folder (looked at now, not at the last scan): the last
  // check before the capture is called complete.
  void CheckKeptPhotos() const {
    for (const std::string& name : kept_) {
      std::error_code ec;
      if (!fs::is_regular_file(Path(name), ec)) Gone(name);
    }
  }
  bool Complete() const { return ds_.missing_positions.empty() && board_; }
  // The complete capture's checks: the board photo's geometry against the slides', and the
  // record of what was compared (checks.json, stage "acquire watch").
  void RecordChecks() {
    list_.CheckBoardGeometry(Path(ds_.calibration.photo));
    CheckLog checks(o_.out_dir, "acquire watch");
    names_and_times_.Record(checks, o_.photos_dir);
    list_.RecordGeometry(checks);
    if (!checks.records().empty()) checks.Save();
  }
  const Dataset& dataset() const { return ds_; }
  const std::vector<std::string>& unused() const { return unused_; }

 private:
  std::string Path(const std::string& name) const { return o_.photos_dir + "/" + name; }

  // The photo decodes, whole, and has the capture's image size.
  void CheckPhoto(const std::string& name) {
    const Photo photo = DecodePhoto(Path(name));
    list_.CheckImageSize(Path(name), photo.pixels.cols, photo.pixels.rows);
  }

  // A photo taken is gone (deleted or moved during the capture). It is not taken off: with
  // --order every later photo would take another place, and reconstruct --watch may have used it
  // already. The lab puts it back or watches the folder again once it holds what it wants.
  [[noreturn]] void Gone(const std::string& name) const {
    throw InputError(Path(name), "photo",
                     "a photo taken by this watch to stay in the folder until the capture is "
                     "complete",
                     "gone (deleted or moved); put it back, or run the watch again (--force) "
                     "once the folder holds the capture");
  }

  void Add(const NamedPhoto& n) {
    list_.Add(n);
    const int count = list_.Count(n.i, n.j, n.positive);
    if (count > per_slide_)
      throw InputError(n.where, "photos",
                       std::to_string(per_slide_) + " photo(s) through slide " +
                           (n.positive ? "p" : "n") + " at position (" + std::to_string(n.i) +
                           ", " + std::to_string(n.j) +
                           ") (--brackets, --exposures or the manifest)",
                       std::to_string(count));
  }

  // --order: the new files take the next places of the capture, in name order or in the order
  // of their EXIF time (equal times in name order). A file that belongs before one already
  // placed came too late: the order cannot be trusted.
  void AddInOrder(std::vector<std::string> files) {
    if (files.empty()) return;
    std::vector<std::pair<std::string, std::string>> keyed;  // (time or "", name)
    for (const std::string& f : files) {
      std::string key;
      if (o_.order == "capture") {
        const PhotoExif& exif = list_.headers().Of(Path(f));
        if (!exif.date_time)
          throw InputError(Path(f), "EXIF DateTimeOriginal", "a capture time (--order capture)",
                           "nothing (missing); use --order name or a manifest");
        key = *exif.date_time;
      }
      keyed.emplace_back(key, f);
    }
    std::sort(keyed.begin(), keyed.end(), Before);
    if (last_ && Before(keyed.front(), *last_))
      throw InputError(Path(keyed.front().second), "capture order",
                       "a photo taken after " + last_->second + ", which is placed already",
                       "one that sorts before it (" +
                           (o_.order == "capture" ? "EXIF time " + keyed.front().first
                                                  : std::string("name order")) +
                           "); use a manifest");
    const size_t expected = OrderedPhotoCount(o_, ds_.grid);
    for (const auto& key : keyed) {
      if (placed_ >= expected)
        throw InputError(Path(key.second), "capture order",
                         "at most " + std::to_string(expected) + " photos (the grid is complete)",
                         "one more");
      // In name order, the EXIF times must not run backwards, as import checks them: a photo in
      // the wrong place shifts every later one.
      if (o_.order == "name") {
        names_and_times_.Next(key.second, list_.headers().Of(Path(key.second)));
        if (!names_and_times_.Agree()) {
          CheckLog checks(o_.out_dir, "acquire watch");
          names_and_times_.Fail(checks, o_.photos_dir);
        }
      }
      Add(OrderedPhoto(o_, ds_.grid, placed_++, key.second));
      last_ = key;
    }
  }

  // Capture order of (EXIF time or "", name): time, then name order (NameOrderLess), as import.
  static bool Before(const std::pair<std::string, std::string>& a,
                     const std::pair<std::string, std::string>& b) {
    if (a.first != b.first) return a.first < b.first;
    return NameOrderLess(a.second, b.second);
  }

  const ImportOptions& o_;
  Dataset ds_;
  CaptureList list_;
  SettleTracker tracker_;
  int per_slide_ = 1;
  std::map<std::string, std::vector<NamedPhoto>> by_file_;  // manifest rows by file
  std::optional<FilePattern> pattern_;
  std::set<std::string> taken_;  // files looked at (placed, the board, or unused)
  std::set<std::string> kept_;   // files taken as photos (placed or the board): must stay
  std::vector<std::string> unused_;
  std::optional<std::pair<std::string, std::string>> last_;  // --order: the last file placed
  size_t placed_ = 0;
  bool board_ = false;
  NameTimeOrder names_and_times_;  // --order name
};

}  // namespace

void WatchOptions::Check() const {
  import.Check();
  if (import.partial) throw BadInput("watch: --partial is import's (watch is partial as it goes)");
  if (!(settle_s >= 0 && settle_s <= 3600))
    throw InputError("--settle", "", "seconds in [0, 3600]", std::to_string(settle_s));
  if (!(poll_s >= 0.01 && poll_s <= 1))
    throw InputError("--poll", "", "seconds in [0.01, 1] (a stop is seen within a second)",
                     std::to_string(poll_s));
  if (!(idle_timeout_s >= 0 && std::isfinite(idle_timeout_s)))
    throw InputError("--idle-timeout", "", "seconds >= 0", std::to_string(idle_timeout_s));
}

WatchReport RunWatch(const WatchOptions& w) {
  w.Check();
  KeepPhotoBuffersOutOfTheHeap();
  const ImportOptions& o = w.import;
  if (!fs::is_directory(o.photos_dir)) throw BadInput(o.photos_dir + ": photo folder not found");
  WatchReport report;
  const std::string out_json = o.out_dir + "/dataset.json";
  // A complete dataset is skipped as import skips it; a partial one (a watch that was stopped)
  // is watched again from the start: the files there are taken again as they settle.
  if (fs::exists(out_json) && !o.force && !Dataset::Load(o.out_dir).Partial()) {
    LogInfo(out_json, " is complete, skipping (use --force to watch again)");
    report.skipped = true;
    return report;
  }
  Watcher watcher(w);
  watcher.Write();
  LogInfo("watching ", o.photos_dir, " (", watcher.dataset().grid.count(), " positions; ",
          "a file is taken once unchanged for ", w.settle_s, " s)");
  auto last_change = Clock::now();
  size_t missing = watcher.dataset().missing_positions.size();
  while (true) {
    if (watcher.Step()) last_change = Clock::now();
    if (watcher.dataset().missing_positions.size() != missing) {
      missing = watcher.dataset().missing_positions.size();
      LogInfo(watcher.dataset().grid.count() - int(missing), "/", watcher.dataset().grid.count(),
              " positions complete");
    }
    if (watcher.Complete()) {
      watcher.CheckKeptPhotos();
      watcher.RecordChecks();
      break;
    }
    if (StopRequested()) {
      report.stopped = true;
      break;
    }
    if (w.idle_timeout_s > 0 && Seconds(Clock::now() - last_change) > w.idle_timeout_s) {
      report.idle = true;
      break;
    }
    PauseUnlessStopped(w.poll_s);
  }
  report.complete = watcher.Complete();
  report.photos = int(watcher.dataset().photos.size());
  report.missing = watcher.dataset().missing_positions;
  report.unused = watcher.unused();
  return report;
}

}  // namespace lumislab
