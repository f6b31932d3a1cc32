// The one parallel-for of lumislab: a fixed number of worker threads take indices from a shared
// counter. An exception thrown by the body on any thread stops the others from taking new
// indices and is rethrown on the calling thread once all of them have finished, so a worker's
// error reaches the tool's usual exit codes instead of terminating the process.
#pragma once

#include <functional>

namespace lumislab {

// Upper bound of the value every --threads option accepts (not of the count 0 resolves to).
constexpr int kMaxThreads = 256;

// 0 -> the machine's cores (std::thread::hardware_concurrency(), at least 1, not capped at
// kMaxThreads); otherwise `requested`, which must be in [0, kMaxThreads] (BadInput naming
// --threads otherwise).
int ResolveThreads(int requested);

// Runs body(k) for k in [0, count) on min(threads, count) threads (the caller is one of them;
// fewer when the system refuses to start one). `threads` <= 1 runs in order on the calling
// thread. The first exception is rethrown after every thread has stopped; indices not yet taken
// then are never run.
void ParallelFor(int count, int threads, const std::function<void(int)>& body);

}  // namespace lumislab
