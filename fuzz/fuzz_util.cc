#include "fuzz/fuzz_util.h"

#include <unistd.h>

#include <filesystem>

namespace lumislab::fuzz {

const std::string& TempDir() {
  static const std::string dir = [] {
    // Every input is written to a file: a RAM-backed folder keeps that cheap.
    const char* env = std::getenv("TMPDIR");
    std::string base = env && *env ? env : "/tmp";
    if (!(env && *env) && access("/dev/shm", W_OK | X_OK) == 0) base = "/dev/shm";
    std::string pattern = base + "/lumislab-fuzz-" + std::to_string(getpid()) + "-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("lumislab fuzz: mkdtemp");
      std::abort();
    }
    return pattern;
  }();
  static const bool registered = [] {
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(TempDir(), ec);
    });
    return true;
  }();
  (void)registered;
  return dir;
}

std::string SubDir(const std::string& name) {
  const std::string dir = TempDir() + "/" + name;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "lumislab fuzz: cannot create %s: %s\n", dir.c_str(),
                 ec.message().c_str());
    std::abort();
  }
  return dir;
}

void WriteFile(const std::string& path, const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(("lumislab fuzz: cannot write " + path).c_str());
    std::abort();
  }
}

void ReportError(const Error& e) {
  static const bool verbose = [] {
    const char* v = std::getenv("LUMISLAB_FUZZ_VERBOSE");
    return v != nullptr && std::string(v) == "1";
  }();
  if (verbose) std::fprintf(stderr, "lumislab::Error (exit %d): %s\n", e.exit_code(), e.what());
}

void UnexpectedException(const char* what, const char* type) {
  std::fprintf(stderr,
               "\n==lumislab-fuzz== FINDING: an exception that is not a lumislab::Error "
               "escaped the reader: %s: %s\n",
               type, what);
  std::abort();
}

void Finding(const std::string& message) {
  std::fprintf(stderr, "\n==lumislab-fuzz== FINDING: %s\n", message.c_str());
  std::abort();
}

}  // namespace lumislab::fuzz
