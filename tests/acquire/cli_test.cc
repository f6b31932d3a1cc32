// lumislab-acquire's command line, in process: exit codes, --print-scene, subcommands.
#include "acquire/cli.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "acquire_test_util.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "lib/synthetic/scene.h"

namespace lumislab {
namespace {

int RunTool(std::vector<std::string> args) {
  args.insert(args.begin(), "lumislab-acquire");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return RunMain("acquire", [&] { return RunAcquire(int(argv.size()), argv.data()); });
}

TEST(AcquireCli, ExitCodes) {
  EXPECT_EQ(RunTool({"--help"}), 0);
  EXPECT_EQ(RunTool({"synth", "--help"}), 0);
  EXPECT_EQ(RunTool({"filter", "--help"}), 0);
  EXPECT_EQ(RunTool({}), 2);                               // a subcommand is required
  EXPECT_EQ(RunTool({"synth", "--out", "/tmp/x"}), 2);     // --scene is required
  EXPECT_EQ(RunTool({"synth", "--scene", "default"}), 2);  // --out is required
  EXPECT_EQ(RunTool({"synth", "--scene", "/nonexistent/scene.json", "--out", "/tmp/x"}), 2);
  EXPECT_EQ(RunTool({"filter", "--dpi", "1", "--out", "/tmp/x"}), 2);
  EXPECT_EQ(RunTool({"synth", "--scene", "default", "--print-scene"}), 0);
}

TEST(AcquireCli, FilterWritesTheSlides) {
  const std::string dir = acquire_test::FreshDir("cli_filter");
  EXPECT_EQ(
      RunTool({"filter", "--spacing-mm", "2.5", "--k-max", "2", "--dpi", "300", "--out", dir}), 0);
  for (const char* f : {"filter_p.png", "filter_n.png", "filter.json"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
}

TEST(AcquireCli, ScenesRunAndBadScenesExit2) {
  const std::string dir = acquire_test::FreshDir("cli_synth");
  const std::string good = dir + "/scene.json", bad = dir + "/bad.json";
  WriteTextAtomically(good, acquire_test::SmallSceneJson());
  std::string text = acquire_test::SmallSceneJson();
  text.replace(text.find("\"lobe_exponent\": 8"), 18, "\"lobe_exponent\": \"x\"");
  WriteTextAtomically(bad, text);
  EXPECT_EQ(RunTool({"synth", "--scene", bad, "--out", dir + "/bad_ds"}), 2);
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad_ds/dataset.json"));
  EXPECT_EQ(RunTool({"synth", "--scene", good, "--out", dir + "/ds", "--threads", "2",
                     "--truth-resolution", "30"}),
            0);
  EXPECT_TRUE(std::filesystem::exists(dir + "/ds/photos/pos_2_2_n.exr"));
  EXPECT_EQ(RunTool({"synth", "--scene", good, "--out", dir + "/ds", "--threads", "-4"}), 2);
}

}  // namespace
}  // namespace lumislab
