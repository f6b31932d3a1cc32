// ReconstructPosition and RunReconstruct on tiny analytic datasets (no acquire stage needed):
// accuracy against the analytic E_ij, masks, saturation, brackets, errors, skip/force, --watch.
#include "reconstruct/reconstructor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <opencv2/core.hpp>
#include <thread>

#include "core/error.h"
#include "core/slab.h"
#include "reconstruct/cli.h"
#include "synthetic_dataset.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ExpectedFit;
using testing::FreshTestDir;
using testing::MakeSyntheticDataset;
using testing::PointTruth;
using testing::RelativeL2;
using testing::SyntheticDataset;
using testing::SyntheticOptions;

constexpr int kRes = 40;  // 3 mm texels on the 120 mm screen

SlabPosition Reconstruct(const SyntheticDataset& s, int i, int j, PositionReport* report,
                         ReconstructOptions options = {}) {
  options.resolution = kRes;
  const SlabInfo info = SlabInfo::FromDataset(s.dataset, kRes);
  return ReconstructPosition(s.dataset, s.calibration, info, i, j, options, report);
}

// Accuracy of one reconstructed position: against what the fit must give for perfect data
// (tight: rectification and area averaging), and against E at the texel centres (looser: the
// bell basis's approximation error for this deliberately sharp light, ~0.4 %).
struct Accuracy {
  double vs_fit = 0, vs_centres = 0;
};
Accuracy Measure(const SyntheticDataset& s, int i, int j, const SlabPosition& p,
                 const SlabLayout& layout) {
  Accuracy a;
  a.vs_fit = RelativeL2(p, ExpectedFit(s, i, j, layout, p));
  a.vs_centres = RelativeL2(p, PointTruth(s, i, j, layout));
  return a;
}
// kFitTolerance: the exact path (F = 1, K = 9 samples per texel, as dense as the pixels).
// kAutoTolerance: the default path box-averages the photo F x F first (F = 3 here), which adds a
// smoothing bias of ~texel^2/72 Laplacian(E) (1/3 of the box's own, ~1.3e-3 for this sharp light;
// ~1e-5 for the broad light of real luminaires at 4 mm texels).
constexpr double kFitTolerance = 3e-4, kAutoTolerance = 2e-3, kCentreTolerance = 6e-3;
ReconstructOptions ExactPath() {
  ReconstructOptions o;
  o.samples_per_texel = 9;
  return o;
}

int RunCli(std::vector<std::string> args) {
  std::vector<char*> argv;
  static char name[] = "lumislab-reconstruct";
  argv.push_back(name);
  for (auto& a : args) argv.push_back(a.data());
  return RunReconstruct(int(argv.size()), argv.data());
}

TEST(Reconstruct, FrontalExrMatchesAnalyticTruth) {
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("frontal"), SyntheticOptions());
  const SlabLayout layout = s.dataset.Layout(kRes);
  for (int i = 0; i < 2; ++i) {
    PositionReport r;
    const SlabPosition p = Reconstruct(s, i, 0, &r, ExactPath());
    const Accuracy a = Measure(s, i, 0, p, layout);
    std::printf(
        "frontal position %d: relative L2 %.2e vs exact fit, %.2e vs centres, K=%d, %d CG "
        "iterations\n",
        i, a.vs_fit, a.vs_centres, r.samples_per_texel, r.fit_iterations);
    EXPECT_LE(a.vs_fit, kFitTolerance);
    EXPECT_LE(a.vs_centres, kCentreTolerance);
    EXPECT_EQ(r.saturated_pixels, 0);
    EXPECT_LE(r.fit_iterations, 40);
    // The default path.
    const SlabPosition q = Reconstruct(s, i, 0, &r);
    const Accuracy b = Measure(s, i, 0, q, layout);
    std::printf("  default path (F=%d, K=%d): %.2e vs exact fit, %.2e vs centres\n", r.downsample,
                r.samples_per_texel, b.vs_fit, b.vs_centres);
    EXPECT_LE(b.vs_fit, kAutoTolerance);
    EXPECT_LE(b.vs_centres, kCentreTolerance);
    // 3 mm texels, 3 px/mm: samples at least as dense as the (averaged) pixels.
    EXPECT_GE(r.samples_per_texel * r.downsample, 9);
  }
}

