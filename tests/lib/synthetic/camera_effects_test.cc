// The camera effects of issue 8 (vignetting, screen_gain, ambient, dark, brackets, response,
// stage_error): each against an analytic expectation, deterministic for a seed, its parameters
// refused out of range naming the field, and the truth untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "acquire/synth.h"
#include "acquire_test_util.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "lib/photo/photo_io.h"
#include "lib/synthetic/effects.h"
#include "lib/synthetic/render.h"

namespace lumislab {
namespace {

using acquire_test::ExpectEffectsRefused;
using acquire_test::FileBytes;
using acquire_test::FreshDir;
using acquire_test::SmallScene;
using acquire_test::SmallSynthOptions;

template <typename T>
const T& Only(const SynthScene& scene) {
  EXPECT_EQ(scene.effects.size(), 1u);
  const T* effect = dynamic_cast<const T*>(scene.effects.at(0).get());
  EXPECT_NE(effect, nullptr);
  return *effect;
}

// Small scene: 320 x 240 px, f = 260 px, principal point (159.5, 119.5); its corner pixel
// centre (0, 0) is at r = 1, 199.3 px off the axis.
TEST(VignettingEffect, CornerIsCos4TimesThePolynomial) {
  const double f = 260, d2 = 159.5 * 159.5 + 119.5 * 119.5;
  const double cos4 = std::pow(f * f / (f * f + d2), 2);  // 0.4401
  for (bool with_cos4 : {true, false}) {
    const SynthScene scene =
        SmallScene(std::string(R"([{"type": "vignetting", "k1": -0.2, )") +
                   R"("k2": 0.05, "cos4": )" + (with_cos4 ? "true" : "false") + "}]");
    ImageF img(320, 240, 3, 0.5f);
    scene.effects[0]->Apply(img, {});
    const double expected = 0.5 * (with_cos4 ? cos4 : 1.0) * (1 - 0.2 + 0.05);
    for (auto [x, y] : {std::pair(0, 0), std::pair(319, 0), std::pair(0, 239), std::pair(319, 239)})
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.at(x, y, c), expected, 1e-6) << x << "," << y;
    // Half a pixel from the principal point: r^2 = 0.5 / d2, angle ~ 0.
    const double t = 0.5 / d2;
    const double centre =
        0.5 * (with_cos4 ? std::pow(f * f / (f * f + 0.5), 2) : 1.0) * (1 - 0.2 * t + 0.05 * t * t);
    EXPECT_NEAR(img.at(159, 119, 1), centre, 1e-6);
  }
}

// The gain is a function of the screen point, not of the pixel: two cameras seeing the screen
// from different places apply the same gain at the same lab point. |gain - 1| <= amplitude, and
// with one blob the gain reaches 1 +- amplitude at its centre.
TEST(ScreenGainEffect, DefinedInScreenCoordinatesAndBounded) {
  const std::string effects =
      R"([{"type": "screen_gain", "amplitude": 0.15, "blobs": 1, "size_mm": 300, "seed": 3}])";
  const SynthScene a = SmallScene(effects);
  const SynthScene b = ParseScene(
      acquire_test::SmallSceneJson(effects).replace(
          acquire_test::SmallSceneJson(effects).find("[0, -400, 2400]"), 15, "[90, -300, 2300]"),
      "moved.json");
  ASSERT_NE(a.camera.position_mm, b.camera.position_mm);
  const auto& gain_a = Only<ScreenGainEffect>(a);
  const auto& gain_b = Only<ScreenGainEffect>(b);
  double largest = 0;
  for (const SynthScene* scene : {&a, &b}) {
    ImageF img(320, 240, 3, 1.0f);
    scene->effects[0]->Apply(img, {});
    const ScreenView view = ScreenView::Of(*scene);
    ASSERT_GT(view.pixels.size(), 10000u);
    std::vector<bool> on_screen(320 * 240, false);
    for (size_t k = 0; k < view.pixels.size(); ++k) {
      on_screen[view.pixels[k]] = true;
      const double g = gain_a.Gain(view.lab_mm[k]);  // a's gain at b's lab points too
      ASSERT_NEAR(img.data[size_t(view.pixels[k]) * 3 + 1], g, 1e-6);
      ASSERT_LE(std::abs(g - 1), 0.15 + 1e-12);
      largest = std::max(largest, std::abs(g - 1));
    }
    for (int p = 0; p < 320 * 240; ++p) {
      if (!on_screen[p]) {
        ASSERT_EQ(img.data[size_t(p) * 3], 1.0f) << "off the screen: " << p;
      }
    }
  }
  EXPECT_GT(largest, 0.14);
  const Eigen::Vector2d point(123, -45);
  EXPECT_EQ(gain_a.Gain(point), gain_b.Gain(point));  // same seed, same screen
  const SynthScene other = SmallScene(
      R"([{"type": "screen_gain", "amplitude": 0.15, "blobs": 1, "size_mm": 300, "seed": 4}])");
  EXPECT_NE(Only<ScreenGainEffect>(other).Gain(point), gain_a.Gain(point));
}

// Ambient light adds level x exposure to every screen pixel of both slides, so E+ - E- is that
// of the clean capture (to float rounding of the sums: 1.2e-7); nothing off the screen.
TEST(AmbientEffect, CancelsInTheSlideDifference) {
  const SynthScene clean = SmallScene("[]");
  const SynthScene lit = SmallScene(R"([{"type": "ambient", "level": 0.05}])");
  const double scale = ChooseRadiometricScale(clean, 1);
  EXPECT_EQ(ChooseRadiometricScale(lit, 1), scale);
  const ScreenView view = ScreenView::Of(clean);
  const ImageF p0 = SynthPhoto(clean, view, scale, 1, 2, true);
  const ImageF n0 = SynthPhoto(clean, view, scale, 1, 2, false);
  const ImageF p = SynthPhoto(lit, view, scale, 1, 2, true);
  const ImageF n = SynthPhoto(lit, view, scale, 1, 2, false);
  std::vector<bool> on_screen(p.data.size() / 3, false);
  for (int px : view.pixels) on_screen[px] = true;
  double worst = 0;
  for (size_t k = 0; k < p.data.size(); ++k) {
    if (!on_screen[k / 3]) {
      ASSERT_EQ(p.data[k], p0.data[k]);
      continue;
    }
    ASSERT_NEAR(p.data[k] - p0.data[k], 0.05, 1.2e-7);
    ASSERT_NEAR(n.data[k] - n0.data[k], 0.05, 1.2e-7);
    worst = std::max(worst,
                     std::abs((double(p.data[k]) - n.data[k]) - (double(p0.data[k]) - n0.data[k])));
  }
  EXPECT_LE(worst, 1.2e-7);
}

// Dark frames (a zero render): mean = black level + dark current x exposure time within 1e-3
// under sensor noise; hot pixels are the seeded fraction, the same in every photo, at
// black + hot_current x t. dataset.json records the black level (white = 1 + black) so the
// decoder gives the render back.
TEST(DarkEffect, LevelHotPixelsAndRecordedBlackLevel) {
  const SynthScene scene = SmallScene(
      R"([{"type": "dark", "black_level": 0.02, "dark_current": 0.01, "hot_fraction": 0.002,
           "hot_current": 0.5, "seed": 5}, {"type": "sensor_noise", "seed": 1}])");
  const auto* dark = dynamic_cast<const DarkEffect*>(scene.effects[0].get());
  ASSERT_NE(dark, nullptr);
  int hot = 0;
  for (int p = 0; p < 320 * 240; ++p) hot += dark->Hot(p);
  EXPECT_NEAR(hot, 0.002 * 320 * 240, 5 * std::sqrt(0.002 * 320 * 240));  // 153.6 +- 62
  EXPECT_GT(hot, 0);
  for (int photo : {0, 7}) {
    ImageF img(320, 240, 3, 0.f);
    ApplyEffects(scene, {photo, 2.0}, &img);  // t = 2 s
    double sum = 0, hot_sum = 0;
    int n = 0;
    for (int p = 0; p < 320 * 240; ++p)
      for (int c = 0; c < 3; ++c)
        if (dark->Hot(p)) {
          hot_sum += img.data[size_t(p) * 3 + c];
        } else {
          sum += img.data[size_t(p) * 3 + c];
          ++n;
        }
    EXPECT_NEAR(sum / n, 0.02 + 0.01 * 2, 1e-3) << "photo " << photo;
    EXPECT_NEAR(hot_sum / (3 * hot), 0.02 + 0.5 * 2, 1e-3) << "photo " << photo;
  }

  const SynthScene level_only = SmallScene(R"([{"type": "dark", "black_level": 0.03}])");
  const std::string dir = FreshDir("dark");
  RunSynth(level_only, SmallSynthOptions(dir + "/ds"));
  const Dataset ds = Dataset::Load(dir + "/ds");
  EXPECT_DOUBLE_EQ(ds.black_level, 0.03);
  EXPECT_DOUBLE_EQ(ds.white_level, 1.03);
  const PhotoEntry entry = ds.PhotosOf(1, 1)[0];
  const Photo photo = DecodePhoto(ds.Path(entry.file), PhotoSpecOf(ds, entry));
  const LinearReader reader(photo);
  const SynthScene clean = SmallScene("[]");
  const ImageF render =
      SynthPhoto(clean, ScreenView::Of(clean), *ds.radiometric_scale, 1, 1, entry.positive);
  for (int y = 0; y < 240; y += 7)
    for (int x = 0; x < 320; x += 5) {
      float rgb[3];
      bool clipped[3];
      reader.Read(y, x, rgb, clipped);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(rgb[c], render.at(x, y, c), 1e-6);
    }
}

