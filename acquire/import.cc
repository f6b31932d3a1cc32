#include "acquire/import.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/log.h"
#include "lib/photo/exif.h"
#include "lib/photo/photo_io.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

constexpr double kMinExposure = 1e-9, kMaxExposure = 1e9;  // as dataset.json's photos[].exposure

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// p / n and the spellings labs use for them; nullopt for anything else.
std::optional<bool> ParseSlide(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (text == "p" || text == "+" || text == "pos" || text == "plus") return true;
  if (text == "n" || text == "-" || text == "neg" || text == "minus") return false;
  return std::nullopt;
}

// A strictly parsed number (the whole text), or nullopt.
std::optional<double> ParseNumber(const std::string& text) {
  if (text.empty() || text.size() > 40) return std::nullopt;
  std::istringstream in(text);
  double v = 0;
  if (!(in >> v) || !in.eof() || !std::isfinite(v)) return std::nullopt;
  return v;
}
std::optional<int> ParseIndex(const std::string& text) {
  if (text.empty() || text.size() > 6 || text.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  return std::stoi(text);
}

// One photo of the capture as the user's description names it; `where` names the manifest line
// or the file for messages.
struct Named {
  int i = 0, j = 0;
  bool positive = true;
  std::string file;  // relative to the photo folder
  std::optional<double> exposure;
  int bracket = -1;  // index in the slide's bracket, when only that is known
  std::string where;
};

std::vector<Named> FromManifest(const std::string& manifest) {
  CheckInputFile(manifest, "manifest");
  std::ifstream in(manifest);
  std::vector<Named> out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(Trim(cell));
    if (!line.empty() && line.back() == ',') cells.push_back("");
    if (out.empty() && !cells.empty() && cells[0] == "i") continue;  // the header row
    const std::string field = "line " + std::to_string(number);
    if (cells.size() < 4 || cells.size() > 5)
      throw InputError(manifest, field, "i,j,slide,file[,exposure]",
                       std::to_string(cells.size()) + " column(s)");
    Named n;
    const auto i = ParseIndex(cells[0]), j = ParseIndex(cells[1]);
    const auto slide = ParseSlide(cells[2]);
    if (!i) throw InputError(manifest, field + ", column i", "an index >= 0", cells[0]);
    if (!j) throw InputError(manifest, field + ", column j", "an index >= 0", cells[1]);
    if (!slide) throw InputError(manifest, field + ", column slide", "p or n", cells[2]);
    if (cells[3].empty())
      throw InputError(manifest, field + ", column file", "a file name", "\"\"");
    n.i = *i;
    n.j = *j;
    n.positive = *slide;
    n.file = cells[3];
    if (cells.size() == 5 && !cells[4].empty()) {
      n.exposure = ParseNumber(cells[4]);
      if (!n.exposure || *n.exposure < kMinExposure || *n.exposure > kMaxExposure)
        throw InputError(manifest, field + ", column exposure",
                         "a relative exposure in [1e-9, 1e9]", cells[4]);
    }
    n.where = manifest + ": " + field;
    out.push_back(n);
  }
  if (out.empty()) throw InputError(manifest, "rows", "at least one photo row", "none");
  return out;
}

// The template's placeholders become capture groups; the rest matches literally.
std::vector<Named> FromPattern(const std::string& pattern, const std::vector<std::string>& files) {
  static const std::map<std::string, std::string> kGroups = {
      {"i", "([0-9]+)"},
      {"j", "([0-9]+)"},
      {"slide", "(p|n|pos|neg|plus|minus|P|N|POS|NEG)"},
      {"exposure", "([0-9]*\\.?[0-9]+(?:[eE][-+]?[0-9]+)?)"},
      {"bracket", "([0-9]+)"}};
  std::string regex;
  std::vector<std::string> order;
  for (size_t k = 0; k < pattern.size();) {
    if (pattern[k] == '{') {
      const size_t end = pattern.find('}', k);
      const std::string name = end == std::string::npos ? "" : pattern.substr(k + 1, end - k - 1);
      if (!kGroups.count(name) || std::count(order.begin(), order.end(), name))
        throw InputError("--pattern", "",
                         "placeholders {i} {j} {slide} [{exposure}] [{bracket}], "
                         "each once",
                         pattern);
      regex += kGroups.at(name);
      order.push_back(name);
      k = end + 1;
    } else {
      if (std::string("\\^$.|?*+()[]{}").find(pattern[k]) != std::string::npos) regex += '\\';
      regex += pattern[k++];
    }
  }
  for (const char* needed : {"i", "j", "slide"})
    if (!std::count(order.begin(), order.end(), needed))
      throw InputError("--pattern", "", std::string("a template with {") + needed + "}", pattern);
  const std::regex re(regex);
  std::vector<Named> out;
  for (const std::string& file : files) {
    std::smatch m;
    if (!std::regex_match(file, m, re)) continue;
    Named n;
    n.file = file;
    n.where = file;
    for (size_t g = 0; g < order.size(); ++g) {
      const std::string value = m[int(g) + 1].str();
      const std::string& name = order[g];
      if (name == "slide") {
        n.positive = *ParseSlide(value);
      } else if (name == "exposure") {
        n.exposure = ParseNumber(value);
        if (!n.exposure || *n.exposure < kMinExposure || *n.exposure > kMaxExposure)
          throw InputError(file, "{exposure}", "a relative exposure in [1e-9, 1e9]", value);
      } else {
        const auto index = ParseIndex(value);
        if (!index) throw InputError(file, "{" + name + "}", "an index", value);
        (name == "i" ? n.i : name == "j" ? n.j : n.bracket) = *index;
      }
    }
    out.push_back(n);
  }
  if (out.empty()) throw BadInput("--pattern: no file of the photo folder matches " + pattern);
  return out;
}

