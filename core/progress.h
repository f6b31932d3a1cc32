// Progress reporter: a bar on a terminal, plain "label: k/n" lines otherwise. Thread-safe: every
// member, done() included, takes the one mutex.
#pragma once

#include <chrono>
#include <mutex>
#include <string>

namespace lumislab {

class Progress {
 public:
  Progress(std::string label, int total);
  ~Progress();
  void Advance(int n = 1, const std::string& note = "");
  void Finish();
  int done() const;

 private:
  void Draw(const std::string& note);
  std::string label_;
  int total_;
  int done_ = 0;
  bool tty_;
  bool finished_ = false;
  int last_line_percent_ = -1;
  std::chrono::steady_clock::time_point start_;
  mutable std::mutex mutex_;
};

}  // namespace lumislab
