#include "core/input_file.h"

#include <algorithm>
#include <cctype>
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

bool IsTemporaryPhotoName(const std::string& name) {
  if (name.empty() || name[0] == '.' || name[0] == '~' || name.back() == '~') return true;
  auto ends_with = [&](const std::string& end) {
    return name.size() >= end.size() &&
           std::equal(end.rbegin(), end.rend(), name.rbegin(),
                      [](char a, char b) { return a == std::tolower((unsigned char)b); });
  };
  for (const char* end : {".part", ".partial", ".tmp", ".crdownload"})
    if (ends_with(end)) return true;
  return false;
}

std::vector<std::string> FolderFiles(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    std::error_code ec;
    if (IsTemporaryPhotoName(name) || !entry.is_regular_file(ec)) continue;
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace lumislab
