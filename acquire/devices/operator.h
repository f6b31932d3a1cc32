// The operator: told what to do (put a slide in, place the board, move a stage by hand) and
// asked to confirm when it is done. By default at the terminal: the request goes to stderr and
// Enter on stdin confirms; the wait has no timeout (a person may take long) but ends at once on
// a stop signal, and with an error when stdin ends (nobody there to answer). Or a program does
// it (`--operator <program>`, a lab's automation: a relay board, a slide changer): it is called
// as `<program> <action> <argument> <request text>` and its exit code 0 confirms.
#pragma once

#include <string>

#include "acquire/devices/device.h"

namespace lumislab {

class Operator {
 public:
  // `program` empty: the terminal.
  explicit Operator(DeviceLog* log, std::string program = "", double timeout_s = 600)
      : log_(log), program_(std::move(program)), timeout_s_(timeout_s) {}
  // Asks for `action` (slide, board, move, home) with its `argument` (p, n, on, off, the
  // targets), `request` being the words a person reads. DeviceStopped on a stop signal;
  // DeviceError when stdin ends or the program fails.
  void Ask(const std::string& action, const std::string& argument, const std::string& request,
           const std::string& doing);
  const std::string& program() const { return program_; }

 private:
  DeviceLog* log_;
  std::string program_;
  double timeout_s_;
};

// True when `program` names an executable file: a path, or a name found in PATH.
bool ProgramFound(const std::string& program);

}  // namespace lumislab
