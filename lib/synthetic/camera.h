// The synthetic pinhole camera (lab frame, mm). OpenCV conventions: pixel centres at integer
// coordinates, x right, y down; camera axes x right, y down, z forward.
#pragma once

#include <Eigen/Core>

namespace lumislab {

struct CameraSpec {
  int width = 0;  // px
  int height = 0;
  double focal_px = 0;
  Eigen::Vector3d position_mm{0, 0, 0};  // lab frame
  Eigen::Vector3d look_at_mm{0, 0, 0};
  double exposure = 1;                // multiplies the normalised value (may saturate on purpose)
  double radiometric_scale_w_m2 = 0;  // 0: chosen so the brightest pixel is ~0.85
};

class PinholeCamera {
 public:
  explicit PinholeCamera(const CameraSpec& spec);

  const CameraSpec& spec() const { return spec_; }
  Eigen::Matrix3d K() const;
  // Columns: the camera's x, y, z axes in the lab frame. "Up" (-y) is as close to lab +y as the
  // view allows (lab +z when looking along y), so the image is upright.
  const Eigen::Matrix3d& lab_from_camera() const { return lab_from_camera_; }
  Eigen::Vector2d Project(const Eigen::Vector3d& lab_mm) const;  // px
  // Homography of the plane z = plane_z_mm: lab (x, y, 1) -> pixel (homogeneous), and inverse.
  Eigen::Matrix3d ImageFromScreen(double plane_z_mm) const;
  Eigen::Matrix3d ScreenFromImage(double plane_z_mm) const;
  // Lab (x, y) on the plane z = plane_z_mm seen at pixel (px, py); false when the plane is not in
  // front of the camera there.
  bool PlanePoint(double px, double py, double plane_z_mm, Eigen::Vector2d* xy_mm) const;

 private:
  CameraSpec spec_;
  Eigen::Matrix3d lab_from_camera_;
};

}  // namespace lumislab
