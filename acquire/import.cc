#include "acquire/import.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "acquire/capture_list.h"
#include "acquire/photo_naming.h"
#include "core/atomic_file.h"
#include "core/checks.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/log.h"
#include "lib/photo/exif.h"
#include "lib/photo/photo_io.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// The files sorted by the time their EXIF gives (DateTimeOriginal, to the second; equal times,
// as in a fast bracket, keep name order). A photo without one is refused: its place is unknown.
std::vector<std::string> ByCaptureTime(const std::string& dir,
                                       const std::vector<std::string>& files,
                                       PhotoHeaders& headers) {
  std::vector<std::pair<std::string, std::string>> timed;
  for (const std::string& f : files) {
    const std::string path = dir + "/" + f;
    const PhotoExif& exif = headers.Of(path);
    if (!exif.date_time)
      throw InputError(path, "EXIF DateTimeOriginal", "a capture time (--order capture)",
                       "nothing (missing); use --order name or a manifest");
    timed.emplace_back(*exif.date_time, f);
  }
  std::stable_sort(timed.begin(), timed.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> out;
  for (const auto& t : timed) out.push_back(t.second);
  return out;
}

// order.positions_and_times: with --manifest or --pattern the file names give the positions; where
// the photos have EXIF times, each slide's positions must follow in time the order the capture
// implies: the manifest's own rows (the first row naming each position and slide), or for a
// pattern the setup's scan (--scan). Per slide, because a lab may shoot every position through
// T+ and then every one through T- (one slide change) as well as both slides at each position;
// a position's photos (its bracket) may come in any order among themselves. A warning only: a
// manifest may list its rows in grid order rather than capture order, and a pattern capture
// may have been scanned another way than --scan says; but where the rows were written as the
// photos were taken, a backward pair is two files given each other's places.
void CheckPositionsInTime(const ImportOptions& o, const SamplingGrid& grid,
                          const std::vector<NamedPhoto>& named, PhotoHeaders& headers,
                          CheckLog& checks) {
  std::map<std::pair<int, int>, int> scan_rank;
  for (int k = 0; k < grid.count(); ++k) scan_rank[ScanPosition(grid, o.scan, k)] = k;
  struct Span {
    int rank = 0;
    std::string first, last, first_file, last_file;  // earliest and latest EXIF time, and files
    int i = 0, j = 0;
  };
  std::map<std::tuple<bool, int, int>, Span> spans;  // (slide, i, j)
  for (size_t row = 0; row < named.size(); ++row) {
    const NamedPhoto& n = named[row];
    const PhotoExif& exif = headers.Of(o.photos_dir + "/" + n.file);
    if (!exif.date_time) continue;
    const auto [it, first] = spans.try_emplace({n.positive, n.i, n.j});
    Span& s = it->second;
    if (first) {
      s.rank = !o.manifest.empty() ? int(row) : scan_rank[{n.i, n.j}];
      s.i = n.i, s.j = n.j;
      s.first = s.last = *exif.date_time;
      s.first_file = s.last_file = n.file;
    }
    if (*exif.date_time < s.first) s.first = *exif.date_time, s.first_file = n.file;
    if (*exif.date_time > s.last) s.last = *exif.date_time, s.last_file = n.file;
  }
  int compared = 0, backward = 0;
  std::string message;
  for (const bool positive : {true, false}) {
    std::vector<const Span*> order;
    for (const auto& [key, span] : spans)
      if (std::get<0>(key) == positive) order.push_back(&span);
    std::sort(order.begin(), order.end(),
              [](const Span* a, const Span* b) { return a->rank < b->rank; });
    for (size_t k = 1; k < order.size(); ++k) {
      ++compared;
      const Span& a = *order[k - 1];
      const Span& b = *order[k];
      if (!(b.first < a.last)) continue;  // equal times (to the second) agree
      if (backward++ > 0) continue;
      const auto at = [](const Span& s) {
        return "(" + std::to_string(s.i) + ", " + std::to_string(s.j) + ")";
      };
      message = o.photos_dir + "/" + b.first_file + ": EXIF time " + b.first + " (slide " +
                (positive ? "p" : "n") + " at position " + at(b) + ") is before " + a.last +
                " of " + a.last_file + " at position " + at(a) + ", which " +
                (!o.manifest.empty()
                     ? o.manifest +
                           " lists before it: the rows are not in capture order, or "
                           "(if they were written as the photos were taken) they give "
                           "these files each other's places"
                     : "the scan (--scan " + o.scan +
                           ") takes before it: the grid was scanned another way, or the names "
                           "carry the wrong positions");
    }
  }
  if (compared == 0) return;  // no record where nothing was compared
  const nlohmann::json values = {
      {"position_pairs_compared", compared},
      {"backward_pairs", backward},
      {"order", !o.manifest.empty() ? "manifest rows" : "scan " + o.scan}};
  if (backward == 0)
    checks.Pass("order.positions_and_times",
                std::to_string(compared) +
                    " pairs of consecutive positions (per slide) follow in EXIF "
                    "time the order " +
                    (!o.manifest.empty() ? "of the manifest's rows"
                                         : "of the scan (--scan " + o.scan + ")"),
                values);
  else
    checks.Warn("order.positions_and_times",
                message + " (" + std::to_string(backward) + " of " + std::to_string(compared) +
                    " pairs of consecutive positions backward)",
                values);
}

// A photo count one more than the capture's: name the candidates (a stray test shot is the
// first or the last photo).
std::string StrayHint(const std::vector<std::string>& files, size_t expected) {
  if (files.size() != expected + 1 || files.size() < 3) return "";
  return "; one photo more than the capture: a stray test shot? (the first photo is " +
         files.front() + ", the last " + files.back() + ")";
}

// The files in the order of the capture (their name order, or their EXIF time order). All of
// them, or with --partial a capture that stopped early: the positions after the last photo are
// missing.
std::vector<NamedPhoto> FromOrder(const ImportOptions& o, const SamplingGrid& grid,
                                  const std::vector<std::string>& files) {
  const size_t per_slide = OrderedPerSlide(o);
  const size_t expected = OrderedPhotoCount(o, grid);
  if (files.size() > expected || (files.size() < expected && !o.partial)) {
    std::ostringstream got;
    got << files.size() << " photos";
    if (files.size() < expected) {
      const size_t complete = files.size() / (2 * per_slide);
      const auto [i, j] = ScanPosition(grid, o.scan, int(complete));
      got << " (the first missing: position (" << i << ", " << j << "), " << complete
          << " positions complete; --partial imports them)";
    }
    throw InputError(o.photos_dir, "photos",
                     std::to_string(expected) + " photos (" + std::to_string(grid.count()) +
                         " positions x 2 slides x " + std::to_string(per_slide) + " exposure(s))",
                     got.str() + StrayHint(files, expected));
  }
  std::vector<NamedPhoto> out;
  for (size_t k = 0; k < files.size(); ++k) out.push_back(OrderedPhoto(o, grid, k, files[k]));
  return out;
}

std::vector<NamedPhoto> FromPattern(const std::string& pattern,
                                    const std::vector<std::string>& files) {
  const FilePattern matcher(pattern);
  std::vector<NamedPhoto> out;
  for (const std::string& file : files)
    if (auto n = matcher.Match(file)) out.push_back(*n);
  if (out.empty()) throw BadInput("--pattern: no file of the photo folder matches " + pattern);
  return out;
}

// Both slides everywhere, every slide with as many exposures as the fullest one: the first
// position that is not is an error (BadInput naming the slide), or with --partial a missing
// position.
std::vector<PhotoEntry> CompleteEntries(const CaptureList& list, const ImportOptions& o,
                                        const SamplingGrid& grid,
                                        std::vector<std::pair<int, int>>* missing) {
  const int brackets = !o.order.empty() ? int(OrderedPerSlide(o))
                       : o.brackets > 0 ? o.brackets
                                        : list.MostPerSlide();
  std::vector<PhotoEntry> entries = list.Entries(brackets, missing);
  if (o.partial && missing->size() < size_t(grid.count())) return entries;
  if (missing->empty()) return entries;
  const auto [i, j] = missing->front();
  const bool positive = list.Count(i, j, true) != brackets;
  throw InputError(o.photos_dir, "photos",
                   std::to_string(brackets) + " photo(s) through slide " + (positive ? "p" : "n") +
                       " at every position",
                   std::to_string(list.Count(i, j, positive)) + " at position (" +
                       std::to_string(i) + ", " + std::to_string(j) + ")" +
                       (o.partial ? " (no position complete)" : ""));
}

}  // namespace

