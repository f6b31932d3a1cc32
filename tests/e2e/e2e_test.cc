// End to end on synthetic captures: acquire -> calibrate -> reconstruct, compared with the
// analytic truth/ that the synthetic acquisition writes.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "core/dataset.h"
#include "core/slab_compare.h"
#include "noise_floor.h"
#include "test_util.h"

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::SceneJson;
using testing::WriteFile;

const char* kFrontalCamera =
    R"({"size_px": [1600, 1200], "focal_px": 1300, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";
// About 50 degrees off the screen normal, from the side and below.
const char* kObliqueCamera =
    R"({"size_px": [1600, 1200], "focal_px": 1100, "position_mm": [1400, -300, 1900],
        "look_at_mm": [0, 0, 750]})";
const char* kNoise =
    R"([{"type": "sensor_noise", "full_well_e": 20000, "read_noise_e": 3, "seed": 7},
        {"type": "quantization", "bit_depth": 16}])";
constexpr double kFullWell = 20000, kReadNoise = 3;

// acquire (scene file or "default") -> calibrate -> reconstruct; returns the dataset folder.
std::string RunPipeline(const std::string& name, const std::string& scene_json) {
  const std::string dir = FreshDir(name);
  std::string scene = "default";
  if (!scene_json.empty()) {
    scene = dir + "/scene.json";
    WriteFile(scene, scene_json);
  }
  const std::string ds = dir + "/ds";
  auto r = RunTool("lumislab-acquire", "synth --scene " + scene + " --out " + ds);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-calibrate", "screen --dataset " + ds);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-reconstruct", "--dataset " + ds);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return ds;
}

// Datasets are gigabytes: keep them only when a test failed, for inspection.
void CleanUp(std::initializer_list<std::string> datasets) {
  if (::testing::Test::HasFailure()) return;
  for (const auto& ds : datasets)
    std::filesystem::remove_all(std::filesystem::path(ds).parent_path());
}

TEST(EndToEnd, DefaultSceneNoiseFreeMatchesTruth) {
  if (testing::kSanitized)
    GTEST_SKIP() << "full-size accuracy run: the Release build's (the sanitized build runs the "
                    "smaller end-to-end tests)";
  const std::string ds = RunPipeline("e2e_default", "");
  const SlabComparison c = CompareSlabs(ds + "/slab", ds + "/truth");
  std::printf("default scene, noise-free: %s\n", c.Summary().c_str());
  ASSERT_EQ(c.positions.size(), 63u);
  for (const auto& p : c.positions) {
    EXPECT_LE(p.relative_l2, 0.005) << "position " << p.i << "," << p.j;
    EXPECT_GT(p.lit_texels, 1000) << "position " << p.i << "," << p.j;
  }
  CleanUp({ds});
}

// The photo of an oblique camera is resampled much more unevenly; the slab must be as good.
TEST(EndToEnd, ObliqueViewAsAccurateAsFrontal) {
  if (testing::kSanitized)
    GTEST_SKIP() << "full-size accuracy run: the Release build's (the sanitized build runs the "
                    "smaller end-to-end tests)";
  const std::string frontal = RunPipeline("e2e_frontal", SceneJson(3, 3, kFrontalCamera, "[]"));
  const std::string oblique = RunPipeline("e2e_oblique", SceneJson(3, 3, kObliqueCamera, "[]"));
  const SlabComparison f = CompareSlabs(frontal + "/slab", frontal + "/truth");
  const SlabComparison o = CompareSlabs(oblique + "/slab", oblique + "/truth");
  std::printf("frontal 3x3: %s\noblique 3x3: %s\n", f.Summary().c_str(), o.Summary().c_str());
  EXPECT_LE(f.max_relative_l2, 0.005);
  EXPECT_LE(o.max_relative_l2, 0.005);
  EXPECT_LE(o.max_relative_l2, std::max(1.5 * f.max_relative_l2, 0.002));
  for (const auto& p : o.positions) EXPECT_GT(p.lit_texels - p.unseen_lit_texels, 1000);
  CleanUp({frontal, oblique});
}

TEST(EndToEnd, NoisyCaptureWithinNoiseFloor) {
  if (testing::kSanitized)
    GTEST_SKIP() << "full-size accuracy run: the Release build's (the sanitized build runs the "
                    "smaller end-to-end tests)";
  const std::string clean = RunPipeline("e2e_clean", SceneJson(3, 3, kFrontalCamera, "[]"));
  const std::string noisy = RunPipeline("e2e_noisy", SceneJson(3, 3, kFrontalCamera, kNoise));
  const SlabComparison c = CompareSlabs(noisy + "/slab", noisy + "/truth");
  // The sensor of kNoise, one 16-bit exposure per slide (tests/e2e/noise_floor.h).
  testing::SensorNoiseModel sensor;
  sensor.full_well_e = kFullWell;
  sensor.read_noise_e = kReadNoise;
  sensor.code_step = [](double) { return 1.0 / 65535; };
  const double floor =
      testing::PredictNoiseFloor(noisy + "/slab", clean, clean + "/calib/screen.json",
                                 clean + "/truth", sensor)
          .overall;
  std::printf("noisy 3x3: %s; predicted noise floor %.3f %%, ratio %.2f\n", c.Summary().c_str(),
              100 * floor, c.overall_relative_l2 / floor);
  EXPECT_GT(floor, 0.0);
  EXPECT_LE(c.overall_relative_l2, 1.5 * floor);
  // The noise must be visible at all (otherwise this test would not test the fit with noise).
  const SlabComparison clean_c = CompareSlabs(clean + "/slab", clean + "/truth");
  EXPECT_GT(c.overall_relative_l2, 1.5 * clean_c.overall_relative_l2);
  CleanUp({clean, noisy});
}

