#include "grbl_emulator.h"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace lumislab {
namespace {

constexpr size_t kPlannerBlocks = 15;   // GRBL's planner buffer (OPT:V,15,128)
constexpr size_t kLineBufferSize = 80;  // longer lines are refused with error:11
constexpr size_t kMaxEvents = 20000;

std::string Format(const char* format, double x, double y, double z) {
  char text[96];
  std::snprintf(text, sizeof text, format, x, y, z);
  return text;
}

// "name:v0,v1,...": the first `n` values, three decimals (a status report's position field).
std::string AxesField(const char* name, const GrblAxes& v, int n) {
  std::string text = name;
  for (int i = 0; i < n; ++i) text += (i ? "," : ":") + Format("%.3f", v[i], 0, 0);
  return text;
}

}  // namespace

double GrblEmulator::Segment::Distance(double t) const {
  double tau = t - t_start;
  if (tau <= 0) return 0;
  if (tau < t1) return v0 * tau + a * tau * tau / 2;
  const double d1 = v0 * t1 + a * t1 * t1 / 2;
  tau -= t1;
  if (tau < t2) return d1 + vp * tau;
  const double d2 = vp * t2;
  tau -= t2;
  if (tau < t3) return std::min(length, d1 + d2 + vp * tau - a * tau * tau / 2);
  return length;
}

double GrblEmulator::Segment::Speed(double t) const {
  double tau = t - t_start;
  if (tau <= 0) return v0;
  if (tau < t1) return v0 + a * tau;
  tau -= t1;
  if (tau < t2) return vp;
  tau -= t2;
  if (tau < t3) return std::max(0.0, vp - a * tau);
  return 0;
}

GrblEmulator::GrblEmulator(const GrblEmulatorOptions& options) : options_(options) {
  char name[256] = {};
  if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) {
    throw std::runtime_error(std::string("grbl emulator: openpty: ") + std::strerror(errno));
  }
  slave_path_ = name;
  // Raw on both sides before anyone opens the slave: no echo, no CR/LF translation. The slave
  // stays open here so that the master never reads EIO between two openings by the driver.
  termios tty{};
  ::tcgetattr(slave_, &tty);
  ::cfmakeraw(&tty);
  ::tcsetattr(slave_, TCSANOW, &tty);
  ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  ::fcntl(master_, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave_, F_SETFD, FD_CLOEXEC);
  epoch_ = Clock::now();
  position_ = planned_ = options_.start_mm;
  if (options_.require_homing) state_ = "Alarm";
  thread_ = std::thread([this] { Serve(); });
}

GrblEmulator::~GrblEmulator() {
  quit_ = true;
  if (thread_.joinable()) thread_.join();
  if (!link_path_.empty()) ::unlink(link_path_.c_str());
  ::close(master_);
  ::close(slave_);
}

void GrblEmulator::Link(const std::string& path) {
  ::unlink(path.c_str());
  if (::symlink(slave_path_.c_str(), path.c_str()) != 0) {
    throw std::runtime_error("grbl emulator: cannot link " + path + ": " + std::strerror(errno));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  link_path_ = path;
}

double GrblEmulator::SimNow() const {
  return std::chrono::duration<double>(Clock::now() - epoch_).count() * options_.speed_factor;
}

GrblAxes GrblEmulator::PositionAt(double t) const {
  if (!in_segment_) return position_;
  const double s = segment_.length > 0 ? segment_.Distance(t) / segment_.length : 1;
  GrblAxes p{};
  for (int i = 0; i < 4; ++i)
    p[i] = segment_.start[i] + s * (segment_.target[i] - segment_.start[i]);
  return p;
}

GrblAxes GrblEmulator::Position() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return PositionAt(SimNow());
}

std::string GrblEmulator::State() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

std::vector<GrblEmulator::Event> GrblEmulator::Events() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_;
}

void GrblEmulator::SetSilent(bool silent) {
  std::lock_guard<std::mutex> lock(mutex_);
  silent_ = silent;
  Record(silent ? "silent" : "answering");
}

void GrblEmulator::InjectAlarm(int code) {
  std::lock_guard<std::mutex> lock(mutex_);
  RaiseAlarm(code, SimNow());
}

