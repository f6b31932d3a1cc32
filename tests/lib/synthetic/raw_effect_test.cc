// The `raw` effect (docs/formats.md §10): photos stored as an RGGB Bayer mosaic in a DNG that
// the one decoder reads back through LibRaw. Each mosaic sample is the sensor code of its
// channel's value (black + v (white - black), clipped at white), the decoder gives back
// (code - black) / (white - black) at every sample site, EXIF gives the exposure, and bad
// parameters are refused naming the field. Not listed, nothing changes (the default and
// quantized photos are checked value for value in effects_test.cc).
#include <gtest/gtest.h>

#include <filesystem>

#include "acquire/synth.h"
#include "acquire_test_util.h"
#include "core/dataset.h"
#include "lib/photo/exif.h"
#include "lib/photo/photo_io.h"
#include "lib/synthetic/effects.h"
#include "lib/synthetic/render.h"

namespace lumislab {
namespace {

using acquire_test::FreshDir;
using acquire_test::SmallScene;

TEST(RawEffect, DngMosaicDecodesToTheSensorCodes) {
  const std::string dir = FreshDir("raw_effect");
  const SynthScene scene =
      SmallScene(R"([{"type": "raw", "bit_depth": 12, "black_level": 256, "white_level": 4000}])");
  const RawEffect& raw = *scene.Raw();
  SynthOptions options;
  options.out_dir = dir + "/ds";
  options.truth_resolution = 20;
  options.threads = 2;
  const double scale = RunSynth(scene, options).radiometric_scale;
  const Dataset ds = Dataset::Load(options.out_dir);
  const PhotoEntry entry = ds.PhotosOf(1, 1)[0];
  EXPECT_EQ(entry.file, "photos/pos_1_1_p.dng");
  const std::string path = ds.PhotoPath(entry.file);
  EXPECT_EQ(DetectPhotoFormat(path), PhotoFormat::kRaw);
  // EXIF: t ISO / N^2 is the photo's relative exposure.
  EXPECT_NEAR(*ReadPhotoExif(path).RelativeExposure(), entry.exposure, 1e-6);

  ImageF plus, minus;
  RenderPosition(scene, ScreenView::Of(scene), 1, 1, scale, &plus, &minus);
  const Photo photo = DecodePhoto(path);
  ASSERT_EQ(photo.pixels.type(), CV_32FC3);
  ASSERT_EQ(photo.pixels.cols, plus.width);
  const double range = raw.white_level() - raw.black_level();
  int lit = 0;
  for (int y = 0; y < plus.height; ++y)
    for (int x = 0; x < plus.width; ++x) {
      // The channel this site samples (RGGB), decoded as stored.
      const int c = (y % 2 == 0) ? (x % 2 == 0 ? 0 : 1) : (x % 2 == 0 ? 1 : 2);
      const double expected = (raw.Code(plus.at(x, y, c)) - raw.black_level()) / range;
      ASSERT_NEAR(photo.pixels.at<cv::Vec3f>(y, x)[c], expected, 1e-6) << x << "," << y;
      lit += expected > 0.01;
    }
  EXPECT_GT(lit, 1000);
  // The sensor codes: a value of 1 or more is white (clipped), a value of 0 is black.
  EXPECT_EQ(raw.Code(1.5f), 4000);
  EXPECT_EQ(raw.Code(0.0f), 256);
  EXPECT_EQ(raw.Code(-1.0f), 0);
}

TEST(RawEffect, ParametersRefusedNamingTheField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"([{"type": "raw", "bit_depth": 10}])", "effects[0].bit_depth"},
      {R"([{"type": "raw", "bit_depth": 12, "black_level": 2000}])", "effects[0].black_level"},
      {R"([{"type": "raw", "black_level": 512, "white_level": 1000}])", "effects[0].white_level"},
      {R"([{"type": "raw", "bit_depth": 12, "white_level": 5000}])", "effects[0].white_level"},
      {R"([{"type": "raw", "gain": 1}])", "effects[0].gain"},
      {R"([{"type": "raw"}, {"type": "raw"}])", "effects[1].type"},
      {R"([{"type": "raw"}, {"type": "response"}])", "effects[1].type"},
      {R"([{"type": "quantization"}, {"type": "raw"}])", "effects[1].type"},
  };
  acquire_test::ExpectEffectsRefused(cases);
}

}  // namespace
}  // namespace lumislab
