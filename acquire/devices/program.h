// An external program as a device (the command: stage and camera): run with arguments, its
// output logged line by line in the device log, its exit code the answer.
#pragma once

#include <string>
#include <vector>

#include "acquire/devices/device.h"

namespace lumislab {

// Runs `program` (a path, or a name looked up in PATH) with `args`, its stdin /dev/null, its
// stdout and stderr read into the device log under `device`. Returns its output. DeviceError
// naming `device` and `doing` when it cannot be started, exits non-zero or runs past
// `timeout_s` (then killed: SIGTERM, SIGKILL a second later); DeviceStopped after a stop
// signal (passed on to it the same way).
std::string RunDeviceProgram(const std::string& device, const std::string& doing,
                             const std::string& program, const std::vector<std::string>& args,
                             double timeout_s, DeviceLog* log);

}  // namespace lumislab
