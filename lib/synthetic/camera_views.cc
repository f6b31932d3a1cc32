#include "lib/synthetic/camera_views.h"

#include <Eigen/Geometry>
#include <cmath>

#include "core/error.h"
#include "core/geometry.h"
#include "lib/synthetic/board.h"
#include "lib/synthetic/camera.h"
#include "lib/synthetic/scene.h"

namespace lumislab {
namespace {

BoardLook ViewBoardLook() {
  BoardLook look;
  look.dot = false;  // OpenCV's chessboard has none
  look.quiet_zone_squares = 1;
  look.surround = 0.25;
  return look;
}

double Fraction(double x) { return x - std::floor(x); }

// True when the board and its margin are wholly in the photo (2 px inside), in front of the
// camera, seen through the lens.
bool InView(const PinholeCamera& camera, const BoardPose& pose) {
  const CalibrationTarget t = ViewBoardTarget();
  const double w = camera.spec().width, h = camera.spec().height;
  // The margin's outline, sampled along its edges (the lens bends straight edges).
  const Eigen::Vector2d lo = t.origin_mm - Eigen::Vector2d::Constant(t.square_mm);
  const Eigen::Vector2d size(t.squares_x * t.square_mm + 2 * t.square_mm,
                             t.squares_y * t.square_mm + 2 * t.square_mm);
  for (int k = 0; k <= 40; ++k) {
    const double s = k / 40.0;
    for (const Eigen::Vector2d& b : {Eigen::Vector2d(s, 0), Eigen::Vector2d(s, 1),
                                     Eigen::Vector2d(0, s), Eigen::Vector2d(1, s)}) {
      const Eigen::Vector2d xy = lo + b.cwiseProduct(size);
      const Eigen::Vector3d p =
          pose.rotation * Eigen::Vector3d(xy.x(), xy.y(), 0) + pose.translation_mm;
      if (!(p.z() > 0)) return false;
      const Eigen::Vector2d px = camera.model().Project(p);
      if (!(px.x() >= 2 && px.y() >= 2 && px.x() <= w - 3 && px.y() <= h - 3)) return false;
    }
  }
  return true;
}

}  // namespace

CalibrationTarget ViewBoardTarget() {
  CalibrationTarget t;
  t.squares_x = kViewBoardInnerCols + 1;
  t.squares_y = kViewBoardInnerRows + 1;
  t.square_mm = kViewBoardSquareMm;
  t.origin_mm = -0.5 * t.square_mm * Eigen::Vector2d(t.squares_x, t.squares_y);
  return t;
}

double BoardPose::TiltDeg() const {
  return std::acos(std::min(1.0, std::abs(rotation(2, 2)))) * 180 / kPi;
}

std::vector<BoardPose> CameraViewPoses(const SynthScene& scene, int count) {
  const PinholeCamera camera(scene.camera);
  const CameraModel& m = camera.model();
  const CalibrationTarget t = ViewBoardTarget();
  // Distance at which the board, facing the camera, spans half the photo's width.
  const double z0 = t.squares_x * t.square_mm * m.fx / (0.6 * scene.camera.width);
  std::vector<BoardPose> poses;
  for (int k = 0; k < count; ++k) {
    // Golden-ratio sequences: every parameter spread evenly, no two views alike.
    const double tilt = (12 + 23 * Fraction(0.38197 * k + 0.1)) * kPi / 180;
    const double axis = 2.39996 * k;  // golden angle: tilt axes in every direction
    const double spin = (Fraction(0.7549 * k + 0.3) - 0.5) * 30 * kPi / 180;
    double z = z0 * (0.8 + 0.5 * Fraction(0.61803 * k + 0.5));
    const double place = 2.39996 * k + 1.0;
    Eigen::Vector2d offset(0.28 * scene.camera.width * std::cos(place),
                           0.28 * scene.camera.height * std::sin(place));
    BoardPose pose;
    pose.rotation = (Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(axis), std::sin(axis), 0)) *
                     Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()))
                        .matrix();
    bool fits = false;
    for (int attempt = 0; attempt < 60 && !fits; ++attempt) {
      // The board centre on the ray of the ideal pinhole pixel centre + offset.
      const Eigen::Vector2d n = m.Normalised(Eigen::Vector2d(m.cx, m.cy) + offset);
      pose.translation_mm = z * Eigen::Vector3d(n.x(), n.y(), 1);
      fits = InView(camera, pose);
      offset *= 0.85;
      z *= 1.03;
    }
    if (!fits)
      throw BadInput(scene.source + ": camera: expected a view that holds a " +
                     std::to_string(kViewBoardInnerCols) + "x" +
                     std::to_string(kViewBoardInnerRows) +
                     " board for --calibration-views, got a lens that folds or a photo too small");
    poses.push_back(pose);
  }
  return poses;
}

ImageF RenderCameraView(const SynthScene& scene, const BoardPose& pose, int threads) {
  const PinholeCamera camera(scene.camera);
  const PixelRays rays(camera, threads);
  const Eigen::Vector3d normal = pose.rotation.col(2);  // board normal, camera frame
  const double plane = normal.dot(pose.translation_mm);
  const Eigen::Matrix3d board_from_camera = pose.rotation.transpose();
  return RenderBoardPhoto(
      ViewBoardTarget(), scene.camera.width, scene.camera.height,
      [&](const Eigen::Vector2d& px, Eigen::Vector2d* board_mm) {
        const Eigen::Vector3d ray = rays(px.x(), px.y());
        const double denominator = normal.dot(ray);
        if (denominator == 0) return false;
        const double s = plane / denominator;
        if (!(s > 0)) return false;
        *board_mm = (board_from_camera * (s * ray - pose.translation_mm)).head<2>();
        return true;
      },
      ViewBoardLook(), threads);
}

}  // namespace lumislab
