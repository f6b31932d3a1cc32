#include "lib/lightfield/camera.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/geometry.h"

namespace lumislab {

Eigen::Matrix4f Perspective(double fov_y_deg, double aspect, double near_mm, double far_mm) {
  const double f = 1.0 / std::tan(0.5 * fov_y_deg * M_PI / 180.0);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = float(f / aspect);
  m(1, 1) = float(f);
  m(2, 2) = float((far_mm + near_mm) / (near_mm - far_mm));
  m(2, 3) = float(2 * far_mm * near_mm / (near_mm - far_mm));
  m(3, 2) = -1;
  return m;
}

Eigen::Matrix4f LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                       const Eigen::Vector3d& up) {
  const Eigen::Vector3d f = (target - eye).normalized();
  const Eigen::Vector3d s = f.cross(up).normalized();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m.cast<float>();
}

Eigen::Matrix4f PlaneView(double plane_z_mm, double extent_mm) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = float(2.0 / extent_mm);
  m(1, 1) = float(2.0 / extent_mm);
  // depth = (D - z) / 4D: the plane (z = D) is nearest, anything in front of it is behind it.
  m(2, 2) = float(-1.0 / (4.0 * plane_z_mm));
  m(2, 3) = 0.25f;
  m(3, 3) = 1;
  return m;
}

Eigen::Isometry3d PoseFromValues(const std::vector<double>& v) {
  if (v.size() != 6) throw BadInput("--luminaire-pose needs x,y,z,rx,ry,rz (mm, degrees)");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = RotationZyxDegrees(Eigen::Vector3d(v[3], v[4], v[5]));
  pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return pose;
}

std::vector<double> ValuesFromPose(const Eigen::Isometry3d& pose) {
  // R = Rz(c) Ry(b) Rx(a): R20 = -sin b, R21 = cos b sin a, R22 = cos b cos a,
  // R10 = sin c cos b, R00 = cos c cos b.
  const Eigen::Matrix3d r = pose.linear();
  const double b = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  double a = 0, c = 0;
  if (std::abs(r(2, 0)) < 1 - 1e-12) {
    a = std::atan2(r(2, 1), r(2, 2));
    c = std::atan2(r(1, 0), r(0, 0));
  } else {  // gimbal lock: a = 0, R01 = -sin c, R11 = cos c
    c = std::atan2(-r(0, 1), r(1, 1));
  }
  const double k = 180.0 / M_PI;
  const Eigen::Vector3d t = pose.translation();
  std::vector<double> values = {t.x(), t.y(), t.z(), a * k, b * k, c * k};
  for (double& v : values) v = std::abs(v) < 1e-9 ? 0.0 : v;  // fields and command lines show 0
  return values;
}

}  // namespace lumislab
