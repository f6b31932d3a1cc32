// The scene block calibration_captures (docs/formats.md §10): nothing without it, the slide
// photos unchanged with it, each kind of frame made through the effects that apply to it, and
// its members checked naming the field.
#include "lib/synthetic/calibration_captures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "acquire/synth.h"
#include "acquire_test_util.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/json.h"
#include "lib/synthetic/render.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using acquire_test::FileBytes;
using acquire_test::FreshDir;
using acquire_test::SmallSceneJson;
using acquire_test::SmallSynthOptions;

const char* kEffects =
    R"([{"type": "vignetting", "k1": -0.1}, {"type": "ambient", "level": 0.03},
        {"type": "dark", "black_level": 0.01, "dark_current": 0.05, "hot_fraction": 0.002,
         "hot_current": 0.5, "seed": 3},
        {"type": "sensor_noise", "seed": 4}])";
const char* kCaptures =
    R"({"dark_frames": 2, "dark_stops": [0, 1], "flat_frames": 1, "response_stops": [-1, 1],
        "reference": {"position": [1, 1], "point_mm": [0, 0]}})";

std::string WithCaptures(const std::string& effects, const std::string& captures) {
  return SmallSceneJson(effects + ", \"calibration_captures\": " + captures);
}

// Without the block nothing of it is made; with it, every file the capture wrote without it is
// the same to the byte (the frames' noise streams come after the slide photos').
TEST(CalibrationCaptures, AbsentBlockChangesNothing) {
  const std::string without = FreshDir("captures_without") + "/ds";
  const std::string with = FreshDir("captures_with") + "/ds";
  RunSynth(ParseScene(SmallSceneJson(kEffects), "small.json"), SmallSynthOptions(without));
  RunSynth(ParseScene(WithCaptures(kEffects, kCaptures), "small.json"), SmallSynthOptions(with));
  EXPECT_FALSE(fs::exists(without + "/calibration"));
  for (const char* f : {"flat.exr", "dark.exr", "reference.json"})
    EXPECT_FALSE(fs::exists(without + "/truth/" + f)) << f;
  int compared = 0;
  for (const auto& e : fs::recursive_directory_iterator(without)) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), without).string();
    ASSERT_TRUE(fs::exists(with + "/" + rel)) << rel;
    EXPECT_EQ(FileBytes(e.path().string()), FileBytes(with + "/" + rel)) << rel;
    ++compared;
  }
  EXPECT_GT(compared, 18 + 9);  // the slide photos and the truth positions at least
  const JsonDocument manifest = JsonDocument::Load(with + "/calibration/captures.json");
  EXPECT_EQ(manifest.root()["dark"].Size(), 4u);
  EXPECT_EQ(manifest.root()["flat"].Size(), 1u);
  EXPECT_EQ(manifest.root()["response"].Size(), 2u);
  for (const char* kind : {"dark", "flat", "response"})
    for (size_t k = 0; k < manifest.root()[kind].Size(); ++k)
      EXPECT_TRUE(fs::exists(with + "/" + manifest.root()[kind][k]["file"].String()));
  EXPECT_TRUE(fs::exists(with + "/truth/reference.json"));
}

