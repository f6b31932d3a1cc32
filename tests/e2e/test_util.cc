#include "test_util.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;

namespace lumislab::testing {

CommandResult RunShell(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

CommandResult RunTool(const std::string& tool, const std::string& args) {
  return RunShell(std::string(LUMISLAB_BIN_DIR) + "/" + tool + " " + args + " 2>&1");
}

std::string FreshDir(const std::string& name) {
  // Named after the build too: the tests of two build folders (build/, build-asan/) may run at
  // the same time.
  const std::string build = LUMISLAB_BIN_DIR;
  uint64_t hash = 1469598103934665603ull;
  for (const char c : build) hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  std::ostringstream tag;
  tag << std::hex << (hash & 0xffffff);
  const fs::path dir = fs::temp_directory_path() / ("lumislab_test_" + tag.str() + "_" + name);
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

bool InSanitizerSample(const std::string& name, int every) {
  if (!kSanitized || every <= 1) return true;
  uint32_t h = 2166136261u;
  for (const unsigned char c : name) h = (h ^ c) * 16777619u;
  return h % uint32_t(every) == 0;
}

CommandResult RunToolIn(const std::string& cwd, const std::string& tool, const std::string& args,
                        double timeout_s, long memory_kb) {
  std::ostringstream cmd;
  cmd << "cd " << ShellQuote(cwd) << " && ";
  if (memory_kb > 0) {
#ifdef LUMISLAB_SANITIZED
    // ASan reserves terabytes of address space for its shadow memory, so `ulimit -v` would stop
    // every sanitized tool at start-up; its allocator enforces the same limit instead: an
    // allocation larger than the limit, or a resident size above it, ends the tool with a report.
    const long mb = memory_kb / 1024;
    const char* asan = std::getenv("ASAN_OPTIONS");
    cmd << "ASAN_OPTIONS="
        << ShellQuote(std::string(asan ? asan : "") + (asan ? ":" : "") +
                      "max_allocation_size_mb=" + std::to_string(mb) +
                      ":hard_rss_limit_mb=" + std::to_string(mb))
        << " && export ASAN_OPTIONS && ";
#else
    cmd << "ulimit -v " << memory_kb << " && ";
#endif
  }
  cmd << "exec timeout -k 5 " << timeout_s << " " << LUMISLAB_BIN_DIR << "/" << tool << " " << args
      << " </dev/null 2>&1";
  return RunShell(cmd.str());
}

namespace {
double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

ToolProcess::ToolProcess(const std::string& cwd, const std::string& tool,
                         const std::vector<std::string>& args, const std::string& log) {
  const std::string path = std::string(LUMISLAB_BIN_DIR) + "/" + tool;
  std::vector<std::string> words = {path};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const int out = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
  start_s_ = NowS();
  if (out >= 0 && in >= 0) {
    pid_ = fork();
    if (pid_ == 0) {  // child: async-signal-safe calls only, then exec
      if (chdir(cwd.c_str()) != 0) _exit(126);
      dup2(in, 0);
      dup2(out, 1);
      dup2(out, 2);
      execv(path.c_str(), argv.data());
      _exit(127);
    }
  }
  if (out >= 0) close(out);
  if (in >= 0) close(in);
}

ToolProcess::~ToolProcess() {
  if (Running()) {
    kill(pid_, SIGKILL);
    WaitFor(10);
  }
}

bool ToolProcess::Running() {
  if (pid_ <= 0 || exit_code_ >= 0) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) != pid_) return true;
  signalled_ = WIFSIGNALED(status);
  exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return false;
}

bool ToolProcess::Signal(int signal) { return Running() && kill(pid_, signal) == 0; }

bool ToolProcess::WaitFor(double timeout_s) {
  const double deadline = NowS() + timeout_s;
  while (Running()) {
    if (NowS() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  return true;
}

double ToolProcess::Elapsed() const { return NowS() - start_s_; }

bool WaitUntil(const std::function<bool()>& done, double seconds) {
  const double deadline = NowS() + seconds;
  while (!done()) {
    if (NowS() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
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
