#include "lib/synthetic/camera.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/parallel.h"

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
  model_.image_width = spec.width;
  model_.image_height = spec.height;
  model_.fx = model_.fy = spec.focal_px;
  model_.cx = 0.5 * (spec.width - 1);  // image centre, pixel centres at integers
  model_.cy = 0.5 * (spec.height - 1);
  if (spec.lens) {
    const LensSpec& lens = *spec.lens;
    model_.cx += lens.principal_offset_px.x();
    model_.cy += lens.principal_offset_px.y();
    model_.k1 = lens.k1;
    model_.k2 = lens.k2;
    model_.k3 = lens.k3;
    model_.p1 = lens.p1;
    model_.p2 = lens.p2;
  }
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = model_.fx;
  k(1, 1) = model_.fy;
  k(0, 2) = model_.cx;
  k(1, 2) = model_.cy;
  return k;
}

Eigen::Vector2d PinholeCamera::Project(const Eigen::Vector3d& lab_mm) const {
  if (spec_.lens)
    return model_.Project(lab_from_camera_.transpose() * (lab_mm - spec_.position_mm));
  const Eigen::Vector3d p = K() * lab_from_camera_.transpose() * (lab_mm - spec_.position_mm);
  return p.head<2>() / p.z();
}

Eigen::Vector3d PinholeCamera::RayOfPixel(double px, double py) const {
  // Without a lens this is the ideal pinhole's ray, computed as it always was (the photos of a
  // scene without `lens` stay the same to the bit); with one, the lens is undistorted (exactly
  // the same ray when all its coefficients are 0).
  if (!spec_.lens) return {(px - model_.cx) / model_.fx, (py - model_.cy) / model_.fy, 1.0};
  const Eigen::Vector2d n = model_.UndistortToNormalised({px, py});
  return {n.x(), n.y(), 1.0};
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
  return PlanePointOfRay(RayOfPixel(px, py), plane_z_mm, xy_mm);
}

bool PinholeCamera::PlanePointOfRay(const Eigen::Vector3d& ray_camera, double plane_z_mm,
                                    Eigen::Vector2d* xy_mm) const {
  const Eigen::Vector3d ray = lab_from_camera_ * ray_camera;
  if (ray.z() == 0) return false;
  const double a = (plane_z_mm - spec_.position_mm.z()) / ray.z();
  if (!(a > 0)) return false;
  *xy_mm = (spec_.position_mm + a * ray).head<2>();
  return true;
}

PixelRays::PixelRays(const PinholeCamera& camera, int threads) : camera_(camera) {
  const CameraModel& m = camera.model();
  table_ = camera.spec().lens && m.HasDistortion() && m.image_width >= 2 && m.image_height >= 2;
  if (!table_) return;
  width_ = m.image_width;
  height_ = m.image_height;
  rays_.resize(size_t(width_) * height_);
  ParallelFor(height_, threads, [&](int y) {
    for (int x = 0; x < width_; ++x)
      rays_[size_t(y) * width_ + x] = m.UndistortToNormalised({double(x), double(y)});
  });
}

Eigen::Vector3d PixelRays::operator()(double px, double py) const {
  if (!table_) return camera_.RayOfPixel(px, py);
  // The cell of pixel centres around (px, py); outside the outer centres (up to half a pixel)
  // the border cell extrapolates linearly.
  const int x0 = std::clamp(int(std::floor(px)), 0, width_ - 2);
  const int y0 = std::clamp(int(std::floor(py)), 0, height_ - 2);
  const double a = px - x0, b = py - y0;
  const Eigen::Vector2d* row0 = &rays_[size_t(y0) * width_ + x0];
  const Eigen::Vector2d* row1 = row0 + width_;
  const Eigen::Vector2d n =
      (1 - b) * ((1 - a) * row0[0] + a * row0[1]) + b * ((1 - a) * row1[0] + a * row1[1]);
  return {n.x(), n.y(), 1.0};
}

}  // namespace lumislab