// Effects that the pipeline already undoes leave the slab as accurate as a clean capture: a
// black level (recorded in dataset.json), stray light on both slides (cancels in E+ - E-) and an
// exposure bracket with clipped photos (merged from the unclipped exposures).
TEST(EndToEnd, BlackLevelAmbientAndBracketsLeaveTheSlabAccurate) {
  // An accuracy run at full size; each of its paths runs under the sanitizers in smaller tests
  // (Reconstruct.ExposureBracketsRecoverClippedHighlights, BracketMerge.*, AmbientEffect.*,
  // DarkEffect.*); this one is too long to run there.
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run: the Release build's";
  const std::string ds = RunPipeline(
      "e2e_cancelling",
      SceneJson(3, 3, kFrontalCamera,
                R"([{"type": "ambient", "level": 0.05}, {"type": "dark", "black_level": 0.04},
                    {"type": "brackets", "stops": [-2, 0, 2]}])"));
  const SlabComparison c = CompareSlabs(ds + "/slab", ds + "/truth");
  std::printf("black level, ambient, brackets 3x3: %s\n", c.Summary().c_str());
  EXPECT_EQ(c.positions.size(), 9u);
  EXPECT_LE(c.max_relative_l2, 0.005);
  CleanUp({ds});
}

// A bracketed capture whose recorded exposures are nominal, as EXIF's are: the synthetic photos
// were taken at exactly 2^-2, 2^0, 2^2, dataset.json is rewritten to say 0.25 * 0.95 and
// 4 * 1.06. reconstruct warns about both ratios (> 5 % off); with the recorded exposures the
// slab is off by more than 1 %, with --bracket-ratios estimated it is back within the 0.5 % of
// an exact capture.
TEST(EndToEnd, NominalBracketExposuresEstimatedFromThePixels) {
  if (testing::kSanitized)
    GTEST_SKIP() << "accuracy run: the Release build's (the bracket-ratio paths run under the "
                    "sanitizers in reconstruct_test and photo_merge_test)";
  const std::string ds = RunPipeline(
      "e2e_nominal_brackets",
      SceneJson(2, 2,
                R"({"size_px": [800, 600], "focal_px": 650, "position_mm": [0, -400, 2400],
                    "look_at_mm": [0, 0, 750]})",
                R"([{"type": "brackets", "stops": [-2, 0, 2]}])"));
  Dataset dataset = Dataset::Load(ds);
  for (auto& e : dataset.photos) e.exposure *= e.exposure < 0.5 ? 0.95 : e.exposure > 2 ? 1.06 : 1;
  dataset.Save(ds);
  auto r = RunTool("lumislab-reconstruct", "--dataset " + ds + " --force");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: position 0,0 slide p: exposures 0.2375 -> 1: ratio 4"),
            std::string::npos)
      << r.output;
  const SlabComparison recorded = CompareSlabs(ds + "/slab", ds + "/truth");
  r = RunTool("lumislab-reconstruct", "--dataset " + ds + " --force --bracket-ratios estimated");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const SlabComparison estimated = CompareSlabs(ds + "/slab", ds + "/truth");
  std::printf("nominal exposures 2x2: recorded %s\n  estimated %s\n", recorded.Summary().c_str(),
              estimated.Summary().c_str());
  EXPECT_GT(recorded.overall_relative_l2, 0.01);
  EXPECT_LE(estimated.max_relative_l2, 0.005);
  CleanUp({ds});
}

// A stage that puts the luminaire up to 0.5 mm off its grid position (h = 5 mm) is an error the
// reconstruction cannot see: the slab departs from the nominal truth measurably.
TEST(EndToEnd, StageErrorIsMeasurableAgainstTheTruth) {
  const std::string ds = RunPipeline(
      "e2e_stage_error",
      SceneJson(3, 3, kFrontalCamera, R"([{"type": "stage_error", "max_mm": 0.5, "seed": 2}])"));
  const SlabComparison c = CompareSlabs(ds + "/slab", ds + "/truth");
  std::printf("stage error 0.5 mm 3x3: %s\n", c.Summary().c_str());
  EXPECT_GT(c.overall_relative_l2, 0.01);
  CleanUp({ds});
}

}  // namespace
}  // namespace lumislab
