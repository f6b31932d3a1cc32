// The synthetic capture against its analytic model: slide photos, calibration photo, truth slab,
// true camera, skip/force, and the printed filter slides.
#include "acquire/synth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "acquire/filter_print.h"
#include "acquire_test_util.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/json.h"
#include "core/slab.h"
#include "lib/synthetic/camera.h"
#include "lib/synthetic/render.h"
#include "lib/synthetic/truth.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using acquire_test::FreshDir;
using acquire_test::SmallScene;

// peak (v+ - v-) * scale / exposure at a pixel equals the truth E_ij at the screen point that
// pixel sees (luminaire frame: lab + c_ij), to float precision.
TEST(Synth, SlidePhotosReproduceTheFilteredIrradiance) {
  const SynthScene scene = SmallScene();
  const ScreenView view = ScreenView::Of(scene);
  ASSERT_GT(view.pixels.size(), 1000u);
  const double scale = 0.37;
  const DualFilter f = scene.Filter();
  const PinholeCamera camera(scene.camera);
  for (const auto& [i, j] : {std::pair{0, 0}, std::pair{2, 1}, std::pair{1, 2}}) {
    ImageF plus, minus;
    RenderPosition(scene, view, i, j, scale, &plus, &minus);
    const Eigen::Vector2d c = scene.grid.Centre(i, j);
    double max_truth = 0;
    int compared = 0;
    for (int y = 0; y < plus.height; y += 3)
      for (int x = 0; x < plus.width; x += 3) {
        Eigen::Vector2d lab;
        ASSERT_TRUE(camera.PlanePoint(x, y, scene.distance_mm, &lab));
        if (std::abs(lab.x()) > 600 || std::abs(lab.y()) > 600) {
          for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(plus.at(x, y, ch), 0.f);
          continue;
        }
        const Eigen::Vector3d truth = scene.luminaire.FilteredIrradiance(
            f, scene.grid.spacing_mm, c, scene.distance_mm, lab.x() + c.x(), lab.y() + c.y());
        max_truth = std::max(max_truth, truth.cwiseAbs().maxCoeff());
        for (int ch = 0; ch < 3; ++ch) {
          const double measured =
              f.Peak2D() * (double(plus.at(x, y, ch)) - minus.at(x, y, ch)) * scale;
          const double slides = std::max<double>(plus.at(x, y, ch), minus.at(x, y, ch));
          // float storage: relative 1e-5 of the larger slide value
          EXPECT_NEAR(measured, truth[ch], 1e-5 * f.Peak2D() * slides * scale + 1e-12)
              << i << "," << j << " px " << x << "," << y;
          compared += std::abs(truth[ch]) > 0;
          if (std::abs(truth[ch]) > 0.05 * max_truth) {
            EXPECT_NEAR(measured / truth[ch], 1.0, 1e-5);
          }
        }
      }
    EXPECT_GT(compared, 1000);
    EXPECT_GT(max_truth, 0);
  }
}

// The brightest pixel of all photos is about 0.85 and none is saturated.
TEST(Synth, RadiometricScalePutsTheBrightestPixelNear085) {
  const SynthScene scene = SmallScene();
  const ScreenView view = ScreenView::Of(scene);
  const double scale = ChooseRadiometricScale(scene, 2);
  float brightest = 0;
  for (int j = 0; j < scene.grid.nv; ++j)
    for (int i = 0; i < scene.grid.nu; ++i) {
      ImageF plus, minus;
      RenderPosition(scene, view, i, j, scale, &plus, &minus);
      for (float v : plus.data) brightest = std::max(brightest, v);
      for (float v : minus.data) brightest = std::max(brightest, v);
    }
  EXPECT_NEAR(brightest, 0.85, 0.03);
}

