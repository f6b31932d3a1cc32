// The one check of an input path before it is opened (docs/architecture.md §7.3): it must exist and
// be a regular file. A FIFO would block the reader forever and a folder or device is never a valid
// input, so they are refused by name before any library sees them.
#pragma once

#include <string>
#include <vector>

namespace lumislab {

// Throws BadInput "<path>: <what> not found" or "<path>: not a regular file (a folder, FIFO or
// device is not a <what>)". `what`: "file", "photo", "scene file", ...
void CheckInputFile(const std::string& path, const std::string& what);

// A name that a copy or download in progress uses, never a camera's photo: a leading '.' (our
// own temporaries, rsync) or '~', a trailing '~', or the endings .part, .partial, .tmp and
// .crdownload (any case).
bool IsTemporaryPhotoName(const std::string& name);
// The name order of photo files: natural order, digit runs compared as numbers (capt9.tif before
// capt10.tif, as cameras and gphoto2's %n count without leading zeros), ties (IMG_01 and
// IMG_1) broken by the plain text, so that it is a total order. The one name order of every
// stage (import and watch --order name, folder listings).
bool NameOrderLess(const std::string& a, const std::string& b);
struct NameOrder {
  bool operator()(const std::string& a, const std::string& b) const { return NameOrderLess(a, b); }
};

// The regular files of `dir` that are not temporary names, in name order (every stage that
// lists a folder of photos lists it here).
std::vector<std::string> FolderFiles(const std::string& dir);

}  // namespace lumislab