std::pair<int, int> ScanPosition(const SamplingGrid& grid, const std::string& scan, int k) {
  if (scan == "columns") return {k / grid.nv, k % grid.nv};
  const int j = k / grid.nu, along = k % grid.nu;
  return {scan == "serpentine" && j % 2 == 1 ? grid.nu - 1 - along : along, j};
}

bool IsDatasetFile(const ImportOptions& o, const std::string& name) {
  if (name != "dataset.json") return false;
  std::error_code ec;
  return fs::equivalent(o.photos_dir, o.out_dir, ec) && !ec;
}

void ImportOptions::Check() const {
  const int ways = !manifest.empty() + !pattern.empty() + !order.empty();
  if (ways != 1)
    throw BadInput("import: give exactly one of --manifest, --pattern and --order (got " +
                   std::to_string(ways) + ")");
  if (!order.empty() && order != "name" && order != "capture")
    throw InputError("--order", "", "name or capture", order);
  if (scan != "rows" && scan != "serpentine" && scan != "columns")
    throw InputError("--scan", "", "rows, serpentine or columns", scan);
  if (order.empty() && !exposures.empty())
    throw BadInput("--exposures: only with --order (a manifest or pattern names each exposure)");
  for (const double e : exposures)
    if (!(e >= kMinPhotoExposure && e <= kMaxPhotoExposure))
      throw InputError("--exposures", "", "relative exposures in [1e-9, 1e9]", std::to_string(e));
  if (brackets < 0 || brackets > 100)
    throw InputError("--brackets", "", "1 .. 100 photos per slide", std::to_string(brackets));
  if (brackets > 0 && !manifest.empty())
    throw BadInput("--brackets: only with --order or --pattern (a manifest names each photo)");
  if (brackets > 0 && !exposures.empty() && size_t(brackets) != exposures.size())
    throw InputError("--brackets", "",
                     "the number of --exposures (" + std::to_string(exposures.size()) + ")",
                     std::to_string(brackets));
  if (std::set<double>(exposures.begin(), exposures.end()).size() != exposures.size())
    throw InputError("--exposures", "", "different exposures", "a repeated value");
}