// Each photo is checked once (a regular file, an image by its content, BadInput naming it
// otherwise) and its EXIF read once, however many steps ask for it.
class PhotoHeaders {
 public:
  const PhotoExif& Of(const std::string& path) {
    auto it = exif_.find(path);
    if (it == exif_.end()) {
      CheckInputFile(path, "photo");
      DetectPhotoFormat(path);
      it = exif_.emplace(path, ReadPhotoExif(path)).first;
    }
    return it->second;
  }

 private:
  std::map<std::string, PhotoExif> exif_;
};

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

// The files in the order of the capture (their name order, or their EXIF time order): position
// by position in the scan, slide p then n, each slide's bracket in the given order.
std::vector<Named> FromOrder(const ImportOptions& o, const SamplingGrid& grid,
                             const std::vector<std::string>& files) {
  const size_t per_slide = std::max<size_t>(1, o.exposures.size());
  const size_t expected = size_t(grid.count()) * 2 * per_slide;
  if (files.size() != expected) {
    std::ostringstream got;
    got << files.size() << " photos";
    if (files.size() < expected) {
      const size_t complete = files.size() / (2 * per_slide);
      const auto [i, j] = ScanPosition(grid, o.scan, int(complete));
      got << " (the first missing: position (" << i << ", " << j << "), " << complete
          << " positions complete)";
    }
    throw InputError(o.photos_dir, "photos",
                     std::to_string(expected) + " photos (" + std::to_string(grid.count()) +
                         " positions x 2 slides x " + std::to_string(per_slide) + " exposure(s))",
                     got.str());
  }
  std::vector<Named> out;
  for (size_t k = 0; k < files.size(); ++k) {
    Named n;
    const size_t position = k / (2 * per_slide), within = k % (2 * per_slide);
    std::tie(n.i, n.j) = ScanPosition(grid, o.scan, int(position));
    n.positive = within < per_slide;
    n.bracket = int(within % per_slide);
    if (!o.exposures.empty()) n.exposure = o.exposures[size_t(n.bracket)];
    n.file = files[k];
    n.where = files[k];
    out.push_back(n);
  }
  return out;
}

// One camera, one lens, one ISO for the whole capture, as far as the photos' EXIF tells: the
// first photo that states a field sets it, and a photo that states another value is refused.
class SameCamera {
 public:
  void Check(const std::string& path, const PhotoExif& exif) {
    Field(path, "EXIF camera make", exif.make, make_);
    Field(path, "EXIF camera model", exif.model, model_);
    Field(path, "EXIF lens model", exif.lens_model, lens_);
    Field(path, "EXIF ISO", exif.iso ? std::optional<std::string>(Number(*exif.iso)) : std::nullopt,
          iso_);
  }

 private:
  static std::string Number(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  }
  static void Field(const std::string& path, const std::string& field,
                    const std::optional<std::string>& value,
                    std::optional<std::pair<std::string, std::string>>& first) {
    if (!value) return;
    if (!first) {
      first = std::make_pair(*value, path);
    } else if (first->first != *value) {
      throw InputError(
          path, field,
          "\"" + first->first + "\" as in " + first->second + " (one camera for the whole capture)",
          "\"" + *value + "\"");
    }
  }
  std::optional<std::pair<std::string, std::string>> make_, model_, lens_, iso_;
};

