#include "acquire/import.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <sstream>

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

// How the photos' name order and their EXIF time order agree (order.names_and_times): the
// photos with a time, compared in name order; the first pair whose times run backwards.
struct OrderAgreement {
  int timed = 0;        // photos with an EXIF time
  int equal_times = 0;  // consecutive (in name order) photos with the same time, to the second
  std::string earlier, later, earlier_time, later_time;  // the first backward pair, by name
  bool Agree() const { return earlier.empty(); }
};

// `files` in name order (FolderFiles, NameOrderLess: capt2 before capt10).
OrderAgreement CompareNameAndTimeOrder(const std::string& dir,
                                       const std::vector<std::string>& files,
                                       PhotoHeaders& headers) {
  OrderAgreement out;
  const std::string* previous = nullptr;
  std::string previous_time;
  for (const std::string& f : files) {
    const PhotoExif& exif = headers.Of(dir + "/" + f);
    if (!exif.date_time) continue;
    ++out.timed;
    if (previous) {
      out.equal_times += *exif.date_time == previous_time;
      if (*exif.date_time < previous_time && out.Agree()) {
        out.earlier = *previous, out.later = f;
        out.earlier_time = previous_time, out.later_time = *exif.date_time;
      }
    }
    previous = &f;
    previous_time = *exif.date_time;
  }
  return out;
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

  CaptureList list(o, ds.grid);
  // Every order the folder states, cross-checked where there are two: with --order, the names'
  // and the EXIF times'. --order name against times that run backwards is refused (a photo in
  // the wrong place shifts every later one); --order capture against names that do is a warning
  // (a camera's counter wraps at 9999, two cards).
  OrderAgreement agreement;
  if (!o.order.empty()) {
    agreement = CompareNameAndTimeOrder(o.photos_dir, files, list.headers());
    if (o.order == "name" && !agreement.Agree())
      CheckLog(fs::is_directory(o.out_dir) ? o.out_dir : "", "acquire import")
          .Fail("order.names_and_times",
                o.photos_dir + "/" + agreement.later + ": EXIF DateTimeOriginal: expected " +
                    agreement.earlier_time + " or later (--order name: taken after " +
                    agreement.earlier + "), got " + agreement.later_time +
                    ": the name order is not the capture order (--order capture follows the "
                    "EXIF time)",
                {{"earlier", agreement.earlier}, {"later", agreement.later}});
  }
  if (o.order == "capture") files = ByCaptureTime(o.photos_dir, files, list.headers());
  const std::vector<NamedPhoto> named = !o.manifest.empty()  ? ManifestPhotos(o.manifest)
                                        : !o.pattern.empty() ? FromPattern(o.pattern, files)
                                                             : FromOrder(o, ds.grid, files);
  for (const NamedPhoto& n : named) list.Add(n);
  // Watch makes the same check before any photo arrives (the message names the manifest).
  if (!o.manifest.empty() && !o.partial) CheckManifestCompletes(o.manifest, named, ds.grid);
  ds.photos = CompleteEntries(list, o, ds.grid, &ds.missing_positions);
  std::set<std::string> used;
  for (const auto& e : ds.photos) used.insert(e.file);
  for (const std::string& f : files)
    if (!used.count(f)) report.unused.push_back(f);

  WriteImportedDataset(ds, o.out_dir);
  if (agreement.timed > 1) {  // (no record where nothing was compared)
    CheckLog checks(o.out_dir, "acquire import");
    const nlohmann::json values = {{"photos_with_time", agreement.timed},
                                   {"equal_consecutive_times", agreement.equal_times}};
    if (agreement.Agree())
      checks.Pass("order.names_and_times",
                  std::to_string(agreement.timed) +
                      " photos: name order and EXIF time order agree (" +
                      std::to_string(agreement.equal_times) +
                      " consecutive pairs with the same time, to the second)",
                  values);
    else
      checks.Warn("order.names_and_times",
                  o.photos_dir + "/" + agreement.later + ": EXIF time " + agreement.later_time +
                      " is before that of " + agreement.earlier + " (" + agreement.earlier_time +
                      "), which comes before it by name: the photos were ordered by their time "
                      "(--order capture)",
                  values);
    checks.Save();
  }
  report.photos = int(ds.photos.size());
  report.brackets = ds.photos.empty() ? 0 : list.MostPerSlide();
  report.missing = ds.missing_positions;
  return report;
}

}  // namespace lumislab
