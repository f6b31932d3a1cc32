// What a scene name resolves to for the preview: the mesh, the luminaire's pose in the scene and
// an orbit camera (or, for the receiver plane, the plane and its extent).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/slab.h"
#include "lib/lightfield/scenes.h"

namespace lumislab {

// The scene as asked for on the command line.
struct SceneRequest {
  std::string name = "crypt";    // crypt | cloister | plane | <file> (Assimp)
  std::vector<double> pose;      // x,y,z,rx,ry,rz (mm, degrees); empty: the scene's default
  double receiver_plane_mm = 0;  // plane: D (0: the slab's d)
  double extent_mm = 0;          // plane: side W (0: window * D / d)
};

struct SceneSetup {
  Mesh mesh;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // luminaire frame -> scene frame
  Eigen::Vector3d camera_target{0, 0, 0};
  double camera_distance = 3000, camera_yaw_deg = 30, camera_pitch_deg = 20;
  bool plane = false;
  bool closed_room = false;  // built-in rooms: cull back faces so the camera sees in
  double plane_z = 0, extent = 0;
};

// The slab's d and window give the plane's defaults. BadInput for an unreadable scene file or a
// pose that is not 6 values.
SceneSetup MakeSceneSetup(const SceneRequest& request, const SlabInfo& info);
// Scene `name` with its default pose (and, for the plane, D = d and the window's extent).
SceneSetup MakeSceneSetup(const std::string& name, const SlabInfo& info);
// Orbit camera (70 degrees vertical field of view): clip-from-scene matrix.
Eigen::Matrix4f OrbitCamera(const SceneSetup& setup, double aspect);

}  // namespace lumislab
