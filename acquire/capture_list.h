// The list of a capture's photos that `acquire import` and `acquire watch` share (docs/formats.md
// §3), each photo checked as it is added, as a lab wants before a long run: import hands it a whole
// folder at once; watch hands it each photo as it arrives. The photos come named by photo_naming.h.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "acquire/import.h"
#include "acquire/photo_naming.h"
#include "core/checks.h"
#include "core/dataset.h"
#include "lib/photo/exif.h"

namespace lumislab {

// Each photo is checked once (a regular file, an image by its content, BadInput naming it
// otherwise) and its EXIF read once, however many steps ask for it.
class PhotoHeaders {
 public:
  const PhotoExif& Of(const std::string& path);

 private:
  std::map<std::string, PhotoExif> exif_;
};

// How the photos' name order and their EXIF time order agree (order.names_and_times), fed one
// photo at a time in name order (NameOrderLess: capt2 before capt10): import feeds the folder,
// watch --order name each photo as it places it. Photos without a time are passed over.
class NameTimeOrder {
 public:
  void Next(const std::string& name, const PhotoExif& exif);
  int timed() const { return timed_; }  // photos with an EXIF time
  bool Agree() const { return earlier_.empty(); }
  // --order name against times that run backwards: a photo in the wrong place shifts every later
  // one. Recorded for `checks`'s stage and thrown (exit 2), naming the first backward pair.
  [[noreturn]] void Fail(CheckLog& checks, const std::string& photos_dir) const;
  // Where more than one photo has a time: a pass, or (--order capture, names that run backwards:
  // a counter that wrapped at 9999, two cards) a warning.
  void Record(CheckLog& checks, const std::string& photos_dir) const;

 private:
  int timed_ = 0, equal_times_ = 0;  // equal: consecutive photos with the same time (a bracket)
  std::string previous_, previous_time_;
  std::string earlier_, later_, earlier_time_, later_time_;  // the first backward pair, by name
  nlohmann::json Values() const;
};

// The photos of a capture, each checked as it is added (BadInput naming the photo): inside the
// grid, one camera make, model, lens, ISO (and image size, when given) across the capture, one
// focal length and orientation (camera.same_geometry, recorded for `stage` in checks.json), an
// exposure, no file or (position, slide, exposure) twice.
class CaptureList {
 public:
  // `stage`: the stage whose checks.json records camera.same_geometry ("acquire import").
  CaptureList(const ImportOptions& options, const SamplingGrid& grid, std::string stage);
  PhotoHeaders& headers() { return headers_; }
  void Add(const NamedPhoto& photo);
  // The camera's image size (px), checked like the EXIF fields.
  void CheckImageSize(const std::string& path, int width, int height);
  // The board photo's focal length and orientation against the slide photos': the screen
  // calibration made from it holds for them only with the same geometry.
  void CheckBoardGeometry(const std::string& path);
  // camera.same_geometry passed, with the capture's focal length and orientation; no record
  // where no photo states either.
  void RecordGeometry(CheckLog& checks) const;

  int Count(int i, int j, bool positive) const;  // photos of a slide so far
  int MostPerSlide() const;                      // the largest Count
  // Both slides of (i, j) hold `per_slide` photos.
  bool Complete(int i, int j, int per_slide) const {
    return Count(i, j, true) == per_slide && Count(i, j, false) == per_slide;
  }
  // The photos of the positions Complete with `per_slide`, in dataset.json's order (j, i, slide
  // p then n, exposure), and the other positions (grid order: j, then i).
  std::vector<PhotoEntry> Entries(int per_slide,
                                  std::vector<std::pair<int, int>>* incomplete) const;

 private:
  const ImportOptions& options_;
  SamplingGrid grid_;
  PhotoHeaders headers_;
  std::vector<PhotoEntry> entries_;
  std::map<std::tuple<int, int, bool>, int> per_slide_;
  std::map<std::string, std::string> where_of_file_;
  std::map<std::tuple<int, int, bool, double>, std::string> where_of_slide_;
  // The first photo that stated each camera field: (value, path).
  std::map<std::string, std::pair<std::string, std::string>> camera_;
  void SameCamera(const std::string& path, const std::string& field,
                  const std::optional<std::string>& value);
  std::string stage_;
  int geometry_photos_ = 0;  // photos (and board) that stated a focal length or orientation
  bool board_checked_ = false;
  void SameGeometry(const std::string& path, const PhotoExif& exif);
};

}  // namespace lumislab
