#include "acquire_test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.h"

namespace lumislab::acquire_test {

std::string SmallSceneJson(const std::string& effects_json, const std::string& camera_extra) {
  return R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 3, "nv": 3, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8},
      {"position_mm": [-3, 1, -12], "intensity_w_sr": [0.5, 0.6, 0.9], "lobe_exponent": 3} ] },
  "camera": { "size_px": [320, 240], "focal_px": 260, "position_mm": [0, -400, 2400],
              "look_at_mm": [0, 0, 750])" +
         camera_extra + R"( },
  "effects": )" +
         effects_json + " }\n";
}

SynthScene SmallScene(const std::string& effects_json) {
  return ParseScene(SmallSceneJson(effects_json), "small.json");
}

std::string FreshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("lumislab_acquire_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

SynthOptions SmallSynthOptions(const std::string& out) {
  SynthOptions options;
  options.out_dir = out;
  options.threads = 2;
  options.truth_resolution = 20;
  options.photo_format = "float";
  return options;
}

void ExpectEffectsRefused(const std::vector<std::pair<std::string, std::string>>& cases) {
  for (const auto& [effects, field] : cases) {
    try {
      SmallScene(effects);
      ADD_FAILURE() << "accepted: " << effects;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::kBadInput) << effects;
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("small.json: " + field + ": expected ", 0), 0u)
          << effects << " -> " << message;
    }
  }
}

}  // namespace lumislab::acquire_test