// The named photos as dataset entries, with every check a lab wants before a long run.
std::vector<PhotoEntry> ToEntries(const std::vector<Named>& named, const ImportOptions& o,
                                  const SamplingGrid& grid, PhotoHeaders& headers) {
  std::vector<PhotoEntry> entries;
  std::map<std::tuple<int, int, bool>, int> per_slide;
  std::map<std::string, std::string> where_of_file;
  SameCamera camera;
  std::map<std::tuple<int, int, bool, double>, std::string> where_of_slide;
  for (const Named& n : named) {
    if (n.i >= grid.nu || n.j >= grid.nv)
      throw InputError(n.where, "position",
                       "i < " + std::to_string(grid.nu) + " and j < " + std::to_string(grid.nv) +
                           " (the setup's grid)",
                       "(" + std::to_string(n.i) + ", " + std::to_string(n.j) + ")");
    const std::string path = o.photos_dir + "/" + n.file;
    const PhotoExif& exif = headers.Of(path);
    camera.Check(path, exif);
    PhotoEntry e;
    e.i = n.i;
    e.j = n.j;
    e.positive = n.positive;
    e.file = n.file;
    if (n.exposure) {
      e.exposure = *n.exposure;
    } else if (const auto relative = exif.RelativeExposure()) {
      if (!(*relative >= kMinExposure && *relative <= kMaxExposure))
        throw InputError(path, "EXIF exposure t ISO / N^2", "a value in [1e-9, 1e9]",
                         std::to_string(*relative));
      e.exposure = *relative;
    } else if (o.exposure) {
      e.exposure = *o.exposure;
    } else {
      throw BadInput(n.where +
                     ": no exposure for this photo (no EXIF exposure time, f-number and ISO; give "
                     "it in the manifest, the pattern's {exposure}, --exposures, or --exposure "
                     "for all)");
    }
    // The same photo twice, or two photos of one slide at one exposure, would be merged as if
    // they were different measurements.
    const auto [file_it, new_file] = where_of_file.emplace(e.file, n.where);
    const auto [slide_it, new_slide] =
        where_of_slide.emplace(std::make_tuple(e.i, e.j, e.positive, e.exposure), n.where);
    if (!new_file || !new_slide)
      throw InputError(n.where, new_file ? "slide and exposure" : "file",
                       "a photo not named before",
                       new_file ? "the same position, slide and exposure as " + slide_it->second
                                : e.file + ", named before by " + file_it->second);
    ++per_slide[{e.i, e.j, e.positive}];
    entries.push_back(e);
  }
  // Complete: both slides everywhere, every slide with the same number of exposures.
  int brackets = 0;
  for (const auto& [key, count] : per_slide) brackets = std::max(brackets, count);
  for (int j = 0; j < grid.nv; ++j)
    for (int i = 0; i < grid.nu; ++i)
      for (const bool positive : {true, false}) {
        const auto it = per_slide.find({i, j, positive});
        const int count = it == per_slide.end() ? 0 : it->second;
        if (count != brackets)
          throw InputError(o.photos_dir, "photos",
                           std::to_string(brackets) + " photo(s) through slide " +
                               (positive ? "p" : "n") + " at every position",
                           std::to_string(count) + " at position (" + std::to_string(i) + ", " +
                               std::to_string(j) + ")");
      }
  std::sort(entries.begin(), entries.end(), [](const PhotoEntry& a, const PhotoEntry& b) {
    return std::make_tuple(a.j, a.i, !a.positive, a.exposure) <
           std::make_tuple(b.j, b.i, !b.positive, b.exposure);
  });
  return entries;
}

}  // namespace

std::pair<int, int> ScanPosition(const SamplingGrid& grid, const std::string& scan, int k) {
  if (scan == "columns") return {k / grid.nv, k % grid.nv};
  const int j = k / grid.nu, along = k % grid.nu;
  return {scan == "serpentine" && j % 2 == 1 ? grid.nu - 1 - along : along, j};
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
    if (!(e >= kMinExposure && e <= kMaxExposure))
      throw InputError("--exposures", "", "relative exposures in [1e-9, 1e9]", std::to_string(e));
  if (std::set<double>(exposures.begin(), exposures.end()).size() != exposures.size())
    throw InputError("--exposures", "", "different exposures", "a repeated value");
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
  Dataset ds = Dataset::Parse(JsonDocument::Load(o.setup_file), o.out_dir, false);
  ds.synthetic = false;
  // The photo folder as the dataset will name it: relative to the dataset folder, so that the
  // two can move together.
  const fs::path photos = fs::weakly_canonical(fs::absolute(o.photos_dir));
  const fs::path out = fs::weakly_canonical(fs::absolute(o.out_dir));
  ds.photo_folder = photos.lexically_relative(out).string();
  if (ds.photo_folder.empty()) ds.photo_folder = photos.string();
  if (ds.photo_folder == ".") ds.photo_folder = "";

  const std::string calibration = o.photos_dir + "/" + ds.calibration.photo;
  CheckInputFile(calibration, "calibration photo");
  DetectPhotoFormat(calibration);
  std::vector<std::string> files;
  for (const std::string& f : FolderFiles(o.photos_dir))
    if (f != ds.calibration.photo) files.push_back(f);

  PhotoHeaders headers;
  if (o.order == "capture") files = ByCaptureTime(o.photos_dir, files, headers);
  std::vector<Named> named = !o.manifest.empty()  ? FromManifest(o.manifest)
                             : !o.pattern.empty() ? FromPattern(o.pattern, files)
                                                  : FromOrder(o, ds.grid, files);
  ds.photos = ToEntries(named, o, ds.grid, headers);
  std::set<std::string> used;
  for (const auto& e : ds.photos) used.insert(e.file);
  for (const std::string& f : files)
    if (!used.count(f)) report.unused.push_back(f);

  // Read back through the one dataset reader (duplicates, ranges) before it is written.
  const nlohmann::json json = ds.ToJson();
  Dataset::Parse(JsonDocument::Parse(json.dump(2), out_json), o.out_dir);
  MakeDirectories(o.out_dir);
  WriteJsonAtomically(out_json, json);
  report.photos = int(ds.photos.size());
  report.brackets = int(ds.photos.size()) / (2 * ds.grid.count());
  return report;
}

}  // namespace lumislab
