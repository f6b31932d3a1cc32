#include "acquire/devices/program.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include "core/stop_signal.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

// Ends the child and whatever it started (its process group): SIGTERM, then SIGKILL when it is
// still there a second later; reaps it.
void EndChild(pid_t pid) {
  kill(-pid, SIGTERM);
  for (int k = 0; k < 20; ++k) {
    if (waitpid(pid, nullptr, WNOHANG) == pid) {
      kill(-pid, SIGKILL);  // what it started and left behind
      return;
    }
    usleep(50000);
  }
  kill(-pid, SIGKILL);
  waitpid(pid, nullptr, 0);
}

}  // namespace

std::string RunDeviceProgram(const std::string& device, const std::string& doing,
                             const std::string& program, const std::vector<std::string>& args,
                             double timeout_s, DeviceLog* log) {
  std::string line = program;
  for (const std::string& a : args) line += " " + a;
  if (log) log->Sent(device, line);
  int pipe_fd[2];
  if (pipe2(pipe_fd, O_CLOEXEC) != 0)
    throw DeviceError(device, doing, std::string("cannot make a pipe: ") + std::strerror(errno));
  std::vector<std::string> words = {program};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipe_fd[0]), close(pipe_fd[1]);
    throw DeviceError(device, doing, std::string("cannot start ") + program);
  }
  if (pid == 0) {
    setpgid(0, 0);  // its own process group: a timeout or a stop ends what it started too
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, 0);
    dup2(pipe_fd[1], 1);
    dup2(pipe_fd[1], 2);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    execvp(program.c_str(), argv.data());
    const std::string message = "cannot run " + program + ": " + std::strerror(errno) + "\n";
    (void)!write(2, message.data(), message.size());
    _exit(127);
  }
  close(pipe_fd[1]);
  const auto start = Clock::now();
  std::string output, pending;
  bool open_pipe = true;
  int status = 0;
  auto log_lines = [&](bool all) {
    size_t nl;
    while ((nl = pending.find('\n')) != std::string::npos) {
      if (log) log->Received(device, pending.substr(0, nl));
      pending.erase(0, nl + 1);
    }
    if (all && !pending.empty()) {
      if (log) log->Received(device, pending);
      pending.clear();
    }
  };
  for (;;) {
    if (open_pipe) {
      pollfd p{pipe_fd[0], POLLIN, 0};
      if (poll(&p, 1, 50) > 0) {
        char buffer[4096];
        const ssize_t n = read(pipe_fd[0], buffer, sizeof buffer);
        if (n > 0) {
          output.append(buffer, size_t(n));
          pending.append(buffer, size_t(n));
          log_lines(false);
        } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
          open_pipe = false;
        }
      }
    } else {
      usleep(20000);
    }
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (StopRequested()) {
      EndChild(pid);
      close(pipe_fd[0]);
      log_lines(true);
      throw DeviceStopped(device, doing);
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (elapsed > timeout_s) {
      EndChild(pid);
      close(pipe_fd[0]);
      log_lines(true);
      if (log) log->Note(device, "timed out, killed");
      throw DeviceError(
          device, doing,
          program + " did not finish within " + std::to_string(int(timeout_s)) + " s (killed)");
    }
  }
  // The rest of what it wrote before it exited, for at most a second: a process it left running
  // may hold the pipe open for ever.
  const auto drain_end = Clock::now() + std::chrono::seconds(1);
  while (open_pipe && Clock::now() < drain_end) {
    pollfd p{pipe_fd[0], POLLIN, 0};
    if (poll(&p, 1, 50) <= 0) continue;
    char buffer[4096];
    const ssize_t n = read(pipe_fd[0], buffer, sizeof buffer);
    if (n <= 0) break;
    output.append(buffer, size_t(n));
    pending.append(buffer, size_t(n));
  }
  close(pipe_fd[0]);
  log_lines(true);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::string tail = output.size() > 300 ? output.substr(output.size() - 300) : output;
    while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r')) tail.pop_back();
    throw DeviceError(device, doing,
                      program + " failed (exit " + std::to_string(code) + ")" +
                          (tail.empty() ? "" : ": " + tail));
  }
  return output;
}

}  // namespace lumislab
