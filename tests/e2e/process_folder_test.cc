// pipelines/process-folder.sh: reconstruct's options passed through to the tool, and the
// dataset's consistency report (checks.json, docs/verifies.md) printed at the end of a run and
// when a check stops it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

testing::CommandResult ProcessFolder(const std::string& root, const std::string& args) {
  return testing::RunShell(
      "cd " + testing::ShellQuote(root) + " && env -u DISPLAY LUMISLAB_BIN=" +
      testing::ShellQuote(LUMISLAB_BIN_DIR) + " timeout -k 5 300 bash " +
      testing::ShellQuote(std::string(LUMISLAB_SOURCE_DIR) + "/pipelines/process-folder.sh") + " " +
      args + " 2>&1");
}

TEST(ProcessFolder, PassesReconstructOptionsAndPrintsTheConsistencyReport) {
  const std::string root = testing::FreshDir("process_folder");
  testing::WriteFile(root + "/scene.json",
                     testing::SceneJson(3, 3,
                                        R"({"size_px": [320, 240], "focal_px": 270,
                                            "position_mm": [0, -400, 2400],
                                            "look_at_mm": [0, 0, 750]})",
                                        "[]"));
  const auto synth = testing::RunTool(
      "lumislab-acquire", "synth --scene " + testing::ShellQuote(root + "/scene.json") + " --out " +
                              testing::ShellQuote(root + "/ds"));
  ASSERT_EQ(synth.exit_code, 0) << synth.output;

  const auto ok = ProcessFolder(root, "ds --resolution 48 --bracket-ratios estimated --threads 1");
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  // The options reached reconstruct (its parameter line) and the slab has their resolution.
  EXPECT_NE(ok.output.find("resolution=48"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("bracket_ratios=estimated"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("threads=1"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("consistency report (ds/checks.json):"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("0 warnings, 0 failed"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("slab: ds/slab"), std::string::npos) << ok.output;

  // The same capture with the slides of every photo exchanged in dataset.json: reconstruct stops
  // the run (exit 2) and the report says which check and why.
  const std::string json_path = root + "/ds/dataset.json";
  nlohmann::json dataset = nlohmann::json::parse(testing::ReadBinaryFile(json_path));
  for (auto& photo : dataset["photos"]) photo["slide"] = photo["slide"] == "p" ? "n" : "p";
  testing::WriteFile(json_path, dataset.dump(1));
  const auto bad = ProcessFolder(root, "ds --resolution 48 --force");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("failed  slides.sign"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("1 failed"), std::string::npos) << bad.output;
  EXPECT_EQ(bad.output.find("slab: ds/slab"), std::string::npos) << bad.output;

  // A value left out is the script's own usage error, before any tool runs.
  const auto usage = ProcessFolder(root, "ds --resolution");
  EXPECT_EQ(usage.exit_code, 2) << usage.output;
  EXPECT_NE(usage.output.find("--resolution needs a value"), std::string::npos) << usage.output;
}

}  // namespace
}  // namespace lumislab
