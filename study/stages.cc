#include "study/stages.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>

#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"

namespace fs = std::filesystem;

namespace lumislab {

std::string ToolPath(const std::string& tool) {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const fs::path path = (ec ? fs::path(".") : self.parent_path()) / tool;
  if (!fs::exists(path))
    throw Failure(tool + " not found beside lumislab-study (" + path.string() + ")");
  return path.string();
}

double RunStage(const std::string& tool, const std::vector<std::string>& args,
                const std::string& log) {
  const std::string path = ToolPath(tool);
  std::vector<std::string> words = {path};
  words.insert(words.end(), args.begin(), args.end());
  std::string line;
  for (const auto& w : words) line += (line.empty() ? "" : " ") + w;
  LogInfo("running ", line);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw Failure("cannot start " + tool);
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) dup2(fd, 1), dup2(fd, 2), close(fd);
    std::vector<char*> argv;
    for (auto& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    execv(path.c_str(), argv.data());
    _exit(127);
  }
  // Polled so that a stop signal reaches the stage too: it finishes its item and leaves what it
  // wrote valid (docs/architecture.md §7.6), and the study stops after it.
  int status = 0;
  bool forwarded = false;
  for (;;) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid || (done < 0 && errno != EINTR)) break;
    if (StopRequested() && !forwarded) kill(pid, SIGTERM), forwarded = true;
    usleep(20000);
  }
  if (StopRequested())
    throw Failure("stopped by a signal during " + tool + "; run again to continue");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Failure(line + " failed (exit " +
                  std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)) +
                  "); see " + log);
  return seconds;
}

}  // namespace lumislab
