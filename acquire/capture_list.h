// What `acquire import` and `acquire watch` share (docs/design.md §5.3): how a capture's
// description (a manifest, a file-name template or the capture order) names each photo, and the
// list of photos checked one by one as a lab wants before a long run. import hands it a whole
// folder at once; watch hands it each photo as it arrives.
#pragma once

#include <map>
#include <optional>
#include <regex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "acquire/import.h"
#include "core/dataset.h"
#include "lib/photo/exif.h"

namespace lumislab {

// One photo of the capture as the user's description names it; `where` names the manifest line
// or the file for messages.
struct NamedPhoto {
  int i = 0, j = 0;
  bool positive = true;
  std::string file;  // relative to the photo folder
  std::optional<double> exposure;
  int bracket = -1;  // index in the slide's bracket, when only that is known
  std::string where;
};

// (Folder listing and temporary names: core/input_file.h.)

// The rows of a manifest (CSV: i,j,slide,file[,exposure]); BadInput naming the line.
std::vector<NamedPhoto> ManifestPhotos(const std::string& manifest);

// A file-name template: {i} {j} {slide}, optional {exposure} and {bracket}, the rest literal.
class FilePattern {
 public:
  explicit FilePattern(const std::string& pattern);  // BadInput naming --pattern
  // The photo a file name names, or nullopt when the name does not match.
  std::optional<NamedPhoto> Match(const std::string& file) const;

 private:
  std::string pattern_;
  std::regex regex_;
  std::vector<std::string> order_;  // placeholder names, in the order they appear
};

// The k-th photo taken in a capture in order (options.order): position by position in the scan,
// slide p then n, each slide's bracket in --exposures order.
NamedPhoto OrderedPhoto(const ImportOptions& options, const SamplingGrid& grid, size_t k,
                        const std::string& file);
// Photos a capture in order holds: positions x 2 slides x OrderedPerSlide.
size_t OrderedPhotoCount(const ImportOptions& options, const SamplingGrid& grid);
// Photos per slide of a capture in order: --exposures' count, else --brackets, else 1.
size_t OrderedPerSlide(const ImportOptions& options);

// Each photo is checked once (a regular file, an image by its content, BadInput naming it
// otherwise) and its EXIF read once, however many steps ask for it.
class PhotoHeaders {
 public:
  const PhotoExif& Of(const std::string& path);

 private:
  std::map<std::string, PhotoExif> exif_;
};

// The dataset for the options: the setup file, photo_folder naming the camera's folder relative
// to the dataset folder, no photos yet.
Dataset ImportSkeleton(const ImportOptions& options);
// Reads `dataset` back through the one dataset reader (duplicates, ranges) and writes it as
// <out_dir>/dataset.json (atomic).
void WriteImportedDataset(const Dataset& dataset, const std::string& out_dir);

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
