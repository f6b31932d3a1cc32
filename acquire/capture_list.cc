#include "acquire/capture_list.h"

#include <algorithm>
#include <sstream>

#include "core/error.h"
#include "core/input_file.h"
#include "lib/photo/photo_io.h"

namespace lumislab {
namespace {

std::string Number(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

const PhotoExif& PhotoHeaders::Of(const std::string& path) {
  auto it = exif_.find(path);
  if (it == exif_.end()) {
    CheckInputFile(path, "photo");
    DetectPhotoFormat(path);
    it = exif_.emplace(path, ReadPhotoExif(path)).first;
  }
  return it->second;
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
  CheckInGrid(n, grid_);
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
