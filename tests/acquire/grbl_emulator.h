// A GRBL 1.1 controller on a pseudo-terminal, for the tests of acquire/devices/grbl_stage and for
// runs without a stage: a thread speaks GRBL's line protocol on the pty's master while the driver
// opens the slave (SlavePath) as it would /dev/ttyUSB0. It moves three axes (X Y Z, machine
// frame, mm) over simulated time with a trapezoidal speed profile, answers `?` with status
// reports, and does what GRBL 1.1 does on feed hold, resume, soft reset, homing, soft limits and
// the alarm lock (github.com/gnea/grbl doc/markdown/interface.md, commands.md). With `axes` = 4
// it has a fourth, rotary axis A in degrees as 4-axis GRBL 1.1 builds have it (grbl-Mega-5X):
// reported after X Y Z in MPos/WPos, one more setting per group ($103, $113, $123, $133), named
// by $I ([AXS:4:XYZA]), not scaled by G20, and planned with the linear axes (its degrees count
// as millimetres in a move's length).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace lumislab {

// X Y Z (mm) and A (degrees, with axes = 4).
using GrblAxes = std::array<double, 4>;

struct GrblEmulatorOptions {
  double speed_factor = 1;                   // simulated time runs this much faster
  int axes = 3;                              // 3: X Y Z; 4: X Y Z and the rotary A
  GrblAxes travel_min_mm = {0, 0, 0, -360};  // soft limits, machine frame (A: degrees)
  GrblAxes travel_max_mm = {300, 300, 100, 360};
  GrblAxes home_mm = {0, 0, 0, 0};   // machine position after $H
  GrblAxes start_mm = {0, 0, 0, 0};  // machine position at power-up
  GrblAxes wco_mm = {0, 0, 0, 0};    // work coordinate offset (WPos = MPos - WCO)
  // Fault: A stops this many degrees short of every target (a slipping coupling) and reports it.
  double a_shortfall_deg = 0;
  double homing_s = 1;  // duration of $H, simulated
  double acceleration_mm_s2 = 500;
  double max_rate_mm_min = 6000;  // G0's speed, and the most G1's feed can reach
  bool soft_limits = true;        // $20
  bool report_wpos = false;       // $10=0: WPos (and WCO) in the status instead of MPos
  bool require_homing = false;    // power-up in Alarm, "[MSG:'$H'|'$X' to unlock]"
  std::string version = "1.1h";
};

class GrblEmulator {
 public:
  using Clock = std::chrono::steady_clock;
  struct Event {
    Clock::time_point at;
    // "> G1 X10 F1000" received, "> !" a real-time command (status queries '?' are not
    // recorded), "< ok" sent (status reports are not recorded), "state Run" a state change.
    std::string text;
  };

  explicit GrblEmulator(const GrblEmulatorOptions& options = {});
  ~GrblEmulator();  // stops the thread, closes the pty, removes the link
  GrblEmulator(const GrblEmulator&) = delete;
  GrblEmulator& operator=(const GrblEmulator&) = delete;

  const std::string& SlavePath() const { return slave_path_; }
  // A symbolic link at `path` to the slave (replacing a link there); removed by the destructor.
  void Link(const std::string& path);

  // The machine position now (mm, X Y Z; A in degrees), interpolated along the move under way.
  GrblAxes Position() const;
  // GRBL's state as its status report names it: "Idle", "Run", "Hold:1", "Alarm", "Home", ...
  std::string State() const;
  std::vector<Event> Events() const;

  // Fault injection. Silent: reads and drops everything and answers nothing (motion goes on).
  void SetSilent(bool silent);
  // Raises ALARM:<code> now, as GRBL does: motion stops at once; codes 1 and 2 (hard and soft
  // limit) also lock everything but a soft reset ("[MSG:Reset to continue]").
  void InjectAlarm(int code);
  // Puts the controller in the power-up alarm lock (true) or out of it (false), effective now;
  // a soft reset keeps the alarm and announces "[MSG:'$H'|'$X' to unlock]".
  void RequireHoming(bool require);

 private:
  struct Move {
    GrblAxes target{};  // machine mm
    double feed_mm_s = 0;
  };
  struct Segment {  // one straight move with a trapezoidal speed profile, simulated time
    GrblAxes start{}, target{};
    double feed = 0;  // mm/s, as programmed
    double length = 0, v0 = 0, vp = 0, a = 1;
    double t_start = 0, t1 = 0, t2 = 0, t3 = 0;  // accelerate, cruise, decelerate
    double Distance(double t) const;
    double Speed(double t) const;
    double End() const { return t_start + t1 + t2 + t3; }
  };

  void Serve();
  double SimNow() const;
  GrblAxes PositionAt(double t) const;
  void StartSegment(const GrblAxes& target, double feed_mm_s, double v0, double t);
  void Advance(double t);
  void OnRealTime(unsigned char byte, double t);
  void OnLine(const std::string& line, double t);
  std::string ExecuteGcode(const std::string& line, double t);  // "ok" / "error:N" / ""
  std::string ExecuteSystem(const std::string& line, double t);
  void Reset(double t);
  void RaiseAlarm(int code, double t);
  void SendStatus(double t);
  void Send(const std::string& line);
  void SetState(const std::string& state);
  void Record(const std::string& text);
  bool Busy() const;  // a line waits: homing, a full planner, a critical alarm

  GrblEmulatorOptions options_;
  int master_ = -1, slave_ = -1;
  std::string slave_path_, link_path_;
  Clock::time_point epoch_;

  mutable std::mutex mutex_;  // everything below
  std::string state_ = "Idle";
  GrblAxes position_{};  // at rest; during a segment, PositionAt interpolates
  GrblAxes planned_{};   // the end of the last planned move (G91 adds to it)
  bool in_segment_ = false;
  Segment segment_;
  std::vector<Move> queue_;  // planned moves after the segment under way
  Move held_;                // the move a feed hold interrupted, resumed by '~'
  bool hold_has_move_ = false;
  double homing_end_ = 0;
  bool critical_ = false;  // waits for a soft reset
  bool soft_limit_after_hold_ = false;
  bool ok_owed_ = false;  // the line a soft limit interrupted: GRBL answers it after the reset
  bool absolute_ = true, inches_ = false;
  int motion_mode_ = 0;  // G0 / G1
  double feed_mm_min_ = 0;
  int reports_ = 0;                 // status reports since the reset (WCO every tenth)
  std::string line_;                // bytes of the line being received
  std::vector<std::string> lines_;  // complete lines not executed yet
  std::vector<Event> events_;
  bool silent_ = false;
  int pending_alarm_ = 0;

  std::atomic<bool> quit_{false};
  std::thread thread_;
};

}  // namespace lumislab
