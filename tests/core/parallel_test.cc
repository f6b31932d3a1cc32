// core/parallel.h's contract: every index run once, on min(threads, count) threads of which the
// caller is one, in order on the caller when threads <= 1, and a body's exception rethrown on the
// caller after every thread has stopped, the indices not yet taken never run.
#include "core/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

// The threads that ran a body, collected under a lock.
class ThreadSet {
 public:
  void Add() {
    std::lock_guard<std::mutex> lock(mutex_);
    ids_.insert(std::this_thread::get_id());
  }
  std::set<std::thread::id> ids() {
    std::lock_guard<std::mutex> lock(mutex_);
    return ids_;
  }

 private:
  std::mutex mutex_;
  std::set<std::thread::id> ids_;
};

TEST(ParallelFor, EveryIndexRunsExactlyOnce) {
  for (const int threads : {1, 2, 3, 8, 64}) {
    const int count = 2000;
    std::vector<std::atomic<int>> runs(count);
    for (auto& r : runs) r = 0;
    ParallelFor(count, threads, [&](int k) { ++runs[k]; });
    for (int k = 0; k < count; ++k)
      ASSERT_EQ(runs[k].load(), 1) << "index " << k << ", " << threads << " threads";
  }
}

TEST(ParallelFor, NothingToDoRunsNothing) {
  int calls = 0;
  ParallelFor(0, 4, [&](int) { ++calls; });
  ParallelFor(-3, 4, [&](int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ParallelFor, OneThreadOrFewerRunsInOrderOnTheCaller) {
  for (const int threads : {1, 0, -2}) {
    std::vector<int> order;
    bool elsewhere = false;
    const auto caller = std::this_thread::get_id();
    ParallelFor(50, threads, [&](int k) {
      order.push_back(k);  // no lock: a second thread would be a data race (and the test's)
      elsewhere |= std::this_thread::get_id() != caller;
    });
    std::vector<int> expected(50);
    for (int k = 0; k < 50; ++k) expected[k] = k;
    EXPECT_EQ(order, expected) << threads << " threads";
    EXPECT_FALSE(elsewhere) << threads << " threads";
  }
}

// Each body waits until `threads` bodies run at the same time: only when ParallelFor really runs
// that many threads does every body return (a deadline turns a missing thread into a failure).
TEST(ParallelFor, RunsTheRequestedNumberOfThreadsTheCallerAmongThem) {
  for (const int threads : {2, 4, 7}) {
    std::atomic<int> arrived{0};
    std::atomic<bool> timed_out{false};
    ThreadSet seen;
    ParallelFor(threads, threads, [&](int) {
      seen.Add();
      ++arrived;
      const auto deadline = Clock::now() + std::chrono::seconds(30);
      while (arrived < threads && !timed_out) {
        if (Clock::now() > deadline) timed_out = true;
        std::this_thread::yield();
      }
    });
    EXPECT_FALSE(timed_out) << "fewer than " << threads << " threads ran at once";
    const auto ids = seen.ids();
    EXPECT_EQ(int(ids.size()), threads);
    EXPECT_EQ(ids.count(std::this_thread::get_id()), 1u) << "the caller is one of the threads";
  }
}

TEST(ParallelFor, NeverMoreThreadsThanIndices) {
  ThreadSet seen;
  ParallelFor(3, 16, [&](int) {
    seen.Add();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  });
  EXPECT_LE(seen.ids().size(), 3u);
  ThreadSet caps;
  std::atomic<int> calls{0};
  ParallelFor(200, 3, [&](int) {
    caps.Add();
    ++calls;
  });
  EXPECT_EQ(calls.load(), 200);
  EXPECT_LE(caps.ids().size(), 3u);
}

TEST(ParallelFor, ABodysExceptionReachesTheCallerWithItsTypeAndMessage) {
  for (const int threads : {1, 4}) {
    try {
      ParallelFor(100, threads, [&](int k) {
        if (k == 37) throw BadInput("item 37: expected something, got nothing");
      });
      ADD_FAILURE() << "nothing rethrown, " << threads << " threads";
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2);
      EXPECT_STREQ(e.what(), "item 37: expected something, got nothing");
    }
    // Any exception, not only lumislab's.
    EXPECT_THROW(ParallelFor(10, threads,
                             [&](int k) {
                               if (k == 3) throw std::out_of_range("3");
                             }),
                 std::out_of_range);
  }
}

// In order: the indices after the throwing one are never run.
TEST(ParallelFor, OneThreadStopsAtTheFirstException) {
  std::vector<int> ran;
  EXPECT_THROW(ParallelFor(10, 1,
                           [&](int k) {
                             ran.push_back(k);
                             if (k == 4) throw Failure("4");
                           }),
               Error);
  EXPECT_EQ(ran, (std::vector<int>{0, 1, 2, 3, 4}));
}

// Several threads: after the first exception the others take no new index, and ParallelFor
// returns only when every thread has stopped (no body runs after it returned).
TEST(ParallelFor, AfterAnExceptionNoNewIndexIsTakenAndAllThreadsHaveStopped) {
  const int count = 1000;
  std::atomic<int> calls{0};
  std::atomic<int> running{0};
  EXPECT_THROW(ParallelFor(count, 4,
                           [&](int k) {
                             ++running;
                             ++calls;
                             if (k == 0) {
                               --running;
                               throw Failure("0");
                             }
                             std::this_thread::sleep_for(std::chrono::milliseconds(2));
                             --running;
                           }),
               Error);
  EXPECT_EQ(running.load(), 0) << "a body still ran after ParallelFor returned";
  const int after = calls.load();
  // Each of the other three threads finishes the index it holds, and may take one more before
  // it sees the failure; 1000 indices at 2 ms each would take 0.7 s on three threads.
  EXPECT_LT(after, 100);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(calls.load(), after) << "a body started after ParallelFor returned";
}

TEST(ResolveThreads, ZeroMeansTheMachinesCoresOtherwiseTheRequest) {
  EXPECT_EQ(ResolveThreads(0), int(std::max(1u, std::thread::hardware_concurrency())));
  EXPECT_EQ(ResolveThreads(1), 1);
  EXPECT_EQ(ResolveThreads(5), 5);
  EXPECT_EQ(ResolveThreads(kMaxThreads), kMaxThreads);
}

TEST(ResolveThreads, OutOfRangeIsBadInputNamingTheOption) {
  for (const int bad : {-1, kMaxThreads + 1}) {
    try {
      ResolveThreads(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2);
      EXPECT_EQ(std::string(e.what()),
                "--threads: expected 0 (all cores) .. 256, got " + std::to_string(bad));
    }
  }
}

}  // namespace
}  // namespace lumislab
