#include "test_util.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace lumislab::testing {

CommandResult RunTool(const std::string& tool, const std::string& args) {
  const std::string cmd = std::string(LUMISLAB_BIN_DIR) + "/" + tool + " " + args + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::string FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("lumislab_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

void WriteFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string SceneJson(int nu, int nv, const std::string& camera_json,
                      const std::string& effects_json) {
  return R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": )" +
         std::to_string(nu) + R"(, "nv": )" + std::to_string(nv) + R"(, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8},
      {"position_mm": [-3, 1, -12], "intensity_w_sr": [0.5, 0.6, 0.9], "lobe_exponent": 3} ] },
  "camera": )" +
         camera_json +
         R"(,
  "effects": )" +
         effects_json + " }\n";
}

static int Count(const std::string& dir, bool temporary) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       it != fs::recursive_directory_iterator(); ++it) {
    if (!it->is_regular_file()) continue;
    const std::string name = it->path().filename().string();
    n += (!name.empty() && name[0] == '.') == temporary;
  }
  return n;
}
int CountFinalFiles(const std::string& dir) { return Count(dir, false); }
int CountTemporaryFiles(const std::string& dir) { return Count(dir, true); }

}  // namespace lumislab::testing
