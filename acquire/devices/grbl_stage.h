// A translation stage driven by a GRBL 1.1 controller on a serial port (URI
// grbl:/dev/ttyUSB0[?baud=115200]). It speaks GRBL's simple send-response protocol (one line,
// then its `ok` or `error:N`), moves with absolute G1 in mm, and polls the real-time status
// report `?` until the stage is at rest (github.com/gnea/grbl, doc/markdown/interface.md). A
// fourth, rotary axis (4-axis builds such as grbl-Mega-5X: A in degrees, reported after X Y Z in
// MPos/WPos) is moved alone with G0 and checked against tolerance_deg.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "acquire/devices/device.h"
#include "acquire/devices/serial_port.h"

namespace lumislab {

class GrblStage : public Stage {
 public:
  // `port` is the path of the tty and `baud` its rate, already taken from the URI.
  GrblStage(const std::string& uri, const std::string& port, int baud);
  ~GrblStage() override;

  void Connect(const StageSettings& settings, DeviceLog* log) override;
  void Home() override;
  AxisTargets MoveTo(const AxisTargets& target) override;
  void Close() noexcept override;

 private:
  struct Status {
    std::string state;            // "Idle", "Run", "Hold:0", ...: the first field as sent
    std::vector<double> work_mm;  // work position (what G1 targets): MPos - WCO, or WPos
  };

  void Send(const std::string& line);
  void SendRealTime(char byte);
  // Sends `line` and waits up to `timeout_s` for its `ok`; throws on `error:N`, an alarm, a reset
  // of the controller, silence and the stop signal (after halting the stage).
  void Command(const std::string& line, const std::string& doing, double timeout_s);
  // Sends `?` and returns the status report that answers it.
  Status Query(const std::string& doing);
  // The next line within `timeout_s` after `sent` was sent; handles push messages (alarms, a
  // reset) and throws on silence or the stop signal.
  std::string Reply(const std::string& sent, const std::string& doing, double timeout_s,
                    double stated_s);
  Status ParseStatus(const std::string& report, const std::string& doing);
  // Feed hold, a short wait for the hold to complete, soft reset: the stage stops with its
  // position kept when the hold completes in time. Never throws.
  void Halt(bool homing) noexcept;
  [[noreturn]] void Stopped(const std::string& doing);
  // DeviceError, or BadInput while connecting (a device that cannot be used at all).
  Error Fail(const std::string& doing, const std::string& what) const;
  void LogStatus(const std::string& report);
  // The read-back tolerance of `axis`: tolerance_deg for the rotary axis, else tolerance_mm.
  double Tolerance(char axis) const;
  void Note(const std::string& text);

  std::string port_path_;
  int baud_;
  StageSettings settings_;
  DeviceLog* log_ = nullptr;
  std::unique_ptr<SerialPort> port_;
  bool connecting_ = false;
  bool moving_ = false;            // motion may be under way: Close() halts it
  bool homing_ = false;            // $H under way: GRBL ignores feed hold and `?` then
  bool modes_set_ = false;         // G21 G90 accepted
  size_t axis_count_ = 0;          // axes in the status report
  std::vector<double> wco_mm_;     // last work coordinate offset reported (WCO:)
  std::string last_logged_state_;  // status reports are logged when the state changes
};

std::unique_ptr<Stage> MakeGrblStage(const std::string& uri, const std::string& port, int baud);

// GRBL 1.1's text for an `error:N` / `ALARM:N` code (doc/csv/error_codes_en_US.csv,
// alarm_codes_en_US.csv), e.g. GrblAlarmText(2) == "soft limit (motion target exceeds machine
// travel)"; "unknown code" for one the tables do not list.
std::string GrblErrorText(int code);
std::string GrblAlarmText(int code);

}  // namespace lumislab
