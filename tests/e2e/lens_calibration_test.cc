// Issue 9's synthetic evidence: a strong barrel lens (k1 = -0.25, small k2, p1, p2, principal
// point off centre), the camera calibrated from 15 board views (`acquire synth
// --calibration-views`, `calibrate camera`), then the screen from a board covering only a third
// of it (`calibrate screen` with calib/camera.json: the screen's pose alone). Against truth/: the
// intrinsics, the screen -> pixel mapping over the whole screen and the slab. The same capture
// calibrated from the single board photo (no camera.json) is measured and printed beside it.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/camera_calibration.h"
#include "core/json.h"
#include "core/screen_calibration.h"
#include "core/slab_compare.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::SceneJson;
using testing::WriteFile;

const char* kCamera =
    R"({"size_px": [800, 600], "focal_px": 650, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";
const char* kLens =
    R"([{"type": "lens", "k1": -0.25, "k2": 0.05, "p1": 0.001, "p2": -0.0008,
         "principal_offset_px": [9, -6]}])";
// 10 x 9 squares of 70 mm: 700 x 630 mm, 31 % of the 1200 x 1200 mm screen.
const char* kBoard = R"(, "calibration": {"squares": [10, 9], "square_mm": 70})";
constexpr int kResolution = 100;

// The true camera of truth/camera.json: lab point -> photo pixel, through the lens.
struct TrueCamera {
  CameraModel model;
  Eigen::Matrix3d lab_from_camera;
  Eigen::Vector3d position_mm;
  double plane_z_mm = 0;

  explicit TrueCamera(const std::string& path) {
    const JsonDocument doc = JsonDocument::Load(path);
    const JsonView root = doc.root();
    const std::vector<double> k = root["K"].Numbers(9), r = root["lab_from_camera"].Numbers(9);
    const std::vector<double> p = root["position_mm"].Numbers(3);
    model.image_width = root["size_px"][0].Int();
    model.image_height = root["size_px"][1].Int();
    model.fx = k[0];
    model.fy = k[4];
    model.cx = k[2];
    model.cy = k[5];
    const JsonView d = root["distortion"];
    model.k1 = d["k1"].Number();
    model.k2 = d["k2"].Number();
    model.p1 = d["p1"].Number();
    model.p2 = d["p2"].Number();
    model.k3 = d["k3"].Number();
    for (int i = 0; i < 9; ++i) lab_from_camera(i / 3, i % 3) = r[i];
    position_mm = {p[0], p[1], p[2]};
    plane_z_mm = root["screen_plane_z_mm"].Number();
  }
  Eigen::Vector2d Pixel(const Eigen::Vector2d& screen_mm) const {
    const Eigen::Vector3d lab(screen_mm.x(), screen_mm.y(), plane_z_mm);
    return model.Project(lab_from_camera.transpose() * (lab - position_mm));
  }
};

// Largest |calibrated screen point - true screen point| (mm) over a 10 mm grid of the whole
// screen, at the true pixel of each point (points whose pixel is in the photo).
double ScreenMappingMaxErrorMm(const ScreenCalibration& c, const TrueCamera& truth) {
  double worst = 0;
  for (double y = -600; y <= 600; y += 10)
    for (double x = -600; x <= 600; x += 10) {
      const Eigen::Vector2d px = truth.Pixel({x, y});
      if (px.x() < 0 || px.y() < 0 || px.x() > c.image_width - 1 || px.y() > c.image_height - 1)
        continue;
      worst = std::max(worst, (c.ScreenFromImage(px) - Eigen::Vector2d(x, y)).norm());
    }
  return worst;
}

struct SlabError {
  double mean = 0, max = 0;
};
SlabError Errors(const SlabComparison& c) {
  SlabError e;
  for (const auto& p : c.positions) {
    e.mean += p.relative_l2 / double(c.positions.size());
    e.max = std::max(e.max, p.relative_l2);
  }
  return e;
}

