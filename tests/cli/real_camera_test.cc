// A real camera's capture end to end (issue 8's evidence): `acquire synth --camera-folder` writes
// what a lab brings home — camera-named photos with EXIF in capture order, three brackets, a
// camera response (8-bit JPEG) or a Bayer RAW (DNG), vignetting, a screen that is not uniform
// (±15 %), a dark level with hot pixels, ambient light, sensor noise, the dark/flat/response
// calibration frames and a reference meter reading, and no dataset.json. The chain a lab runs:
//   acquire import --order capture → calibrate response (JPEG) → dark → screen → flat → scale →
//   reconstruct
// must give a slab within 1 % relative L2 of truth/ per position and within 1.5x of the noise
// floor predicted for it (tests/cli/noise_floor.h). Each correction is then switched off in
// turn (the chain rerun without it) and the error printed: the evidence table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/slab_compare.h"
#include "lib/synthetic/effects.h"
#include "noise_floor.h"
#include "slab_masks.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::RunToolIn;
using testing::WriteFile;

// 960 x 720 px behind the screen, 3 x 3 grid.
const char* kCamera =
    R"({"size_px": [960, 720], "focal_px": 780, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";

// The lab's light and screen and the camera's lens, as every camera below sees them.
const char* kLab =
    R"({"type": "screen_gain", "amplitude": 0.15, "blobs": 6, "size_mm": 250, "seed": 2},
       {"type": "ambient", "level": 0.02},
       {"type": "vignetting", "k1": -0.1})";

// The sensor's noise, as a camera at base ISO has it: a full well of 30000 e- at the white
// level, 4 e- read noise. Listed after the dark signal (whose shot noise counts too) and before
// the brackets' clip (the full well) and the camera's output (curve or RAW codes), so it acts
// on the sensor signal and dithers the output's rounding. Reconstruct is told the same
// (--full-well, --read-noise: a lab knows its sensor), so its merge weights are the optimal
// ones that the predicted floor assumes.
const char* kSensorNoise =
    R"({"type": "sensor_noise", "full_well_e": 30000, "read_noise_e": 4, "seed": 11})";
constexpr double kFullWell = 30000, kReadNoise = 4;
const char* kBrackets = R"({"type": "brackets", "stops": [-2, 0, 2]})";

// Slab texels per side: 8 mm texels on the 1.2 m screen, about 4 x 4 photo pixels each (a
// lab matches the slab's resolution to its camera; 300 would give 2 x 2 here).
constexpr int kResolution = 150;

// The calibrate steps in the order each needs the ones before (flat and scale need the screen).
constexpr const char* kOrder[] = {"response", "dark", "screen", "flat", "scale"};

const char* kCaptures =
    R"({"dark_frames": 4, "dark_stops": [-2, 0, 2], "flat_frames": 4, "flat_level": 0.5,
        "response_stops": [-3, -2.5, -2, -1.5, -1, -0.5, 0, 0.5, 1, 1.5, 2], "reference": {"position": [1, 1],
        "point_mm": [0, 0]}})";

