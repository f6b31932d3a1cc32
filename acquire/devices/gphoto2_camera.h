// The camera driver for `gphoto2[:<model>][@<port>]` (acquire/devices/device.h): a camera that
// libgphoto2 drives over USB or PTP/IP ("gphoto2@ptpip:192.168.1.20:15740",
// "gphoto2:Canon EOS 80D@usb:001,004", plain "gphoto2" for the first camera detected).
//
// What bounds each blocking libgphoto2 call (none of them can be interrupted from outside):
//   * PTP/IP: every socket connect, read and write of camlibs/ptp2/ptpip.c waits at most 2.5 s
//     (PTPIP_DEFAULT_TIMEOUT_S/MS, fixed in libgphoto2); a camera that stops answering fails the
//     call in flight with GP_ERROR_TIMEOUT, one that is gone fails it at once.
//   * USB: the port timeouts camlibs/ptp2 sets itself (a start timeout during gp_camera_init,
//     then its normal and capture timeouts, settable only in ~/.gphoto/settings).
//   * The capture is gp_camera_trigger_capture and then gp_camera_wait_for_event in slices of
//     50 ms until the new file is announced, the stop signal or capture_timeout_s. Not
//     gp_camera_capture: for a generic PTP camera it loops until the ObjectAdded event arrives
//     and never gives up while the event connection stays open and silent.
// A stop signal is seen between calls (and by libgphoto2's cancel callback during transfers).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "acquire/devices/device.h"

struct _Camera;
struct _GPContext;
struct _CameraAbilitiesList;
struct _GPPortInfoList;

namespace lumislab {

// `model`: libgphoto2's model name ("Canon EOS 80D", "PTP/IP Camera"; "" as detected, or
// "PTP/IP Camera" for a ptpip: port); `port`: libgphoto2's port path ("usb:001,004",
// "ptpip:127.0.0.1:15740"; "" the first camera detected). `uri` names the camera in messages and
// the device log.
std::unique_ptr<Camera> MakeGphoto2Camera(const std::string& uri, const std::string& model,
                                          const std::string& port);

// A shutter-speed choice as cameras spell it ("1/4000", "1/4000s", "0.5", "30", "30s", "2.5\"",
// "1 1/3", a generic PTP camera's "0.0080s") in seconds; nullopt for "Bulb", "Time" and what is
// not a time.
std::optional<double> ParseShutterSpeed(const std::string& choice);

class Gphoto2Camera : public Camera {
 public:
  Gphoto2Camera(std::string uri, std::string model, std::string port);
  ~Gphoto2Camera() override;

  void Connect(const CameraSettings& settings, DeviceLog* log) override;
  std::vector<double> ShutterSpeeds() override;
  void SetShutterSpeed(double seconds) override;
  std::string Capture(const std::string& path_stem) override;
  void Close() noexcept override;

  // What libgphoto2 said during the last call (its context's error and status messages and its
  // error log lines), for error messages.
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  struct Detected {
    std::string model, port;
  };
  std::vector<Detected> Detect();
  void ChooseModelAndPort(std::string* model, std::string* port);
  template <typename F>
  int Run(const std::string& text, F&& call);
  std::string Describe(int result) const;
  void ApplyChoice(const std::vector<std::string>& names, const std::string& value,
                   const std::string& what);
  void ReadShutterSpeeds();
  std::pair<std::string, std::string> WaitForNewFile();
  void Download(const std::string& folder, const std::string& name, const std::string& path);
  void CheckExposure(const std::string& path);

  std::string model_, port_;
  CameraSettings settings_;
  DeviceLog* log_ = nullptr;
  DeviceLog no_log_;
  _GPContext* context_ = nullptr;
  _Camera* camera_ = nullptr;
  _CameraAbilitiesList* abilities_ = nullptr;
  _GPPortInfoList* ports_ = nullptr;
  std::vector<std::pair<double, std::string>> shutter_choices_;  // s ascending, widget choice
  double shutter_s_ = 0;  // the exposure time set through SetShutterSpeed; 0: not set by us
  std::vector<std::string> messages_;
};

}  // namespace lumislab
