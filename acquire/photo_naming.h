// How a capture's description names each photo (docs/formats.md §3), for `acquire import`
// and `acquire watch`: a manifest (CSV), a file-name template, or the capture order. The photos
// so named are checked and listed by capture_list.h. (Folder listing and temporary names:
// core/input_file.h.)
#pragma once

#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "acquire/import.h"
#include "core/dataset.h"

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

// The rows of a manifest (CSV: i,j,slide,file[,exposure]); BadInput naming the line.
std::vector<NamedPhoto> ManifestPhotos(const std::string& manifest);

// The photo's position is inside the setup's grid: BadInput naming photo.where otherwise.
void CheckInGrid(const NamedPhoto& photo, const SamplingGrid& grid);
// The manifest's rows can complete the grid: every row inside it (CheckInGrid), and both slides
// of every position with as many rows as the fullest slide. BadInput naming the manifest and the
// first position (grid order: j, then i) they cannot complete otherwise: import would refuse the
// folder, and watch would wait for it forever. Returns the rows per slide.
int CheckManifestCompletes(const std::string& manifest, const std::vector<NamedPhoto>& rows,
                           const SamplingGrid& grid);

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

}  // namespace lumislab