// The fit matches box averages (it conserves the flux through each texel), so its coefficients
// differ from the centre values by -(texel^2 / 24) Laplacian(E) to leading order, while the plain
// box averages differ by +(texel^2 / 24) Laplacian(E). Both predictions are checked here.
TEST(Reconstruct, FitDeviatesFromCentresByTheBellModelError) {
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("fit_vs_box"), SyntheticOptions());
  const SlabLayout layout = s.dataset.Layout(kRes);
  const SlabPosition fitted = Reconstruct(s, 1, 0, nullptr, ExactPath());
  const ImageF centres = PointTruth(s, 1, 0, layout);
  // Predicted centre value + model error, Laplacian by central differences (0.5 mm steps).
  SlabPosition predicted_fit = fitted, predicted_box = fitted;
  const double h2 = layout.TexelW() * layout.TexelH(), e = 0.5;
  for (int row = 0; row < kRes; ++row)
    for (int col = 0; col < kRes; ++col) {
      const Eigen::Vector2d st = layout.TexelCentre(col, row);
      for (int c = 0; c < 3; ++c) {
        auto f = [&](double ds, double dt) { return s.Truth(1, 0, c, st.x() + ds, st.y() + dt); };
        const double lap = (f(e, 0) + f(-e, 0) + f(0, e) + f(0, -e) - 4 * f(0, 0)) / (e * e);
        predicted_fit.irradiance.at(col, row, c) = float(f(0, 0) - h2 / 24 * lap);
        predicted_box.irradiance.at(col, row, c) = float(f(0, 0) + h2 / 24 * lap);
      }
    }
  const double err_centres = RelativeL2(fitted, centres);
  const double err_model = RelativeL2(fitted, predicted_fit.irradiance);
  const double box_vs_centres = RelativeL2(predicted_box, centres);
  std::printf(
      "fit vs centres %.2e, fit vs centres - h^2/24 Laplacian %.2e, box model vs centres "
      "%.2e\n",
      err_centres, err_model, box_vs_centres);
  EXPECT_LT(err_model, 0.25 * err_centres);  // the deviation is the predicted model error
  EXPECT_NEAR(err_centres, box_vs_centres, 0.2 * box_vs_centres);
}

TEST(Reconstruct, ObliqueDistortedPngAsAccurate) {
  SyntheticOptions o;
  o.perspective = 0.002;  // the pixel footprint varies by +-12 % across the screen
  o.k1 = 0.03;
  o.ext = ".png";
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("oblique"), o);
  const SlabLayout layout = s.dataset.Layout(kRes);
  // Seen obliquely, the texels along the screen's edge have samples whose reads reach past it;
  // they are the mean of their other samples (rectify.h sample_weight), a sub-texel mean that
  // the box-average fit models only approximately: measured 2.1e-3 (auto) and 4.3e-4 (exact
  // path), up to 1.1x and 1.45x the tolerances of the frontal tests.
  constexpr double kEdgeFactor = 1.7;
  for (int i = 0; i < 2; ++i) {
    const SlabPosition q = Reconstruct(s, i, 0, nullptr);
    EXPECT_LE(Measure(s, i, 0, q, layout).vs_fit, kEdgeFactor * kAutoTolerance);
    const SlabPosition p = Reconstruct(s, i, 0, nullptr, ExactPath());
    const Accuracy a = Measure(s, i, 0, p, layout);
    std::printf(
        "oblique distorted png position %d: relative L2 %.2e vs exact fit, %.2e vs "
        "centres\n",
        i, a.vs_fit, a.vs_centres);
    EXPECT_LE(a.vs_fit, kEdgeFactor * kFitTolerance);
    EXPECT_LE(a.vs_centres, kCentreTolerance);
  }
}

