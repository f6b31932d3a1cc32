// Effects of the synthetic capture: noise statistics match the sensor model, quantization is
// exact, and effects that are not listed cost nothing and change nothing.
#include "acquire/effects.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "acquire/render.h"
#include "acquire/synth.h"
#include "acquire_test_util.h"
#include "core/dataset.h"
#include "core/exr_io.h"

namespace lumislab {
namespace {

using acquire_test::FreshDir;
using acquire_test::SmallScene;

// Sample mean and variance of all values of a CV_32FC3 image.
std::pair<double, double> MeanVariance(const cv::Mat& m) {
  double sum = 0, sum2 = 0;
  const size_t n = m.total() * m.channels();
  const float* p = m.ptr<float>(0);
  for (size_t k = 0; k < n; ++k) sum += p[k];
  const double mean = sum / n;
  for (size_t k = 0; k < n; ++k) sum2 += (p[k] - mean) * (p[k] - mean);
  return {mean, sum2 / (n - 1)};
}

TEST(SensorNoise, VarianceFollowsTheModel) {
  const double full_well = 20000, read = 3;
  const SensorNoiseEffect noise(full_well, read, 7);
  for (double v : {0.0, 0.01, 0.25, 0.8}) {
    cv::Mat img(200, 200, CV_32FC3, cv::Scalar::all(v));  // 120000 samples: variance +-0.4 %
    noise.Apply(img, {3});
    const auto [mean, var] = MeanVariance(img);
    const double model = (v * full_well + read * read) / (full_well * full_well);
    EXPECT_NEAR(var / model, 1.0, 0.05) << "v = " << v;
    EXPECT_NEAR(mean, v, 5 * std::sqrt(model / 120000)) << "v = " << v;
  }
}

TEST(SensorNoise, DeterministicPerSeedAndPhoto) {
  auto noisy = [](unsigned long long seed, int photo) {
    cv::Mat img(40, 50, CV_32FC3, cv::Scalar::all(0.3));
    SensorNoiseEffect(20000, 3, seed).Apply(img, {photo});
    return img;
  };
  auto same = [](const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF) == 0; };
  EXPECT_TRUE(same(noisy(7, 2), noisy(7, 2)));
  EXPECT_FALSE(same(noisy(7, 2), noisy(7, 3)));
  EXPECT_FALSE(same(noisy(7, 2), noisy(8, 2)));
}

TEST(Quantization, ClipsAndRoundsToTheBitDepth) {
  cv::Mat img(1, 4, CV_32FC3);
  const float values[4] = {-0.1f, 0.5f, 1.3f, 0.1234f};
  for (int x = 0; x < 4; ++x) img.at<cv::Vec3f>(0, x) = cv::Vec3f::all(values[x]);
  QuantizationEffect(8).Apply(img, {0});
  EXPECT_EQ(img.at<cv::Vec3f>(0, 0)[0], 0.f);
  EXPECT_FLOAT_EQ(img.at<cv::Vec3f>(0, 1)[1], 128.f / 255);
  EXPECT_EQ(img.at<cv::Vec3f>(0, 2)[2], 1.f);
  EXPECT_FLOAT_EQ(img.at<cv::Vec3f>(0, 3)[0], 31.f / 255);
}

// effects []: the stored photos are the base render, bit for bit, and no effect step runs.
// Listing an effect runs it once per photo and changes the photos.
TEST(Effects, UnlistedEffectsCostNothingAndChangeNothing) {
  const std::string dir = FreshDir("effects");
  SynthOptions options;
  options.threads = 2;
  options.truth_resolution = 20;

  const SynthScene clean = SmallScene("[]");
  options.out_dir = dir + "/clean";
  Effect::ResetInvocationCount();
  const double scale = RunSynth(clean, options).radiometric_scale;
  EXPECT_EQ(Effect::InvocationCount(), 0);
  const ScreenView view = ScreenView::Of(clean);
  ImageF plus, minus;
  RenderPosition(clean, view, 2, 1, scale, &plus, &minus);
  EXPECT_EQ(ReadExr(dir + "/clean/photos/pos_2_1_p.exr", {"R", "G", "B"}).data, plus.data);
  EXPECT_EQ(ReadExr(dir + "/clean/photos/pos_2_1_n.exr", {"R", "G", "B"}).data, minus.data);

  const SynthScene noisy = SmallScene(R"([{"type": "sensor_noise", "seed": 11}])");
  options.out_dir = dir + "/noisy";
  Effect::ResetInvocationCount();
  EXPECT_EQ(RunSynth(noisy, options).radiometric_scale, scale);
  EXPECT_EQ(Effect::InvocationCount(), 18);  // 3x3 positions x 2 slides
  const ImageF noisy_plus = ReadExr(dir + "/noisy/photos/pos_2_1_p.exr", {"R", "G", "B"});
  EXPECT_NE(noisy_plus.data, plus.data);
  // Noise is seeded per photo: one thread gives the same photos as two.
  options.out_dir = dir + "/noisy1";
  options.threads = 1;
  RunSynth(noisy, options);
  EXPECT_EQ(ReadExr(dir + "/noisy1/photos/pos_2_1_p.exr", {"R", "G", "B"}).data, noisy_plus.data);
}

// With quantization the photos are 16-bit PNG (BGR) holding round(v 65535) of the base render.
TEST(Effects, QuantizedPhotosAre16BitPngOfTheRender) {
  const std::string dir = FreshDir("quantized");
  const SynthScene scene = SmallScene(R"([{"type": "quantization"}])");
  SynthOptions options;
  options.out_dir = dir + "/ds";
  options.truth_resolution = 20;
  const double scale = RunSynth(scene, options).radiometric_scale;
  const Dataset ds = Dataset::Load(options.out_dir);
  EXPECT_EQ(ds.PhotosOf(1, 1)[0].file, "photos/pos_1_1_p.png");
  EXPECT_DOUBLE_EQ(ds.saturation_level, 1.0);
  const cv::Mat png = cv::imread(ds.Path("photos/pos_1_1_p.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_16UC3);
  ImageF plus, minus;
  RenderPosition(scene, ScreenView::Of(scene), 1, 1, scale, &plus, &minus);
  int lit = 0;
  for (int y = 0; y < png.rows; ++y)
    for (int x = 0; x < png.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double v = std::min(1.0, std::max(0.0, double(plus.at(x, y, c))));
        ASSERT_EQ(png.at<cv::Vec3w>(y, x)[2 - c], std::lround(v * 65535)) << x << "," << y;
        lit += v > 0.01;
      }
  EXPECT_GT(lit, 1000);
}

}  // namespace
}  // namespace lumislab

namespace lumislab {
namespace {

// "exposure" multiplies the values (the radiometric scale stays that of exposure 1) and may
// saturate on purpose: clipped pixels sit at the saturation level, 65535.
TEST(Effects, ExposureSaturatesOnPurpose) {
  const std::string dir = FreshDir("exposure");
  const std::string effects = R"([{"type": "quantization", "bit_depth": 12}])";
  const SynthScene normal = acquire_test::SmallScene(effects);
  const SynthScene bright =
      ParseScene(acquire_test::SmallSceneJson(effects, R"(, "exposure": 3)"), "bright.json");
  EXPECT_EQ(ChooseRadiometricScale(bright, 1), ChooseRadiometricScale(normal, 1));
  SynthOptions options;
  options.out_dir = dir + "/ds";
  options.truth_resolution = 20;
  RunSynth(bright, options);
  const Dataset ds = Dataset::Load(options.out_dir);
  EXPECT_DOUBLE_EQ(ds.photos[0].exposure, 3.0);
  int saturated = 0, off_grid = 0;
  for (const auto& p : ds.photos) {
    const cv::Mat png = cv::imread(ds.Path(p.file), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(png.type(), CV_16UC3);
    for (auto it = png.begin<cv::Vec3w>(); it != png.end<cv::Vec3w>(); ++it)
      for (int c = 0; c < 3; ++c) {
        saturated += (*it)[c] == 65535;
        // 12-bit levels k / 4095 stored as round(k / 4095 * 65535).
        const double k = (*it)[c] / 65535.0 * 4095;
        off_grid += std::abs((*it)[c] - std::lround(std::round(k) / 4095 * 65535)) > 0;
      }
  }
  EXPECT_GT(saturated, 100);
  EXPECT_EQ(off_grid, 0);
}

}  // namespace
}  // namespace lumislab
