// The synthetic pinhole camera (lab frame, mm). OpenCV conventions: pixel centres at integer
// coordinates, x right, y down; camera axes x right, y down, z forward.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/camera_calibration.h"

namespace lumislab {

// The `lens` effect (docs/formats.md §10): OpenCV's five-coefficient Brown-Conrady distortion
// (core/camera_calibration.h) and the principal point moved off the image centre.
struct LensSpec {
  double k1 = 0, k2 = 0, k3 = 0, p1 = 0, p2 = 0;
  Eigen::Vector2d principal_offset_px{0, 0};  // principal point - image centre, px
};

struct CameraSpec {
  int width = 0;  // px
  int height = 0;
  double focal_px = 0;
  Eigen::Vector3d position_mm{0, 0, 0};  // lab frame
  Eigen::Vector3d look_at_mm{0, 0, 0};
  double exposure = 1;                // multiplies the normalised value (may saturate on purpose)
  double radiometric_scale_w_m2 = 0;  // 0: chosen so the brightest pixel is ~0.85
  // A listed `lens` effect; none: an ideal pinhole with the principal point at the image centre.
  std::optional<LensSpec> lens;
};

// The synthetic camera: a pinhole, seen through the lens of spec.lens when there is one (pixel
// <-> ray through CameraModel, the model lumislab-calibrate camera fits).
class PinholeCamera {
 public:
  explicit PinholeCamera(const CameraSpec& spec);

  const CameraSpec& spec() const { return spec_; }
  Eigen::Matrix3d K() const;  // the principal point includes the lens's offset
  // The true intrinsics and distortion, as calib/camera.json would hold them.
  const CameraModel& model() const { return model_; }
  // Columns: the camera's x, y, z axes in the lab frame. "Up" (-y) is as close to lab +y as the
  // view allows (lab +z when looking along y), so the image is upright.
  const Eigen::Matrix3d& lab_from_camera() const { return lab_from_camera_; }
  Eigen::Vector2d Project(const Eigen::Vector3d& lab_mm) const;  // px, distorted by the lens
  // The ray (camera frame, z = 1) that pixel (px, py) sees: undistorted by the lens.
  Eigen::Vector3d RayOfPixel(double px, double py) const;
  // Homography of the plane z = plane_z_mm: lab (x, y, 1) -> pixel (homogeneous), and inverse.
  // With a lens these map the ideal pinhole pixels (K times the undistorted ray).
  Eigen::Matrix3d ImageFromScreen(double plane_z_mm) const;
  Eigen::Matrix3d ScreenFromImage(double plane_z_mm) const;
  // Lab (x, y) on the plane z = plane_z_mm seen at pixel (px, py); false when the plane is not in
  // front of the camera there.
  bool PlanePoint(double px, double py, double plane_z_mm, Eigen::Vector2d* xy_mm) const;
  // The same for a ray in the camera frame (RayOfPixel, PixelRays).
  bool PlanePointOfRay(const Eigen::Vector3d& ray_camera, double plane_z_mm,
                       Eigen::Vector2d* xy_mm) const;

 private:
  CameraSpec spec_;
  CameraModel model_;
  Eigen::Matrix3d lab_from_camera_;
};

// The rays of a camera's pixels for renders that sample every pixel many times (the board
// photos: 34 samples a pixel). With a lens, the rays of the pixel centres are undistorted once
// (exactly, CameraModel) and a sample between them interpolates the four nearest bilinearly: the
// lens is smooth on the scale of a pixel, so the sample is off by about f''/8 per pixel^2, below
// 0.001 px for the lenses the lens effect allows. Without distortion every ray is exact.
class PixelRays {
 public:
  PixelRays(const PinholeCamera& camera, int threads);
  Eigen::Vector3d operator()(double px, double py) const;  // camera frame, z = 1

 private:
  const PinholeCamera& camera_;
  bool table_ = false;
  int width_ = 0, height_ = 0;
  std::vector<Eigen::Vector2d> rays_;  // undistorted normalised (x, y) of each pixel centre
};

}  // namespace lumislab
