// Camera and pose math of the preview (column vectors, GL clip conventions, mm): the matrices the
// renderer is given, computed without GL.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace lumislab {

// Clip-from-eye perspective projection (gluPerspective).
Eigen::Matrix4f Perspective(double fov_y_deg, double aspect, double near_mm, double far_mm);
// Eye-from-world view matrix (gluLookAt).
Eigen::Matrix4f LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                       const Eigen::Vector3d& up);
// Orthographic view of the plane z = plane_z (luminaire frame = scene frame), square of side
// extent: column 0 at -x, row 0 (after Read) at +y, i.e. +x right and +y up, the plane seen from
// behind it looking along -z (docs/formats.md §17, "Orientation"); nearer-to-plane surfaces never
// hide it.
Eigen::Matrix4f PlaneView(double plane_z_mm, double extent_mm);
// Pose from "x,y,z,rx,ry,rz" (mm, degrees; R = Rz Ry Rx); BadInput unless 6 values.
Eigen::Isometry3d PoseFromValues(const std::vector<double>& values);
// The inverse: x,y,z,rx,ry,rz with ry in [-90, 90] and rx, rz in (-180, 180] (rx = 0 at
// ry = +-90, where only rz - rx or rz + rx is defined).
std::vector<double> ValuesFromPose(const Eigen::Isometry3d& pose);

}  // namespace lumislab
