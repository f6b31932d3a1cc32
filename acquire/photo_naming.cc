#include "acquire/photo_naming.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <tuple>

#include "core/error.h"
#include "core/input_file.h"

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

void CheckInGrid(const NamedPhoto& n, const SamplingGrid& grid) {
  if (n.i >= grid.nu || n.j >= grid.nv)
    throw InputError(n.where, "position",
                     "i < " + std::to_string(grid.nu) + " and j < " + std::to_string(grid.nv) +
                         " (the setup's grid)",
                     "(" + std::to_string(n.i) + ", " + std::to_string(n.j) + ")");
}

int CheckManifestCompletes(const std::string& manifest, const std::vector<NamedPhoto>& rows,
                           const SamplingGrid& grid) {
  std::map<std::tuple<int, int, bool>, int> count;
  int per_slide = 0;
  for (const NamedPhoto& n : rows) {
    CheckInGrid(n, grid);
    per_slide = std::max(per_slide, ++count[{n.i, n.j, n.positive}]);
  }
  for (int j = 0; j < grid.nv; ++j)
    for (int i = 0; i < grid.nu; ++i)
      for (const bool positive : {true, false}) {
        const auto it = count.find({i, j, positive});
        const int got = it == count.end() ? 0 : it->second;
        if (got != per_slide)
          throw InputError(manifest, "rows",
                           std::to_string(per_slide) + " row(s) for slide " +
                               (positive ? "p" : "n") + " at every position of the setup's grid",
                           std::to_string(got) + " at position (" + std::to_string(i) + ", " +
                               std::to_string(j) + ")");
      }
  return per_slide;
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

}  // namespace lumislab