void GrblEmulator::RequireHoming(bool require) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (require && state_ == "Idle") SetState("Alarm");
  if (!require && state_ == "Alarm" && !critical_) SetState("Idle");
}

void GrblEmulator::Record(const std::string& text) {
  if (events_.size() < kMaxEvents) events_.push_back({Clock::now(), text});
}

void GrblEmulator::SetState(const std::string& state) {
  if (state == state_) return;
  state_ = state;
  Record("state " + state);
}

void GrblEmulator::Send(const std::string& line) {
  if (silent_) return;
  if (line.empty() || line[0] != '<') Record("< " + line);
  const std::string bytes = line + "\r\n";
  // Non-blocking: with nobody reading the slave the pty's buffer fills, and the reply is lost as
  // it would be on a wire, rather than the thread blocking.
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t wrote = ::write(master_, bytes.data() + done, bytes.size() - done);
    if (wrote <= 0) break;
    done += static_cast<size_t>(wrote);
  }
}

void GrblEmulator::StartSegment(const GrblAxes& target, double feed_mm_s, double v0, double t) {
  Segment s;
  s.start = position_;
  s.target = target;
  double squared = 0;
  for (int i = 0; i < 4; ++i) squared += (target[i] - position_[i]) * (target[i] - position_[i]);
  s.length = std::sqrt(squared);
  if (s.length < 1e-9 || feed_mm_s <= 0) {
    position_ = target;
    in_segment_ = false;
    return;
  }
  // Trapezoid: accelerate from v0 to vp, cruise, decelerate to rest at the target.
  s.a = options_.acceleration_mm_s2;
  s.feed = feed_mm_s;
  s.v0 = v0;
  s.vp = std::max(v0, std::min(feed_mm_s, std::sqrt(s.a * s.length + v0 * v0 / 2)));
  s.t1 = (s.vp - v0) / s.a;
  const double d1 = (s.vp * s.vp - v0 * v0) / (2 * s.a);
  const double d3 = s.vp * s.vp / (2 * s.a);
  s.t3 = s.vp / s.a;
  s.t2 = std::max(0.0, s.length - d1 - d3) / s.vp;
  s.t_start = t;
  segment_ = s;
  in_segment_ = true;
}

void GrblEmulator::Advance(double t) {
  if (state_ == "Home" && t >= homing_end_) {
    position_ = planned_ = options_.home_mm;
    SetState("Idle");
    Send("ok");  // the $H line's answer comes when the cycle ends
  }
  if (!in_segment_ || t < segment_.End()) return;
  const double end = segment_.End();
  position_ = segment_.target;
  in_segment_ = false;
  if (state_ == "Hold:1") {
    SetState("Hold:0");
    if (soft_limit_after_hold_) RaiseAlarm(2, t);  // GRBL: hold to rest, then the alarm
    return;
  }
  if (!queue_.empty()) {
    const Move next = queue_.front();
    queue_.erase(queue_.begin());
    StartSegment(next.target, next.feed_mm_s, 0, end);
    Advance(t);
    return;
  }
  if (state_ == "Run") SetState("Idle");
}

void GrblEmulator::RaiseAlarm(int code, double t) {
  position_ = planned_ = PositionAt(t);  // the steppers stop at once
  in_segment_ = false;
  queue_.clear();
  hold_has_move_ = false;
  soft_limit_after_hold_ = false;
  Send("ALARM:" + std::to_string(code));
  SetState("Alarm");
  if (code == 1 || code == 2) {
    Send("[MSG:Reset to continue]");
    critical_ = true;
  }
}

void GrblEmulator::Reset(double t) {
  int alarm = 0;
  if (state_ == "Run" || state_ == "Hold:1") alarm = 3;  // position lost: ALARM:3
  if (state_ == "Home") alarm = 6;
  const bool locked = alarm != 0 || state_ == "Alarm";
  position_ = planned_ = PositionAt(t);
  in_segment_ = false;
  queue_.clear();
  lines_.clear();
  line_.clear();
  hold_has_move_ = false;
  soft_limit_after_hold_ = false;
  critical_ = false;
  if (alarm) Send("ALARM:" + std::to_string(alarm));
  if (ok_owed_) Send("ok");
  ok_owed_ = false;
  absolute_ = true;
  inches_ = false;
  motion_mode_ = 0;
  feed_mm_min_ = 0;
  reports_ = 0;
  Send("");
  Send("Grbl " + options_.version + " ['$' for help]");
  SetState(locked ? "Alarm" : "Idle");
  if (locked) Send("[MSG:'$H'|'$X' to unlock]");
}

