// The `lens` effect: the synthetic camera seen through OpenCV's Brown-Conrady distortion with a
// principal point off the image centre. Pixel -> screen and screen -> pixel agree with the model
// of core/camera_calibration.h, every photo the camera takes goes through it, truth/camera.json
// records it, and a lens of all zeros changes no photo by a bit.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "acquire/synth.h"
#include "acquire_test_util.h"
#include "core/exr_io.h"
#include "core/json.h"
#include "lib/synthetic/calibration_captures.h"
#include "lib/synthetic/render.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using acquire_test::ExpectEffectsRefused;
using acquire_test::FileBytes;
using acquire_test::FreshDir;
using acquire_test::SmallScene;
using acquire_test::SmallSynthOptions;

// A strong barrel lens (k1 = -0.25) that stays one to one over the 320 x 240 photo (f = 260 px).
const char* kLens =
    R"([{"type": "lens", "k1": -0.25, "k2": 0.08, "k3": -0.01, "p1": 0.001, "p2": -0.0015,
         "principal_offset_px": [6.5, -4]}])";

// Every file of `a` and `b` (recursively) the same to the byte; returns how many were compared.
int ExpectSameFiles(const std::string& a, const std::string& b) {
  int compared = 0;
  for (const auto& e : fs::recursive_directory_iterator(a)) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), a).string();
    if (rel == "truth/camera.json") continue;  // records the (zero) lens it was given
    EXPECT_EQ(FileBytes(e.path().string()), FileBytes(b + "/" + rel)) << rel;
    ++compared;
  }
  return compared;
}

TEST(LensEffect, PixelAndScreenMapsAreTheCameraModel) {
  const SynthScene scene = SmallScene(kLens);
  ASSERT_TRUE(scene.camera.lens.has_value());
  const PinholeCamera camera(scene.camera);
  const CameraModel& m = camera.model();
  EXPECT_DOUBLE_EQ(m.cx, 159.5 + 6.5);
  EXPECT_DOUBLE_EQ(m.cy, 119.5 - 4);
  EXPECT_DOUBLE_EQ(m.k1, -0.25);
  EXPECT_DOUBLE_EQ(m.p2, -0.0015);
  double largest_shift = 0;
  for (double y = 0; y <= 239; y += 17)
    for (double x = 0; x <= 319; x += 23) {
      Eigen::Vector2d lab;
      ASSERT_TRUE(camera.PlanePoint(x, y, scene.distance_mm, &lab));
      const Eigen::Vector3d point(lab.x(), lab.y(), scene.distance_mm);
      // Back through the lens to the same pixel, as CameraModel::Project maps the camera point.
      const Eigen::Vector2d px = camera.Project(point);
      EXPECT_NEAR(px.x(), x, 1e-8);
      EXPECT_NEAR(px.y(), y, 1e-8);
      const Eigen::Vector3d in_camera =
          camera.lab_from_camera().transpose() * (point - scene.camera.position_mm);
      EXPECT_NEAR((m.Project(in_camera) - Eigen::Vector2d(x, y)).norm(), 0, 1e-8);
      // The ideal pinhole pixel (truth's homography) is where the lens moved the point from.
      const Eigen::Vector3d h = camera.ImageFromScreen(scene.distance_mm) * lab.homogeneous();
      largest_shift = std::max(largest_shift, (h.hnormalized() - Eigen::Vector2d(x, y)).norm());
    }
  EXPECT_GT(largest_shift, 20);  // barrel distortion moves the corners by tens of pixels
}

