#include "acquire/devices/grbl_stage.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/stop_signal.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

constexpr char kAxes[] = "XYZABC";       // GRBL's axis letters, in the order of its status report
constexpr char kSoftReset = 0x18;        // Ctrl-X
constexpr double kPollInterval_s = 0.1;  // status polls during a move (GRBL advises <= 5-10 Hz)
constexpr double kHoldWait_s = 0.3;      // feed hold to its completion, before the soft reset
constexpr double kResetWait_s = 0.5;     // soft reset to the welcome message, while halting

Clock::time_point After(double seconds) {
  return Clock::now() +
         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

std::string Number(double value, const char* format = "%g") {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

bool StartsWith(const std::string& text, const char* prefix) {
  return text.compare(0, std::strlen(prefix), prefix) == 0;
}

// "Hold:0" -> "Hold".
std::string BaseState(const std::string& state) { return state.substr(0, state.find(':')); }

// The code of "error:N" / "ALARM:N" (0 when unreadable).
int Code(const std::string& line) { return std::atoi(line.c_str() + line.find(':') + 1); }

std::string Describe(const AxisTargets& axes) {
  std::string text;
  for (const auto& [axis, mm] : axes) {
    text += (text.empty() ? "" : " ") + std::string(1, axis) + "=" + Number(mm);
  }
  return text;
}

bool ParseNumbers(const std::string& text, std::vector<double>* values) {
  values->clear();
  size_t at = 0;
  while (at <= text.size()) {
    const size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(value)) return false;
    values->push_back(value);
    at = comma + 1;
  }
  return !values->empty();
}

}  // namespace

GrblStage::GrblStage(const std::string& uri, const std::string& port, int baud)
    : Stage(uri), port_path_(port), baud_(baud) {}

GrblStage::~GrblStage() { Close(); }

std::unique_ptr<Stage> MakeGrblStage(const std::string& uri, const std::string& port, int baud) {
  return std::make_unique<GrblStage>(uri, port, baud);
}

Error GrblStage::Fail(const std::string& doing, const std::string& what) const {
  if (connecting_) return BadInput(uri() + ": " + doing + ": " + what);
  return DeviceError(uri(), doing, what);
}

void GrblStage::Note(const std::string& text) {
  if (log_) log_->Note(uri(), text);
}

void GrblStage::Send(const std::string& line) {
  if (log_) log_->Sent(uri(), line);
  port_->Write(line + "\n");
}

void GrblStage::SendRealTime(char byte) {
  // Status queries '?' are not logged: a move sends ten a second (their replies are, see
  // LogStatus).
  if (byte != '?' && log_) log_->Sent(uri(), std::string(1, byte));
  port_->Write(std::string(1, byte));
}

void GrblStage::LogStatus(const std::string& report) {
  // A move polls the status ten times a second; a report is logged only when the machine state
  // changes (Idle -> Run -> Idle), so the log keeps the transitions and not the poll.
  const std::string state = report.substr(1, report.find_first_of("|>") - 1);
  if (state == last_logged_state_) return;
  last_logged_state_ = state;
  if (log_) log_->Received(uri(), report);
}

[[noreturn]] void GrblStage::Stopped(const std::string& doing) {
  if (moving_) Halt(homing_);
  throw DeviceStopped(uri(), doing);
}

// `timeout_s` is what is left of the wait; `stated_s` the timeout the message names (the whole
// wait's, not what was left of it when this reply was awaited).
std::string GrblStage::Reply(const std::string& sent, const std::string& doing, double timeout_s,
                             double stated_s) {
  const auto end = After(timeout_s);
  for (;;) {
    std::string line;
    switch (port_->ReadLine(SecondsLeft(end), &line)) {
      case SerialPort::Read::kStopped:
        Stopped(doing);
      case SerialPort::Read::kTimeout:
        throw Fail(doing, "no reply to '" + sent + "' within " + Number(stated_s) + " s");
      case SerialPort::Read::kLine:
        break;
    }
    if (line[0] == '<') return line;  // a status report, logged by LogStatus
    if (log_) log_->Received(uri(), line);
    if (StartsWith(line, "ALARM:")) {
      throw Fail(doing, line + " " + GrblAlarmText(Code(line)));
    }
    if (StartsWith(line, "Grbl ")) {
      // A welcome message: the controller was reset (power, a USB reconnect that toggles DTR).
      // While connecting it can be the welcome of the reset the port's opening caused.
      if (connecting_) continue;
      throw Fail(doing, "the controller reset itself ('" + line +
                            "'): its position may be lost, home it again");
    }
    if (line[0] == '[' || line[0] == '>') continue;  // feedback and startup-line messages
    return line;
  }
}