void GrblEmulator::SendStatus(double t) {
  const GrblAxes m = PositionAt(t);
  const GrblAxes& wco = options_.wco_mm;
  GrblAxes w{};
  for (int i = 0; i < 4; ++i) w[i] = m[i] - wco[i];
  const int n = options_.axes;
  std::string report = "<" + state_ + "|";
  report += options_.report_wpos ? AxesField("WPos", w, n) : AxesField("MPos", m, n);
  const double speed = in_segment_ ? segment_.Speed(t) * 60 : 0;  // mm/min
  report += Format("|FS:%.0f,%.0f", speed, 0, 0);
  if (reports_++ % 10 == 0) report += "|" + AxesField("WCO", wco, n);
  Send(report + ">");
}

void GrblEmulator::OnRealTime(unsigned char byte, double t) {
  switch (byte) {
    case '?':
      // Not answered while homing or in a critical alarm (interface.md).
      if (state_ != "Home" && !critical_) SendStatus(t);
      return;
    case '!':
      Record("> !");
      if (state_ == "Idle") {
        SetState("Hold:0");
      } else if (state_ == "Run") {
        // Decelerate along the path to rest; the rest of the move waits for '~'.
        const GrblAxes at = PositionAt(t);
        const double v = segment_.Speed(t);
        const double left = segment_.length - segment_.Distance(t);
        const double stop = std::min(left, v * v / (2 * options_.acceleration_mm_s2));
        held_ = {segment_.target, segment_.feed};
        hold_has_move_ = true;
        GrblAxes stop_at = at;
        for (int i = 0; i < 4; ++i) {
          stop_at[i] += (segment_.target[i] - segment_.start[i]) / segment_.length * stop;
        }
        position_ = at;
        StartSegment(stop_at, std::max(v, 1e-6), v, t);
        SetState(in_segment_ ? "Hold:1" : "Hold:0");
      }
      return;
    case '~':
      Record("> ~");
      if (state_ != "Hold:0") return;
      if (hold_has_move_) {
        hold_has_move_ = false;
        StartSegment(held_.target, held_.feed_mm_s, 0, t);
        SetState("Run");
        Advance(t);
      } else if (!queue_.empty()) {
        const Move next = queue_.front();
        queue_.erase(queue_.begin());
        StartSegment(next.target, next.feed_mm_s, 0, t);
        SetState("Run");
        Advance(t);
      } else {
        SetState("Idle");
      }
      return;
    case 0x18:
      Record("> <0x18>");
      Reset(t);
      return;
    default:
      return;  // overrides (0x80 and up): not emulated
  }
}

bool GrblEmulator::Busy() const {
  return state_ == "Home" || critical_ || queue_.size() >= kPlannerBlocks;
}

