// Counts the GL calls made through the glad loader (tests only): while a GlCallCounter lives,
// every entry point glad loaded is replaced by a shim that counts its calls by name and forwards
// to the driver's function; its destructor puts the driver's pointers back. Install it after
// gladLoadGL (a context made current), around the calls to count.
#pragma once

#include <map>
#include <string>

namespace lumislab {

class GlCallCounter {
 public:
  GlCallCounter();
  ~GlCallCounter();
  GlCallCounter(const GlCallCounter&) = delete;
  GlCallCounter& operator=(const GlCallCounter&) = delete;

  // Calls per entry point since construction or the last Reset (those never called absent).
  std::map<std::string, long> Counts() const;
  long Total() const;
  void Reset();
};

}  // namespace lumislab