void GrblStage::Command(const std::string& line, const std::string& doing, double timeout_s) {
  Send(line);
  const auto end = After(timeout_s);
  for (;;) {
    // The timeout runs from the command, whatever else arrives meanwhile.
    const std::string reply = Reply(line, doing, std::max(0.0, SecondsLeft(end)), timeout_s);
    if (reply == "ok") return;
    if (StartsWith(reply, "error:")) {
      throw Fail(doing, "'" + line + "' answered " + reply + " " + GrblErrorText(Code(reply)));
    }
    if (reply[0] == '<') LogStatus(reply);  // a stray status report
  }
}

GrblStage::Status GrblStage::Query(const std::string& doing) {
  SendRealTime('?');
  const auto end = After(settings_.reply_timeout_s);
  for (;;) {
    const std::string reply =
        Reply("?", doing, std::max(0.0, SecondsLeft(end)), settings_.reply_timeout_s);
    if (reply[0] != '<') continue;  // a stray ok/error, already logged
    LogStatus(reply);
    return ParseStatus(reply, doing);
  }
}

GrblStage::Status GrblStage::ParseStatus(const std::string& report, const std::string& doing) {
  // <Idle|MPos:1.000,2.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>; which of MPos and WPos comes
  // is set by $10, and WCO (WPos = MPos - WCO) only now and then, so the last one is kept.
  Status status;
  std::vector<double> machine, work;
  size_t at = 1;
  bool first = true;
  while (at < report.size()) {
    size_t bar = report.find_first_of("|>", at);
    if (bar == std::string::npos) bar = report.size();
    const std::string field = report.substr(at, bar - at);
    at = bar + 1;
    if (first) {
      status.state = field;
      first = false;
      continue;
    }
    const size_t colon = field.find(':');
    if (colon == std::string::npos) continue;
    const std::string name = field.substr(0, colon), values = field.substr(colon + 1);
    std::vector<double>* into = name == "MPos"   ? &machine
                                : name == "WPos" ? &work
                                : name == "WCO"  ? &wco_mm_
                                                 : nullptr;
    if (into && !ParseNumbers(values, into)) {
      throw Fail(doing, "unreadable status report '" + report + "'");
    }
  }
  if (report.back() != '>' || status.state.empty() || (machine.empty() && work.empty())) {
    throw Fail(doing, "unreadable status report '" + report + "'");
  }
  if (work.empty()) {
    work = machine;
    for (size_t i = 0; i < work.size() && i < wco_mm_.size(); ++i) work[i] -= wco_mm_[i];
  }
  status.work_mm = work;
  return status;
}

void GrblStage::Halt(bool homing) noexcept {
  try {
    // Feed hold decelerates along the path so the position is kept; a soft reset while the hold
    // is still in progress (Hold:1) would stop the steppers at once (ALARM:3, position lost).
    // GRBL ignores a feed hold and `?` while homing: there only the reset stops it.
    if (!homing) {
      SendRealTime('!');
      const auto end = After(kHoldWait_s);
      bool held = false;
      while (!held && SecondsLeft(end) > 0) {
        port_->Write("?");
        std::string line;
        const auto slice = After(std::min(0.05, std::max(0.0, SecondsLeft(end))));
        while (!held &&
               port_->ReadLine(SecondsLeft(slice), &line, true) == SerialPort::Read::kLine) {
          if (line[0] == '<') {
            LogStatus(line);
            const std::string state = line.substr(1, line.find_first_of("|>") - 1);
            held = state == "Hold:0" || state == "Idle" || BaseState(state) == "Alarm";
          } else if (log_) {
            log_->Received(uri(), line);
          }
        }
      }
    }
    SendRealTime(kSoftReset);
    const auto end = After(kResetWait_s);
    std::string line;
    while (port_->ReadLine(SecondsLeft(end), &line, true) == SerialPort::Read::kLine) {
      if (log_) log_->Received(uri(), line);
      if (StartsWith(line, "Grbl ")) break;
    }
    Note("halted: feed hold, then soft reset");
  } catch (...) {
    // Halting is the last thing done before an error or a stop is reported; a port that fails
    // now has nothing more to tell.
  }
  moving_ = false;
  homing_ = false;
  modes_set_ = false;  // a reset restores GRBL's default modes
}