class RealCamera : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("real_camera_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(root_);
  }
  bool Run(const std::string& tool, const std::string& args) {
    const auto r = RunToolIn(root_, tool, args, 300);
    EXPECT_EQ(r.exit_code, 0) << tool << " " << args << "\n" << r.output;
    return r.exit_code == 0;
  }
  // Writes the capture of a scene with the lab's effects, the camera's dark signal `dark`, the
  // sensor noise (when `noisy`), the brackets and the camera's output `output` (curve or RAW)
  // into the folder `cam`, which the chains below then read. With noise, also the same capture
  // without noise and output, float EXR sensor values, into clean/: the expected values of the
  // noisy photos, for the predicted noise floor.
  void Capture(const std::string& cam, const std::string& dark, const std::string& output,
               double saturation_level, bool noisy) {
    cam_ = cam;
    const std::string sensor = dark + ", " + (noisy ? kSensorNoise + std::string(", ") : "");
    WriteFile(root_ + "/" + cam + ".json",
              testing::SceneJson(3, 3, kCamera,
                                 std::string("[") + kLab + ", " + sensor + kBrackets + ", " +
                                     output + "], \"calibration_captures\": " + kCaptures));
    ASSERT_TRUE(Run("lumislab-acquire", "synth --scene " + cam + ".json --out " + cam +
                                            " --camera-folder --truth-resolution " +
                                            std::to_string(kResolution)));
    ASSERT_FALSE(fs::exists(root_ + "/" + cam + "/dataset.json"));
    // What the lab knows of its camera and writes into the setup: where its codes clip.
    const std::string setup_file = root_ + "/" + cam + "/setup.json";
    nlohmann::json setup = nlohmann::json::parse(ReadBinaryFile(setup_file));
    setup["radiometry"]["saturation_level"] = saturation_level;
    WriteFile(setup_file, setup.dump(2));
    if (!noisy) return;
    WriteFile(root_ + "/clean.json",
              testing::SceneJson(3, 3, kCamera,
                                 std::string("[") + kLab + ", " + dark + ", " + kBrackets + "]"));
    ASSERT_TRUE(
        Run("lumislab-acquire", "synth --scene clean.json --out clean --truth-resolution 1"));
  }
  // The noise floor predicted for the all-corrections chain in dataset folder `ds` on the noisy
  // capture: the sensor's noise through the merged brackets, the flat frames' noise and the
  // scale reading's (tests/cli/noise_floor.h); prints it with the measured error per position.
  testing::NoiseFloor CompareWithNoiseFloor(const std::string& ds, const SlabComparison& measured,
                                            const testing::SensorNoiseModel& sensor) {
    testing::ChainNoiseModel chain;
    chain.gain_exr = root_ + "/" + cam_ + "/truth/flat.exr";
    chain.dark_exr = root_ + "/" + cam_ + "/truth/dark.exr";
    chain.flat_frames = 4;  // kCaptures
    chain.flat_level = 0.5;
    chain.reference_i = chain.reference_j = 1;
    chain.reference_radius_px = 3;  // calibrate scale's default
    const testing::NoiseFloor floor = testing::PredictNoiseFloor(
        root_ + "/" + ds + "/slab", root_ + "/clean", root_ + "/" + ds + "/calib/screen.json",
        root_ + "/" + cam_ + "/truth", sensor, chain);
    std::printf(
        "with sensor noise: predicted noise floor (of which the scale reading %.3f %%), "
        "measured error, ratio\n",
        100 * floor.scale_relative);
    std::printf("  all positions  %.3f %%  %.3f %%  %.2f\n", 100 * floor.overall,
                100 * measured.overall_relative_l2, measured.overall_relative_l2 / floor.overall);
    for (const auto& p : measured.positions)
      for (const auto& f : floor.positions)
        if (f.i == p.i && f.j == p.j)
          std::printf("  position %d,%d   %.3f %%  %.3f %%  %.2f\n", p.i, p.j, 100 * f.relative,
                      100 * p.relative_l2, p.relative_l2 / f.relative);
    return floor;
  }
  // The calibrate step `step` on dataset folder `ds`.
  bool Calibrate(const std::string& ds, const std::string& step) {
    if (step == "screen") return Run("lumislab-calibrate", "screen --dataset " + ds);
    if (step == "scale")
      return Run("lumislab-calibrate",
                 "scale --dataset " + ds + " --reference " + cam_ + "/truth/reference.json");
    // response, dark, flat: every frame of the kind, exposures from their EXIF
    return Run("lumislab-calibrate",
               step + " --dataset " + ds + " --frames " + cam_ + "/calibration/" + step + "/*");
  }
  // The chain on dataset folder `ds` with the calibrate steps of kOrder that `corrections` lists
  // (screen always) except `off`; the steps before `off` are copied from `from` (the full chain,
  // same inputs, same results), the later ones run again (each decodes its frames with the
  // corrections before it). Returns the slab compared with truth/.
  SlabComparison RunChain(const std::string& ds, const std::vector<std::string>& corrections,
                          const std::string& off, const std::string& from) {
    if (!Run("lumislab-acquire", "import --photos " + cam_ + "/camera --setup " + cam_ +
                                     "/setup.json --out " + ds + " --order capture --brackets 3"))
      return {};
    bool after_off = off.empty();
    for (const char* step : kOrder) {
      if (step == off) {
        after_off = true;
        continue;
      }
      if (step != std::string("screen") &&
          std::find(corrections.begin(), corrections.end(), step) == corrections.end())
        continue;
      if (!after_off && !from.empty()) {  // the same as in the full chain
        fs::create_directories(root_ + "/" + ds + "/calib");
        for (const auto& e : fs::directory_iterator(root_ + "/" + from + "/calib"))
          // step.json, and a map it names (step-<hash>.exr)
          if (e.path().stem() == step ||
              e.path().stem().string().rfind(step + std::string("-"), 0) == 0)
            fs::copy_file(e.path(), root_ + "/" + ds + "/calib/" + e.path().filename().string());
        continue;
      }
      if (!Calibrate(ds, step)) return {};
    }
    if (!Run("lumislab-reconstruct",
             "--dataset " + ds + " --resolution " + std::to_string(kResolution) + " --full-well " +
                 std::to_string(kFullWell) + " --read-noise " + std::to_string(kReadNoise)))
      return {};
    return CompareSlabs(root_ + "/" + ds + "/slab", root_ + "/" + cam_ + "/truth");
  }
  // The whole chain, then each correction left out in turn; prints the table and returns the
  // comparisons (all corrections first).
  std::vector<SlabComparison> Evidence(const std::string& title,
                                       const std::vector<std::string>& corrections) {
    std::vector<SlabComparison> rows;
    std::printf(
        "evidence, %s: slab error against truth/ (relative L2 over lit texels: all "
        "positions together / worst position)\n",
        title.c_str());
    for (int off = -1; off < int(corrections.size()); ++off) {
      const std::string label = off < 0 ? "all corrections" : "without " + corrections[off];
      rows.push_back(RunChain("ds_" + std::to_string(off + 1), corrections,
                              off < 0 ? "" : corrections[off], off < 0 ? "" : "ds_0"));
      std::printf("  %-18s %.4f / %.4f  (%zu positions)\n", label.c_str(),
                  rows.back().overall_relative_l2, rows.back().max_relative_l2,
                  rows.back().positions.size());
    }
    return rows;
  }
  std::string root_;
  std::string cam_ = "cam";  // the capture the chains read
};