TEST(LensCalibration, CameraFromViewsThenScreenPoseMatchesTruth) {
  if (testing::kSanitized)
    GTEST_SKIP()
        << "accuracy run: the Release build's (the lens, the views and the pose solve "
           "run under the sanitizers in synthetic_lens_effect_test and calibrate_cli_test)";
  const std::string dir = FreshDir("lens_calibration");
  std::string scene = SceneJson(2, 2, kCamera, kLens);
  scene.insert(scene.rfind('}'), kBoard);
  WriteFile(dir + "/scene.json", scene);
  const std::string ds = dir + "/ds", res = std::to_string(kResolution);
  auto r = RunTool("lumislab-acquire", "synth --scene " + dir + "/scene.json --out " + ds +
                                           " --calibration-views 15 --truth-resolution " + res);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  // The single board photo alone (today's calibration): the lens fitted from one view.
  r = RunTool("lumislab-calibrate", "screen --dataset " + ds + " --max-rms-px 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("model: homography+radial2"), std::string::npos) << r.output;
  r = RunTool("lumislab-reconstruct", "--dataset " + ds + " --resolution " + res);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  fs::rename(ds + "/slab", ds + "/slab_single_view");
  fs::rename(ds + "/calib/screen.json", dir + "/screen_single_view.json");

  // The camera from the views, then the screen's pose with the lens known.
  r = RunTool("lumislab-calibrate", "camera --photos " + ds +
                                        "/calibration/camera --board 12x9 --square-mm 25 "
                                        "--dataset " +
                                        ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-calibrate", "screen --dataset " + ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("model: camera+pose"), std::string::npos) << r.output;
  r = RunTool("lumislab-reconstruct", "--dataset " + ds + " --resolution " + res);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const TrueCamera truth(ds + "/truth/camera.json");
  const CameraCalibration camera = CameraCalibration::Load(ds + "/calib/camera.json");
  EXPECT_EQ(camera.ViewsUsed(), 15);
  const double fx_error = camera.fx / truth.model.fx - 1, fy_error = camera.fy / truth.model.fy - 1;
  const double cx_error = camera.cx - truth.model.cx, cy_error = camera.cy - truth.model.cy;
  EXPECT_LE(std::abs(fx_error), 0.003);
  EXPECT_LE(std::abs(fy_error), 0.003);
  EXPECT_LE(std::abs(cx_error), 1.0);
  EXPECT_LE(std::abs(cy_error), 1.0);

  const ScreenCalibration posed = ScreenCalibration::Load(ds + "/calib/screen.json");
  const ScreenCalibration single = ScreenCalibration::Load(dir + "/screen_single_view.json");
  ASSERT_TRUE(posed.camera.has_value());
  EXPECT_EQ(posed.method, "camera+pose");
  EXPECT_FALSE(single.camera.has_value());
  const double posed_mm = ScreenMappingMaxErrorMm(posed, truth);
  const double single_mm = ScreenMappingMaxErrorMm(single, truth);
  EXPECT_LE(posed_mm, 0.1);

  const SlabComparison posed_slab = CompareSlabs(ds + "/slab", ds + "/truth");
  const SlabComparison single_slab = CompareSlabs(ds + "/slab_single_view", ds + "/truth");
  ASSERT_EQ(posed_slab.positions.size(), 4u);
  for (const auto& p : posed_slab.positions)
    EXPECT_LE(p.relative_l2, 0.005) << "position " << p.i << "," << p.j;
  const SlabError pe = Errors(posed_slab), se = Errors(single_slab);
  // The single view cannot see the lens beyond its board: it must be measurably worse.
  EXPECT_GT(single_mm, 2 * posed_mm);

  std::printf(
      "lens k1 -0.25, 15 views, board on a third of the screen\n"
      "                      camera.json + pose   single view\n"
      "fx, fy error          %+.3f %%, %+.3f %%    (fitted as a homography)\n"
      "cx, cy error          %+.2f px, %+.2f px\n"
      "screen RMS            %.3f px, %.3f mm    %.3f px, %.3f mm\n"
      "screen map max error  %.3f mm             %.2f mm\n"
      "slab rel. L2 mean     %.3f %%              %.3f %%\n"
      "slab rel. L2 max      %.3f %%              %.3f %%\n",
      100 * fx_error, 100 * fy_error, cx_error, cy_error, posed.rms_px, posed.rms_mm, single.rms_px,
      single.rms_mm, posed_mm, single_mm, 100 * pe.mean, 100 * se.mean, 100 * pe.max, 100 * se.max);
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