// brackets [-2, 0, 2]: three photos per slide, named by their stop, with exposures 1/4, 1, 4;
// +2 stops is 4x the 0-stop photo exactly where that stays below 1, and 1 where it clips.
TEST(BracketsEffect, ExposureSeriesScalesAndClips) {
  const SynthScene scene = SmallScene(R"([{"type": "brackets", "stops": [-2, 0, 2]}])");
  const std::string dir = FreshDir("brackets");
  RunSynth(scene, SmallSynthOptions(dir + "/ds"));
  const Dataset ds = Dataset::Load(dir + "/ds");
  ASSERT_EQ(ds.photos.size(), 3u * 3 * 2 * 3);
  const std::vector<PhotoEntry> photos = ds.PhotosOf(2, 1);
  ASSERT_EQ(photos.size(), 6u);
  EXPECT_EQ(photos[0].file, "photos/pos_2_1_p_ev-2.exr");
  EXPECT_EQ(photos[1].file, "photos/pos_2_1_p_ev+0.exr");
  EXPECT_EQ(photos[2].file, "photos/pos_2_1_p_ev+2.exr");
  EXPECT_EQ(photos[5].file, "photos/pos_2_1_n_ev+2.exr");
  EXPECT_DOUBLE_EQ(photos[0].exposure, 0.25);
  EXPECT_DOUBLE_EQ(photos[1].exposure, 1.0);
  EXPECT_DOUBLE_EQ(photos[2].exposure, 4.0);
  const ImageF low = ReadExr(ds.Path(photos[0].file), {"R", "G", "B"});
  const ImageF mid = ReadExr(ds.Path(photos[1].file), {"R", "G", "B"});
  const ImageF high = ReadExr(ds.Path(photos[2].file), {"R", "G", "B"});
  // The 0-stop photo is the plain render: the bracket changes nothing else.
  const SynthScene clean = SmallScene("[]");
  EXPECT_EQ(mid.data,
            SynthPhoto(clean, ScreenView::Of(clean), *ds.radiometric_scale, 2, 1, true).data);
  int linear = 0, clipped = 0;
  for (size_t k = 0; k < mid.data.size(); ++k) {
    ASSERT_EQ(low.data[k], mid.data[k] / 4);
    if (4 * mid.data[k] < 1) {
      ASSERT_EQ(high.data[k], 4 * mid.data[k]);
      linear += mid.data[k] > 0.01f;
    } else {
      ASSERT_EQ(high.data[k], 1.0f);
      ++clipped;
    }
  }
  EXPECT_GT(linear, 1000);
  EXPECT_GT(clipped, 100);
}

