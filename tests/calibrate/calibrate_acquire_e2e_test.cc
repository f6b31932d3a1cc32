// lumislab-acquire synth -> lumislab-calibrate screen, against the true camera the synthetic
// acquisition writes (truth/camera.json, screen_from_image row-major, lab mm on the screen).
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/dataset.h"
#include "core/json.h"
#include "core/screen_calibration.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

int Run(const std::string& command_line) {
  const int status = std::system((command_line + " > /dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Scene(const std::string& camera_json) {
  return R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 1, "nv": 1, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8} ] },
  "camera": )" +
         camera_json +
         R"(,
  "effects": [{"type": "quantization", "bit_depth": 16}] })";
}

struct Errors {
  double board_max = 0, board_rms = 0, screen_max = 0;
};

// acquire + calibrate; max / RMS mapping error over the pixels that see the board, and max over
// the pixels that see the screen window (where distortion is extrapolated beyond the board).
Errors AcquireAndCalibrate(const std::string& name, const std::string& camera_json) {
  const std::string dir = fs::path(::testing::TempDir()) /
                          ("lumislab_calibrate_e2e_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/scene.json") << Scene(camera_json);
  const std::string bin = LUMISLAB_BIN_DIR;
  const std::string ds = dir + "/ds";
  EXPECT_EQ(Run(bin + "/lumislab-acquire synth --scene " + dir + "/scene.json --out " + ds), 0);
  EXPECT_EQ(Run(bin + "/lumislab-calibrate screen --threads 2 --dataset " + ds), 0);
  const Dataset dataset = Dataset::Load(ds);
  const ScreenCalibration c = ScreenCalibration::Load(ds + "/calib/screen.json");
  const JsonDocument truth = JsonDocument::Load(ds + "/truth/camera.json");
  const std::vector<double> h = truth.root()["screen_from_image"].Numbers(9);
  const Eigen::Matrix3d screen_from_image =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(h.data());
  EXPECT_EQ(c.image_width, truth.root()["size_px"][0].Int());

  const CalibrationTarget& t = dataset.calibration;
  const Eigen::Vector2d lo = t.origin_mm;
  const Eigen::Vector2d hi = lo + t.square_mm * Eigen::Vector2d(t.squares_x, t.squares_y);
  Errors e;
  int n = 0;
  for (int y = 0; y < c.image_height; y += 2)
    for (int x = 0; x < c.image_width; x += 2) {
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector2d s = (screen_from_image * p.homogeneous()).hnormalized();
      const double err = (c.ScreenFromImage(p) - s).norm();
      if (std::abs(s.x()) <= 0.5 * dataset.screen_w_mm &&
          std::abs(s.y()) <= 0.5 * dataset.screen_h_mm)
        e.screen_max = std::max(e.screen_max, err);
      if (s.x() < lo.x() || s.y() < lo.y() || s.x() > hi.x() || s.y() > hi.y()) continue;
      e.board_max = std::max(e.board_max, err);
      e.board_rms += err * err;
      ++n;
    }
  e.board_rms = std::sqrt(e.board_rms / std::max(n, 1));
  std::printf(
      "%s: rms %.4f px, k1 %.5f, k2 %.5f; board: max %.4f mm, rms %.4f mm (%d px); screen "
      "window: max %.4f mm\n",
      name.c_str(), c.rms_px, c.k1, c.k2, e.board_max, e.board_rms, n, e.screen_max);
  return e;
}

TEST(CalibrateAcquireEndToEnd, DefaultCamera) {
  const Errors e = AcquireAndCalibrate(
      "default", R"({"size_px": [1600, 1200], "focal_px": 1300, "position_mm": [0, -400, 2400],
                     "look_at_mm": [0, 0, 750]})");
  EXPECT_LT(e.board_max, 0.2);
  EXPECT_LT(e.screen_max, 0.2);
}

// About 50 degrees off the screen normal, from the side and below.
TEST(CalibrateAcquireEndToEnd, ObliqueCamera) {
  const Errors e = AcquireAndCalibrate(
      "oblique", R"({"size_px": [1600, 1200], "focal_px": 1100, "position_mm": [1400, -300, 1900],
                     "look_at_mm": [0, 0, 750]})");
  EXPECT_LT(e.board_max, 0.2);
  EXPECT_LT(e.screen_max, 0.2);
}

}  // namespace
}  // namespace lumislab
