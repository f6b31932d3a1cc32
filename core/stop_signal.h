// The one stop-signal scheme: while a StopSignalScope lives, SIGINT and SIGTERM only set a flag
// that long-running loops poll (StopRequested) so they can finish the item in hand and leave a
// valid partial result; the previous handlers come back when the scope ends.
#pragma once

#include <csignal>

namespace lumislab {

class StopSignalScope {
 public:
  StopSignalScope();  // clears the flag and installs the handlers
  ~StopSignalScope();
  StopSignalScope(const StopSignalScope&) = delete;
  StopSignalScope& operator=(const StopSignalScope&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

// True once SIGINT or SIGTERM arrived inside a StopSignalScope.
bool StopRequested();
// Sets the flag as a signal would (tests, and loops that stop for another reason).
void RequestStop();
// Sleeps `seconds` in 50 ms slices so that a stop signal ends the pause at once; false when
// stopped.
bool PauseUnlessStopped(double seconds);

}  // namespace lumislab
