#include "core/geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace lumislab {

double GeometryTerm(double d, double u, double v, double s, double t) {
  const double r2 = d * d + (s - u) * (s - u) + (t - v) * (t - v);
  return d * d / (r2 * r2);
}

double ShiftInvariantGeometry(double d, const Eigen::Vector2d& c, double s, double t) {
  return GeometryTerm(d, c.x(), c.y(), s, t);
}

double ShiftInvariantError(double theta0, double relative_width) {
  // A point of M at angle theta0 from the filter centre, i.e. at s = d tan(theta0) (d = 1); the
  // basis support spans u in [-w/2, w/2] on S. cos^4 is monotonic in |s - u|, so its extremes
  // over the support are at the ends, or at |s - u| = 0 when the support straddles s.
  const double s = std::tan(theta0);
  const double half = 0.5 * relative_width;
  auto cos4 = [](double du) {
    const double c2 = 1.0 / (1.0 + du * du);
    return c2 * c2;
  };
  const double a = cos4(s - half), b = cos4(s + half);
  double hi = std::max(a, b), lo = std::min(a, b);
  if (std::abs(s) <= half) hi = 1.0;
  return (hi - lo) / cos4(s);
}

Eigen::Matrix3d RotationZyxDegrees(const Eigen::Vector3d& degrees) {
  const Eigen::Vector3d r = degrees * kPi / 180;
  return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d RotationZyxDegreesOf(const Eigen::Matrix3d& r) {
  // R = Rz Ry Rx: R(2,0) = -sin y, R(2,1) / R(2,2) = tan x, R(1,0) / R(0,0) = tan z.
  double x, y, z;
  if (std::abs(r(2, 0)) < 1 - 1e-12) {
    y = std::asin(-r(2, 0));
    x = std::atan2(r(2, 1), r(2, 2));
    z = std::atan2(r(1, 0), r(0, 0));
  } else {  // gimbal lock (y = +-90): only x -+ z is defined; take x = 0
    y = r(2, 0) < 0 ? kPi / 2 : -kPi / 2;
    x = 0;
    z = std::atan2(-r(0, 1), r(1, 1));
  }
  return Eigen::Vector3d(x, y, z) * 180 / kPi;
}

Eigen::Vector3d TypeCDirection(double c_deg, double gamma_deg) {
  const double c = c_deg * kPi / 180, g = gamma_deg * kPi / 180;
  return {std::sin(g) * std::cos(c), -std::sin(g) * std::sin(c), std::cos(g)};
}

Eigen::Vector2d TypeCAngles(const Eigen::Vector3d& w) {
  const double gamma = std::atan2(std::hypot(w.x(), w.y()), w.z()) * 180 / kPi;
  double c = std::atan2(-w.y(), w.x()) * 180 / kPi;
  if (c < 0) c += 360;
  if (c >= 360) c -= 360;
  return {c, gamma};
}

Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& r) {
  const double angle = r.norm();
  return angle > 0 ? Eigen::AngleAxisd(angle, r / angle).toRotationMatrix()
                   : Eigen::Matrix3d::Identity();
}

Eigen::Vector2d IntersectPlaneZ(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                double z_plane) {
  const double t = (z_plane - p.z()) / (q.z() - p.z());
  return (p + t * (q - p)).head<2>();
}

}  // namespace lumislab
