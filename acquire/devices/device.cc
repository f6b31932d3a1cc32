#include "acquire/devices/device.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>

namespace lumislab {

void DeviceLog::Open(const std::string& path) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::FILE* file = std::fopen(path.c_str(), "a");
  if (!file)
    throw IoError(path, std::string("cannot open the device log: ") + std::strerror(errno));
  if (file_) std::fclose(file_);
  file_ = file;
  path_ = path;
  for (const std::string& line : kept_) std::fputs(line.c_str(), file_);
  kept_.clear();
  std::fflush(file_);
}

DeviceLog::~DeviceLog() {
  if (file_) std::fclose(file_);
}

void DeviceLog::Write(const std::string& device, char direction, const std::string& text) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const int ms = static_cast<int>(
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char stamp[40];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &utc);
  // Control characters (a GRBL soft reset is 0x18) are written as <0x18> so that the log stays
  // one line per exchange.
  std::string shown;
  for (unsigned char c : text) {
    if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "<0x%02x>", c);
      shown += hex;
    } else {
      shown += static_cast<char>(c);
    }
  }
  char head[64];
  std::snprintf(head, sizeof head, "%s.%03dZ ", stamp, ms);
  const std::string line = head + device + " " + direction + " " + shown + "\n";
  std::lock_guard<std::mutex> lock(mutex_);
  if (!file_) {
    kept_.push_back(line);
    return;
  }
  std::fputs(line.c_str(), file_);
  std::fflush(file_);
}

Error DeviceError(const std::string& device, const std::string& doing, const std::string& what) {
  return Failure(device + ": " + doing + ": " + what);
}

Error DeviceStopped(const std::string& device, const std::string& doing) {
  return Failure(device + ": " + doing + ": stopped by a signal");
}

}  // namespace lumislab