TEST(Reconstruct, OffScreenTexelsAreMaskedAndZero) {
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("mask"), SyntheticOptions());
  // Position (0, 0) has c = (-2.5, 0) mm: the texel column at s = +60 sees lab x = 62.5 beyond
  // the screen edge; the column at s = -60 is on the screen.
  // The top and bottom rows lie on the screen's edge (c_y = 0): their samples' bilinear reads
  // may reach photo pixels beyond it, which are then not seen either (rectify.cc MarkInside).
  const SlabPosition p = Reconstruct(s, 0, 0, nullptr);
  for (int row = 0; row < kRes; ++row) {
    EXPECT_EQ(p.mask.at(kRes - 1, row, 0), 0.f) << row;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(p.irradiance.at(kRes - 1, row, c), 0.f);
    if (row == 0 || row == kRes - 1) continue;
    EXPECT_EQ(p.mask.at(0, row, 0), 1.f) << row;
    EXPECT_EQ(p.mask.at(kRes / 2, row, 0), 1.f) << row;
  }
}

TEST(Reconstruct, SaturatedPixelsAreCountedAndLeftOut) {
  SyntheticOptions o;
  o.amplitude = 1.3;  // the centre of the T+ photo clips
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("saturated"), o);
  ASSERT_GT(s.saturated_pixels_total, 100);
  const SlabLayout layout = s.dataset.Layout(kRes);
  int counted = 0;
  for (int i = 0; i < 2; ++i) {
    PositionReport r;
    const SlabPosition p = Reconstruct(s, i, 0, &r);
    counted += r.saturated_pixels;
    EXPECT_GT(r.saturated_texels, 0);
    // Texels whose centre is clipped in the photo are not seen; what is seen is still exact.
    for (int row = 0; row < kRes; ++row)
      for (int col = 0; col < kRes; ++col) {
        const Eigen::Vector2d st = layout.TexelCentre(col, row);
        const Eigen::Vector2d lab = st - s.dataset.grid.Centre(i, 0);
        if (s.Photo(i, 0, true, 0, lab.x(), lab.y()) >= 1.0) {
          ASSERT_EQ(p.mask.at(col, row, 0), 0.f) << col << "," << row;
        }
      }
    EXPECT_LE(Measure(s, i, 0, p, layout).vs_fit, kAutoTolerance);
  }
  EXPECT_EQ(counted, s.saturated_pixels_total);
}

TEST(Reconstruct, ExposureBracketsRecoverClippedHighlights) {
  SyntheticOptions o;
  o.amplitude = 1.6;  // clipped at exposure 1, fine at exposure 0.25
  o.exposures = {1.0, 0.25};
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("brackets"), o);
  EXPECT_EQ(s.saturated_pixels_total, 0);
  const SlabLayout layout = s.dataset.Layout(kRes);
  PositionReport r;
  const SlabPosition p = Reconstruct(s, 1, 0, &r);
  EXPECT_EQ(r.saturated_pixels, 0);
  EXPECT_EQ(r.saturated_texels, 0);
  EXPECT_LE(Measure(s, 1, 0, p, layout).vs_fit, kAutoTolerance);
}

