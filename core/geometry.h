// Geometry terms of docs/method.md §3. Lengths in mm; d is the S-M distance.
#pragma once

#include <Eigen/Core>

namespace lumislab {

inline constexpr double kPi = 3.14159265358979323846;

// g = cos^2(theta) / R^2 = d^2 / R^4 between (u,v) on S and (s,t) on M, in mm^-2.
double GeometryTerm(double d, double u, double v, double s, double t);
// Shift-invariant g_ij(s,t): the geometry term frozen at the filter centre c.
double ShiftInvariantGeometry(double d, const Eigen::Vector2d& c, double s, double t);
// E_r(theta0) = (max cos^4 - min cos^4) / cos^4(theta0) over one basis support of relative width
// w (support width / d) seen from M at angle theta0 (radians) — paper Fig. 3.
double ShiftInvariantError(double theta0, double relative_width);

// The rotation Rz(z) Ry(y) Rx(x) of angles in degrees (x about X first, then y about Y, z about
// Z, all about the fixed axes): how scene files, emitters and --luminaire-pose give orientations.
Eigen::Matrix3d RotationZyxDegrees(const Eigen::Vector3d& degrees);
// Its inverse: the angles (x, y, z) in degrees, y within [-90, 90], of a rotation matrix.
Eigen::Vector3d RotationZyxDegreesOf(const Eigen::Matrix3d& rotation);

// The rotation of a rotation vector (axis times angle in radians: OpenCV's rvec, what Rodrigues'
// formula takes; the calibrations' poses); the identity for the zero vector.
Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& r);

// Type C photometry in the luminaire frame (docs/formats.md §17, "Orientation"): gamma = 0 along
// +z (towards the screen), C = 0 towards +x, C = 90 towards -y, so that C counts
// counter-clockwise seen looking along gamma = 0, as IES LM-63 and Radiance's ies2rad count it
// "viewed from above" with gamma = 0 pointing down. The unit direction of (C, gamma), degrees:
// (sin gamma cos C, -sin gamma sin C, cos gamma).
Eigen::Vector3d TypeCDirection(double c_deg, double gamma_deg);
// Its inverse for any non-zero w: (C in [0, 360), gamma in [0, 180]) in degrees; C = 0 on the
// gamma = 0 and 180 axis.
Eigen::Vector2d TypeCAngles(const Eigen::Vector3d& w);

// Where the line from point p (luminaire frame, mm) through q crosses the plane z = z_plane.
Eigen::Vector2d IntersectPlaneZ(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double z_plane);

}  // namespace lumislab
