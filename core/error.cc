#include "core/error.h"

#include <cstdio>
#include <exception>
#include <new>

namespace lumislab {

Error InputError(const std::string& file, const std::string& field, const std::string& expected,
                 const std::string& got) {
  std::string message = file + ": ";
  if (!field.empty()) message += field + ": ";
  message += "expected " + expected + ", got " + got;
  return Error(ExitCode::kBadInput, message);
}

Error BadInput(const std::string& message) { return Error(ExitCode::kBadInput, message); }

Error IoError(const std::string& file, const std::string& what) {
  return Error(ExitCode::kIoError, file + ": " + what);
}

Error Failure(const std::string& message) { return Error(ExitCode::kFailure, message); }

int ReportException(const char* tool) {
  try {
    throw;
  } catch (const Error& e) {
    std::fprintf(stderr, "lumislab-%s: error: %s\n", tool, e.what());
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "lumislab-%s: error: out of memory\n", tool);
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lumislab-%s: error: %s\n", tool, e.what());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "lumislab-%s: error: unknown failure\n", tool);
    return 1;
  }
}

}  // namespace lumislab
