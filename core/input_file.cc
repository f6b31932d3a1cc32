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

bool NameOrderLess(const std::string& a, const std::string& b) {
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  size_t x = 0, y = 0;
  while (x < a.size() && y < b.size()) {
    if (digit(a[x]) && digit(b[y])) {
      // Two numbers: without their leading zeros, the longer is larger, else the text decides
      // (any length, no overflow).
      size_t x_end = x, y_end = y;
      while (x_end < a.size() && digit(a[x_end])) ++x_end;
      while (y_end < b.size() && digit(b[y_end])) ++y_end;
      size_t x0 = x, y0 = y;
      while (x0 + 1 < x_end && a[x0] == '0') ++x0;
      while (y0 + 1 < y_end && b[y0] == '0') ++y0;
      if (x_end - x0 != y_end - y0) return x_end - x0 < y_end - y0;
      const int c = a.compare(x0, x_end - x0, b, y0, y_end - y0);
      if (c != 0) return c < 0;
      x = x_end;
      y = y_end;
    } else {
      if (a[x] != b[y]) return (unsigned char)a[x] < (unsigned char)b[y];
      ++x;
      ++y;
    }
  }
  if (x < a.size() || y < b.size()) return y < b.size() && x == a.size();
  return a < b;  // equal up to leading zeros: the text decides
}

std::vector<std::string> FolderFiles(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    std::error_code ec;
    if (IsTemporaryPhotoName(name) || !entry.is_regular_file(ec)) continue;
    names.push_back(name);
  }
  std::sort(names.begin(), names.end(), NameOrderLess);
  return names;
}

}  // namespace lumislab
