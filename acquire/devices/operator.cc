#include "acquire/devices/operator.h"

#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "acquire/devices/program.h"
#include "core/stop_signal.h"

namespace lumislab {

void Operator::Ask(const std::string& action, const std::string& argument,
                   const std::string& request, const std::string& doing) {
  if (!program_.empty()) {
    RunDeviceProgram("operator:" + program_, doing, program_, {action, argument, request},
                     timeout_s_, log_);
    return;
  }
  const std::string device = "operator";
  if (log_) log_->Sent(device, request);
  // What was typed before the question is not its answer (an Enter pressed twice).
  if (isatty(0)) tcflush(0, TCIFLUSH);
  std::fprintf(stderr, "\n>>> %s, then press Enter (Ctrl-C stops the capture)\n", request.c_str());
  std::fflush(stderr);
  std::string line;
  for (;;) {
    if (StopRequested()) throw DeviceStopped(device, doing);
    pollfd p{0, POLLIN, 0};
    const int ready = poll(&p, 1, 50);
    if (ready < 0 && errno != EINTR) throw DeviceError(device, doing, "cannot read the terminal");
    if (ready <= 0) continue;
    char c;
    const ssize_t n = read(0, &c, 1);
    if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN))
      throw DeviceError(device, doing,
                        "standard input ended before the operator answered (run capture on a "
                        "terminal, or configure a slide axis and a motorised stage)");
    if (n < 0) continue;
    if (c == '\n') break;
    line += c;
  }
  if (log_) log_->Received(device, line.empty() ? "(Enter)" : line);
}

bool ProgramFound(const std::string& program) {
  if (program.empty()) return false;
  if (program.find('/') != std::string::npos) return access(program.c_str(), X_OK) == 0;
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    if (!dir.empty() && access((dir + "/" + program).c_str(), X_OK) == 0) return true;
  return false;
}

}  // namespace lumislab
