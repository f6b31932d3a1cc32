// Shared by the libFuzzer targets of fuzz/ (fuzz/README.md).
//
// A target hands the fuzzer's bytes to one of lumislab's readers. lumislab::Error is how a reader
// says "bad input" (exit 2), "I/O error" (3) or "failure" (1): a normal outcome, ignored here.
// Anything else is a finding: a crash or sanitizer report (the fuzz build has ASan and UBSan),
// an allocation beyond -malloc_limit_mb / -rss_limit_mb, a hang beyond -timeout, or an exception
// that is not a lumislab::Error (FUZZ_END prints it and aborts, so libFuzzer saves the input).
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <typeinfo>

#include "core/error.h"

namespace lumislab::fuzz {

// This process's own temporary folder ($TMPDIR, else /dev/shm, else /tmp;
// lumislab-fuzz-<pid>-XXXXXX), created on
// first use and removed at exit (a crashed run leaves it: the crash is what matters then).
const std::string& TempDir();
// TempDir()/name, created on first use.
std::string SubDir(const std::string& name);
// Writes `size` bytes to `path` (aborts when it cannot: that is the machine, not a finding).
void WriteFile(const std::string& path, const uint8_t* data, size_t size);
// LUMISLAB_FUZZ_VERBOSE=1: print the message of each lumislab::Error (to see which seeds a
// reader accepts: `LUMISLAB_FUZZ_VERBOSE=1 build-fuzz/fuzz/fuzz_scene fuzz/corpus/fuzz_scene/*`).
void ReportError(const ::lumislab::Error& e);
// Reports an exception that is not a lumislab::Error and aborts (libFuzzer saves the input).
[[noreturn]] void UnexpectedException(const char* what, const char* type);
// Reports a broken invariant (a file the project wrote that it cannot read back) and aborts.
[[noreturn]] void Finding(const std::string& message);

}  // namespace lumislab::fuzz

// LLVMFuzzerTestOneInput's body goes between these: lumislab::Error is a normal outcome.
#define FUZZ_BEGIN try {
#define FUZZ_END                                                            \
  }                                                                         \
  catch (const ::lumislab::Error& e) {                                      \
    ::lumislab::fuzz::ReportError(e);                                       \
  }                                                                         \
  catch (const std::exception& e) {                                         \
    ::lumislab::fuzz::UnexpectedException(e.what(), typeid(e).name());      \
  }                                                                         \
  catch (...) {                                                             \
    ::lumislab::fuzz::UnexpectedException("(not a std::exception)", "..."); \
  }                                                                         \
  return 0;
