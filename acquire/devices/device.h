// The devices `lumislab-acquire capture` drives (docs/architecture.md §4, docs/formats.md §3): a
// translation stage that moves the luminaire, a camera that photographs the screen, and the
// operator at the terminal. One interface per kind; each driver is its own file, chosen by the
// scheme of a URI (acquire/devices/uri.h):
//   stages:  grbl:<port>[?baud=N]   command:<program>   manual
//   cameras: gphoto2[:<model>][@<port>]   command:<program>   folder:<dir>
// Every wait on a device has a timeout and polls the stop signal (core/stop_signal.h) in slices
// of at most 50 ms, so a stalled device or a Ctrl-C never hangs the capture.
#pragma once

#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace lumislab {

// Appends every command sent to a device and every reply to one text file (the dataset's
// capture/devices.log), a line each, flushed at once so that a kill -9 loses nothing:
//   2026-12-04T21:40:01.123Z grbl:/dev/ttyUSB0 > G1 X10.000 Y20.000 F1000
//   2026-12-04T21:40:01.131Z grbl:/dev/ttyUSB0 < ok
// '>' sent, '<' received, '#' a note (what the capture is doing, a timeout, a retry).
// Thread-safe. A log without a path keeps its lines until Open gives it one (the capture opens
// its devices before it makes the dataset folder, so that a device it cannot use leaves nothing
// behind); one never opened writes nothing (tests).
class DeviceLog {
 public:
  DeviceLog() = default;
  explicit DeviceLog(const std::string& path) { Open(path); }
  ~DeviceLog();
  // Appends to `path` from now on, the lines kept so far first; IoError naming it when it
  // cannot be opened.
  void Open(const std::string& path);
  DeviceLog(const DeviceLog&) = delete;
  DeviceLog& operator=(const DeviceLog&) = delete;

  void Sent(const std::string& device, const std::string& text) { Write(device, '>', text); }
  void Received(const std::string& device, const std::string& text) { Write(device, '<', text); }
  void Note(const std::string& device, const std::string& text) { Write(device, '#', text); }
  void Write(const std::string& device, char direction, const std::string& text);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<std::string> kept_;  // lines written before Open
  std::mutex mutex_;
};

// A device that failed during the capture (stopped answering, an alarm, gone): exit 1 with
// "<device uri>: <what it was doing>: <what happened>". A device that cannot be used at all
// before anything moves (not found, not a tty, a setting it cannot take) is BadInput (exit 2)
// with the same shape of message.
Error DeviceError(const std::string& device, const std::string& doing, const std::string& what);
// The capture was stopped by SIGINT/SIGTERM while `device` was `doing` something (exit 1).
Error DeviceStopped(const std::string& device, const std::string& doing);

// Seconds from now to `end` (negative once past): what every device wait has left of its timeout.
inline double SecondsLeft(std::chrono::steady_clock::time_point end) {
  return std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
}

// Stage axes and their targets, in the stage's own frame and unit (mm, absolute): {'X', 12.5}.
using AxisTargets = std::vector<std::pair<char, double>>;

struct StageSettings {          // setup.json "lab.stage" (docs/formats.md §3)
  bool home = false;            // home ($H for GRBL) once before the first move
  double feed_mm_min = 1000;    // feed rate of the moves
  double tolerance_mm = 0.01;   // read-back position vs. target, per axis
  double reply_timeout_s = 5;   // a command's reply
  double move_timeout_s = 120;  // one move, from the command to Idle
  double settle_s = 0;          // wait after a move before the photo (vibration)
  // A rotary axis (lab.rotation_axis), in degrees: its read-back tolerance, and its moves are
  // rapid (G0) since a linear feed does not apply to it. '\0': none.
  char rotary_axis = '\0';
  double tolerance_deg = 0.05;
};

class Stage {
 public:
  virtual ~Stage() = default;
  const std::string& uri() const { return uri_; }
  // Opens the device and checks that it answers; BadInput naming the URI when it cannot be used
  // (no such port, not a tty, no answer within reply_timeout_s, an alarm it cannot clear).
  virtual void Connect(const StageSettings& settings, DeviceLog* log) = 0;
  // Homing cycle (settings.home); DeviceError when it fails.
  virtual void Home() = 0;
  // Moves the given axes to their absolute targets, waits until the stage is at rest, checks the
  // position read back against the targets (tolerance_mm) and returns it (same axes, same order;
  // the targets themselves for a stage that cannot be read back). DeviceError on an alarm, an
  // error reply, a timeout or a position off target; DeviceStopped after a stop signal, which
  // halts the stage first (GRBL: feed hold then soft reset) so that it is still within 1 s.
  virtual AxisTargets MoveTo(const AxisTargets& target) = 0;
  // Leaves the device in a safe state (motion stopped) and closes it; never throws.
  virtual void Close() noexcept = 0;

 protected:
  explicit Stage(std::string uri) : uri_(std::move(uri)) {}

 private:
  std::string uri_;
};

struct CameraSettings {           // setup.json "lab.camera" (docs/formats.md §3)
  std::string aperture;           // as the camera's widget spells it ("8", "f/8"); "" leaves it
  std::string iso;                // "100"; "" leaves it
  std::string image_format;       // "RAW", "Large Fine JPEG", ...; "" leaves it
  bool delete_from_card = false;  // delete each photo from the camera's card once downloaded
  double capture_timeout_s = 60;  // from the trigger to the photo on disk (longest exposure +)
  double connect_timeout_s = 10;  // finding and opening the camera
};

class Camera {
 public:
  virtual ~Camera() = default;
  const std::string& uri() const { return uri_; }
  // Finds and opens the camera and applies the settings; BadInput naming the URI and the setting
  // when the camera is not found or cannot take one (the values it offers listed).
  virtual void Connect(const CameraSettings& settings, DeviceLog* log) = 0;
  // The exposure times the camera can be set to (s, ascending); empty when any time is accepted
  // (command:, folder:, where lumislab cannot set it).
  virtual std::vector<double> ShutterSpeeds() = 0;
  // Sets the exposure time of the next photos: one of ShutterSpeeds() (BadInput otherwise), or
  // for a camera that cannot be set, a request the operator or program is told about.
  virtual void SetShutterSpeed(double seconds) = 0;
  // Takes one photo and stores it as `path_stem` + "." + the extension of the camera's file
  // (lower case: jpg, dng, cr2, ...), written under a temporary name and renamed into place;
  // returns that path. DeviceError when no photo arrives within capture_timeout_s or the camera
  // is gone; DeviceStopped after a stop signal.
  virtual std::string Capture(const std::string& path_stem) = 0;
  virtual void Close() noexcept = 0;

 protected:
  explicit Camera(std::string uri) : uri_(std::move(uri)) {}

 private:
  std::string uri_;
};

}  // namespace lumislab
