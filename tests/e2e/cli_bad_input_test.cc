// Bad input on the command line: exit code 2, a message naming the file and the field, and no
// half-written file under a final name.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "core/atomic_file.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::CommandResult;
using testing::CountTemporaryFiles;
using testing::FreshDir;
using testing::RunTool;
using testing::SceneJson;
using testing::WriteFile;

const char* kSmallCamera =
    R"({"size_px": [640, 480], "focal_px": 560, "position_mm": [0, -200, 2400],
        "look_at_mm": [0, 0, 750]})";

class CliBadInput : public ::testing::Test {
 protected:
  // One small PNG dataset (2x2 grid, 640x480 photos), acquired once and copied per test.
  static void SetUpTestSuite() {
    // Per process: ctest runs each test in its own process, several at once.
    const std::string dir = FreshDir("cli_master_" + std::to_string(getpid()));
    WriteFile(dir + "/scene.json",
              SceneJson(2, 2, kSmallCamera, R"([{"type": "quantization", "bit_depth": 16}])"));
    master_ = dir + "/ds";
    const CommandResult r =
        RunTool("lumislab-acquire", "synth --scene " + dir + "/scene.json --out " + master_);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { fs::remove_all(fs::path(master_).parent_path()); }
  void SetUp() override {
    ds_ = FreshDir(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "/ds";
    fs::copy(master_, ds_, fs::copy_options::recursive);
  }
  void ReplaceInDatasetJson(const std::string& from, const std::string& to) {
    std::string text = ReadTextFile(ds_ + "/dataset.json");
    text = std::regex_replace(text, std::regex(from), to, std::regex_constants::format_first_only);
    WriteFile(ds_ + "/dataset.json", text);
  }
  static void ExpectBadInput(const CommandResult& r, const std::vector<std::string>& mentions) {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    for (const auto& m : mentions) EXPECT_NE(r.output.find(m), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("terminate called"), std::string::npos) << r.output;
  }
  CommandResult Calibrate() { return RunTool("lumislab-calibrate", "screen --dataset " + ds_); }
  CommandResult Reconstruct() {
    return RunTool("lumislab-reconstruct", "--dataset " + ds_ + " --resolution 60");
  }
  static std::string master_;
  std::string ds_;
};
std::string CliBadInput::master_;

TEST_F(CliBadInput, GoodDatasetRuns) {
  ASSERT_EQ(Calibrate().exit_code, 0);
  const CommandResult r = Reconstruct();
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(ds_ + "/slab/pos_1_1.exr"));
  EXPECT_EQ(CountTemporaryFiles(ds_), 0);
}

TEST_F(CliBadInput, MissingPhoto) {
  ASSERT_EQ(Calibrate().exit_code, 0);
  fs::remove(ds_ + "/photos/pos_1_0_n.png");
  ExpectBadInput(Reconstruct(), {"pos_1_0_n.png"});
  EXPECT_FALSE(fs::exists(ds_ + "/slab/pos_1_0.exr"));
  EXPECT_EQ(CountTemporaryFiles(ds_), 0);
}

TEST_F(CliBadInput, CorruptPng) {
  ASSERT_EQ(Calibrate().exit_code, 0);
  {
    std::ofstream f(ds_ + "/photos/pos_0_1_p.png", std::ios::binary | std::ios::trunc);
    f << "\x89PNG\r\n\x1a\n garbage, not a real PNG stream";
  }
  ExpectBadInput(Reconstruct(), {"pos_0_1_p.png"});
  EXPECT_FALSE(fs::exists(ds_ + "/slab/pos_0_1.exr"));
  EXPECT_EQ(CountTemporaryFiles(ds_), 0);
}

TEST_F(CliBadInput, WrongFieldInDatasetJson) {
  ReplaceInDatasetJson("\"distance_mm\": [0-9.e+]+", "\"distance_mm\": \"far\"");
  ExpectBadInput(Calibrate(), {"dataset.json", "setup.distance_mm", "\"far\""});
  ExpectBadInput(Reconstruct(), {"dataset.json", "setup.distance_mm"});
  EXPECT_FALSE(fs::exists(ds_ + "/calib/screen.json"));
}

TEST_F(CliBadInput, NegativeGridSize) {
  ReplaceInDatasetJson("\"nu\": 2", "\"nu\": -3");
  ExpectBadInput(Reconstruct(), {"dataset.json", "setup.grid.nu", "-3"});
  // The same in a scene file, for the acquisition.
  const std::string dir = FreshDir("cli_negative_scene");
  std::string scene = SceneJson(2, 2, kSmallCamera, "[]");
  scene.replace(scene.find("\"nu\": 2"), 7, "\"nu\": -3");
  WriteFile(dir + "/scene.json", scene);
  ExpectBadInput(
      RunTool("lumislab-acquire", "synth --scene " + dir + "/scene.json --out " + dir + "/ds"),
      {"scene.json", "grid.nu", "-3"});
  EXPECT_FALSE(fs::exists(dir + "/ds/dataset.json"));
}

TEST_F(CliBadInput, MissingCalibration) {
  ExpectBadInput(Reconstruct(), {"calib/screen.json"});
  EXPECT_FALSE(fs::exists(ds_ + "/slab/slab.json"));
}

TEST_F(CliBadInput, CorruptCalibrationJson) {
  ASSERT_EQ(Calibrate().exit_code, 0);
  std::string text = ReadTextFile(ds_ + "/calib/screen.json");
  text = std::regex_replace(text, std::regex("\"k1\": [-0-9.e+]+"), "\"k1\": null");
  WriteFile(ds_ + "/calib/screen.json", text);
  ExpectBadInput(Reconstruct(), {"screen.json", "distortion.k1"});
}

TEST_F(CliBadInput, MissingOrBlankCalibrationPhoto) {
  fs::remove(ds_ + "/photos/calib_0.png");
  ExpectBadInput(Calibrate(), {"calib_0.png"});
  EXPECT_FALSE(fs::exists(ds_ + "/calib/screen.json"));
  // A photo without a checkerboard (a slab photo in its place).
  fs::copy_file(ds_ + "/photos/pos_0_0_p.png", ds_ + "/photos/calib_0.png");
  ExpectBadInput(Calibrate(), {"calib_0.png"});
  EXPECT_FALSE(fs::exists(ds_ + "/calib/screen.json"));
}

TEST_F(CliBadInput, UnknownEffectInScene) {
  const std::string dir = FreshDir("cli_unknown_effect");
  WriteFile(dir + "/scene.json", SceneJson(2, 2, kSmallCamera, R"([{"type": "lens_flare"}])"));
  ExpectBadInput(
      RunTool("lumislab-acquire", "synth --scene " + dir + "/scene.json --out " + dir + "/ds"),
      {"scene.json", "effects[0].type", "lens_flare"});
}

TEST_F(CliBadInput, MissingDatasetFolder) {
  ExpectBadInput(RunTool("lumislab-reconstruct", "--dataset /nonexistent/lumislab"),
                 {"/nonexistent/lumislab/dataset.json"});
  ExpectBadInput(RunTool("lumislab-calibrate", "screen --dataset /nonexistent/lumislab"),
                 {"/nonexistent/lumislab/dataset.json"});
}

}  // namespace
}  // namespace lumislab
