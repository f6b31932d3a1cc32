#include "acquire/devices/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "acquire/devices/device.h"
#include "core/error.h"
#include "core/stop_signal.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

bool BaudConstant(int baud, speed_t* speed) {
  switch (baud) {
    case 9600:
      *speed = B9600;
      return true;
    case 19200:
      *speed = B19200;
      return true;
    case 38400:
      *speed = B38400;
      return true;
    case 57600:
      *speed = B57600;
      return true;
    case 115200:
      *speed = B115200;
      return true;
    case 230400:
      *speed = B230400;
      return true;
    case 460800:
      *speed = B460800;
      return true;
    case 921600:
      *speed = B921600;
      return true;
    default:
      return false;
  }
}

}  // namespace

SerialPort::SerialPort(const std::string& uri, const std::string& path, int baud)
    : uri_(uri), path_(path) {
  speed_t speed;
  if (!BaudConstant(baud, &speed)) {
    throw BadInput(uri_ + ": baud " + std::to_string(baud) +
                   " is not a serial rate lumislab can set (9600, 19200, 38400, 57600, 115200, "
                   "230400, 460800, 921600)");
  }
  // O_NONBLOCK: opening a tty whose modem lines are down would otherwise wait for carrier, and a
  // FIFO without a writer would block. O_NOCTTY: the port never becomes our controlling tty.
  fd_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int error = errno;
    struct stat info {};
    if (::stat(path_.c_str(), &info) != 0 || error == ENOENT) {
      throw BadInput(uri_ + ": " + path_ + ": no such serial port");
    }
    throw BadInput(uri_ + ": " + path_ + ": cannot open the serial port: " + std::strerror(error));
  }
  if (!::isatty(fd_)) {
    Close();
    throw BadInput(uri_ + ": " + path_ + " is not a serial port (tty)");
  }
  termios tty{};
  if (::tcgetattr(fd_, &tty) != 0) {
    const int error = errno;
    Close();
    throw BadInput(uri_ + ": " + path_ +
                   ": cannot read the port's settings: " + std::strerror(error));
  }
  ::cfmakeraw(&tty);
  tty.c_cflag |= CLOCAL | CREAD;  // ignore modem control lines; enable the receiver
  tty.c_cflag &= ~(CSTOPB | CRTSCTS);
  tty.c_cc[VMIN] = 0;
  tty.c_cc[VTIME] = 0;
  if (::cfsetispeed(&tty, speed) != 0 || ::cfsetospeed(&tty, speed) != 0 ||
      ::tcsetattr(fd_, TCSANOW, &tty) != 0) {
    const int error = errno;
    Close();
    throw BadInput(uri_ + ": " + path_ + ": cannot set the port to " + std::to_string(baud) +
                   " baud, raw: " + std::strerror(error));
  }
}

SerialPort::~SerialPort() { Close(); }

void SerialPort::Close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void SerialPort::DiscardInput() {
  pending_.clear();
  if (fd_ >= 0) ::tcflush(fd_, TCIFLUSH);
}

SerialPort::Read SerialPort::ReadLine(double timeout_s, std::string* line, bool ignore_stop) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(std::max(0.0, timeout_s)));
  for (;;) {
    // A complete line may already be buffered from the last read.
    for (size_t newline; (newline = pending_.find('\n')) != std::string::npos;) {
      std::string text = pending_.substr(0, newline);
      pending_.erase(0, newline + 1);
      while (!text.empty() && (text.back() == '\r' || text.back() == '\0')) text.pop_back();
      // A device may send a line end before its first line ("\r\nGrbl 1.1h ..."); skip it.
      const size_t start = text.find_first_not_of("\r");
      if (start == std::string::npos) continue;
      *line = text.substr(start);
      return Read::kLine;
    }
    if (!ignore_stop && StopRequested()) return Read::kStopped;
    const double left = SecondsLeft(end);
    if (left <= 0) return Read::kTimeout;
    if (fd_ < 0) throw DeviceError(uri_, "reading " + path_, "the port is closed");
    pollfd wait{fd_, POLLIN, 0};
    const int slice_ms = static_cast<int>(std::clamp(left * 1000, 1.0, 50.0));
    const int ready = ::poll(&wait, 1, slice_ms);
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw DeviceError(uri_, "reading " + path_, std::strerror(errno));
    }
    if (ready == 0) continue;
    char buffer[256];
    const ssize_t got = ::read(fd_, buffer, sizeof buffer);
    if (got > 0) {
      pending_.append(buffer, static_cast<size_t>(got));
    } else if (got == 0 || (errno != EAGAIN && errno != EINTR)) {
      // A hung-up tty reads 0 or EIO: the device was unplugged or closed its end.
      throw DeviceError(uri_, "reading " + path_,
                        got == 0 ? "the port hung up" : std::string(std::strerror(errno)));
    } else if (wait.revents & (POLLHUP | POLLERR)) {
      throw DeviceError(uri_, "reading " + path_, "the port hung up");
    }
  }
}

void SerialPort::Write(const std::string& bytes) {
  if (fd_ < 0) throw DeviceError(uri_, "writing to " + path_, "the port is closed");
  const auto end = Clock::now() + std::chrono::seconds(1);
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t wrote = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (wrote > 0) {
      done += static_cast<size_t>(wrote);
      continue;
    }
    if (wrote < 0 && errno != EAGAIN && errno != EINTR) {
      throw DeviceError(uri_, "writing to " + path_, std::strerror(errno));
    }
    // The output buffer is full (a device that does not read): wait for room, bounded.
    if (SecondsLeft(end) <= 0) {
      throw DeviceError(uri_, "writing to " + path_, "the port takes no more data");
    }
    pollfd wait{fd_, POLLOUT, 0};
    ::poll(&wait, 1, 50);
  }
}

}  // namespace lumislab