// response: y = (x (1 + s) / (1 + s x))^(1/gamma) in 8-bit levels; the photos are JPEG;
// truth/response.json holds the inverse per code, and the JPEG's codes are within JPEG error of
// the curve's.
TEST(ResponseEffect, CurveJpegAndTrueCurveRecorded) {
  const SynthScene scene =
      SmallScene(R"([{"type": "response", "gamma": 2.2, "shoulder": 0.5, "quality": 95}])");
  const auto& response = Only<ResponseEffect>(scene);
  for (double x : {0.0, 0.01, 0.18, 0.5, 0.9, 1.0}) {
    const double y = std::pow(x * 1.5 / (1 + 0.5 * x), 1 / 2.2);
    EXPECT_NEAR(response.Curve(x), y, 1e-12);
    EXPECT_NEAR(response.Inverse(y), x, 1e-12);
  }
  ImageF levels(4, 1, 3);
  const float in[4] = {-0.2f, 0.18f, 0.7f, 1.5f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) levels.at(x, 0, c) = in[x];
  response.Apply(levels, {});
  EXPECT_EQ(levels.at(0, 0, 0), 0.f);
  EXPECT_FLOAT_EQ(levels.at(1, 0, 1), float(std::round(response.Curve(0.18) * 255) / 255));
  EXPECT_EQ(levels.at(3, 0, 2), 1.f);

  const std::string dir = FreshDir("response");
  RunSynth(scene, SmallSynthOptions(dir + "/ds"));
  const Dataset ds = Dataset::Load(dir + "/ds");
  const PhotoEntry entry = ds.PhotosOf(1, 1)[0];
  EXPECT_EQ(entry.file, "photos/pos_1_1_p.jpg");
  EXPECT_EQ(DetectPhotoFormat(ds.Path(entry.file)), PhotoFormat::kJpeg);
  const nlohmann::json truth = nlohmann::json::parse(FileBytes(dir + "/ds/truth/response.json"));
  EXPECT_EQ(truth["curve"], "gamma");
  ASSERT_EQ(truth["linear_of_code"].size(), 256u);
  for (int k : {0, 1, 64, 200, 255})
    EXPECT_DOUBLE_EQ(truth["linear_of_code"][k].get<double>(), response.Inverse(k / 255.0));
  const cv::Mat jpeg = cv::imread(ds.Path(entry.file), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(jpeg.type(), CV_8UC3);
  const SynthScene clean = SmallScene("[]");
  const ImageF render = SynthPhoto(clean, ScreenView::Of(clean), *ds.radiometric_scale, 1, 1, true);
  double error = 0;
  for (int y = 0; y < jpeg.rows; ++y)
    for (int x = 0; x < jpeg.cols; ++x)
      for (int c = 0; c < 3; ++c)
        error += std::abs(jpeg.at<cv::Vec3b>(y, x)[2 - c] -
                          std::round(response.Curve(render.at(x, y, c)) * 255));
  EXPECT_LT(error / (jpeg.total() * 3), 1.0);  // mean code error of quality-95 JPEG
  // A decoder given the true curve (the table of truth/response.json) gets the render back over
  // the lit pixels (render > 0.05): to 8-bit rounding from the ideal codes, and to that plus
  // JPEG error from the file's.
  double ideal2 = 0, jpeg2 = 0, ref2 = 0;
  for (int y = 0; y < jpeg.rows; ++y)
    for (int x = 0; x < jpeg.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double r = render.at(x, y, c);
        if (r < 0.05) continue;
        const int ideal_code = int(std::lround(response.Curve(r) * 255));
        const double ideal = truth["linear_of_code"][ideal_code];
        const double decoded = truth["linear_of_code"][jpeg.at<cv::Vec3b>(y, x)[2 - c]];
        ideal2 += (ideal - r) * (ideal - r);
        jpeg2 += (decoded - r) * (decoded - r);
        ref2 += r * r;
      }
  ASSERT_GT(ref2, 0);
  const double ideal_error = std::sqrt(ideal2 / ref2), jpeg_error = std::sqrt(jpeg2 / ref2);
  std::printf("through the true curve, relative L2 over lit pixels: 8-bit %.3f %%, JPEG %.3f %%\n",
              100 * ideal_error, 100 * jpeg_error);
  EXPECT_LT(ideal_error, 0.005);
  EXPECT_LT(jpeg_error, 0.02);

  const SynthScene srgb = SmallScene(R"([{"type": "response", "curve": "srgb"}])");
  EXPECT_EQ(DatasetSkeleton(srgb).photo_transfer, "srgb");
  EXPECT_EQ(DatasetSkeleton(scene).photo_transfer, "auto");
}

// stage_error: per position a seeded offset within +-max_mm on each axis, reproducible, that the
// render uses (E at lab point x through the luminaire at c + offset), while truth/ is the same
// as the clean capture's.
TEST(StageErrorEffect, SeededBoundedOffsetsMoveTheRenderNotTheTruth) {
  const SynthScene scene = SmallScene(R"([{"type": "stage_error", "max_mm": 0.4, "seed": 9}])");
  const SynthScene again = SmallScene(R"([{"type": "stage_error", "max_mm": 0.4, "seed": 9}])");
  const SynthScene other = SmallScene(R"([{"type": "stage_error", "max_mm": 0.4, "seed": 10}])");
  double largest = 0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d o = scene.StageOffsetMm(i, j);
      EXPECT_LE(o.cwiseAbs().maxCoeff(), 0.4);
      EXPECT_EQ(o, again.StageOffsetMm(i, j));
      EXPECT_NE(o, other.StageOffsetMm(i, j));
      largest = std::max(largest, o.cwiseAbs().maxCoeff());
    }
  EXPECT_GT(largest, 0.1);

  const double scale = ChooseRadiometricScale(scene, 1);
  const ScreenView view = ScreenView::Of(scene);
  ImageF plus, minus;
  RenderPosition(scene, view, 2, 0, scale, &plus, &minus);
  const Eigen::Vector2d c = scene.grid.Centre(2, 0) + scene.StageOffsetMm(2, 0);
  const DualFilter filter = scene.Filter();
  for (size_t k = 0; k < view.pixels.size(); k += 997) {
    Eigen::Vector3d e_plus, e_minus;
    const Eigen::Vector2d st = view.lab_mm[k] + c;
    scene.luminaire.SlideIrradiance(filter, filter.Peak2D(), scene.grid.spacing_mm, c,
                                    scene.distance_mm, st.x(), st.y(), &e_plus, &e_minus);
    EXPECT_EQ(plus.data[size_t(view.pixels[k]) * 3], float(e_plus[0] / scale));
  }
  const SynthScene clean = SmallScene("[]");
  ImageF clean_plus, clean_minus;
  RenderPosition(clean, view, 2, 0, scale, &clean_plus, &clean_minus);
  EXPECT_NE(plus.data, clean_plus.data);

  const std::string dir = FreshDir("stage_error");
  RunSynth(scene, SmallSynthOptions(dir + "/moved"));
  RunSynth(clean, SmallSynthOptions(dir + "/clean"));
  for (const char* file : {"truth/pos_0_0.exr", "truth/pos_2_1.exr", "truth/slab.json"})
    EXPECT_EQ(FileBytes(dir + "/moved/" + file), FileBytes(dir + "/clean/" + file)) << file;
  EXPECT_NE(FileBytes(dir + "/moved/photos/pos_2_1_p.exr"),
            FileBytes(dir + "/clean/photos/pos_2_1_p.exr"));
}

