#include "acquire/capture_list.h"

#include <algorithm>
#include <filesystem>
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

// EXIF Orientation as a person reads it (decoders turn the pixels by it).
std::string OrientationText(int orientation) {
  const char* what = orientation == 1   ? "upright"
                     : orientation == 3 ? "turned 180 degrees"
                     : orientation == 6 ? "turned 90 degrees clockwise"
                     : orientation == 8 ? "turned 90 degrees counter-clockwise"
                                        : "mirrored";
  return std::to_string(orientation) + " (" + what + ")";
}

}  // namespace

void NameTimeOrder::Next(const std::string& name, const PhotoExif& exif) {
  if (!exif.date_time) return;
  ++timed_;
  if (!previous_.empty()) {
    equal_times_ += *exif.date_time == previous_time_;
    if (*exif.date_time < previous_time_ && Agree()) {
      earlier_ = previous_, later_ = name;
      earlier_time_ = previous_time_, later_time_ = *exif.date_time;
    }
  }
  previous_ = name;
  previous_time_ = *exif.date_time;
}

nlohmann::json NameTimeOrder::Values() const {
  nlohmann::json values = {{"photos_with_time", timed_}, {"equal_consecutive_times", equal_times_}};
  if (!Agree()) values["earlier"] = earlier_, values["later"] = later_;
  return values;
}

void NameTimeOrder::Fail(CheckLog& checks, const std::string& photos_dir) const {
  checks.Fail("order.names_and_times",
              photos_dir + "/" + later_ + ": EXIF DateTimeOriginal: expected " + earlier_time_ +
                  " or later (--order name: taken after " + earlier_ + "), got " + later_time_ +
                  ": the name order is not the capture order (--order capture follows the "
                  "EXIF time)",
              Values());
}

void NameTimeOrder::Record(CheckLog& checks, const std::string& photos_dir) const {
  if (timed_ < 2) return;  // no record where nothing was compared
  if (Agree())
    checks.Pass("order.names_and_times",
                std::to_string(timed_) + " photos: name order and EXIF time order agree (" +
                    std::to_string(equal_times_) +
                    " consecutive pairs with the same time, to the second)",
                Values());
  else
    checks.Warn("order.names_and_times",
                photos_dir + "/" + later_ + ": EXIF time " + later_time_ + " is before that of " +
                    earlier_ + " (" + earlier_time_ +
                    "), which comes before it by name: the photos were ordered by their time "
                    "(--order capture)",
                Values());
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

CaptureList::CaptureList(const ImportOptions& options, const SamplingGrid& grid, std::string stage)
    : options_(options), grid_(grid), stage_(std::move(stage)) {}

// camera.same_geometry: the screen calibration maps the screen into the photo once, from the
// board photo; a zoom touched (focal length) or a photo the decoder turns (orientation) puts the
// screen elsewhere in the photo. Any difference from the first photo that states the field is
// refused: no capture means it.
void CaptureList::SameGeometry(const std::string& path, const PhotoExif& exif) {
  const std::optional<std::string> focal =
      exif.focal_length ? std::optional<std::string>(Number(*exif.focal_length) + " mm")
                        : std::nullopt;
  const std::optional<std::string> orientation =
      exif.orientation ? std::optional<std::string>(OrientationText(*exif.orientation))
                       : std::nullopt;
  geometry_photos_ += focal || orientation;
  for (const auto& [field, value, why] :
       {std::make_tuple("EXIF focal length", focal, "the zoom was touched"),
        std::make_tuple("EXIF orientation", orientation,
                        "the camera was turned, or its orientation sensor tagged the photo "
                        "turned and the decoder turns its pixels (turn auto-rotate off)")}) {
    if (!value) continue;
    const auto [it, first] = camera_.emplace(field, std::make_pair(*value, path));
    if (first || it->second.first == *value) continue;
    const std::string dir = std::filesystem::is_directory(options_.out_dir) ? options_.out_dir : "";
    CheckLog(dir, stage_)
        .Fail("camera.same_geometry",
              path + ": " + field + ": expected " + it->second.first + " as in " +
                  it->second.second +
                  " (the screen calibration assumes one geometry in every photo, the board photo's "
                  "too), got " +
                  *value + ": " + why,
              {{"photo", path},
               {"field", field},
               {"expected", it->second.first},
               {"got", *value},
               {"as_in", it->second.second}});
  }
}

void CaptureList::CheckBoardGeometry(const std::string& path) {
  SameGeometry(path, headers_.Of(path));
  board_checked_ = true;
}

void CaptureList::RecordGeometry(CheckLog& checks) const {
  if (geometry_photos_ == 0) return;
  nlohmann::json values = {{"photos", geometry_photos_}, {"board_photo", board_checked_}};
  std::string found;
  for (const char* field : {"EXIF focal length", "EXIF orientation"}) {
    const auto it = camera_.find(field);
    if (it == camera_.end()) continue;
    values[field] = it->second.first;
    found += std::string(found.empty() ? "" : ", ") + field + " " + it->second.first;
  }
  checks.Pass("camera.same_geometry",
              std::to_string(geometry_photos_) + " photos" +
                  (board_checked_ ? " (the board photo too)" : "") +
                  " state one geometry: " + found,
              values);
}

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
  SameGeometry(path, exif);
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