// The white dot of square (0, 0) appears where the target contract and the true camera put it.
TEST(Synth, CalibrationPhotoGeometry) {
  SynthScene scene = SmallScene();
  scene.camera.width = 1600;  // the default camera: squares of ~45 px, the dot ~18 px wide
  scene.camera.height = 1200;
  scene.camera.focal_px = 1300;
  const ImageF img = RenderCalibration(scene, 2);  // linear reflectance
  ASSERT_EQ(img.channels, 1);
  const PinholeCamera camera(scene.camera);
  const CalibrationTarget& t = scene.calibration;
  auto pixel_of = [&](double a, double b) {  // board coordinates in squares -> pixel
    const Eigen::Vector2d lab = t.origin_mm + Eigen::Vector2d(a, b) * t.square_mm;
    return camera.Project({lab.x(), lab.y(), scene.distance_mm});
  };
  // Centroid of the bright pixels inside square (0, 0) = the dot's centre (small perspective).
  const Eigen::Vector2d dot = pixel_of(0.5, 0.5);
  const double radius_px = (pixel_of(0.5, 0.9) - dot).norm();
  double sx = 0, sy = 0, sw = 0;
  // radius_px is 0.4 square: the window stays inside square (0, 0).
  for (int y = int(dot.y() - radius_px); y <= int(dot.y() + radius_px); ++y)
    for (int x = int(dot.x() - radius_px); x <= int(dot.x() + radius_px); ++x) {
      const double w = std::max(0.0, img.at(x, y, 0) - 0.05);
      sx += w * x, sy += w * y, sw += w;
    }
  ASSERT_GT(sw, 0);
  EXPECT_NEAR(sx / sw, dot.x(), 0.1);
  EXPECT_NEAR(sy / sw, dot.y(), 0.1);
  auto value = [&](double a, double b) {
    const Eigen::Vector2d p = pixel_of(a, b);
    return img.at(int(std::lround(p.x())), int(std::lround(p.y())), 0);
  };
  EXPECT_NEAR(value(0.5, 0.5), 0.8, 1e-6);     // dot: white 0.8
  EXPECT_NEAR(value(0.12, 0.12), 0.05, 1e-6);  // square (0,0) outside the dot: black 0.05
  EXPECT_NEAR(value(1.5, 0.5), 0.8, 1e-6);     // (1,0) white
  EXPECT_NEAR(value(1.5, 1.5), 0.05, 1e-6);    // (1,1) black
  EXPECT_NEAR(value(t.squares_x - 0.5, t.squares_y - 0.5),
              (t.squares_x + t.squares_y) % 2 ? 0.8 : 0.05, 1e-6);
  EXPECT_NEAR(value(-0.25, 0.5), 0.8, 1e-6);  // white screen around the board
  EXPECT_EQ(img.at(0, 0, 0), 0.f);            // outside the screen
  // A corner is sub-pixel exact: around the inner corner (1,1) the area-sampled pixels average
  // half-way between black and white.
  const Eigen::Vector2d corner = pixel_of(1, 1);
  const int cx = int(std::floor(corner.x())), cy = int(std::floor(corner.y()));
  double mean = 0;
  for (int y = cy - 2; y <= cy + 3; ++y)
    for (int x = cx - 2; x <= cx + 3; ++x) mean += img.at(x, y, 0);
  mean /= 36;
  EXPECT_NEAR(mean, 0.5 * (0.8 + 0.05), 0.047);
}

// The whole capture on disk: dataset.json, photos, truth slab equal to TruthPosition, camera.
TEST(Synth, WritesACompleteDatasetAndSkipsItAfterwards) {
  const std::string dir = FreshDir("complete");
  const SynthScene scene = SmallScene();
  SynthOptions options;
  options.out_dir = dir + "/ds";
  options.threads = 2;
  options.truth_resolution = 40;
  const SynthReport report = RunSynth(scene, options);
  EXPECT_FALSE(report.skipped);
  EXPECT_EQ(report.photos_written, 18);
  const Dataset ds = Dataset::Load(options.out_dir);
  EXPECT_TRUE(ds.synthetic);
  ASSERT_TRUE(ds.radiometric_scale.has_value());
  EXPECT_NEAR(*ds.radiometric_scale, report.radiometric_scale, 1e-9 * report.radiometric_scale);
  EXPECT_EQ(ds.photos.size(), 18u);
  EXPECT_NEAR(ds.filter.peak, DualFilter::Truncated(1).Peak2D(), 1e-12);
  EXPECT_EQ(ds.PhotosOf(2, 1)[1].file, "photos/pos_2_1_n.exr");
  for (const auto& p : ds.photos) EXPECT_TRUE(fs::exists(ds.Path(p.file))) << p.file;
  EXPECT_TRUE(fs::exists(ds.Path(ds.calibration.photo)));
  EXPECT_TRUE(DatasetComplete(options.out_dir));

  const SlabInfo info = SlabInfo::Load(options.out_dir + "/truth");
  EXPECT_TRUE(info.Complete());
  EXPECT_EQ(info.layout.res_x, 40);
  const SlabPosition truth = ReadSlabPosition(options.out_dir + "/truth", info, 2, 0);
  const SlabPosition expected = TruthPosition(scene.luminaire, info, 2, 0);
  EXPECT_EQ(truth.irradiance.data, expected.irradiance.data);
  // Texel (col, row) holds E_ij at its centre.
  const Eigen::Vector2d st = info.layout.TexelCentre(13, 27);
  const Eigen::Vector3d e = scene.luminaire.FilteredIrradiance(
      scene.Filter(), 5, scene.grid.Centre(2, 0), 750, st.x(), st.y());
  EXPECT_NEAR(truth.irradiance.at(13, 27, 1), e[1], 1e-6 * std::abs(e[1]) + 1e-12);

  // truth/camera.json: the exact homography maps the image centre to the look-at point.
  const JsonDocument cam = JsonDocument::Load(options.out_dir + "/truth/camera.json");
  const std::vector<double> h = cam.root()["screen_from_image"].Numbers(9);
  const double u = 159.5, v = 119.5;
  const double w = h[6] * u + h[7] * v + h[8];
  EXPECT_NEAR((h[0] * u + h[1] * v + h[2]) / w, 0, 1e-6);
  EXPECT_NEAR((h[3] * u + h[4] * v + h[5]) / w, 0, 1e-6);

  // truth/luminaire.json: the scene's emitters, read back from the dataset folder (--analytic).
  const Luminaire luminaire = LoadLuminaire(options.out_dir);
  ASSERT_EQ(luminaire.emitters.size(), scene.luminaire.emitters.size());
  for (size_t k = 0; k < luminaire.emitters.size(); ++k) {
    EXPECT_EQ(luminaire.emitters[k].position_mm, scene.luminaire.emitters[k].position_mm);
    EXPECT_EQ(luminaire.emitters[k].intensity_w_sr, scene.luminaire.emitters[k].intensity_w_sr);
    EXPECT_EQ(luminaire.emitters[k].lobe_exponent, scene.luminaire.emitters[k].lobe_exponent);
  }

  // A second run skips the complete dataset; --force redoes it.
  EXPECT_TRUE(RunSynth(scene, options).skipped);
  options.force = true;
  EXPECT_FALSE(RunSynth(scene, options).skipped);
  // A missing photo makes the dataset incomplete again.
  fs::remove(options.out_dir + "/photos/pos_1_1_p.exr");
  EXPECT_FALSE(DatasetComplete(options.out_dir));
}

