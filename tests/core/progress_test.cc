#include "core/progress.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "core/log.h"

namespace lumislab {
namespace {

// done() is read while other threads advance (a data race before it took the lock; a
// ThreadSanitizer build reports it): the count it sees never goes back and ends at the total.
TEST(ProgressTest, DoneIsConsistentWhileOtherThreadsAdvance) {
  const LogLevel saved = GetLogLevel();
  SetLogLevel(LogLevel::kWarning);  // no bar on the test's stderr
  constexpr int kThreads = 4, kSteps = 2000;
  Progress progress("test", kThreads * kSteps);
  std::vector<std::thread> workers;
  for (int t = 0; t < kThreads; ++t)
    workers.emplace_back([&] {
      for (int k = 0; k < kSteps; ++k) progress.Advance();
    });
  int last = 0;
  bool monotonic = true, bounded = true;
  while (last < kThreads * kSteps && monotonic && bounded) {
    const int now = progress.done();
    monotonic = now >= last;
    bounded = now <= kThreads * kSteps;
    last = now;
  }
  for (auto& w : workers) w.join();
  EXPECT_TRUE(monotonic);
  EXPECT_TRUE(bounded);
  EXPECT_EQ(progress.done(), kThreads * kSteps);
  SetLogLevel(saved);
}

}  // namespace
}  // namespace lumislab