Dataset ImportSkeleton(const ImportOptions& o) {
  Dataset ds = Dataset::Parse(JsonDocument::Load(o.setup_file), o.out_dir, false);
  ds.synthetic = false;
  // The photo folder as the dataset will name it: relative to the dataset folder, so that the
  // two can move together.
  const fs::path photos = fs::weakly_canonical(fs::absolute(o.photos_dir));
  const fs::path out = fs::weakly_canonical(fs::absolute(o.out_dir));
  ds.photo_folder = photos.lexically_relative(out).string();
  if (ds.photo_folder.empty()) ds.photo_folder = photos.string();
  if (ds.photo_folder == ".") ds.photo_folder = "";
  return ds;
}

void WriteImportedDataset(const Dataset& ds, const std::string& out_dir) {
  const std::string out_json = out_dir + "/dataset.json";
  const nlohmann::json json = ds.ToJson();
  Dataset::Parse(JsonDocument::Parse(DumpJson(json, out_json), out_json), out_dir);
  MakeDirectories(out_dir);
  WriteJsonAtomically(out_json, json);
}

ImportReport RunImport(const ImportOptions& o) {
  o.Check();
  if (!fs::is_directory(o.photos_dir)) throw BadInput(o.photos_dir + ": photo folder not found");
  ImportReport report;
  const std::string out_json = o.out_dir + "/dataset.json";
  if (fs::exists(out_json) && !o.force) {
    LogInfo(out_json, " exists, skipping (use --force to import again)");
    report.skipped = true;
    return report;
  }
  Dataset ds = ImportSkeleton(o);
  const std::string calibration = o.photos_dir + "/" + ds.calibration.photo;
  CheckInputFile(calibration, "calibration photo");
  DetectPhotoFormat(calibration);
  std::vector<std::string> files;
  for (const std::string& f : FolderFiles(o.photos_dir))
    if (f != ds.calibration.photo && !IsDatasetFile(o, f)) files.push_back(f);

  CaptureList list(o, ds.grid, "acquire import");
  // Every order the folder states, cross-checked where there are two: with --order, the names'
  // and the EXIF times'. --order name against times that run backwards is refused (a photo in
  // the wrong place shifts every later one); --order capture against names that do is a warning
  // (a camera's counter wraps at 9999, two cards).
  NameTimeOrder names_and_times;
  if (!o.order.empty()) {
    for (const std::string& f : files)
      names_and_times.Next(f, list.headers().Of(o.photos_dir + "/" + f));
    if (o.order == "name" && !names_and_times.Agree()) {
      CheckLog checks(fs::is_directory(o.out_dir) ? o.out_dir : "", "acquire import");
      names_and_times.Fail(checks, o.photos_dir);
    }
  }
  if (o.order == "capture") files = ByCaptureTime(o.photos_dir, files, list.headers());
  const std::vector<NamedPhoto> named = !o.manifest.empty()  ? ManifestPhotos(o.manifest)
                                        : !o.pattern.empty() ? FromPattern(o.pattern, files)
                                                             : FromOrder(o, ds.grid, files);
  for (const NamedPhoto& n : named) list.Add(n);
  // Watch makes the same check before any photo arrives (the message names the manifest).
  if (!o.manifest.empty() && !o.partial) CheckManifestCompletes(o.manifest, named, ds.grid);
  ds.photos = CompleteEntries(list, o, ds.grid, &ds.missing_positions);
  list.CheckBoardGeometry(calibration);
  std::set<std::string> used;
  for (const auto& e : ds.photos) used.insert(e.file);
  for (const std::string& f : files)
    if (!used.count(f)) report.unused.push_back(f);

  WriteImportedDataset(ds, o.out_dir);
  CheckLog checks(o.out_dir, "acquire import");
  names_and_times.Record(checks, o.photos_dir);
  list.RecordGeometry(checks);
  if (o.order.empty()) CheckPositionsInTime(o, ds.grid, named, list.headers(), checks);
  if (!checks.records().empty()) checks.Save();  // (no record where nothing was compared)
  report.photos = int(ds.photos.size());
  report.brackets = ds.photos.empty() ? 0 : list.MostPerSlide();
  report.missing = ds.missing_positions;
  return report;
}

}  // namespace lumislab