void GrblStage::Connect(const StageSettings& settings, DeviceLog* log) {
  settings_ = settings;
  log_ = log;
  const std::string doing = "connecting";
  if (!(settings.feed_mm_min > 0) || !(settings.tolerance_mm > 0) ||
      !(settings.tolerance_deg > 0) || !(settings.reply_timeout_s > 0) ||
      !(settings.move_timeout_s > 0) || !(settings.settle_s >= 0)) {
    throw BadInput(uri() + ": " + doing +
                   ": feed_mm_min, tolerance_mm, tolerance_deg, reply_timeout_s and "
                   "move_timeout_s must be "
                   "positive and settle_s not negative");
  }
  Note("opening " + port_path_ + " at " + std::to_string(baud_) + " baud");
  port_ = std::make_unique<SerialPort>(uri(), port_path_, baud_);
  connecting_ = true;
  try {
    port_->DiscardInput();
    // A soft reset puts GRBL in a known state and answers with its welcome message.
    SendRealTime(kSoftReset);
    const auto end = After(settings_.reply_timeout_s);
    for (;;) {
      std::string line;
      const SerialPort::Read read = port_->ReadLine(SecondsLeft(end), &line);
      if (read == SerialPort::Read::kStopped) throw DeviceStopped(uri(), doing);
      if (read == SerialPort::Read::kTimeout) {
        throw BadInput(uri() + ": " + doing + ": no answer to a soft reset (Ctrl-X) within " +
                       Number(settings_.reply_timeout_s) + " s: is a GRBL controller on " +
                       port_path_ + " at " + std::to_string(baud_) + " baud?");
      }
      if (log_) log_->Received(uri(), line);
      if (!StartsWith(line, "Grbl ")) continue;  // boot noise, a half line from before
      if (!StartsWith(line, "Grbl 1.1")) {
        throw BadInput(uri() + ": " + doing + ": '" + line +
                       "': lumislab speaks GRBL 1.1 (its status reports)");
      }
      break;
    }
    const Status status = Query(doing);
    axis_count_ = status.work_mm.size();
    const std::string state = BaseState(status.state);
    if (state == "Alarm") {
      if (!settings_.home) {
        throw BadInput(uri() + ": " + doing +
                       ": the controller is in alarm and locked ([MSG:'$H'|'$X' to unlock]): "
                       "set the stage's \"home\": true so that lumislab homes it ($H), or "
                       "unlock it ($X) in a terminal if its position is known");
      }
      Note("in alarm: the homing cycle will clear it");
    } else if (state != "Idle") {
      throw BadInput(uri() + ": " + doing + ": the controller is in state " + status.state +
                     ", not Idle");
    } else {
      Command("G21 G90", doing, settings_.reply_timeout_s);  // mm, absolute
      modes_set_ = true;
    }
  } catch (...) {
    connecting_ = false;
    port_.reset();
    throw;
  }
  connecting_ = false;
}

void GrblStage::Home() {
  const std::string doing = "homing ($H)";
  if (!port_) throw DeviceError(uri(), doing, "not connected");
  homing_ = true;
  moving_ = true;
  // No status polls while homing: GRBL does not answer them until the cycle ends with `ok`.
  Command("$H", doing, settings_.move_timeout_s);
  homing_ = false;
  moving_ = false;
  Command("G21 G90", doing, settings_.reply_timeout_s);
  modes_set_ = true;
  const Status status = Query(doing);
  std::string at;
  for (size_t i = 0; i < status.work_mm.size(); ++i) {
    at += std::string(at.empty() ? "" : " ") + kAxes[i] + "=" + Number(status.work_mm[i]);
  }
  Note("homed, at " + at);
}