// Without noise: a dark frame is the dark signal alone (no vignetting, no ambient light), a flat
// frame is flat_level x exposure x the true gain plus the dark signal (no ambient light).
TEST(CalibrationCaptures, FramesAreTheirModels) {
  const std::string effects =
      R"([{"type": "vignetting", "k1": -0.1},
          {"type": "screen_gain", "amplitude": 0.1, "seed": 1},
          {"type": "ambient", "level": 0.03},
          {"type": "dark", "black_level": 0.01, "dark_current": 0.05, "hot_fraction": 0.002,
           "hot_current": 0.5, "seed": 3}])";
  const SynthScene scene =
      ParseScene(WithCaptures(effects, R"({"dark_frames": 1, "dark_stops": [1], "flat_frames": 1,
                               "flat_level": 0.4})"),
                 "small.json");
  const std::string ds = FreshDir("captures_models") + "/ds";
  RunSynth(scene, SmallSynthOptions(ds));
  const ImageF dark = ReadExr(ds + "/calibration/dark/dark_ev+1_00.exr", {"R", "G", "B"});
  const ImageF flat = ReadExr(ds + "/calibration/flat/flat_00.exr", {"R", "G", "B"});
  const ImageF truth_dark = ReadExr(ds + "/truth/dark.exr", {"black", "current", "hot"});
  const ImageF truth_gain = ReadExr(ds + "/truth/flat.exr", {"Y"});
  const ScreenView view = ScreenView::Of(scene);
  std::vector<bool> on(320 * 240, false);
  for (int p : view.pixels) on[p] = true;
  int hot = 0;
  for (int p = 0; p < 320 * 240; ++p) {
    const double d = truth_dark.data[p * 3] + 2 * truth_dark.data[p * 3 + 1];  // exposure 2
    hot += truth_dark.data[p * 3 + 2] > 0.5f;
    ASSERT_NEAR(dark.data[p * 3 + 1], d, 1e-6) << p;
    const double light = on[p] ? 0.4 * truth_gain.data[p] : 0.0;
    ASSERT_NEAR(flat.data[p * 3 + 1], light + truth_dark.data[p * 3] + truth_dark.data[p * 3 + 1],
                1e-6)
        << p;
  }
  EXPECT_GT(hot, 50);
  EXPECT_NEAR(truth_dark.data[1], 0.05, 1e-7);  // a pixel's dark current (pixel 0 is not hot)
}

// The reading at the reference point is the slides' irradiance there plus the ambient light;
// its T+ - T- equals the truth slab's E at that point / the filter peak.
TEST(CalibrationCaptures, ReferenceReadingIncludesAmbientLight) {
  const SynthScene scene =
      ParseScene(WithCaptures(R"([{"type": "ambient", "level": 0.05}])",
                              R"({"reference": {"position": [1, 1], "point_mm": [10, -20]}})"),
                 "small.json");
  Eigen::Vector3d plus, minus;
  ReferenceIrradiance(scene, 2.0, &plus, &minus);
  const DualFilter filter = scene.Filter();
  const Eigen::Vector2d c = scene.grid.Centre(1, 1);
  const Eigen::Vector3d e = scene.luminaire.FilteredIrradiance(
      filter, scene.grid.spacing_mm, c, scene.distance_mm, 10 + c.x(), -20 + c.y());
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR((plus[ch] - minus[ch]) * filter.Peak2D(), e[ch], 1e-9 * std::abs(e[ch]) + 1e-12);
    EXPECT_GE(minus[ch], 0.05 * 2.0 - 1e-12);  // ambient level x scale at least
  }
}

void ExpectRefused(const std::string& captures, const std::string& field) {
  try {
    ParseScene(WithCaptures("[]", captures), "scene.json");
    ADD_FAILURE() << "accepted: " << captures;
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("scene.json: calibration_captures." + field),
              std::string::npos)
        << e.what();
  }
}

TEST(CalibrationCaptures, BadMembersNameTheField) {
  ExpectRefused(R"({"dark_frame": 2})", "dark_frame");
  ExpectRefused(R"({"dark_frames": 65})", "dark_frames");
  ExpectRefused(R"({"dark_stops": [0, 0]})", "dark_stops[1]");
  ExpectRefused(R"({"flat_level": 0})", "flat_level");
  ExpectRefused(R"({"response_stops": [1]})", "response_stops");
  ExpectRefused(R"({"reference": {"position": [3, 0], "point_mm": [0, 0]}})",
                "reference.position[0]");
  ExpectRefused(R"({"reference": {"position": [1, 1], "point_mm": [700, 0]}})",
                "reference.point_mm");
  ExpectRefused(R"({"reference": {"position": [1, 1], "point_mm": [0, 0], "unit": "lux"}})",
                "reference.unit");
}

}  // namespace
}  // namespace lumislab
