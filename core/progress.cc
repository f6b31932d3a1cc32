#include "core/progress.h"

#include <unistd.h>

#include <cstdio>

#include "core/log.h"

namespace lumislab {

Progress::Progress(std::string label, int total)
    : label_(std::move(label)),
      total_(total),
      tty_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { Finish(); }

void Progress::Advance(int n, const std::string& note) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += n;
  Draw(note);
}

int Progress::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_;
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (tty_ && GetLogLevel() <= LogLevel::kInfo) std::fprintf(stderr, "\n");
}

void Progress::Draw(const std::string& note) {
  if (GetLogLevel() > LogLevel::kInfo || total_ <= 0) return;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const int percent = int(100.0 * done_ / total_);
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = kWidth * done_ / total_;
    std::fprintf(stderr, "\r%s [%s%s] %d/%d %.1fs %s", label_.c_str(),
                 std::string(filled, '#').c_str(), std::string(kWidth - filled, '.').c_str(), done_,
                 total_, seconds, note.c_str());
    std::fflush(stderr);
  } else if (percent / 10 != last_line_percent_ / 10 || done_ == total_) {
    // Plain lines: at most one per 10 %, and the last one.
    last_line_percent_ = percent;
    std::fprintf(stderr, "%s: %d/%d (%d%%) %.1fs %s\n", label_.c_str(), done_, total_, percent,
                 seconds, note.c_str());
  }
}

}  // namespace lumislab
