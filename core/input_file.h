// The one check of an input path before it is opened (docs/design.md §7.3): it must exist and be
// a regular file. A FIFO would block the reader forever and a folder or device is never a valid
// input, so they are refused by name before any library sees them.
#pragma once

#include <string>
#include <vector>

namespace lumislab {

// Throws BadInput "<path>: <what> not found" or "<path>: not a regular file (a folder, FIFO or
// device is not a <what>)". `what`: "file", "photo", "scene file", ...
void CheckInputFile(const std::string& path, const std::string& what);

// The names of the regular files in `dir` that are not hidden (a copy in progress is written
// under a '.' name by careful tools), sorted by name.
std::vector<std::string> FolderFiles(const std::string& dir);

}  // namespace lumislab