AxisTargets GrblStage::MoveTo(const AxisTargets& target) {
  const std::string doing = "moving to " + Describe(target);
  if (!port_) throw DeviceError(uri(), doing, "not connected");
  std::vector<size_t> index;
  for (const auto& [axis, mm] : target) {
    const char* at = std::strchr(kAxes, axis);
    if (axis == '\0' || !at) {
      throw BadInput(uri() + ": " + doing + ": '" + std::string(1, axis) +
                     "' is not a GRBL axis (X Y Z A B C)");
    }
    const size_t i = static_cast<size_t>(at - kAxes);
    if (i >= axis_count_) {
      throw BadInput(uri() + ": " + doing + ": the controller has " + std::to_string(axis_count_) +
                     " axes, no " + std::string(1, axis));
    }
    if (!std::isfinite(mm)) throw BadInput(uri() + ": " + doing + ": the target is not finite");
    for (size_t j : index) {
      if (j == i) throw BadInput(uri() + ": " + doing + ": axis " + axis + " given twice");
    }
    index.push_back(i);
  }
  if (target.empty()) return {};
  if (!modes_set_) {
    Command("G21 G90", doing, settings_.reply_timeout_s);
    modes_set_ = true;
  }
  // A move of the rotary axis alone is a rapid (G0, the controller's own rate for it, $11x): the
  // feed rate is a linear one, in mm/min.
  const bool rapid = target.size() == 1 && target[0].first == settings_.rotary_axis;
  std::string line = rapid ? "G0" : "G1";
  for (const auto& [axis, mm] : target) line += " " + std::string(1, axis) + Number(mm, "%.3f");
  if (!rapid) line += " F" + Number(settings_.feed_mm_min);
  // GRBL answers `ok` once the move is planned, not done: the status then tells when it is.
  Command(line, doing, settings_.reply_timeout_s);
  moving_ = true;
  const auto end = After(settings_.move_timeout_s);
  bool idle_before = false;
  Status status;
  for (;;) {
    status = Query(doing);
    const std::string state = BaseState(status.state);
    if (state == "Idle") {
      // A move that has not started yet also reads Idle for a moment after its `ok`: Idle counts
      // at the target, or when it is read twice in a row.
      bool there = true;
      for (size_t k = 0; k < target.size(); ++k) {
        there = there && index[k] < status.work_mm.size() &&
                std::abs(status.work_mm[index[k]] - target[k].second) <= Tolerance(target[k].first);
      }
      if (there || idle_before) break;
      idle_before = true;
    } else if (state == "Run" || state == "Jog" || state == "Home") {
      idle_before = false;
    } else {
      const std::string why = state == "Hold"    ? " (feed hold)"
                              : state == "Door"  ? " (safety door open)"
                              : state == "Alarm" ? " (alarm)"
                                                 : "";
      throw Fail(doing, "the controller went to state " + status.state + why);
    }
    if (SecondsLeft(end) <= 0) {
      Halt(false);
      throw Fail(doing, "not at rest within " + Number(settings_.move_timeout_s) +
                            " s (move_timeout_s); halted");
    }
    if (!PauseUnlessStopped(kPollInterval_s)) Stopped(doing);
  }
  moving_ = false;
  AxisTargets actual;
  for (size_t k = 0; k < target.size(); ++k) {
    const char axis = target[k].first;
    if (index[k] >= status.work_mm.size()) {
      throw Fail(doing, "the status report has no position for axis " + std::string(1, axis));
    }
    const double mm = status.work_mm[index[k]];
    if (std::abs(mm - target[k].second) > Tolerance(axis)) {
      const bool rotary = axis == settings_.rotary_axis;
      const char* unit = rotary ? " deg" : " mm";
      throw Fail(doing, std::string(1, axis) + " is at " + Number(mm, "%.3f") + unit +
                            ", not at its target " + Number(target[k].second, "%.3f") + unit +
                            (rotary ? " (lab.rotation_axis.tolerance_deg " : " (tolerance_mm ") +
                            Number(Tolerance(axis)) + ")");
    }
    actual.emplace_back(axis, mm);
  }
  Note("at " + Describe(actual));
  if (!PauseUnlessStopped(settings_.settle_s)) throw DeviceStopped(uri(), doing);
  return actual;
}

double GrblStage::Tolerance(char axis) const {
  return axis == settings_.rotary_axis ? settings_.tolerance_deg : settings_.tolerance_mm;
}

void GrblStage::Close() noexcept {
  if (!port_) return;
  if (moving_) Halt(homing_);
  port_.reset();
  Note("closed");
}

}  // namespace lumislab
