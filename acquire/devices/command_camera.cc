#include "acquire/devices/command_camera.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include "acquire/devices/operator.h"
#include "acquire/devices/program.h"
#include "acquire/settle_tracker.h"
#include "core/atomic_file.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/photo/photo_format.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// Renames `tmp` to `stem`.<its extension>; IoError naming the target when it cannot.
std::string PlacePhoto(const std::string& tmp, const std::string& stem,
                       const std::string& raw_extension) {
  const std::string path = stem + "." + PhotoExtensionOf(tmp, raw_extension);
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw IoError(path, "cannot rename the downloaded photo into place: " + ec.message());
  }
  return path;
}

class CommandCamera : public Camera {
 public:
  CommandCamera(const std::string& uri, const std::string& program)
      : Camera(uri), program_(program) {}
  void Connect(const CameraSettings& settings, DeviceLog* log) override {
    settings_ = settings;
    log_ = log;
    if (!ProgramFound(program_))
      throw BadInput(uri() + ": " + program_ + " is not an executable program (nor in PATH)");
  }
  std::vector<double> ShutterSpeeds() override { return {}; }
  void SetShutterSpeed(double seconds) override { shutter_s_ = seconds; }
  std::string Capture(const std::string& stem) override {
    const std::string tmp = TemporaryPathFor(stem + ".photo");
    try {
      RunDeviceProgram(uri(), "capturing " + fs::path(stem).filename().string(), program_,
                       {"capture", tmp, Num(shutter_s_, 6)}, settings_.capture_timeout_s, log_);
      if (!fs::is_regular_file(tmp))
        throw DeviceError(uri(), "capturing", program_ + " exited 0 but wrote no photo at " + tmp);
      return PlacePhoto(tmp, stem, "");
    } catch (...) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw;
    }
  }
  void Close() noexcept override {}

 private:
  std::string program_;
  CameraSettings settings_;
  DeviceLog* log_ = nullptr;
  double shutter_s_ = 0;
};

class FolderCamera : public Camera {
 public:
  FolderCamera(const std::string& uri, const std::string& dir)
      : Camera(uri), dir_(dir), tracker_(kSettleS) {}
  void Connect(const CameraSettings& settings, DeviceLog* log) override {
    settings_ = settings;
    log_ = log;
    if (!fs::is_directory(dir_)) throw BadInput(uri() + ": " + dir_ + ": folder not found");
    tracker_.Scan(dir_);
    for (const auto& [name, settled] : tracker_.Files()) taken_.insert(name);
  }
  std::vector<double> ShutterSpeeds() override { return {}; }
  void SetShutterSpeed(double seconds) override {
    shutter_s_ = seconds;
    if (log_) log_->Note(uri(), "exposure time wanted: " + Num(seconds, 6) + " s");
  }
  std::string Capture(const std::string& stem) override {
    const std::string name = fs::path(stem).filename().string();
    std::fprintf(stderr, "lumislab-acquire: waiting for photo %s (%s s) in %s\n", name.c_str(),
                 Num(shutter_s_, 6).c_str(), dir_.c_str());
    if (log_) log_->Note(uri(), "waiting for " + name + " (" + Num(shutter_s_, 6) + " s)");
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
      tracker_.Scan(dir_);
      for (const auto& [file, settled] : tracker_.Files()) {
        if (!settled || taken_.count(file)) continue;
        taken_.insert(file);
        if (log_) log_->Received(uri(), file);
        const std::string tmp = TemporaryPathFor(stem + ".photo");
        std::error_code ec;
        fs::copy_file(dir_ + "/" + file, tmp, fs::copy_options::overwrite_existing, ec);
        if (ec) {
          fs::remove(tmp, ec);
          throw IoError(tmp, "cannot copy " + dir_ + "/" + file + ": " + ec.message());
        }
        std::string raw = fs::path(file).extension().string();
        if (!raw.empty()) raw.erase(0, 1);
        for (char& c : raw) c = char(std::tolower(static_cast<unsigned char>(c)));
        return PlacePhoto(tmp, stem, raw);
      }
      const double waited =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (waited > settings_.capture_timeout_s)
        throw DeviceError(uri(), "waiting for " + name,
                          "no new photo in " + dir_ + " within " +
                              std::to_string(int(settings_.capture_timeout_s)) + " s");
      if (!PauseUnlessStopped(0.1)) throw DeviceStopped(uri(), "waiting for " + name);
    }
  }
  void Close() noexcept override {}

 private:
  static constexpr double kSettleS = 0.5;  // a file unchanged this long has been written
  std::string dir_;
  SettleTracker tracker_;
  std::set<std::string> taken_;
  CameraSettings settings_;
  DeviceLog* log_ = nullptr;
  double shutter_s_ = 0;
};

}  // namespace

std::string PhotoExtensionOf(const std::string& path, const std::string& raw_extension) {
  switch (DetectPhotoFormat(path)) {
    case PhotoFormat::kJpeg:
      return "jpg";
    case PhotoFormat::kTiff:
      return "tif";
    case PhotoFormat::kPng:
      return "png";
    case PhotoFormat::kExr:
      return "exr";
    case PhotoFormat::kRaw:
      return raw_extension.empty() ? "dng" : raw_extension;
  }
  return "photo";
}

std::unique_ptr<Camera> MakeCommandCamera(const std::string& uri, const std::string& program) {
  return std::make_unique<CommandCamera>(uri, program);
}

std::unique_ptr<Camera> MakeFolderCamera(const std::string& uri, const std::string& dir) {
  return std::make_unique<FolderCamera>(uri, dir);
}

}  // namespace lumislab
