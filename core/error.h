// Errors with the exit codes of docs/architecture.md §7. Thrown, never aborted on; mains turn them
// into codes.
#pragma once

#include <stdexcept>
#include <string>

namespace lumislab {

enum class ExitCode : int { kOk = 0, kFailure = 1, kBadInput = 2, kIoError = 3 };

class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }
  int exit_code() const { return static_cast<int>(code_); }

 private:
  ExitCode code_;
};

// Bad input: "file: field: expected X, got Y" (exit 2).
Error InputError(const std::string& file, const std::string& field, const std::string& expected,
                 const std::string& got);
// Bad input with a free-form message (exit 2); the message must name the file.
Error BadInput(const std::string& message);
// I/O failure (exit 3): could not read/write/rename.
Error IoError(const std::string& file, const std::string& what);
// Anything else that went wrong (exit 1).
Error Failure(const std::string& message);

// Throws Failure with file:line when `cond` is false (COLMAP's THROW_CHECK, never aborts).
#define LUMISLAB_CHECK(cond, msg)                                                               \
  do {                                                                                          \
    if (!(cond))                                                                                \
      throw ::lumislab::Failure(std::string(__FILE__) + ":" + std::to_string(__LINE__) + ": " + \
                                (msg));                                                         \
  } while (0)

// Runs `body` and maps exceptions to exit codes, printing "lumislab-<tool>: error: ..." on stderr.
// Every main() is `return lumislab::RunMain("reconstruct", [&] { return Run(argc, argv); });`
template <typename F>
int RunMain(const char* tool, F&& body);
int ReportException(const char* tool);  // call inside a catch(...) block

template <typename F>
int RunMain(const char* tool, F&& body) {
  try {
    return body();
  } catch (...) {
    return ReportException(tool);
  }
}

}  // namespace lumislab
