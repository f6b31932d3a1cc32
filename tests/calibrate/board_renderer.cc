#include "board_renderer.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <opencv2/core.hpp>

namespace lumislab {
namespace testing {

Eigen::Matrix3d CameraScreenFromImage(int width, int height, double focal_px,
                                      const Eigen::Vector3d& position_mm,
                                      const Eigen::Vector3d& look_at_mm) {
  const Eigen::Vector3d z = (look_at_mm - position_mm).normalized();
  Eigen::Vector3d up(0, 1, 0);
  if (std::abs(z.dot(up)) > 0.999) up = Eigen::Vector3d(0, 0, 1);
  const Eigen::Vector3d y = -(up - up.dot(z) * z).normalized();  // image y points down
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Matrix3d lab_from_camera;
  lab_from_camera << x, y, z;
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = focal_px;
  k(0, 2) = 0.5 * (width - 1);
  k(1, 2) = 0.5 * (height - 1);
  Eigen::Matrix3d plane;  // (x, y, 1) on z = 0 -> lab point minus camera position
  plane << Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), -position_mm;
  const Eigen::Matrix3d image_from_screen = k * lab_from_camera.transpose() * plane;
  Eigen::Matrix3d h = image_from_screen.inverse();
  return h / h(2, 2);
}

ScreenCalibration TrueCalibration(int width, int height, double focal_px,
                                  const Eigen::Vector3d& position_mm,
                                  const Eigen::Vector3d& look_at_mm, double k1, double k2) {
  ScreenCalibration c;
  c.image_width = width;
  c.image_height = height;
  c.screen_from_image = CameraScreenFromImage(width, height, focal_px, position_mm, look_at_mm);
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

namespace {

// Reflectance of the board scene at lab point (x, y) mm.
float BoardValue(const CalibrationTarget& t, const Eigen::Vector2d& p, bool dot) {
  const Eigen::Vector2d q = (p - t.origin_mm) / t.square_mm;  // in squares
  if (q.x() < -1 || q.y() < -1 || q.x() > t.squares_x + 1 || q.y() > t.squares_y + 1) return 0.5f;
  if (q.x() < 0 || q.y() < 0 || q.x() >= t.squares_x || q.y() >= t.squares_y) return 0.9f;
  if (dot && (q - Eigen::Vector2d(0.5, 0.5)).norm() < 0.2) return 0.9f;  // the orientation dot
  const int a = int(std::floor(q.x())), b = int(std::floor(q.y()));
  return (a + b) % 2 == 0 ? 0.05f : 0.9f;  // square (0, 0) is black
}

}  // namespace

cv::Mat RenderBoard(const CalibrationTarget& target, const ScreenCalibration& truth,
                    double noise_sigma, bool dot) {
  cv::Mat image(truth.image_height, truth.image_width, CV_32FC1);
  cv::parallel_for_(cv::Range(0, image.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      for (int x = 0; x < image.cols; ++x) {
        double sum = 0;
        for (int k = 0; k < kSamples; ++k) {
          const double u = (k + 0.5) / kSamples,
                       v = ((k * kSampleStride) % kSamples + 0.5) / kSamples;
          sum += BoardValue(target,
                            truth.ScreenFromImage(Eigen::Vector2d(x - 0.5 + u, y - 0.5 + v)), dot);
        }
        image.at<float>(y, x) = float(sum / kSamples);
      }
  });
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
