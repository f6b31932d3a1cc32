// Effects of the synthetic capture: noise statistics match the sensor model, quantization is
// exact, and effects that are not listed cost nothing and change nothing.
#include "lib/synthetic/effects.h"

#include <gtest/gtest.h>
#include <half.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "acquire/synth.h"
#include "acquire_test_util.h"
#include "core/dataset.h"
#include "core/exr_io.h"
#include "lib/synthetic/render.h"

namespace lumislab {
namespace {

using acquire_test::FreshDir;
using acquire_test::SmallScene;

// Sample mean and variance of all values of an image.
std::pair<double, double> MeanVariance(const ImageF& m) {
  double sum = 0, sum2 = 0;
  const size_t n = m.data.size();
  for (float v : m.data) sum += v;
  const double mean = sum / n;
  for (float v : m.data) sum2 += (v - mean) * (v - mean);
  return {mean, sum2 / (n - 1)};
}

// An effect that only counts how often it runs (the scene lists it like any other).
class CountingEffect : public Effect {
 public:
  std::string Type() const override { return "counting"; }
  void Apply(ImageF&, const PhotoContext&) const override { ++count_; }
  int count() const { return count_; }

 private:
  mutable std::atomic<int> count_{0};
};

TEST(SensorNoise, VarianceFollowsTheModel) {
  const double full_well = 20000, read = 3;
  const SensorNoiseEffect noise(full_well, read, 7);
  for (double v : {0.0, 0.01, 0.25, 0.8}) {
    ImageF img(200, 200, 3, float(v));  // 120000 samples: variance +-0.4 %
    noise.Apply(img, {3});
    const auto [mean, var] = MeanVariance(img);
    const double model = (v * full_well + read * read) / (full_well * full_well);
    EXPECT_NEAR(var / model, 1.0, 0.05) << "v = " << v;
    EXPECT_NEAR(mean, v, 5 * std::sqrt(model / 120000)) << "v = " << v;
  }
}

TEST(SensorNoise, DeterministicPerSeedAndPhoto) {
  auto noisy = [](unsigned long long seed, int photo) {
    ImageF img(50, 40, 3, 0.3f);
    SensorNoiseEffect(20000, 3, seed).Apply(img, {photo});
    return img;
  };
  auto same = [](const ImageF& a, const ImageF& b) { return a.data == b.data; };
  EXPECT_TRUE(same(noisy(7, 2), noisy(7, 2)));
  EXPECT_FALSE(same(noisy(7, 2), noisy(7, 3)));
  EXPECT_FALSE(same(noisy(7, 2), noisy(8, 2)));
}

TEST(Quantization, ClipsAndRoundsToTheBitDepth) {
  ImageF img(4, 1, 3);
  const float values[4] = {-0.1f, 0.5f, 1.3f, 0.1234f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) img.at(x, 0, c) = values[x];
  QuantizationEffect(8).Apply(img, {0});
  EXPECT_EQ(img.at(0, 0, 0), 0.f);
  EXPECT_FLOAT_EQ(img.at(1, 0, 1), 128.f / 255);
  EXPECT_EQ(img.at(2, 0, 2), 1.f);
  EXPECT_FLOAT_EQ(img.at(3, 0, 0), 31.f / 255);
}

// effects []: the stored photos are the base render, bit for bit (float photos), and no effect
// step runs (ApplyEffects only walks the scene's list). A listed effect runs once per photo and
// changes the photos.
TEST(Effects, UnlistedEffectsCostNothingAndChangeNothing) {
  const std::string dir = FreshDir("effects");
  SynthOptions options;
  options.threads = 2;
  options.truth_resolution = 20;
  options.photo_format = "float";

  const SynthScene clean = SmallScene("[]");
  options.out_dir = dir + "/clean";
  const double scale = RunSynth(clean, options).radiometric_scale;
  const ScreenView view = ScreenView::Of(clean);
  ImageF plus, minus;
  RenderPosition(clean, view, 2, 1, scale, &plus, &minus);
  EXPECT_EQ(ReadExr(dir + "/clean/photos/pos_2_1_p.exr", {"R", "G", "B"}).data, plus.data);
  EXPECT_EQ(ReadExr(dir + "/clean/photos/pos_2_1_n.exr", {"R", "G", "B"}).data, minus.data);

  SynthScene noisy = SmallScene(R"([{"type": "sensor_noise", "seed": 11}])");
  const auto counting = std::make_shared<CountingEffect>();
  noisy.effects.push_back(counting);
  options.out_dir = dir + "/noisy";
  EXPECT_EQ(RunSynth(noisy, options).radiometric_scale, scale);
  EXPECT_EQ(counting->count(), 18);  // 3x3 positions x 2 slides
  const ImageF noisy_plus = ReadExr(dir + "/noisy/photos/pos_2_1_p.exr", {"R", "G", "B"});
  EXPECT_NE(noisy_plus.data, plus.data);
  // Noise is seeded per photo: one thread gives the same photos as two.
  options.out_dir = dir + "/noisy1";
  options.threads = 1;
  RunSynth(noisy, options);
  EXPECT_EQ(ReadExr(dir + "/noisy1/photos/pos_2_1_p.exr", {"R", "G", "B"}).data, noisy_plus.data);
}

// The default photos are half-float EXR: the render rounded to half, nothing else.
TEST(Effects, DefaultPhotosAreTheRenderInHalfFloat) {
  const std::string dir = FreshDir("half");
  SynthOptions options;
  options.truth_resolution = 20;
  options.out_dir = dir + "/ds";
  const SynthScene scene = SmallScene("[]");
  const double scale = RunSynth(scene, options).radiometric_scale;
  ImageF plus, minus;
  RenderPosition(scene, ScreenView::Of(scene), 1, 2, scale, &plus, &minus);
  const ImageF stored = ReadExr(dir + "/ds/photos/pos_1_2_n.exr", {"R", "G", "B"});
  ASSERT_EQ(stored.data.size(), minus.data.size());
  int lit = 0;
  for (size_t k = 0; k < stored.data.size(); ++k) {
    ASSERT_EQ(stored.data[k], float(half(minus.data[k]))) << k;
    lit += minus.data[k] > 0.01f;
  }
  EXPECT_GT(lit, 1000);
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
