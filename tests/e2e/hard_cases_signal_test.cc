// Hard cases of the signal (issue 10; the chain, the checks and their bounds: hard_cases.h):
// intensities over twelve decades, saturated and nearly dark photos, a tiny full well where noise
// dominates, and the slab's shared-exponent values at their edges.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>

#include "core/basis.h"
#include "core/dataset.h"
#include "core/exr_io.h"
#include "core/slab.h"
#include "core/slab_compare.h"
#include "core/srgbe.h"
#include "hard_cases.h"
#include "lib/lightfield/tone_map.h"
#include "noise_floor.h"
#include "slab_masks.h"
#include "test_util.h"

namespace lumislab::hard_cases {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::WriteFile;

// Intensities spanning 10^-6 ... 10^6 W/sr in one luminaire: a bright emitter whose filter image
// lies left of the screen's centre and a dim one right of it (their images barely overlap).
// Float photos (half floats would flush the dim one, 10^-12 of full scale, to 0) keep it; no
// threshold anywhere may drop it or blow it up. Where it alone lights, the slab's error is
// bounded by the fit's floor, 5.3e-6 of the position's ||E|| (kSolverFloor): light 10^-12
// below a position's peak is below what the slab resolves, and the bound says so.
TEST(HardCases, IntensitiesSpanningTwelveDecades) {
  const CaseRun r =
      RunCase("span",
              Scene(Geometry{}, Emitter(10, 0, -20, 1e6, 2) + ", " + Emitter(-10, 0, -20, 1e-6, 2),
                    kSmallCamera),
              64, "", "--photo-format float");
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  CheckOptions all;
  all.photo_rounding = std::ldexp(1.0, -24);
  ExpectStable("1e6 and 1e-6 W/sr", CheckSlab(r.ds, all));
  CheckOptions dim = all;
  dim.max_truth_fraction = 1e-9;
  ExpectStable("1e6 and 1e-6 W/sr, where the dim one alone lights", CheckSlab(r.ds, dim));
  CleanUp(r);
}

// Saturated photos: exposure 4 clips the brightest part of every position's photos; those
// texels leave the fit (mask 0) with a warning, the rest stays within the bound. Exposure 10^4
// on light that covers the whole screen (an emitter on S) clips everything: exit 2 naming the
// position, nothing confident written.
std::string ExposedCamera(double exposure) {
  return R"({"size_px": [400, 300], "focal_px": 325, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750], "exposure": )" +
         std::to_string(exposure) + "}";
}
TEST(HardCases, SaturatedPhotos) {
  const CaseRun r =
      RunCase("saturated", Scene(Geometry{}, DefaultEmitters(), ExposedCamera(4)), 64);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  EXPECT_TRUE(Says(r.reconstruct, "saturated photo pixels")) << r.reconstruct.output;
  CheckOptions o;
  o.may_drop = [](int, int, int, int) { return true; };
  const auto checks = CheckSlab(r.ds, o);
  for (const auto& p : checks) EXPECT_GT(p.inner_unseen, 0) << p.i << "," << p.j;
  ExpectStable("saturated (exposure 4)", checks);
  CleanUp(r);
  const CaseRun all = RunCase(
      "all_saturated", Scene(Geometry{}, Emitter(1, -1.5, -0.05, 1, 0), ExposedCamera(1e4)), 32);
  EXPECT_EQ(all.reconstruct.exit_code, 2) << all.reconstruct.output;
  EXPECT_TRUE(Says(all.reconstruct, "only saturated texels")) << all.reconstruct.output;
  CleanUp(all);
}

// Nearly dark photos, 16-bit: exposure 10^-3 puts the peak at 56 codes. Rounding moves each
// photo value by at most half a code q = 1/65535 (sensor units), i.e. E by
// peak x scale / exposure x q/2 per slide, two slides; a texel averages such values (no gain)
// and the deconvolution's inverse stencil has absolute row sum 1 / (5/6 - 2/12)^2 = 2.25 in 2D:
// |c - c_exact| <= 2.25 x peak x scale / exposure x q per texel, an L2 floor of that over
// ||E||. Exposure 10^-6 leaves every code 0: the slab would be all zero with a success line;
// reconstruct must warn that no light was measured.
TEST(HardCases, NearlyDarkPhotos) {
  const char* kQuantized = R"([{"type": "quantization", "bit_depth": 16}])";
  const CaseRun r =
      RunCase("dark", Scene(Geometry{}, DefaultEmitters(), ExposedCamera(1e-3), kQuantized), 64);
  ASSERT_EQ(r.reconstruct.exit_code, 0)
      << r.acquire.output << r.calibrate.output << r.reconstruct.output;
  const Dataset dataset = Dataset::Load(r.ds);
  const double step =
      2.25 * dataset.filter.peak * dataset.radiometric_scale.value_or(1) / 1e-3 / 65535;
  CheckOptions o;
  o.texel_error = step;
  ExpectStable("nearly dark (exposure 1e-3, 16-bit)", CheckSlab(r.ds, o));
  CleanUp(r);
  const CaseRun black =
      RunCase("black", Scene(Geometry{}, DefaultEmitters(), ExposedCamera(1e-6), kQuantized), 32);
  EXPECT_EQ(black.reconstruct.exit_code, 0) << black.reconstruct.output;
  EXPECT_TRUE(Says(black.reconstruct, "no light measured")) << black.reconstruct.output;
  CleanUp(black);
}

// A tiny full well (50 e-, read noise 3 e-): noise dominates every texel. The slab's error
// against the truth must stay within the noise floor predicted for this sensor
// (tests/e2e/noise_floor.h, the same capture without noise as the expected values) plus the
// derived model bound; the flux within what that L2 error allows (Cauchy-Schwarz: |sum err| <=
// sqrt(n) ||err||).
TEST(HardCases, TinyFullWellNoiseDominated) {
  if (testing::kSanitized)
    GTEST_SKIP() << "accuracy only (two captures against a noise floor): the Release build's "
                    "(the sanitized build runs noise through acquire and the fit in "
                    "tests/lib/synthetic and reconstruct_test)";
  const char* kTinyWell = R"([{"type": "sensor_noise", "full_well_e": 50, "read_noise_e": 3,
                               "seed": 11}])";
  const CaseRun clean =
      RunCase("tiny_well_clean", Scene(Geometry{}, DefaultEmitters(), kSmallCamera), 64);
  const CaseRun noisy =
      RunCase("tiny_well", Scene(Geometry{}, DefaultEmitters(), kSmallCamera, kTinyWell), 64);
  ASSERT_EQ(clean.reconstruct.exit_code, 0) << clean.reconstruct.output;
  ASSERT_EQ(noisy.reconstruct.exit_code, 0)
      << noisy.acquire.output << noisy.calibrate.output << noisy.reconstruct.output;
  testing::SensorNoiseModel sensor;
  sensor.full_well_e = 50;
  sensor.read_noise_e = 3;
  sensor.code_step = [](double) { return 0.0; };  // float EXR photos: no rounding
  const testing::NoiseFloor floor = testing::PredictNoiseFloor(
      noisy.ds + "/slab", clean.ds, clean.ds + "/calib/screen.json", clean.ds + "/truth", sensor);
  const SlabComparison lit = CompareSlabs(noisy.ds + "/slab", noisy.ds + "/truth");
  // Noise of sigma sqrt(0.85 / 50) = 0.13 at the peak clips some pixels at 1: their texels
  // leave the fit, with a warning.
  EXPECT_TRUE(Says(noisy.reconstruct, "saturated photo pixels")) << noisy.reconstruct.output;
  CheckOptions o;
  o.may_drop = [](int, int, int, int) { return true; };
  const auto checks = CheckSlab(noisy.ds, o);
  double model = 0;
  for (const auto& p : checks) model = std::max(model, p.l2_bound);
  std::printf("tiny full well: lit texels %s; predicted noise floor %.3g %%, model bound %.3g %%\n",
              lit.Summary().c_str(), 100 * floor.overall, 100 * model);
  EXPECT_GT(floor.overall, 0.02);  // noise-dominated indeed
  EXPECT_LE(lit.overall_relative_l2, 1.5 * floor.overall + model);
  for (const auto& p : checks) {
    const std::string at = "position " + std::to_string(p.i) + "," + std::to_string(p.j);
    EXPECT_TRUE(p.finite) << at;
    EXPECT_TRUE(p.zero_where_unseen) << at;
    EXPECT_EQ(p.mask_mismatch, 0) << at;
    // The flux's noise: a sum of independent texel box averages b (sum c = sum b), whose
    // variance is the fitted values' divided by the deconvolution's white-noise gain 1.531^2
    // (noise_floor.h); the lit texels' share is (1.5 x floor x ||E||_lit)^2 and a dark texel's
    // variance (read noise alone) is below a lit one's, so over all values at most
    // values / lit_values times that. 4 sigma.
    const double sigma = p.area_m2 * 1.5 * floor.overall * p.lit_norm *
                         std::sqrt(double(p.values) / std::max(p.lit_values, 1)) / 1.531;
    EXPECT_LE(p.FluxError(), p.flux_bound + 4 * sigma) << at;
  }
  CleanUp(clean);
  CleanUp(noisy);
}