// EXIF exposure times are nominal: the photos were taken at exactly 1/4, 1 and 4, but
// dataset.json says 0.25 * 0.96, 1 and 4 * 1.07. With the recorded exposures the slab is off by
// several per cent; with the ratios estimated from the pixels (the middle exposure anchors them)
// it is as accurate as the exact path allows, and the ratios found are within 0.2 % of 4.
TEST(Reconstruct, BracketRatiosFromThePixelsUndoWrongExposures) {
  SyntheticOptions o;
  o.amplitude = 1.6;  // the centre clips at exposures 1 and 4
  o.exposures = {0.25, 1.0, 4.0};
  SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("bracket_ratios"), o);
  for (auto& e : s.dataset.photos)
    e.exposure *= e.exposure < 0.5 ? 0.96 : e.exposure > 2 ? 1.07 : 1;
  s.dataset.Save(s.dir);
  const SlabLayout layout = s.dataset.Layout(kRes);
  ReconstructOptions estimated_options;
  estimated_options.merge.bracket_ratios = BracketRatios::kEstimated;
  PositionReport recorded_report, estimated_report;
  const SlabPosition recorded = Reconstruct(s, 1, 0, &recorded_report);
  const SlabPosition estimated = Reconstruct(s, 1, 0, &estimated_report, estimated_options);
  ASSERT_EQ(estimated_report.bracket_ratios.size(), 4u);  // 2 pairs x 2 slides
  for (const BracketRatio& b : estimated_report.bracket_ratios) {
    EXPECT_NEAR(b.estimated, 4, 4 * 0.002);
    EXPECT_GT(b.samples, 1000);
    EXPECT_GT(std::abs(b.Deviation()), 0.03);  // what the log reports (a warning above 5 %)
  }
  EXPECT_EQ(estimated_report.exposures, 3);
  EXPECT_GT(estimated_report.dynamic_range_stops, 5);
  const double recorded_error = Measure(s, 1, 0, recorded, layout).vs_fit;
  const double estimated_error = Measure(s, 1, 0, estimated, layout).vs_fit;
  std::printf("wrong exposures: recorded %.2e, estimated ratios %.2e\n", recorded_error,
              estimated_error);
  EXPECT_GT(recorded_error, 0.01);
  EXPECT_LE(estimated_error, kAutoTolerance);
  // The options on the command line: refused values are exit 2 (a parse error, or BadInput).
  EXPECT_EQ(RunCli({"--dataset", s.dir, "--bracket-ratios", "nominal"}), 2);
  try {
    RunCli({"--dataset", s.dir, "--full-well", "0"});
    ADD_FAILURE() << "--full-well 0 accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("--full-well"), std::string::npos) << e.what();
  }
}

// White noise of sigma per photo value: a texel averages N = (px per texel)^2 pixels of both
// slides, E = gain (P - N) doubles the variance, and the deconvolution multiplies the standard
// deviation by a / (a^2 - 4 b^2)^1.5 ~ 1.531 (a = 5/6, b = 1/12). The measured noise must stay
// within 1.5x of that floor (and not be suspiciously below half of it).
TEST(Reconstruct, NoiseWithinThePredictedFloor) {
  SyntheticOptions o;
  const SyntheticDataset clean = MakeSyntheticDataset(FreshTestDir("noise_clean"), o);
  o.noise_sigma = 0.004;
  const SyntheticDataset noisy = MakeSyntheticDataset(FreshTestDir("noise_noisy"), o);
  const SlabLayout layout = clean.dataset.Layout(kRes);
  const double gain = clean.dataset.filter.peak * *clean.dataset.radiometric_scale;
  const double px_per_texel = o.px_per_mm * layout.TexelW();
  const double a = 5.0 / 6, b = 1.0 / 12;
  const double predicted =
      gain * std::sqrt(2.0) * o.noise_sigma / px_per_texel * a / std::pow(a * a - 4 * b * b, 1.5);
  for (const ReconstructOptions& options : {ReconstructOptions(), ExactPath()}) {
    PositionReport r;
    const SlabPosition c = Reconstruct(clean, 0, 0, nullptr, options);
    const SlabPosition n = Reconstruct(noisy, 0, 0, &r, options);
    double sum2 = 0;
    int count = 0;
    for (size_t k = 0; k < c.mask.data.size(); ++k) {
      if (c.mask.data[k] < 0.5f || n.mask.data[k] < 0.5f) continue;
      for (int ch = 0; ch < 3; ++ch) {
        const double d = n.irradiance.data[k * 3 + ch] - c.irradiance.data[k * 3 + ch];
        sum2 += d * d;
        ++count;
      }
    }
    const double rms = std::sqrt(sum2 / count);
    std::printf("noise: F=%d K=%d rms %.3e, predicted floor %.3e (ratio %.2f)\n", r.downsample,
                r.samples_per_texel, rms, predicted, rms / predicted);
    EXPECT_LE(rms, 1.5 * predicted);
    EXPECT_GE(rms, 0.5 * predicted);
  }
}

