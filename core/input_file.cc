#include "core/input_file.h"

#include <algorithm>
#include <filesystem>

#include "core/error.h"

namespace lumislab {

void CheckInputFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw BadInput(path + ": " + what + " not found");
  if (!std::filesystem::is_regular_file(status))
    throw BadInput(path + ": not a regular file (a folder, FIFO or device is not a " + what + ")");
}

std::vector<std::string> FolderFiles(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.' || !entry.is_regular_file()) continue;
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace lumislab
