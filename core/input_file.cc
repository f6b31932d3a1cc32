#include "core/input_file.h"

#include <filesystem>

#include "core/error.h"

namespace lumislab {

void CheckInputFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw BadInput(path + ": " + what + " not found");
  if (!std::filesystem::is_regular_file(status))
    throw BadInput(path + ": not a regular file (a folder, FIFO or device is not a " + what + ")");
}

}  // namespace lumislab
