// Helpers for tests that run the lumislab executables.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace lumislab::testing {

// The sanitized build (ASan + UBSan: the tools run several times slower) runs the expensive,
// repetitive CLI tests in part, so that CI stays within its time; the Release build runs them
// whole. Memory errors are a property of code paths, and the sample keeps every kind of path.
#ifdef LUMISLAB_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
// True outside the sanitized build; inside it, for 1 case in `every`, chosen by a hash of the
// case's name (FNV-1a), so that the sample stays the same when other cases are added.
bool InSanitizerSample(const std::string& name, int every);

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs `command` through sh (popen): its stdout (redirect stderr in the command to keep it), and
// its exit code (128 + signal when a signal ended it).
CommandResult RunShell(const std::string& command);
// Runs build/bin/<tool> with the given argument string (shell-quoted by the caller).
CommandResult RunTool(const std::string& tool, const std::string& args);
// A fresh, empty folder under the system temp folder, named after the test and the build folder.
std::string FreshDir(const std::string& name);
void WriteFile(const std::string& path, const std::string& text);
// Scene JSON of the default luminaire with the given grid, camera and effects (JSON fragments).
std::string SceneJson(int nu, int nv, const std::string& camera_json,
                      const std::string& effects_json);
// Files under `dir` (recursively) whose name does not start with '.', and those that do.
int CountFinalFiles(const std::string& dir);
int CountTemporaryFiles(const std::string& dir);

// Runs build/bin/<tool> <args> from the working folder `cwd` (so that relative paths in `args`
// and in the tool's messages are relative to it), through `timeout` (exit 124 when it runs past
// `timeout_s`) and, when `memory_kb` > 0, under `ulimit -v memory_kb` (in a sanitized build: ASan's
// allocation and resident-size limits of the same size). stdin is /dev/null.
CommandResult RunToolIn(const std::string& cwd, const std::string& tool, const std::string& args,
                        double timeout_s = 20, long memory_kb = 0);
// Single-quotes `text` for sh.
std::string ShellQuote(const std::string& text);

// What is under `dir`, recursively, without following links or opening anything that is not a
// regular file (a FIFO stays unopened): relative path -> "file <size> <hash>", "dir", "fifo",
// "link -> target" or "other". Regular files are hashed over all their bytes.
using TreeSnapshot = std::map<std::string, std::string>;
TreeSnapshot SnapshotTree(const std::string& dir);
// Paths that differ between two snapshots (added, removed or changed), each with what happened.
std::vector<std::string> DiffSnapshots(const TreeSnapshot& before, const TreeSnapshot& after);
// Paths in a snapshot one of whose components starts with '.' (temporary names,
// docs/architecture.md §7.5).
std::vector<std::string> TemporaryPaths(const TreeSnapshot& snapshot);

// A tool started in the background: fork + exec of build/bin/<tool> <args> in `cwd`, stdin
// /dev/null, stdout and stderr into the file `log`. Only this process is ever signalled, by its
// pid; the destructor kills (SIGKILL) and reaps it if it still runs.
class ToolProcess {
 public:
  ToolProcess(const std::string& cwd, const std::string& tool, const std::vector<std::string>& args,
              const std::string& log);
  ~ToolProcess();
  ToolProcess(const ToolProcess&) = delete;
  ToolProcess& operator=(const ToolProcess&) = delete;

  bool started() const { return pid_ > 0; }
  // Reaps the process if it has ended; true while it runs.
  bool Running();
  // Sends `signal` if the process still runs; returns whether it was sent.
  bool Signal(int signal);
  // Waits up to `timeout_s` seconds (polling every 0.5 ms) for the process to end; returns
  // whether it ended.
  bool WaitFor(double timeout_s);
  // Seconds since the start.
  double Elapsed() const;
  // Once ended: the exit code, or 128 + the signal that ended it; and whether a signal did.
  int exit_code() const { return exit_code_; }
  bool signalled() const { return signalled_; }

 private:
  int pid_ = -1;
  int exit_code_ = -1;
  bool signalled_ = false;
  double start_s_ = 0;
};

// Polls `done` every 5 ms until it holds or `seconds` pass; returns whether it held.
bool WaitUntil(const std::function<bool()>& done, double seconds);

std::string ReadBinaryFile(const std::string& path);  // "" when missing
void WriteBinaryFile(const std::string& path, const std::string& bytes);

}  // namespace lumislab::testing
