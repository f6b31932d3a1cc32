// The real-camera chain of tests/e2e/real_camera_test.cc and bench/real_camera_evidence.cc: a
// lab's capture written by `acquire synth --camera-folder` (camera-named photos with EXIF in
// capture order, three brackets, a camera response or Bayer RAW, vignetting, a non-uniform screen,
// dark level and hot pixels, ambient light, sensor noise, the calibration frames and a reference
// meter reading), the chain a lab runs on it
//   acquire import --order capture -> calibrate response (JPEG) -> dark -> screen -> flat -> scale
//   -> reconstruct
// and the noise floor predicted for its slab (tests/e2e/noise_floor.h). The test runs one chain
// per camera; the bench runs the evidence tables (the chain again with each correction left out).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/slab_compare.h"
#include "noise_floor.h"
#include "test_util.h"

namespace lumislab {
namespace real_camera {

namespace fs = std::filesystem;

using testing::ReadBinaryFile;
using testing::RunToolIn;
using testing::WriteFile;

// 960 x 720 px behind the screen, 3 x 3 grid.
inline const char* kCamera =
    R"({"size_px": [960, 720], "focal_px": 780, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";

// The lab's light and screen and the camera's lens, as every camera below sees them.
inline const char* kLab =
    R"({"type": "screen_gain", "amplitude": 0.15, "blobs": 6, "size_mm": 250, "seed": 2},
       {"type": "ambient", "level": 0.02},
       {"type": "vignetting", "k1": -0.1})";

// The sensor's noise, as a camera at base ISO has it: a full well of 30000 e- at the white
// level, 4 e- read noise. Listed after the dark signal (whose shot noise counts too) and before
// the brackets' clip (the full well) and the camera's output (curve or RAW codes), so it acts
// on the sensor signal and dithers the output's rounding. Reconstruct is told the same
// (--full-well, --read-noise: a lab knows its sensor), so its merge weights are the optimal
// ones that the predicted floor assumes.
inline const char* kSensorNoise =
    R"({"type": "sensor_noise", "full_well_e": 30000, "read_noise_e": 4, "seed": 11})";
inline constexpr double kFullWell = 30000, kReadNoise = 4;
inline const char* kBrackets = R"({"type": "brackets", "stops": [-2, 0, 2]})";

// Slab texels per side: 8 mm texels on the 1.2 m screen, about 4 x 4 photo pixels each (a
// lab matches the slab's resolution to its camera; 300 would give 2 x 2 here).
inline constexpr int kResolution = 150;

// The JPEG camera: a gamma-and-shoulder response unlike sRGB (quality 95). A JPEG engine
// subtracts most of the sensor's black level before its curve: what is left is a small offset,
// dark current and hot pixels. JPEG spreads clipped highlights over the codes just below 255: a
// lab takes 0.95 of full scale as clipped for its JPEG camera.
inline const char* kJpegDark = R"({"type": "dark", "black_level": 0.001, "dark_current": 0.0005,
                                   "hot_fraction": 0.0005, "hot_current": 0.5, "seed": 3})";
inline const char* kJpegCurve = R"({"type": "response", "curve": "gamma", "gamma": 2.2,
                                    "shoulder": 0.5, "quality": 95})";
inline constexpr double kJpegSaturation = 0.95;
inline const std::vector<std::string> kJpegCorrections = {"response", "dark", "flat", "scale"};
// The RAW camera: 14-bit RGGB DNG mosaics (linear; no response step). The sensor's black level is
// in the data (on top of the DNG's BlackLevel codes).
inline const char* kDngDark = R"({"type": "dark", "black_level": 0.01, "dark_current": 0.004,
                                  "hot_fraction": 0.0005, "hot_current": 0.5, "seed": 3})";
inline const char* kDngRaw = R"({"type": "raw", "bit_depth": 14})";
inline const std::vector<std::string> kDngCorrections = {"dark", "flat", "scale"};

// The calibrate steps in the order each needs the ones before (flat and scale need the screen).
inline constexpr const char* kOrder[] = {"response", "dark", "screen", "flat", "scale"};

inline const char* kCaptures =
    R"({"dark_frames": 4, "dark_stops": [-2, 0, 2], "flat_frames": 4, "flat_level": 0.5,
        "response_stops": [-3, -2.5, -2, -1.5, -1, -0.5, 0, 0.5, 1, 1.5, 2], "reference": {"position": [1, 1],
        "point_mm": [0, 0]}})";

class RealCameraChain : public ::testing::Test {
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
  // scale reading's (tests/e2e/noise_floor.h); prints it with the measured error per position.
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
  // Every check the calibrate steps recorded in dataset folder `ds`'s checks.json passed
  // (calibrate/radiometric/calibration_checks.h): a lab's legitimate chain trips none.
  void ExpectCalibrationChecksPassed(const std::string& ds) {
    const nlohmann::json j =
        nlohmann::json::parse(ReadBinaryFile(root_ + "/" + ds + "/checks.json"));
    int calibrate_records = 0;
    for (const auto& [stage, record] : j["stages"].items()) {
      if (stage.rfind("calibrate ", 0) != 0) continue;
      for (const auto& c : record["checks"]) {
        ++calibrate_records;
        EXPECT_EQ(c["outcome"], "passed") << stage << ": " << c.dump();
      }
    }
    EXPECT_GE(calibrate_records, 5) << j.dump();
  }
  std::string root_;
  std::string cam_ = "cam";  // the capture the chains read
};

}  // namespace real_camera
}  // namespace lumislab
