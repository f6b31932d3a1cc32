#include "acquire/capture_list.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/json.h"
#include "lib/photo/photo_io.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

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

std::string Number(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

std::vector<NamedPhoto> ManifestPhotos(const std::string& manifest) {
  CheckInputFile(manifest, "manifest");
  // A row is a short line: a manifest of more than 16 MiB (~250 000 rows) is some other file
  // given by mistake (a photo, a video), whose first "line" read whole could take gigabytes.
  constexpr uintmax_t kMaxManifestBytes = 16 << 20;
  std::error_code ec;
  const uintmax_t bytes = fs::file_size(manifest, ec);
  if (!ec && bytes > kMaxManifestBytes)
    throw InputError(manifest, "size", "a manifest of at most 16 MiB (about 250 000 rows)",
                     std::to_string(bytes) + " bytes");
  std::ifstream in(manifest);
  std::vector<NamedPhoto> out;
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
    NamedPhoto n;
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
      if (!n.exposure || *n.exposure < kMinPhotoExposure || *n.exposure > kMaxPhotoExposure)
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
FilePattern::FilePattern(const std::string& pattern) : pattern_(pattern) {
  static const std::map<std::string, std::string> kGroups = {
      {"i", "([0-9]+)"},
      {"j", "([0-9]+)"},
      {"slide", "(p|n|pos|neg|plus|minus|P|N|POS|NEG)"},
      {"exposure", "([0-9]*\\.?[0-9]+(?:[eE][-+]?[0-9]+)?)"},
      {"bracket", "([0-9]+)"}};
  std::string regex;
  for (size_t k = 0; k < pattern.size();) {
    if (pattern[k] == '{') {
      const size_t end = pattern.find('}', k);
      const std::string name = end == std::string::npos ? "" : pattern.substr(k + 1, end - k - 1);
      if (!kGroups.count(name) || std::count(order_.begin(), order_.end(), name))
        throw InputError("--pattern", "",
                         "placeholders {i} {j} {slide} [{exposure}] [{bracket}], "
                         "each once",
                         pattern);
      regex += kGroups.at(name);
      order_.push_back(name);
      k = end + 1;
    } else {
      if (std::string("\\^$.|?*+()[]{}").find(pattern[k]) != std::string::npos) regex += '\\';
      regex += pattern[k++];
    }
  }
  for (const char* needed : {"i", "j", "slide"})
    if (!std::count(order_.begin(), order_.end(), needed))
      throw InputError("--pattern", "", std::string("a template with {") + needed + "}", pattern);
  regex_ = std::regex(regex);
}

std::optional<NamedPhoto> FilePattern::Match(const std::string& file) const {
  std::smatch m;
  if (!std::regex_match(file, m, regex_)) return std::nullopt;
  NamedPhoto n;
  n.file = file;
  n.where = file;
  for (size_t g = 0; g < order_.size(); ++g) {
    const std::string value = m[int(g) + 1].str();
    const std::string& name = order_[g];
    if (name == "slide") {
      n.positive = *ParseSlide(value);
    } else if (name == "exposure") {
      n.exposure = ParseNumber(value);
      if (!n.exposure || *n.exposure < kMinPhotoExposure || *n.exposure > kMaxPhotoExposure)
        throw InputError(file, "{exposure}", "a relative exposure in [1e-9, 1e9]", value);
    } else {
      const auto index = ParseIndex(value);
      if (!index) throw InputError(file, "{" + name + "}", "an index", value);
      (name == "i" ? n.i : name == "j" ? n.j : n.bracket) = *index;
    }
  }
  return n;
}

size_t OrderedPerSlide(const ImportOptions& o) {
  if (!o.exposures.empty()) return o.exposures.size();
  return size_t(std::max(1, o.brackets));
}

size_t OrderedPhotoCount(const ImportOptions& o, const SamplingGrid& grid) {
  return size_t(grid.count()) * 2 * OrderedPerSlide(o);
}

NamedPhoto OrderedPhoto(const ImportOptions& o, const SamplingGrid& grid, size_t k,
                        const std::string& file) {
  const size_t per_slide = OrderedPerSlide(o);
  NamedPhoto n;
  const size_t position = k / (2 * per_slide), within = k % (2 * per_slide);
  std::tie(n.i, n.j) = ScanPosition(grid, o.scan, int(position));
  n.positive = within < per_slide;
  n.bracket = int(within % per_slide);
  if (!o.exposures.empty()) n.exposure = o.exposures[size_t(n.bracket)];
  n.file = file;
  n.where = file;
  return n;
}

const PhotoExif& PhotoHeaders::Of(const std::string& path) {
  auto it = exif_.find(path);
  if (it == exif_.end()) {
    CheckInputFile(path, "photo");
    DetectPhotoFormat(path);
    it = exif_.emplace(path, ReadPhotoExif(path)).first;
  }
  return it->second;
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
  Dataset::Parse(JsonDocument::Parse(json.dump(2), out_json), out_dir);
  MakeDirectories(out_dir);
  WriteJsonAtomically(out_json, json);
}

CaptureList::CaptureList(const ImportOptions& options, const SamplingGrid& grid)
    : options_(options), grid_(grid) {}

// One camera, one lens, one ISO for the whole capture, as far as the photos tell: the first
// photo that states a field sets it, and a photo that states another value is refused.
void CaptureList::SameCamera(const std::string& path, const std::string& field,
                             const std::optional<std::string>& value) {
  if (!value) return;
  const auto [it, first] = camera_.emplace(field, std::make_pair(*value, path));
  if (!first && it->second.first != *value)
    throw InputError(path, field,
                     "\"" + it->second.first + "\" as in " + it->second.second +
                         " (one camera for the whole capture)",
                     "\"" + *value + "\"");
}

void CaptureList::CheckImageSize(const std::string& path, int width, int height) {
  SameCamera(path, "image size", std::to_string(width) + " x " + std::to_string(height) + " px");
}

void CaptureList::Add(const NamedPhoto& n) {
  if (n.i >= grid_.nu || n.j >= grid_.nv)
    throw InputError(n.where, "position",
                     "i < " + std::to_string(grid_.nu) + " and j < " + std::to_string(grid_.nv) +
                         " (the setup's grid)",
                     "(" + std::to_string(n.i) + ", " + std::to_string(n.j) + ")");
  const std::string path = options_.photos_dir + "/" + n.file;
  const PhotoExif& exif = headers_.Of(path);
  SameCamera(path, "EXIF camera make", exif.make);
  SameCamera(path, "EXIF camera model", exif.model);
  SameCamera(path, "EXIF lens model", exif.lens_model);
  SameCamera(path, "EXIF ISO",
             exif.iso ? std::optional<std::string>(Number(*exif.iso)) : std::nullopt);
  PhotoEntry e;
  e.i = n.i;
  e.j = n.j;
  e.positive = n.positive;
  e.file = n.file;
  if (n.exposure) {
    e.exposure = *n.exposure;
  } else if (const auto relative = exif.RelativeExposure()) {
    if (!(*relative >= kMinPhotoExposure && *relative <= kMaxPhotoExposure))
      throw InputError(path, "EXIF exposure t ISO / N^2", "a value in [1e-9, 1e9]",
                       std::to_string(*relative));
    e.exposure = *relative;
  } else if (options_.exposure) {
    e.exposure = *options_.exposure;
  } else {
    throw BadInput(n.where +
                   ": no exposure for this photo (no EXIF exposure time, f-number and ISO; give "
                   "it in the manifest, the pattern's {exposure}, --exposures, or --exposure "
                   "for all)");
  }
  // The same photo twice, or two photos of one slide at one exposure, would be merged as if
  // they were different measurements.
  const auto [file_it, new_file] = where_of_file_.emplace(e.file, n.where);
  const auto [slide_it, new_slide] =
      where_of_slide_.emplace(std::make_tuple(e.i, e.j, e.positive, e.exposure), n.where);
  if (!new_file || !new_slide)
    throw InputError(n.where, new_file ? "slide and exposure" : "file", "a photo not named before",
                     new_file ? "the same position, slide and exposure as " + slide_it->second
                              : e.file + ", named before by " + file_it->second);
  ++per_slide_[{e.i, e.j, e.positive}];
  entries_.push_back(e);
}

int CaptureList::Count(int i, int j, bool positive) const {
  const auto it = per_slide_.find({i, j, positive});
  return it == per_slide_.end() ? 0 : it->second;
}

int CaptureList::MostPerSlide() const {
  int most = 0;
  for (const auto& [key, count] : per_slide_) most = std::max(most, count);
  return most;
}

std::vector<PhotoEntry> CaptureList::Entries(int per_slide,
                                             std::vector<std::pair<int, int>>* incomplete) const {
  std::vector<PhotoEntry> out;
  for (const PhotoEntry& e : entries_)
    if (Complete(e.i, e.j, per_slide)) out.push_back(e);
  incomplete->clear();
  for (int j = 0; j < grid_.nv; ++j)
    for (int i = 0; i < grid_.nu; ++i)
      if (!Complete(i, j, per_slide)) incomplete->push_back({i, j});
  std::sort(out.begin(), out.end(), [](const PhotoEntry& a, const PhotoEntry& b) {
    return std::make_tuple(a.j, a.i, !a.positive, a.exposure) <
           std::make_tuple(b.j, b.i, !b.positive, b.exposure);
  });
  return out;
}

}  // namespace lumislab