void GrblEmulator::OnLine(const std::string& raw, double t) {
  Record("> " + raw);
  if (raw.size() > kLineBufferSize) {
    Send("error:11");
    return;
  }
  // GRBL drops spaces and comments and reads letters in upper case.
  std::string line;
  int parenthesis = 0;
  for (char c : raw) {
    if (c == ';') break;
    if (c == '(') ++parenthesis;
    if (parenthesis == 0 && !std::isspace(static_cast<unsigned char>(c))) {
      line += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
    if (c == ')' && parenthesis > 0) --parenthesis;
  }
  std::string reply;
  if (line.empty()) {
    reply = "ok";  // an empty line is answered too, for syncing (protocol.c)
  } else if (line[0] == '$') {
    reply = ExecuteSystem(line, t);
  } else if (state_ == "Alarm") {
    reply = "error:9";
  } else {
    reply = ExecuteGcode(line, t);
  }
  if (!reply.empty()) Send(reply);
}

std::string GrblEmulator::ExecuteSystem(const std::string& line, double t) {
  const bool idle_or_alarm = state_ == "Idle" || state_ == "Alarm";
  if (line == "$") {
    Send("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]");
  } else if (line == "$H") {
    if (!idle_or_alarm) return "error:8";
    SetState("Home");
    homing_end_ = t + options_.homing_s;
    return "";  // "ok" when the cycle ends (Advance)
  } else if (line == "$X") {
    if (!idle_or_alarm) return "error:8";
    if (state_ == "Alarm") {
      Send("[MSG:Caution: Unlocked]");
      SetState("Idle");
    }
  } else if (line == "$$") {
    if (!idle_or_alarm) return "error:8";
    const auto& max = options_.travel_max_mm;
    const auto& min = options_.travel_min_mm;
    Send(std::string("$10=") + (options_.report_wpos ? "0" : "1"));
    Send(std::string("$20=") + (options_.soft_limits ? "1" : "0"));
    Send("$22=1");
    for (int i = 0; i < options_.axes; ++i) {
      Send("$11" + std::to_string(i) + "=" + Format("%.3f", options_.max_rate_mm_min, 0, 0));
    }
    for (int i = 0; i < options_.axes; ++i) {
      Send("$12" + std::to_string(i) + "=" + Format("%.3f", options_.acceleration_mm_s2, 0, 0));
    }
    for (int i = 0; i < options_.axes; ++i) {
      Send("$13" + std::to_string(i) + "=" + Format("%.3f", max[i] - min[i], 0, 0));
    }
  } else if (line == "$G") {
    Send("[GC:G" + std::to_string(motion_mode_) + " G54 G17 " + (inches_ ? "G20" : "G21") +
         (absolute_ ? " G90" : " G91") + " G94 M5 M9 T0 " + Format("F%g", feed_mm_min_, 0, 0) +
         " S0]");
  } else if (line == "$I") {
    Send("[VER:" + options_.version + ".20190830:]");
    Send("[OPT:V,15,128]");
    if (options_.axes == 4) Send("[AXS:4:XYZA]");
  } else {
    return "error:3";
  }
  return "ok";
}

std::string GrblEmulator::ExecuteGcode(const std::string& line, double t) {
  // Read the whole block first: GRBL executes nothing of a block with an error.
  int motion = -1, distance = -1, units = -1;
  double feed = -1;
  std::array<bool, 4> given{};
  GrblAxes value{};
  for (size_t at = 0; at < line.size();) {
    const char letter = line[at++];
    if (letter < 'A' || letter > 'Z') return "error:1";
    // GRBL's read_float: a sign, digits and one decimal point (no exponent, no hex: strtod
    // would read "G0X1" as G 0x1).
    const size_t begin = at;
    if (at < line.size() && (line[at] == '-' || line[at] == '+')) ++at;
    bool digits = false, point = false;
    for (; at < line.size(); ++at) {
      if (std::isdigit(static_cast<unsigned char>(line[at]))) {
        digits = true;
      } else if (line[at] == '.' && !point) {
        point = true;
      } else {
        break;
      }
    }
    if (!digits) return "error:2";
    const double number = std::strtod(line.substr(begin, at - begin).c_str(), nullptr);
    const bool integer = number == std::floor(number);
    switch (letter) {
      case 'G': {
        if (!integer) return "error:20";  // G38.2, G28.1, ...: not emulated
        const int g = static_cast<int>(number);
        if (g == 0 || g == 1) {
          if (motion >= 0) return "error:21";
          motion = g;
        } else if (g == 90 || g == 91) {
          if (distance >= 0) return "error:21";
          distance = g;
        } else if (g == 20 || g == 21) {
          if (units >= 0) return "error:21";
          units = g;
        } else if (g != 17 && g != 54 && g != 94) {
          return "error:20";
        }
        break;
      }
      case 'M': {
        const int m = static_cast<int>(number);
        if (!integer || (m != 5 && m != 9)) return "error:20";
        break;
      }
      case 'F':
        if (feed >= 0) return "error:25";
        if (number < 0) return "error:4";
        feed = number;
        break;
      case 'A':
        if (options_.axes < 4) return "error:20";  // no such axis: an unsupported command
        [[fallthrough]];
      case 'X':
      case 'Y':
      case 'Z': {
        const int i = letter == 'A' ? 3 : letter - 'X';
        if (given[i]) return "error:25";
        given[i] = true;
        value[i] = number;
        break;
      }
      case 'N':
        break;
      default:
        return "error:20";
    }
  }
  const bool inches = units >= 0 ? units == 20 : inches_;
  const double unit = inches ? 25.4 : 1;
  const double feed_mm_min = feed >= 0 ? feed * unit : feed_mm_min_;
  const bool absolute = distance >= 0 ? distance == 90 : absolute_;
  const int mode = motion >= 0 ? motion : motion_mode_;
  const bool moves = given[0] || given[1] || given[2] || given[3];
  if (moves && mode == 1 && feed_mm_min <= 0) return "error:22";
  // The block is good: its modes apply.
  inches_ = inches;
  absolute_ = absolute;
  motion_mode_ = mode;
  feed_mm_min_ = feed_mm_min;
  if (!moves) return "ok";
  GrblAxes target = planned_;  // machine mm (A: degrees, never scaled by G20)
  for (int i = 0; i < 4; ++i) {
    if (given[i]) {
      const double scale = i == 3 ? 1 : unit;
      target[i] = absolute ? value[i] * scale + options_.wco_mm[i] : planned_[i] + value[i] * scale;
    }
  }
  if (options_.soft_limits) {
    for (int i = 0; i < options_.axes; ++i) {
      if (target[i] < options_.travel_min_mm[i] - 1e-6 ||
          target[i] > options_.travel_max_mm[i] + 1e-6) {
        // GRBL: a hold to rest if moving, then ALARM:2 and the critical lock; the line's `ok`
        // comes only after the reset.
        ok_owed_ = true;
        if (state_ == "Run") {
          soft_limit_after_hold_ = true;
          OnRealTime('!', t);
        } else {
          RaiseAlarm(2, t);
        }
        return "";
      }
    }
  }
  const double rate =
      mode == 0 ? options_.max_rate_mm_min : std::min(feed_mm_min, options_.max_rate_mm_min);
  planned_ = target;
  // The fault a_shortfall_deg: A ends short of its target and reports where it is (as a
  // controller reading an encoder would; open-loop GRBL reports the steps it sent).
  if (given[3] && options_.a_shortfall_deg != 0) {
    const double a0 = queue_.empty() ? (in_segment_ ? segment_.target[3] : position_[3])
                                     : queue_.back().target[3];
    const double turn = target[3] - a0;
    if (std::abs(turn) > options_.a_shortfall_deg)
      target[3] -= std::copysign(options_.a_shortfall_deg, turn);
  }
  if (state_ == "Idle") {
    StartSegment(target, rate / 60, 0, t);
    if (in_segment_) SetState("Run");
  } else {
    queue_.push_back({target, rate / 60});
  }
  return "ok";
}

void GrblEmulator::Serve() {
  while (!quit_) {
    pollfd wait{master_, POLLIN, 0};
    const int ready = ::poll(&wait, 1, 5);
    unsigned char buffer[512];
    ssize_t got = 0;
    if (ready > 0 && (wait.revents & POLLIN)) got = ::read(master_, buffer, sizeof buffer);
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = SimNow();
    Advance(t);
    for (ssize_t i = 0; i < got; ++i) {
      const unsigned char c = buffer[i];
      if (silent_) continue;
      if (c == '?' || c == '!' || c == '~' || c == 0x18 || c >= 0x80) {
        OnRealTime(c, t);  // picked out of the stream wherever they come
      } else if (c == '\n' || c == '\r') {
        if (!critical_) lines_.push_back(line_);
        line_.clear();
      } else if (line_.size() <= kLineBufferSize) {
        line_ += static_cast<char>(c);
      }
    }
    while (!lines_.empty() && !Busy() && !silent_) {
      const std::string next = lines_.front();
      lines_.erase(lines_.begin());
      OnLine(next, t);
    }
  }
}

}  // namespace lumislab
