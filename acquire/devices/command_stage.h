// Stages lumislab cannot talk to itself: `command:<program>` (a vendor's tool, called once per
// move with the targets) and `manual` (the operator moves the stage by hand when told).
#pragma once

#include <memory>
#include <string>

#include "acquire/devices/device.h"

namespace lumislab {

// command:<program>. A move runs `<program> move X=<mm> Y=<mm> ...` (absolute mm, 3 decimals),
// homing `<program> home`; exit code 0 is success, anything else a DeviceError with its output.
// Nothing is read back: MoveTo returns the targets. Each call is bounded by move_timeout_s.
std::unique_ptr<Stage> MakeCommandStage(const std::string& uri, const std::string& program);
// manual: the operator is asked to move the stage to each target and press Enter.
std::unique_ptr<Stage> MakeManualStage(const std::string& uri);

// "X=12.500 Y=-3.000": the targets as the command stage passes them and the prompts show them.
std::string DescribeTargets(const AxisTargets& targets, const char* separator = " ");

}  // namespace lumislab
