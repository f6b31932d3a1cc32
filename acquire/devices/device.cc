#include "acquire/devices/device.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>

namespace lumislab {

DeviceLog::DeviceLog(const std::string& path) : path_(path) {
  if (path_.empty()) return;
  file_ = std::fopen(path_.c_str(), "a");
  if (!file_)
    throw IoError(path_, std::string("cannot open the device log: ") + std::strerror(errno));
}

DeviceLog::~DeviceLog() {
  if (file_) std::fclose(file_);
}

void DeviceLog::Write(const std::string& device, char direction, const std::string& text) {
  if (!file_) return;
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
  std::lock_guard<std::mutex> lock(mutex_);
  std::fprintf(file_, "%s.%03dZ %s %c %s\n", stamp, ms, device.c_str(), direction, shown.c_str());
  std::fflush(file_);
}

Error DeviceError(const std::string& device, const std::string& doing, const std::string& what) {
  return Failure(device + ": " + doing + ": " + what);
}

Error DeviceStopped(const std::string& device, const std::string& doing) {
  return Failure(device + ": " + doing + ": stopped by a signal");
}

}  // namespace lumislab
