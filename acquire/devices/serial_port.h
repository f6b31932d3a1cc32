// A serial port (a tty: a USB-serial adapter, or a pseudo-terminal in the tests) opened raw at a
// baud rate, read line by line with a timeout. Drivers of line-protocol devices (GRBL) use it.
#pragma once

#include <string>

namespace lumislab {

class SerialPort {
 public:
  // Opens `path` raw (no echo, no line editing, 8N1) at `baud`. BadInput "<uri>: <path> ..." when
  // the path does not exist, cannot be opened, is not a tty (a regular file, a FIFO, /dev/null) or
  // does not take the baud rate. `uri` only names the device in messages.
  SerialPort(const std::string& uri, const std::string& path, int baud);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  enum class Read { kLine, kTimeout, kStopped };
  // The next line received, without its line end ("\r\n" or "\n"; empty lines are skipped).
  // Waits at most `timeout_s`, polling in slices of at most 50 ms; kStopped as soon as the stop
  // signal is seen (core/stop_signal.h) unless `ignore_stop` (reads while halting after a stop).
  // DeviceError (exit 1) when the port fails (the device was unplugged).
  Read ReadLine(double timeout_s, std::string* line, bool ignore_stop = false);
  // Writes `bytes` in full (a line with its "\n", or a real-time byte); DeviceError when the port
  // fails or does not take them within a second.
  void Write(const std::string& bytes);
  // Drops what was received and not read yet.
  void DiscardInput();
  void Close() noexcept;
  const std::string& path() const { return path_; }

 private:
  std::string uri_;
  std::string path_;
  int fd_ = -1;
  std::string pending_;  // bytes received after the last complete line
};

}  // namespace lumislab
