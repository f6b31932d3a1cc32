#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "core/error.h"

namespace lumislab {

int ResolveThreads(int requested) {
  if (requested < 0 || requested > kMaxThreads)
    throw BadInput("--threads: expected 0 (all cores) .. " + std::to_string(kMaxThreads) +
                   ", got " + std::to_string(requested));
  if (requested > 0) return requested;
  return int(std::max(1u, std::thread::hardware_concurrency()));
}

void ParallelFor(int count, int threads, const std::function<void(int)>& body) {
  if (count <= 0) return;
  const int workers = std::clamp(threads, 1, count);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (int k = next++; k < count && !failed; k = next++) {
      try {
        body(k);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  try {
    for (int t = 1; t < workers; ++t) pool.emplace_back(work);
  } catch (const std::system_error&) {
    // The system refused another thread: the ones already running (and this one) do the work.
  }
  work();
  for (auto& thread : pool) thread.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace lumislab