// JPEG with a gamma-and-shoulder response unlike sRGB (quality 95): response, dark, flat and
// scale are each needed. The evidence table runs on a noise-free capture, the 1 % and noise
// floor check on the same camera with sensor noise (see below why).
TEST_F(RealCamera, JpegChainCloseToTruth) {
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run (six chains): the Release build's";
  // A JPEG engine subtracts most of the sensor's black level before its curve: what is left is
  // a small offset, dark current and hot pixels.
  const char* dark = R"({"type": "dark", "black_level": 0.001, "dark_current": 0.0005,
                         "hot_fraction": 0.0005, "hot_current": 0.5, "seed": 3})";
  const char* curve = R"({"type": "response", "curve": "gamma", "gamma": 2.2, "shoulder": 0.5,
                          "quality": 95})";
  // JPEG spreads clipped highlights over the codes just below 255: a lab takes 0.95 of full
  // scale as clipped for its JPEG camera.
  Capture("cam", dark, curve, 0.95, /*noisy=*/false);
  const auto rows = Evidence("JPEG camera, noise-free", {"response", "dark", "flat", "scale"});
  ASSERT_EQ(rows.size(), 5u);
  ASSERT_EQ(rows[0].positions.size(), 9u);
  // 0.86 % overall, 0.92 % worst position: without noise the 8-bit rounding of the curve's
  // output and JPEG's coding are not dithered, and 4 x 4-pixel means keep them
  // (docs/design.md §5.16). Held at 1.2 % so that a regression shows.
  for (const auto& p : rows[0].positions)
    EXPECT_LE(p.relative_l2, 0.012) << "position " << p.i << "," << p.j;
  // Each correction matters; the dark map least here (1.2 % without it): the dark signal is
  // the same through T+ and T- and cancels in their difference except through the flat, the
  // scale and the hot pixels (the table is taken on the noise-free capture).
  for (size_t k = 1; k < rows.size(); ++k)
    EXPECT_GT(rows[k].overall_relative_l2, 1.2 * rows[0].overall_relative_l2) << "row " << k;

  // The same camera with sensor noise, all corrections.
  Capture("cam_noisy", dark, curve, 0.95, /*noisy=*/true);
  const SlabComparison noisy = RunChain("ds_noisy", {"response", "dark", "flat", "scale"}, "", "");
  ASSERT_EQ(noisy.positions.size(), 9u);
  // The noise floor: the sensor's noise (its shot noise grown by the ambient light and the dark
  // current) and the curve's rounding, one JPEG code being (1/255) / C'(s) in sensor values.
  const ResponseEffect response("gamma", 2.2, 0.5, 95);
  testing::SensorNoiseModel sensor;
  sensor.full_well_e = kFullWell;
  sensor.read_noise_e = kReadNoise;
  sensor.code_step = [response](double s) {
    const double lo = std::max(0.0, s - 1e-5), hi = std::min(1.0, s + 1e-5);
    return (hi - lo) / 255 / (response.Curve(hi) - response.Curve(lo));
  };
  // The JPEG coding at the effect's quality (tests/cli/noise_floor.h, JpegCodingModel): what
  // the quantiser, the roundings of Y, Cb, Cr and the 4:2:0 chroma leave of the photos' noise
  // and add to it.
  sensor.jpeg_quality = 95;
  sensor.code_of = [response](double s) { return 255 * response.Curve(std::clamp(s, 0.0, 1.0)); };
  // The decoder takes a linear value >= 0.95 as clipped: the codes from the first whose value
  // through the curve reaches it, i.e. sensor values from halfway below that code.
  int first_clipped = 0;
  while (response.Inverse(first_clipped / 255.0) < 0.95) ++first_clipped;
  sensor.saturation = response.Inverse((first_clipped - 0.5) / 255);
  const testing::NoiseFloor floor = CompareWithNoiseFloor("ds_noisy", noisy, sensor);
  // Issue 8 asks for 1 % per position and 1.5x the noise floor. Measured: 0.77 % overall,
  // 0.90 % worst position (2,2); the floor with JPEG's coding 0.79 % (0.74 - 0.97 % per
  // position): ratio 0.97 (0.91 - 1.07 per position). Without the coding in the floor (sensor
  // noise and one rounding of the curve's output) it was 0.47 %, ratio 1.62 (docs/design.md
  // §5.16). The recovered curve gives what the true curve gives; the decoder keeps the
  // fractions of JPEG's YCbCr -> RGB conversion (0.87 % / 1.02 % when it rounded them).
  // The issue's 1 % per position; 0.85 % overall so that a regression shows.
  for (const auto& p : noisy.positions)
    EXPECT_LE(p.relative_l2, 0.01) << "position " << p.i << "," << p.j;
  EXPECT_LE(noisy.overall_relative_l2, 0.0085);
  EXPECT_LE(noisy.overall_relative_l2, 1.5 * floor.overall);
  // The floor is a prediction, not a bound (the quantiser removes some of the noise, and the
  // coding model is good to about 15 % on a known picture: tests/cli/jpeg_coding_noise_test.cc):
  // the error is not below it by more than the model's tolerance there.
  EXPECT_GE(noisy.overall_relative_l2, floor.overall / 1.25);
}