// All the effects in one scene (the fuzzer's seed): a dataset that loads, with 3 JPEG photos per
// slide at exposures 1/4, 1, 4, the black level recorded and the photos the same for a rerun.
TEST(CameraEffects, AllTogetherMakeAValidReproducibleDataset) {
  const SynthScene scene =
      LoadScene(LUMISLAB_SOURCE_DIR "/fuzz/corpus/fuzz_scene/camera_effects.json");
  ASSERT_EQ(scene.effects.size(), 8u);
  const std::string dir = FreshDir("all_effects");
  RunSynth(scene, SmallSynthOptions(dir + "/a"));
  RunSynth(scene, SmallSynthOptions(dir + "/b"));
  const Dataset ds = Dataset::Load(dir + "/a");
  ASSERT_EQ(ds.photos.size(), 2u * 2 * 2 * 3);
  EXPECT_DOUBLE_EQ(ds.black_level, 0.02);
  for (size_t k = 0; k < ds.photos.size(); ++k) {
    const PhotoEntry& p = ds.photos[k];
    EXPECT_DOUBLE_EQ(p.exposure, std::exp2(2.0 * (int(k % 3) - 1))) << p.file;
    EXPECT_EQ(DetectPhotoFormat(ds.Path(p.file)), PhotoFormat::kJpeg) << p.file;
    EXPECT_EQ(FileBytes(ds.Path(p.file)), FileBytes(dir + "/b/" + p.file)) << p.file;
  }
}

