#include "acquire/devices/command_stage.h"

#include <cstdio>

#include "acquire/devices/operator.h"
#include "acquire/devices/program.h"

namespace lumislab {
namespace {

class CommandStage : public Stage {
 public:
  CommandStage(const std::string& uri, const std::string& program)
      : Stage(uri), program_(program) {}

  void Connect(const StageSettings& settings, DeviceLog* log) override {
    settings_ = settings;
    log_ = log;
    if (!ProgramFound(program_))
      throw BadInput(uri() + ": " + program_ + " is not an executable program (nor in PATH)");
  }
  void Home() override {
    RunDeviceProgram(uri(), "homing", program_, {"home"}, settings_.move_timeout_s, log_);
  }
  AxisTargets MoveTo(const AxisTargets& target) override {
    std::vector<std::string> args = {"move"};
    for (const auto& [axis, mm] : target) args.push_back(DescribeTargets({{axis, mm}}));
    RunDeviceProgram(uri(), "moving to " + DescribeTargets(target), program_, args,
                     settings_.move_timeout_s, log_);
    return target;
  }
  void Close() noexcept override {}

 private:
  std::string program_;
  StageSettings settings_;
  DeviceLog* log_ = nullptr;
};

class ManualStage : public Stage {
 public:
  explicit ManualStage(const std::string& uri) : Stage(uri) {}
  void Connect(const StageSettings& settings, DeviceLog* log) override {
    operator_ = Operator(log);
    rotary_axis_ = settings.rotary_axis;
  }
  void Home() override { operator_.Ask("home", "", "Home the stage", "homing"); }
  AxisTargets MoveTo(const AxisTargets& target) override {
    const bool turn = target.size() == 1 && target[0].first == rotary_axis_;
    operator_.Ask("move", DescribeTargets(target),
                  (turn ? "Turn the rotation axis to " : "Move the stage to ") +
                      DescribeTargets(target, ", ") + (turn ? " (degrees)" : " (mm)"),
                  "moving to " + DescribeTargets(target));
    return target;
  }
  void Close() noexcept override {}

 private:
  Operator operator_{nullptr};
  char rotary_axis_ = '\0';  // lab.rotation_axis: its targets are degrees
};

}  // namespace

std::string DescribeTargets(const AxisTargets& targets, const char* separator) {
  std::string out;
  for (const auto& [axis, mm] : targets) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%c=%.3f", axis, mm);
    out += (out.empty() ? "" : separator) + std::string(buffer);
  }
  return out;
}

std::unique_ptr<Stage> MakeCommandStage(const std::string& uri, const std::string& program) {
  return std::make_unique<CommandStage>(uri, program);
}

std::unique_ptr<Stage> MakeManualStage(const std::string& uri) {
  return std::make_unique<ManualStage>(uri);
}

}  // namespace lumislab
