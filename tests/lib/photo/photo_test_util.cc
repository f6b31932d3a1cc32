#include "photo_test_util.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "core/error.h"

namespace lumislab::testing {

std::string ScratchDir() {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("lumislab_photo_test_" + std::to_string(getpid())) /
                                    (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

bool ThrowsBadInputNaming(const std::function<void()>& body, const std::string& path,
                          std::string* message) {
  try {
    body();
  } catch (const Error& e) {
    *message = e.what();
    return e.code() == ExitCode::kBadInput && message->find(path) != std::string::npos;
  }
  *message = "(nothing thrown)";
  return false;
}

}  // namespace lumislab::testing
