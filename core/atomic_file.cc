#include "core/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace fs = std::filesystem;

namespace lumislab {

std::string TemporaryPathFor(const std::string& final_path) {
  static std::atomic<int> counter{0};
  const fs::path p(final_path);
  const std::string name = "." + p.stem().string() + ".tmp" + std::to_string(getpid()) + "_" +
                           std::to_string(counter++) + p.extension().string();
  return (p.parent_path() / name).string();
}

void WriteAtomically(const std::string& final_path,
                     const std::function<void(const std::string& tmp_path)>& write) {
  const std::string tmp = TemporaryPathFor(final_path);
  try {
    write(tmp);
    std::error_code ec;
    if (!fs::exists(tmp, ec)) throw IoError(final_path, "writer produced no file");
    fs::rename(tmp, final_path, ec);
    if (ec) throw IoError(final_path, "cannot rename into place: " + ec.message());
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

void WriteTextAtomically(const std::string& final_path, const std::string& text) {
  WriteAtomically(final_path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.flush();
    if (!out) throw IoError(final_path, "cannot write");
  });
}

std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, "cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool IsTemporaryName(const std::string& filename) {
  const std::string name = fs::path(filename).filename().string();
  return !name.empty() && name[0] == '.';
}

void MakeDirectories(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(dir, "cannot create folder: " + ec.message());
}

}  // namespace lumislab
