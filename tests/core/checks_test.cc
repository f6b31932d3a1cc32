// The dataset's consistency record (core/checks.h): what each stage verified, kept per stage.
#include "core/checks.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/json.h"

namespace lumislab {
namespace {

std::string FreshFolder(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "/checks_" + name + "_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(Checks, EachStageKeepsItsLatestRecords) {
  const std::string dir = FreshFolder("stages");
  CheckLog a(dir, "calibrate dark");
  a.Pass("dark.is_dark", "mean level 0.2 % of full scale", {{"level", 0.002}});
  a.Warn("dark.noise", "noise above the usual", {{"noise", 0.01}});
  a.Save();
  CheckLog b(dir, "reconstruct");
  b.Pass("slab.total_light", "positive");
  b.Save();
  CheckLog a2(dir, "calibrate dark");  // a rerun replaces the stage's records, not the others'
  a2.Pass("dark.is_dark", "mean level 0.3 % of full scale");
  a2.Save();
  const nlohmann::json j = JsonDocument::Load(dir + "/checks.json").raw();
  EXPECT_EQ(j["schema_version"], 1);
  ASSERT_EQ(j["stages"]["calibrate dark"]["checks"].size(), 1u);
  EXPECT_EQ(j["stages"]["calibrate dark"]["checks"][0]["message"],
            "mean level 0.3 % of full scale");
  EXPECT_EQ(j["stages"]["reconstruct"]["checks"][0]["outcome"], "passed");
  EXPECT_EQ(a.warnings(), 1);
  const std::string report = FormatCheckReport(dir);
  EXPECT_NE(report.find("checks: 2 passed, 0 warnings, 0 failed"), std::string::npos) << report;
}

TEST(Checks, AFailureIsRecordedThenThrownAsBadInput) {
  const std::string dir = FreshFolder("fail");
  CheckLog log(dir, "calibrate response");
  log.Pass("response.frames", "5 frames");
  try {
    log.Fail("response.exposure_order", "f.tif: exposure: brighter than g.tif", {{"x", 1}});
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("[response.exposure_order]"), std::string::npos);
  }
  const std::string report = FormatCheckReport(dir);
  EXPECT_NE(report.find("failed  response.exposure_order: f.tif: exposure"), std::string::npos)
      << report;
  EXPECT_NE(report.find("1 passed, 0 warnings, 1 failed"), std::string::npos) << report;
}

TEST(Checks, AForeignRecordIsReplacedAndNoFolderMeansNoRecord) {
  const std::string dir = FreshFolder("foreign");
  std::ofstream(dir + "/checks.json") << "{\"schema_version\": \"x\", \"stages\": 3}";
  EXPECT_EQ(FormatCheckReport(dir), "");
  CheckLog log(dir, "reconstruct");
  log.Pass("slab.total_light", "positive");
  log.Save();
  EXPECT_NE(FormatCheckReport(dir).find("1 passed"), std::string::npos);
  CheckLog bare("", "export");  // a bare slab: logged only
  bare.Warn("x", "y");
  bare.Save();
  EXPECT_EQ(FormatCheckReport(FreshFolder("none")), "");
}

// A stage killed while saving leaves .checks.tmp<pid>_<n>.json; the next stage on the dataset
// removes it even when it has nothing to save (e2e.FaultInjection.CalibrateScreen found one left
// after a rerun that skipped its finished work). A live process's temporary stays.
TEST(Checks, AKilledSavesTemporaryIsRemovedByTheNextStage) {
  const std::string dir = FreshFolder("orphan");
  // pid 2^22 + 1 is above Linux's pid_max limit: no process has it.
  const std::string orphan = dir + "/.checks.tmp4194305_1.json";
  const std::string live = dir + "/.checks.tmp" + std::to_string(getpid()) + "_1.json";
  std::ofstream(orphan) << "{";
  std::ofstream(live) << "{";
  CheckLog rerun(dir, "calibrate screen");
  EXPECT_FALSE(std::filesystem::exists(orphan));
  EXPECT_TRUE(std::filesystem::exists(live));
}

}  // namespace
}  // namespace lumislab