// No light: 16-bit photos whose brightest code lies below the near-black floor (4 codes) are
// reported as such, with that code exactly (the largest stored code minus black over the
// position's photos, from the decoded pixels); lit photos are not, and the code reported for
// them is at least the floor (the check stops at the first row that reaches it). The dim
// photos: the synthetic ones (at most ~40600 codes) divided by 20000.
TEST(Reconstruct, NoLightBelowTheNearBlackFloor) {
  SyntheticOptions o;
  o.ext = ".png";
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("no_light"), o);
  const SlabInfo info = SlabInfo::FromDataset(s.dataset, kRes);
  ReconstructOptions options;
  options.resolution = kRes;
  const double floor = options.merge.near_black_codes;
  for (const int divisor : {1, 20000}) {
    std::vector<DecodedPhoto> photos = DecodePosition(s.dataset, s.calibration, 0, 0);
    double brightest = -1;
    for (DecodedPhoto& p : photos) {
      ASSERT_EQ(p.photo.pixels.depth(), CV_16U);
      p.photo.pixels /= divisor;
      double lo = 0, hi = 0;
      cv::minMaxLoc(p.photo.pixels.reshape(1), &lo, &hi);
      brightest = std::max(brightest, hi - p.photo.spec.black_level * p.photo.CodeMax());
    }
    ASSERT_EQ(brightest<floor, divisor> 1);  // the photos are as dim as meant
    PositionReport r;
    ReconstructDecoded(s.dataset, s.calibration, info, 0, 0, photos, options, &r);
    std::printf("photos / %d: brightest %.0f codes above black, reported %.0f, no light %d\n",
                divisor, brightest, r.brightest_codes, int(r.no_light));
    if (brightest < floor) {
      EXPECT_TRUE(r.no_light);
      EXPECT_EQ(r.brightest_codes, brightest);
    } else {
      EXPECT_FALSE(r.no_light);
      EXPECT_GE(r.brightest_codes, floor);
      EXPECT_LE(r.brightest_codes, brightest);
    }
  }
}

Error CaughtError(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  return Failure("no error thrown");
}

TEST(Reconstruct, BadPhotosNameTheFile) {
  SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("bad_photos"), SyntheticOptions());
  fs::remove(s.dir + "/photos/pos_1_0_n.exr");
  Error e = CaughtError([&] { Reconstruct(s, 1, 0, nullptr); });
  EXPECT_EQ(e.code(), ExitCode::kBadInput);
  EXPECT_NE(std::string(e.what()).find("pos_1_0_n.exr"), std::string::npos) << e.what();
  // Wrong image size against the calibration.
  s.calibration.image_width = 500;
  e = CaughtError([&] { Reconstruct(s, 0, 0, nullptr); });
  EXPECT_EQ(e.code(), ExitCode::kBadInput);
  EXPECT_NE(std::string(e.what()).find("image size"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("pos_0_0_p.exr"), std::string::npos) << e.what();
}