// Listed with all parameters 0 the lens leaves every photo (slides, board, calibration frames)
// and the truth slab bit for bit as without it: the distortion path is exact at zero. Listed
// with distortion it changes them all, and truth/camera.json records it.
TEST(LensEffect, ZeroLensChangesNothingAndARealLensEverything) {
  const std::string captures = R"(, "calibration_captures": {"flat_frames": 1, "dark_frames": 1})";
  auto scene_with = [&](const std::string& effects) {
    std::string json = acquire_test::SmallSceneJson(effects);
    json.insert(json.rfind('}'), captures);
    return ParseScene(json, "small.json");
  };
  const std::string dir = FreshDir("lens");
  RunSynth(scene_with("[]"), SmallSynthOptions(dir + "/none"));
  RunSynth(scene_with(R"([{"type": "lens"}])"), SmallSynthOptions(dir + "/zero"));
  RunSynth(scene_with(kLens), SmallSynthOptions(dir + "/lens"));
  EXPECT_GT(ExpectSameFiles(dir + "/none", dir + "/zero"), 18 + 9 + 2);
  for (const char* file :
       {"photos/pos_1_1_p.exr", "photos/calib_0.png", "calibration/flat/flat_00.exr"})
    EXPECT_NE(FileBytes(dir + "/none/" + file), FileBytes(dir + "/lens/" + file)) << file;
  EXPECT_EQ(FileBytes(dir + "/none/truth/pos_1_1.exr"), FileBytes(dir + "/lens/truth/pos_1_1.exr"));

  const JsonDocument truth_doc = JsonDocument::Load(dir + "/lens/truth/camera.json");
  const JsonView truth = truth_doc.root();
  EXPECT_EQ(truth["distortion"]["model"].String(), "opencv5");
  EXPECT_DOUBLE_EQ(truth["distortion"]["k1"].Number(), -0.25);
  EXPECT_DOUBLE_EQ(truth["distortion"]["k2"].Number(), 0.08);
  EXPECT_DOUBLE_EQ(truth["distortion"]["k3"].Number(), -0.01);
  EXPECT_DOUBLE_EQ(truth["distortion"]["p1"].Number(), 0.001);
  EXPECT_DOUBLE_EQ(truth["distortion"]["p2"].Number(), -0.0015);
  EXPECT_DOUBLE_EQ(truth["principal_point_px"][0].Number(), 166);
  EXPECT_DOUBLE_EQ(truth["principal_point_px"][1].Number(), 115.5);
  const JsonDocument none_doc = JsonDocument::Load(dir + "/none/truth/camera.json");
  const JsonView none = none_doc.root();
  EXPECT_DOUBLE_EQ(none["distortion"]["k1"].Number(), 0);
  EXPECT_DOUBLE_EQ(none["principal_point_px"][0].Number(), 159.5);
}

// The flat frame sees the screen through the lens: its lit pixels are those whose undistorted
// ray meets the screen (ScreenView through the lens), and vignetting is centred on the moved
// principal point.
TEST(LensEffect, CalibrationFramesAndVignettingFollowTheLens) {
  const SynthScene scene = SmallScene(
      R"([{"type": "lens", "k1": -0.2, "k2": 0.05, "principal_offset_px": [10, 5]},
          {"type": "vignetting", "k1": -0.1}])");
  const ScreenView view = ScreenView::Of(scene);
  const PinholeCamera camera(scene.camera);
  for (size_t k = 0; k < view.pixels.size(); k += 501) {
    const int x = view.pixels[k] % view.width, y = view.pixels[k] / view.width;
    Eigen::Vector2d lab;
    ASSERT_TRUE(camera.PlanePoint(x, y, scene.distance_mm, &lab));
    EXPECT_EQ(lab, view.lab_mm[k]);
  }
  const auto& vignetting = dynamic_cast<const VignettingEffect&>(*scene.effects[1]);
  EXPECT_DOUBLE_EQ(vignetting.Factor(169.5, 124.5), 1.0);  // at the principal point
  EXPECT_LT(vignetting.Factor(159.5, 119.5), 1.0);
}

TEST(LensEffect, BadParametersNameTheField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      // Folds back inside the photo (r (1 - 0.25 r^2) peaks at r = 1.15, 0.77 is the corner).
      {R"([{"type": "lens", "k1": -0.25}])", "effects[0].k1"},
      {R"([{"type": "lens", "k1": 1.5}])", "effects[0].k1"},
      {R"([{"type": "lens", "p1": 0.2}])", "effects[0].p1"},
      {R"([{"type": "lens", "principal_offset_px": [100, 0]}])",
       "effects[0].principal_offset_px[0]"},
      {R"([{"type": "lens", "principal_offset_px": [1]}])", "effects[0].principal_offset_px"},
      {R"([{"type": "lens", "k4": 0.1}])", "effects[0].k4"},
      {R"([{"type": "lens"}, {"type": "ambient"}, {"type": "lens"}])", "effects[2].type"},
  };
  ExpectEffectsRefused(cases);
}

}  // namespace
}  // namespace lumislab
