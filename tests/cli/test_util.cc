#include "test_util.h"

#include <sys/stat.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace fs = std::filesystem;

namespace lumislab::testing {

CommandResult RunTool(const std::string& tool, const std::string& args) {
  const std::string cmd = std::string(LUMISLAB_BIN_DIR) + "/" + tool + " " + args + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::string FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("lumislab_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

void WriteFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string SceneJson(int nu, int nv, const std::string& camera_json,
                      const std::string& effects_json) {
  return R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": )" +
         std::to_string(nu) + R"(, "nv": )" + std::to_string(nv) + R"(, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8},
      {"position_mm": [-3, 1, -12], "intensity_w_sr": [0.5, 0.6, 0.9], "lobe_exponent": 3} ] },
  "camera": )" +
         camera_json +
         R"(,
  "effects": )" +
         effects_json + " }\n";
}

static int Count(const std::string& dir, bool temporary) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       it != fs::recursive_directory_iterator(); ++it) {
    if (!it->is_regular_file()) continue;
    const std::string name = it->path().filename().string();
    n += (!name.empty() && name[0] == '.') == temporary;
  }
  return n;
}
int CountFinalFiles(const std::string& dir) { return Count(dir, false); }
int CountTemporaryFiles(const std::string& dir) { return Count(dir, true); }

std::string ShellQuote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

CommandResult RunToolIn(const std::string& cwd, const std::string& tool, const std::string& args,
                        double timeout_s, long memory_kb) {
  std::ostringstream cmd;
  cmd << "cd " << ShellQuote(cwd) << " && ";
  if (memory_kb > 0) cmd << "ulimit -v " << memory_kb << " && ";
  cmd << "exec timeout -k 5 " << timeout_s << " " << LUMISLAB_BIN_DIR << "/" << tool << " " << args
      << " </dev/null 2>&1";
  CommandResult result;
  FILE* pipe = popen(cmd.str().c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

namespace {
// FNV-1a over the bytes of a regular file, with its size.
std::string HashFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "file (unreadable)";
  uint64_t hash = 1469598103934665603ull, size = 0;
  std::array<char, 1 << 16> buf;
  while (in) {
    in.read(buf.data(), buf.size());
    const std::streamsize got = in.gcount();
    for (std::streamsize k = 0; k < got; ++k) {
      hash ^= static_cast<unsigned char>(buf[size_t(k)]);
      hash *= 1099511628211ull;
    }
    size += uint64_t(got);
  }
  std::ostringstream os;
  os << "file " << size << " bytes, hash " << std::hex << hash;
  return os.str();
}
}  // namespace

TreeSnapshot SnapshotTree(const std::string& dir) {
  TreeSnapshot snapshot;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    const fs::path& path = it->path();
    const std::string rel = path.lexically_relative(dir).generic_string();
    const fs::file_status status = it->symlink_status();
    if (fs::is_symlink(status)) {
      snapshot[rel] = "link -> " + fs::read_symlink(path, ec).string();
      ec.clear();
    } else if (fs::is_regular_file(status)) {
      snapshot[rel] = HashFile(path);
    } else if (fs::is_directory(status)) {
      snapshot[rel] = "dir";
    } else if (fs::is_fifo(status)) {
      snapshot[rel] = "fifo";
    } else {
      snapshot[rel] = "other";
    }
  }
  return snapshot;
}

std::vector<std::string> DiffSnapshots(const TreeSnapshot& before, const TreeSnapshot& after) {
  std::vector<std::string> diff;
  for (const auto& [path, what] : before) {
    const auto it = after.find(path);
    if (it == after.end())
      diff.push_back(path + ": removed (was " + what + ")");
    else if (it->second != what)
      diff.push_back(path + ": changed (" + what + " -> " + it->second + ")");
  }
  for (const auto& [path, what] : after)
    if (!before.count(path)) diff.push_back(path + ": added (" + what + ")");
  return diff;
}

std::vector<std::string> TemporaryPaths(const TreeSnapshot& snapshot) {
  std::vector<std::string> out;
  for (const auto& entry : snapshot) {
    for (const auto& part : fs::path(entry.first))
      if (!part.empty() && part.string()[0] == '.' && part != "." && part != "..") {
        out.push_back(entry.first);
        break;
      }
  }
  return out;
}

std::string ReadBinaryFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteBinaryFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace lumislab::testing
