#include "core/atomic_file.h"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/error.h"
#include "core/log.h"

namespace fs = std::filesystem;

namespace lumislab {

std::string TemporaryPathFor(const std::string& final_path) {
  static std::atomic<int> counter{0};
  constexpr size_t kMaxName = 255;  // NAME_MAX of every file system lumislab runs on
  const fs::path p(final_path);
  const std::string tag = ".tmp" + std::to_string(getpid()) + "_" + std::to_string(counter++);
  std::string stem = p.stem().string();
  const std::string ext = p.extension().string();
  const size_t room =
      kMaxName > 1 + tag.size() + ext.size() ? kMaxName - 1 - tag.size() - ext.size() : 0;
  if (stem.size() > room) stem.resize(room);
  return (p.parent_path() / ("." + stem + tag + ext)).string();
}

namespace {
// True while process `pid` runs (a zombie, killed but not yet reaped, does not).
bool ProcessRuns(long pid) {
  if (kill(pid_t(pid), 0) != 0 && errno == ESRCH) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;  // no /proc: trust kill()
  const size_t close = line.rfind(')');        // "pid (comm) S ...": the state follows the name
  return !(close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z');
}
}  // namespace

int RemoveOrphanedTemporaries(const std::string& dir) {
  static const std::regex kTemporary(R"(^\..*\.tmp([0-9]+)_[0-9]+(\.[^.]*)?$)");
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::smatch m;
    if (!std::regex_match(name, m, kTemporary) || m[1].length() > 9) continue;
    const long pid = std::stol(m[1].str());
    if (pid == getpid() || ProcessRuns(pid)) continue;
    std::error_code remove_ec;  // a staging folder (acquire) is removed with its contents
    if (fs::remove_all(it->path(), remove_ec) > 0) ++removed;
  }
  return removed;
}

void CheckOutputPath(const std::string& path) {
  struct stat st {};
  if (path.empty() || lstat(path.c_str(), &st) != 0) return;  // missing: the writer creates it
  if (S_ISREG(st.st_mode)) return;
  if (S_ISLNK(st.st_mode))
    throw BadInput(path +
                   ": is a symbolic link; lumislab does not replace links: give the target's path");
  if (S_ISDIR(st.st_mode)) throw IoError(path, "cannot write a file where a folder is");
  const char* kind = S_ISCHR(st.st_mode)    ? "a character device"
                     : S_ISBLK(st.st_mode)  ? "a block device"
                     : S_ISFIFO(st.st_mode) ? "a FIFO"
                     : S_ISSOCK(st.st_mode) ? "a socket"
                                            : "a special file";
  throw BadInput(path + ": not a regular file (" + kind + "); lumislab writes outputs only as " +
                 "regular files");
}

void RefuseOutputOverInputs(const std::string& path, const std::string& allowed) {
  if (path.empty()) return;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::absolute(path), ec);
  if (ec) return;  // CheckOutputPath and the writer report what is wrong with it
  if (!allowed.empty() && out == fs::weakly_canonical(fs::absolute(allowed), ec)) return;
  auto refuse = [&](const std::string& what) {
    throw BadInput(path + ": is " + what +
                   ", which lumislab reads: write the output elsewhere (--force replaces an "
                   "earlier output, never an input)");
  };
  if (fs::exists(out.parent_path() / "slab.json", ec))
    refuse("in the slab folder " + out.parent_path().string());
  fs::path folder = out.parent_path();
  for (int up = 0; up < 3 && !folder.empty() && folder != folder.root_path(); ++up) {
    if (fs::exists(folder / "dataset.json", ec)) {
      const fs::path inside = out.lexically_relative(folder);
      const std::string top = inside.begin() == inside.end() ? "" : inside.begin()->string();
      if (up == 0 && (top == "dataset.json" || top == "checks.json"))
        refuse("the dataset's " + top);
      for (const char* sub : {"slab", "calib", "calibration", "photos", "truth"})
        if (up > 0 && top == sub) refuse("inside the dataset's " + std::string(sub) + "/");
      return;
    }
    folder = folder.parent_path();
  }
}

void WriteAtomically(const std::string& final_path,
                     const std::function<void(const std::string& tmp_path)>& write) {
  const std::string tmp = TemporaryPathFor(final_path);
  try {
    write(tmp);
    std::error_code ec;
    if (!fs::exists(tmp, ec)) throw IoError(final_path, "writer produced no file");
    CheckOutputPath(final_path);  // the last check: the path may have changed while writing
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

bool WriteFolderStaged(const std::string& final_dir,
                       const std::function<bool(const std::string& staging)>& write) {
  const fs::path parent = fs::absolute(final_dir).parent_path();
  MakeDirectories(parent.string());
  if (const int n = RemoveOrphanedTemporaries(parent.string()))
    LogInfo(parent.string(), ": removed ", n, " staging folder(s) of an interrupted run");
  const std::string staging = TemporaryPathFor(final_dir);
  try {
    if (!write(staging)) {
      std::error_code ec;
      fs::remove_all(staging, ec);
      return false;
    }
    ReplaceFolder(staging, final_dir);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    throw;
  }
  return true;
}

void ReplaceFolder(const std::string& staging, const std::string& final_dir) {
  std::error_code ec;
  const bool had_old = fs::exists(final_dir, ec);
  const std::string old = TemporaryPathFor(final_dir);
  if (had_old) {
    fs::rename(final_dir, old, ec);
    if (ec) throw IoError(final_dir, "cannot move the previous folder aside: " + ec.message());
  }
  fs::rename(staging, final_dir, ec);
  if (ec) {
    std::error_code back;
    if (had_old) fs::rename(old, final_dir, back);
    throw IoError(final_dir, "cannot move the new folder into place: " + ec.message());
  }
  if (had_old) fs::remove_all(old, ec);
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
