#include "lib/synthetic/camera.h"

#include <Eigen/Geometry>
#include <cmath>

namespace lumislab {

PinholeCamera::PinholeCamera(const CameraSpec& spec) : spec_(spec) {
  const Eigen::Vector3d z = (spec.look_at_mm - spec.position_mm).normalized();
  Eigen::Vector3d up(0, 1, 0);
  if (std::abs(z.dot(up)) > 0.999) up = Eigen::Vector3d(0, 0, 1);
  const Eigen::Vector3d y = -(up - up.dot(z) * z).normalized();  // image y points down
  const Eigen::Vector3d x = y.cross(z);
  lab_from_camera_.col(0) = x;
  lab_from_camera_.col(1) = y;
  lab_from_camera_.col(2) = z;
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = spec_.focal_px;
  k(0, 2) = 0.5 * (spec_.width - 1);  // image centre, pixel centres at integers
  k(1, 2) = 0.5 * (spec_.height - 1);
  return k;
}

Eigen::Vector2d PinholeCamera::Project(const Eigen::Vector3d& lab_mm) const {
  const Eigen::Vector3d p = K() * lab_from_camera_.transpose() * (lab_mm - spec_.position_mm);
  return p.head<2>() / p.z();
}

Eigen::Matrix3d PinholeCamera::ImageFromScreen(double plane_z_mm) const {
  Eigen::Matrix3d m;
  m.col(0) = Eigen::Vector3d::UnitX();
  m.col(1) = Eigen::Vector3d::UnitY();
  m.col(2) = Eigen::Vector3d(0, 0, plane_z_mm) - spec_.position_mm;
  Eigen::Matrix3d h = K() * lab_from_camera_.transpose() * m;
  return h / h(2, 2);
}

Eigen::Matrix3d PinholeCamera::ScreenFromImage(double plane_z_mm) const {
  Eigen::Matrix3d h = ImageFromScreen(plane_z_mm).inverse();
  return h / h(2, 2);
}

bool PinholeCamera::PlanePoint(double px, double py, double plane_z_mm,
                               Eigen::Vector2d* xy_mm) const {
  const double f = spec_.focal_px;
  const Eigen::Vector3d ray_cam((px - 0.5 * (spec_.width - 1)) / f,
                                (py - 0.5 * (spec_.height - 1)) / f, 1.0);
  const Eigen::Vector3d ray = lab_from_camera_ * ray_cam;
  if (ray.z() == 0) return false;
  const double a = (plane_z_mm - spec_.position_mm.z()) / ray.z();
  if (!(a > 0)) return false;
  *xy_mm = (spec_.position_mm + a * ray).head<2>();
  return true;
}

}  // namespace lumislab
