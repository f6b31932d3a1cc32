// A real camera's capture end to end (issue 8's evidence), one chain per camera: the capture a
// lab brings home and the chain it runs (tests/e2e/real_camera_chain.h) must give a slab within
// 1 % relative L2 of truth/ per position and within 1.5x of the noise floor predicted for it
// (tests/e2e/noise_floor.h). The evidence tables (each correction switched off in turn, the chain
// rerun without it, and the error printed; each one matters) are bench/real_camera_evidence.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "core/slab_compare.h"
#include "lib/synthetic/effects.h"
#include "noise_floor.h"
#include "real_camera_chain.h"
#include "slab_masks.h"
#include "test_util.h"

namespace lumislab {
namespace {

using RealCamera = real_camera::RealCameraChain;
using real_camera::kDngCorrections;
using real_camera::kDngDark;
using real_camera::kDngRaw;
using real_camera::kFullWell;
using real_camera::kJpegCorrections;
using real_camera::kJpegCurve;
using real_camera::kJpegDark;
using real_camera::kJpegSaturation;
using real_camera::kReadNoise;

// The JPEG camera (response, dark, flat and scale are each needed) with sensor noise, all
// corrections. (Its evidence table runs on the noise-free capture: the bench.)
TEST_F(RealCamera, JpegChainCloseToTruth) {
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run: the Release build's";
  Capture("cam_noisy", kJpegDark, kJpegCurve, kJpegSaturation, /*noisy=*/true);
  const SlabComparison noisy = RunChain("ds_noisy", kJpegCorrections, "", "");
  ASSERT_EQ(noisy.positions.size(), 9u);
  ExpectCalibrationChecksPassed("ds_noisy");
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
  // The JPEG coding at the effect's quality (tests/e2e/jpeg_coding_model.h): what
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
  // noise and one rounding of the curve's output) it was 0.47 %, ratio 1.62 (docs/formats.md §16).
  // The recovered curve gives what the true curve gives; the decoder keeps the fractions of JPEG's
  // YCbCr -> RGB conversion (0.87 % / 1.02 % when it rounded them). The 1 % per position;
  // 0.85 % overall so that a regression shows.
  for (const auto& p : noisy.positions)
    EXPECT_LE(p.relative_l2, 0.01) << "position " << p.i << "," << p.j;
  EXPECT_LE(noisy.overall_relative_l2, 0.0085);
  EXPECT_LE(noisy.overall_relative_l2, 1.5 * floor.overall);
  // The floor is a prediction, not a bound (the quantiser removes some of the noise, and the
  // coding model is good to about 15 % on a known picture: tests/e2e/jpeg_coding_noise_test.cc):
  // the error is not below it by more than the model's tolerance there.
  EXPECT_GE(noisy.overall_relative_l2, floor.overall / 1.25);
}

// The same lab with a RAW camera, with sensor noise, all corrections. (Its evidence table, on
// the same noisy capture, every correction mattering well above the noise: the bench.)
TEST_F(RealCamera, DngChainWithinOnePercentOfTruth) {
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run: the Release build's";
  Capture("cam", kDngDark, kDngRaw, 1.0, /*noisy=*/true);
  const SlabComparison all = RunChain("ds_0", kDngCorrections, "", "");
  ASSERT_EQ(all.positions.size(), 9u);
  ExpectCalibrationChecksPassed("ds_0");
  // The noise floor: 14-bit codes between the DNG's black (512) and white (16383) levels; each
  // pixel samples one channel of the RGGB mosaic.
  testing::SensorNoiseModel sensor;
  sensor.full_well_e = kFullWell;
  sensor.read_noise_e = kReadNoise;
  sensor.code_step = [](double) { return 1.0 / (16383 - 512); };
  sensor.saturation = 1 - 0.5 / (16383 - 512);
  sensor.bayer_rggb = true;
  const testing::NoiseFloor floor = CompareWithNoiseFloor("ds_0", all, sensor);
  // Issue 8: within 1.5x of the predicted noise floor, and 1 % per position. The floor is a
  // prediction, not a bound: the error is also not below floor / 1.5.
  EXPECT_LE(all.overall_relative_l2, 1.5 * floor.overall);
  EXPECT_GE(all.overall_relative_l2, floor.overall / 1.5);
  for (const auto& p : all.positions)
    EXPECT_LE(p.relative_l2, 0.01) << "position " << p.i << "," << p.j;
  // The camera's hot pixels read as their neighbours' mean: no lit texel is left unseen (before,
  // the texels around each one were masked and showed as black specks in the preview), except
  // in the band along the screen's edge whose samples read the frame (docs/method.md §3.5 step 3).
  for (const auto& p : all.positions)
    EXPECT_EQ(testing::UnseenLitTexelsAwayFromTheEdge(root_ + "/ds_0/slab",
                                                      root_ + "/" + cam_ + "/truth", p.i, p.j),
              0)
        << "position " << p.i << "," << p.j;
}

}  // namespace
}  // namespace lumislab