// sRGBE at its edges (core/srgbe.h, docs/method.md §4.3, docs/testing.md §2), beyond the unit tests
// of tests/core/srgbe_test.cc: what the preview's sRGBE accumulation does with it, emulated on the
// CPU (each light pass decodes the running sum, adds and re-encodes).
//  * Every word decodes to a finite value within kSrgbeMax, and re-encoding a decoded value gives
//    the same value back (a pass that adds nothing leaves the image unchanged; no drift).
//  * Near 0 and through the float denormals (2^-149 ... 2^-126) every triple is within
//    max(max|x| / 127.5, 2^-136) of its input; below 2^-136 it is exactly 0, with no sign.
//  * At the top, sums saturate at +-kSrgbeMax (no Inf, no NaN), sign kept.
//  * NaN and +-Inf input are clamped (NaN to 0, Inf to +-kSrgbeMax), never propagated.
//  * Accumulation: P re-encodings of the running sums S_k leave an error of at most
//    sum_k max|S_k| / 127.5 per channel (each encode's bound, docs/method.md §4.3); over
//    intensities spanning 10^-30 ... 10^30 the sum of 63 positions stays within it.
TEST(HardCases, SrgbeAtItsEdges) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Every exponent byte with every byte in R (G and B fixed at two patterns): finite, bounded,
  // and a fixed point of decode -> encode -> decode.
  int words = 0;
  for (uint32_t e = 0; e < 256; ++e)
    for (uint32_t byte = 0; byte < 256; ++byte)
      for (uint32_t gb : {0x0000u, 0xff7fu}) {
        const uint32_t w = byte | gb << 8 | e << 24;
        const auto v = DecodeSrgbe(w);
        for (float x : v) {
          ASSERT_TRUE(std::isfinite(x)) << std::hex << w;
          ASSERT_LE(std::abs(x), kSrgbeMax) << std::hex << w;
        }
        const auto again = DecodeSrgbe(EncodeSrgbe(v[0], v[1], v[2]));
        for (int c = 0; c < 3; ++c) ASSERT_EQ(again[c], v[c]) << std::hex << w << " channel " << c;
        ++words;
      }
  EXPECT_EQ(words, 256 * 256 * 2);
  // Near 0: every power of two from 2^-150 to 2^-120 (through the float denormals), alone and
  // next to a channel 2^5 times larger.
  for (int k = -150; k <= -120; ++k) {
    const float x = std::ldexp(1.0f, k);
    for (const auto& in : {std::array<float, 3>{x, -x, 0}, std::array<float, 3>{x, x * 32, -x}}) {
      const auto out = DecodeSrgbe(EncodeSrgbe(in[0], in[1], in[2]));
      const float bound = SrgbeErrorBound(in[0], in[1], in[2]);
      EXPECT_LE(bound, std::max(std::ldexp(1.0f, -136), 32 * x / 127.5f));
      for (int c = 0; c < 3; ++c) {
        EXPECT_LE(std::abs(out[c] - in[c]), bound) << "2^" << k << " channel " << c;
        if (out[c] != 0) {
          EXPECT_EQ(std::signbit(out[c]), std::signbit(in[c])) << "2^" << k;
        }
      }
    }
    if (k < -136) {
      EXPECT_EQ(EncodeSrgbe(x, -x, x), 0u) << "2^" << k;  // exactly 0, not -0
    }
  }
  // The top: the largest value round-trips exactly; beyond it, and +-Inf, clamp with the sign.
  auto top = DecodeSrgbe(EncodeSrgbe(kSrgbeMax, -kSrgbeMax, 0));
  EXPECT_EQ(top[0], kSrgbeMax);
  EXPECT_EQ(top[1], -kSrgbeMax);
  for (float big : {std::nextafter(kSrgbeMax, inf), std::numeric_limits<float>::max(), inf}) {
    top = DecodeSrgbe(EncodeSrgbe(big, -big, nan));
    EXPECT_EQ(top[0], kSrgbeMax);
    EXPECT_EQ(top[1], -kSrgbeMax);
    EXPECT_EQ(top[2], 0.f);
  }
  // Accumulation over 63 positions, each decade of 10^-30 ... 10^30 in turn, in a shuffled
  // order with signs (signed E_ij): within the sum of the encodes' bounds; and saturation
  // without Inf when the sum passes kSrgbeMax.
  std::mt19937 rng(10);
  for (int trial = 0; trial < 200; ++trial) {
    uint32_t acc = 0;
    double exact[3] = {0, 0, 0}, bound[3] = {0, 0, 0};
    std::uniform_real_distribution<double> exponent(-30, 30), sign(-0.3, 1);
    for (int k = 0; k < 63; ++k) {
      const double scale = std::pow(10.0, exponent(rng));
      const auto prev = DecodeSrgbe(acc);
      float next[3];
      for (int c = 0; c < 3; ++c) {
        const double x = scale * sign(rng);
        exact[c] += x;
        next[c] = float(double(prev[c]) + x);
      }
      acc = EncodeSrgbe(next[0], next[1], next[2]);
      const double largest = std::max({std::abs(next[0]), std::abs(next[1]), std::abs(next[2])});
      for (int c = 0; c < 3; ++c)
        bound[c] += std::max(largest / 127.5, std::ldexp(1.0, -136)) + 1e-7 * largest;
    }
    const auto sum = DecodeSrgbe(acc);
    for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(sum[c] - exact[c]), bound[c]) << trial;
  }
  uint32_t acc = 0;
  for (int k = 0; k < 4; ++k) {
    const auto prev = DecodeSrgbe(acc);
    acc = EncodeSrgbe(prev[0] + kSrgbeMax / 2, prev[1] - kSrgbeMax / 2, prev[2]);
  }
  const auto saturated = DecodeSrgbe(acc);
  EXPECT_EQ(saturated[0], kSrgbeMax);
  EXPECT_EQ(saturated[1], -kSrgbeMax);
}

}  // namespace
}  // namespace lumislab::hard_cases
