// The list of a capture's photos that `acquire import` and `acquire watch` share (docs/formats.md
// §3), each photo checked as it is added, as a lab wants before a long run: import hands it a whole
// folder at once; watch hands it each photo as it arrives. The photos come named by photo_naming.h.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "acquire/import.h"
#include "acquire/photo_naming.h"
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

// The photos of a capture, each checked as it is added (BadInput naming the photo): inside the
// grid, one camera make, model, lens, ISO (and image size, when given) across the capture, an
// exposure, no file or (position, slide, exposure) twice.
class CaptureList {
 public:
  CaptureList(const ImportOptions& options, const SamplingGrid& grid);
  PhotoHeaders& headers() { return headers_; }
  void Add(const NamedPhoto& photo);
  // The camera's image size (px), checked like the EXIF fields.
  void CheckImageSize(const std::string& path, int width, int height);

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
};

}  // namespace lumislab