// The same lab with a RAW camera: 14-bit RGGB DNG mosaics (linear; no response step), with
// sensor noise; the evidence table on that noisy capture (every correction matters well above
// the noise).
TEST_F(RealCamera, DngChainWithinOnePercentOfTruth) {
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run (four chains): the Release build's";
  // The sensor's black level is in the data (on top of the DNG's BlackLevel codes).
  Capture("cam",
          R"({"type": "dark", "black_level": 0.01, "dark_current": 0.004,
              "hot_fraction": 0.0005, "hot_current": 0.5, "seed": 3})",
          R"({"type": "raw", "bit_depth": 14})", 1.0, /*noisy=*/true);
  const auto rows = Evidence("DNG camera, sensor noise", {"dark", "flat", "scale"});
  ASSERT_EQ(rows.size(), 4u);
  ASSERT_EQ(rows[0].positions.size(), 9u);
  // The noise floor: 14-bit codes between the DNG's black (512) and white (16383) levels; each
  // pixel samples one channel of the RGGB mosaic.
  testing::SensorNoiseModel sensor;
  sensor.full_well_e = kFullWell;
  sensor.read_noise_e = kReadNoise;
  sensor.code_step = [](double) { return 1.0 / (16383 - 512); };
  sensor.saturation = 1 - 0.5 / (16383 - 512);
  sensor.bayer_rggb = true;
  const testing::NoiseFloor floor = CompareWithNoiseFloor("ds_0", rows[0], sensor);
  // Issue 8: within 1.5x of the predicted noise floor, and 1 % per position. The floor is a
  // prediction, not a bound: the error is also not below floor / 1.5.
  EXPECT_LE(rows[0].overall_relative_l2, 1.5 * floor.overall);
  EXPECT_GE(rows[0].overall_relative_l2, floor.overall / 1.5);
  for (const auto& p : rows[0].positions)
    EXPECT_LE(p.relative_l2, 0.01) << "position " << p.i << "," << p.j;
  for (size_t k = 1; k < rows.size(); ++k)
    EXPECT_GT(rows[k].overall_relative_l2, 1.5 * rows[0].overall_relative_l2) << "row " << k;
  // The camera's hot pixels read as their neighbours' mean: no lit texel is left unseen (before,
  // the texels around each one were masked and showed as black specks in the preview), except
  // in the band along the screen's edge whose samples read the frame (§3.5 step 3).
  for (const auto& p : rows[0].positions)
    EXPECT_EQ(testing::UnseenLitTexelsAwayFromTheEdge(root_ + "/ds_0/slab",
                                                      root_ + "/" + cam_ + "/truth", p.i, p.j),
              0)
        << "position " << p.i << "," << p.j;
}

}  // namespace
}  // namespace lumislab