TEST(RunReconstruct, WritesSlabSkipsExistingAndForces) {
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("run"), SyntheticOptions());
  ASSERT_EQ(RunCli({"--dataset", s.dir, "--resolution", "40", "--threads", "2"}), 0);
  const SlabInfo info = SlabInfo::Load(s.dir + "/slab");
  EXPECT_TRUE(info.Complete());
  EXPECT_EQ(info.units, "W/m^2");
  const SlabPosition p = ReadSlabPosition(s.dir + "/slab", info, 1, 0);
  EXPECT_LE(Measure(s, 1, 0, p, info.layout).vs_fit, kAutoTolerance);
  const std::string exr = SlabPositionPath(s.dir + "/slab", 1, 0);
  const auto t0 = fs::last_write_time(exr);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(RunCli({"--dataset", s.dir, "--resolution", "40"}), 0);
  EXPECT_EQ(fs::last_write_time(exr), t0);  // skipped
  // Another resolution over an existing slab needs --force.
  const Error e = CaughtError([&] { RunCli({"--dataset", s.dir, "--resolution", "30"}); });
  EXPECT_EQ(e.code(), ExitCode::kBadInput);
  EXPECT_NE(std::string(e.what()).find("slab.json"), std::string::npos) << e.what();
  ASSERT_EQ(RunCli({"--dataset", s.dir, "--resolution", "40", "--force"}), 0);
  EXPECT_NE(fs::last_write_time(exr), t0);
  for (const auto& entry : fs::recursive_directory_iterator(s.dir))
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();  // no temporaries
}

TEST(RunReconstruct, MissingCalibrationIsBadInputAndWritesNothing) {
  SyntheticOptions o;
  o.write_calibration = false;
  const SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("no_calib"), o);
  const Error e = CaughtError([&] { RunCli({"--dataset", s.dir, "--resolution", "40"}); });
  EXPECT_EQ(e.code(), ExitCode::kBadInput);
  EXPECT_NE(std::string(e.what()).find("calib/screen.json"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("lumislab-calibrate screen"), std::string::npos);
  EXPECT_FALSE(fs::exists(s.dir + "/slab"));
}

// --watch: photos arrive one position at a time while the watcher runs; it stops when the grid
// is complete and the result equals the batch result.
TEST(RunReconstruct, WatchProcessesPositionsAsTheyArrive) {
  SyntheticOptions o;
  o.nu = 2;
  o.nv = 2;
  o.write_calibration = false;  // the calibration also arrives late
  SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("watch"), o, /*write_photos=*/false);
  int code = -1;
  std::thread watcher([&] {
    code = RunCli({"--dataset", s.dir, "--resolution", "40", "--watch", "--poll", "0.02",
                   "--idle-timeout", "30"});
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  s.calibration.Save(s.dir + "/calib/screen.json");
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      s.WritePhotos(i, j);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  watcher.join();
  ASSERT_EQ(code, 0);
  const SlabInfo info = SlabInfo::Load(s.dir + "/slab");
  EXPECT_TRUE(info.Complete());
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      EXPECT_LE(Measure(s, i, j, ReadSlabPosition(s.dir + "/slab", info, i, j), info.layout).vs_fit,
                kAutoTolerance);
}

// SIGTERM while watching: the watcher finishes what is in flight and leaves a valid partial slab.
TEST(RunReconstruct, WatchStopsCleanlyOnSigterm) {
  SyntheticOptions o;
  o.nu = 3;
  o.nv = 1;
  SyntheticDataset s = MakeSyntheticDataset(FreshTestDir("watch_sigterm"), o, false);
  s.WritePhotos(0, 0);
  s.WritePhotos(1, 0);  // position (2, 0) never arrives
  int code = -1;
  std::thread watcher([&] {
    code = RunCli({"--dataset", s.dir, "--resolution", "40", "--watch", "--poll", "0.02",
                   "--idle-timeout", "30"});
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    if (fs::exists(s.dir + "/slab/slab.json") &&
        SlabInfo::Load(s.dir + "/slab").present.size() == 2)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::raise(SIGTERM);  // the watcher's handler is installed: it is past its first position
  watcher.join();
  EXPECT_EQ(code, 1);  // stopped before the grid was complete
  const SlabInfo info = SlabInfo::Load(s.dir + "/slab");
  EXPECT_EQ(info.present.size(), 2u);
  EXPECT_FALSE(info.Complete());
  EXPECT_FALSE(fs::exists(SlabPositionPath(s.dir + "/slab", 2, 0)));
  for (const auto& entry : fs::recursive_directory_iterator(s.dir))
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
}

}  // namespace
}  // namespace lumislab