// A live acquisition writes the same files, dataset.json and the calibration photo first.
TEST(Synth, IntervalModeWritesTheSamePhotos) {
  const std::string dir = FreshDir("interval");
  SynthScene scene = SmallScene();
  scene.grid.nu = 2;
  scene.grid.nv = 1;
  SynthOptions options;
  options.out_dir = dir + "/live";
  options.interval_s = 0.01;
  options.truth_resolution = 20;
  RunSynth(scene, options);
  options.out_dir = dir + "/batch";
  options.interval_s = -1;
  RunSynth(scene, options);
  for (const char* f : {"photos/pos_0_0_p.exr", "photos/pos_1_0_n.exr"}) {
    const ImageF a = ReadExr(dir + "/live/" + f, {"R", "G", "B"});
    const ImageF b = ReadExr(dir + "/batch/" + f, {"R", "G", "B"});
    EXPECT_EQ(a.data, b.data) << f;
  }
  EXPECT_LE(fs::last_write_time(dir + "/live/dataset.json"),
            fs::last_write_time(dir + "/live/photos/pos_0_0_p.exr"));
}

TEST(Synth, CameraThatSeesNoScreenIsBadInput) {
  SynthScene scene = SmallScene();
  scene.camera.look_at_mm = {0, 0, 5000};  // looking away from the screen
  try {
    ChooseRadiometricScale(scene, 1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("camera"), std::string::npos);
  }
}

// The printed slides: T+ - T- times the peak integrates to 1 (in units of h^2), 16-bit PNGs of
// the filter window at the requested DPI.
TEST(FilterPrint, SlidesIntegrateToTheDual) {
  const std::string dir = FreshDir("filter");
  FilterPrintOptions options;
  options.spacing_mm = 5;
  options.dpi = 600;
  options.out_dir = dir;
  const FilterPrintReport r = PrintFilter(options);
  EXPECT_NEAR(r.size_mm, 20, 1e-12);
  EXPECT_EQ(r.size_px, int(std::lround(20 / 25.4 * 600)));
  const cv::Mat p = cv::imread(r.plus_png, cv::IMREAD_UNCHANGED);
  const cv::Mat n = cv::imread(r.minus_png, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(p.type(), CV_16UC1);
  ASSERT_EQ(p.rows, r.size_px);
  double sum = 0;
  uint16_t max_p = 0;
  for (int y = 0; y < p.rows; ++y)
    for (int x = 0; x < p.cols; ++x) {
      sum += (double(p.at<uint16_t>(y, x)) - n.at<uint16_t>(y, x)) / 65535;
      max_p = std::max(max_p, p.at<uint16_t>(y, x));
      EXPECT_TRUE(p.at<uint16_t>(y, x) == 0 || n.at<uint16_t>(y, x) == 0);
    }
  const double pixel_h = (r.size_mm / r.size_px) / options.spacing_mm;  // pixel in units of h
  EXPECT_NEAR(sum * r.peak * pixel_h * pixel_h, 1.0, 2e-3);
  EXPECT_GE(max_p, 65000);  // the peak transmits fully
  const JsonDocument j = JsonDocument::Load(r.json);
  EXPECT_NEAR(j.root()["cross_talk"]["k1"].Number(), DualFilter::Truncated(1).CrossTalk(1), 1e-12);
  EXPECT_NEAR(j.root()["peak"].Number(), r.peak, 1e-12);
  options.dpi = 1;
  EXPECT_THROW(PrintFilter(options), Error);
}

}  // namespace
}  // namespace lumislab