// Every parameter out of its range, a parameter the effect does not know, and the effects that
// may be listed once: exit 2 (InputError) naming the scene file and the field.
TEST(EffectParameters, OutOfRangeRefusedNamingTheField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"([{"type": "vignetting", "k1": 2}])", "effects[0].k1"},
      {R"([{"type": "vignetting", "k1": -0.9, "k2": -0.5}])", "effects[0].k2"},
      {R"([{"type": "vignetting", "cos4": 1}])", "effects[0].cos4"},
      {R"([{"type": "screen_gain", "amplitude": 0.2}])", "effects[0].amplitude"},
      {R"([{"type": "screen_gain", "blobs": 0}])", "effects[0].blobs"},
      {R"([{"type": "screen_gain", "size_mm": 0}])", "effects[0].size_mm"},
      {R"([{"type": "ambient", "level": -0.1}])", "effects[0].level"},
      {R"([{"type": "dark", "black_level": 0.6}])", "effects[0].black_level"},
      {R"([{"type": "dark", "dark_current": -1}])", "effects[0].dark_current"},
      {R"([{"type": "dark", "hot_fraction": 0.1}])", "effects[0].hot_fraction"},
      {R"([{"type": "dark", "hot_current": 1000}])", "effects[0].hot_current"},
      {R"([{"type": "brackets", "stops": []}])", "effects[0].stops"},
      {R"([{"type": "brackets", "stops": [0, 9]}])", "effects[0].stops[1]"},
      {R"([{"type": "brackets", "stops": [1, 1]}])", "effects[0].stops[1]"},
      {R"([{"type": "brackets"}])", "effects[0].stops"},
      {R"([{"type": "response", "curve": "log"}])", "effects[0].curve"},
      {R"([{"type": "response", "gamma": 0.5}])", "effects[0].gamma"},
      {R"([{"type": "response", "shoulder": 11}])", "effects[0].shoulder"},
      {R"([{"type": "response", "quality": 0}])", "effects[0].quality"},
      {R"([{"type": "response", "curve": "srgb", "gamma": 2}])", "effects[0].gamma"},
      {R"([{"type": "stage_error", "max_mm": 6}])", "effects[0].max_mm"},
      {R"([{"type": "stage_error", "seed": -1}])", "effects[0].seed"},
      {R"([{"type": "ambient"}, {"type": "ambient"}, {"type": "vignetting", "strength": 1}])",
       "effects[2].strength"},
      {R"([{"type": "brackets", "stops": [0]}, {"type": "brackets", "stops": [1]}])",
       "effects[1].type"},
      {R"([{"type": "dark"}, {"type": "dark"}])", "effects[1].type"},
      {R"([{"type": "quantization"}, {"type": "response"}])", "effects[1].type"},
  };
  ExpectEffectsRefused(cases);
}

}  // namespace
}  // namespace lumislab
