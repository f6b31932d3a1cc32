#include "board_renderer.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <opencv2/core.hpp>

#include "lib/synthetic/board.h"
#include "lib/synthetic/camera.h"

namespace lumislab {
namespace testing {

ScreenCalibration TrueCalibration(int width, int height, double focal_px,
                                  const Eigen::Vector3d& position_mm,
                                  const Eigen::Vector3d& look_at_mm, double k1, double k2) {
  ScreenCalibration c;
  c.image_width = width;
  c.image_height = height;
  CameraSpec camera;
  camera.width = width;
  camera.height = height;
  camera.focal_px = focal_px;
  camera.position_mm = position_mm;
  camera.look_at_mm = look_at_mm;
  c.screen_from_image = PinholeCamera(camera).ScreenFromImage(0.0);
  c.k1 = k1;
  c.k2 = k2;
  c.centre_px = {0.5 * (width - 1), 0.5 * (height - 1)};
  c.scale_px = 0.5 * std::hypot(width, height);
  return c;
}

CalibrationTarget CentredTarget(int squares_x, int squares_y, double square_mm) {
  CalibrationTarget t;
  t.photo = "photos/calib_0.png";
  t.squares_x = squares_x;
  t.squares_y = squares_y;
  t.square_mm = square_mm;
  t.origin_mm = -0.5 * square_mm * Eigen::Vector2d(squares_x, squares_y);
  return t;
}

cv::Mat RenderBoard(const CalibrationTarget& target, const ScreenCalibration& truth,
                    double noise_sigma, bool dot) {
  BoardLook look;
  look.white = 0.9;
  look.black = 0.05;
  look.dot = dot;
  look.quiet_zone_squares = 1;
  look.surround = 0.5;
  const ImageF photo = RenderBoardPhoto(
      target, truth.image_width, truth.image_height,
      [&](const Eigen::Vector2d& pixel, Eigen::Vector2d* lab) {
        *lab = truth.ScreenFromImage(pixel);
        return true;
      },
      look, 2);
  cv::Mat image =
      cv::Mat(photo.height, photo.width, CV_32FC1, const_cast<float*>(photo.data.data())).clone();
  if (noise_sigma > 0) {
    cv::Mat noise(image.size(), CV_32FC1);
    cv::RNG rng(12345);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    image += noise;
  }
  return image;
}

double MaxBoardErrorMm(const ScreenCalibration& recovered, const ScreenCalibration& truth,
                       const CalibrationTarget& t) {
  const Eigen::Vector2d lo = t.origin_mm;
  const Eigen::Vector2d hi = lo + t.square_mm * Eigen::Vector2d(t.squares_x, t.squares_y);
  double worst = 0;
  for (int y = 0; y < truth.image_height; ++y)
    for (int x = 0; x < truth.image_width; ++x) {
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector2d s = truth.ScreenFromImage(p);
      if (s.x() < lo.x() || s.y() < lo.y() || s.x() > hi.x() || s.y() > hi.y()) continue;
      worst = std::max(worst, (recovered.ScreenFromImage(p) - s).norm());
    }
  return worst;
}

bool BoardInView(const CalibrationTarget& t, const ScreenCalibration& truth) {
  const Eigen::Matrix3d image_from_screen = truth.screen_from_image.inverse();
  for (int k = 0; k <= 40; ++k)
    for (int side = 0; side < 4; ++side) {
      const double u = -1 + (t.squares_x + 2) * (side == 0   ? k / 40.0
                                                 : side == 1 ? 1.0
                                                 : side == 2 ? 1 - k / 40.0
                                                             : 0.0);
      const double v = -1 + (t.squares_y + 2) * (side == 1   ? k / 40.0
                                                 : side == 2 ? 1.0
                                                 : side == 3 ? 1 - k / 40.0
                                                             : 0.0);
      const Eigen::Vector2d s = t.origin_mm + t.square_mm * Eigen::Vector2d(u, v);
      const Eigen::Vector3d q = image_from_screen * s.homogeneous();
      if (q.z() == 0) return false;
      const Eigen::Vector2d p = truth.Distort(q.hnormalized());
      if (p.x() < 0 || p.y() < 0 || p.x() > truth.image_width - 1 || p.y() > truth.image_height - 1)
        return false;
    }
  return true;
}

}  // namespace testing
}  // namespace lumislab
