#include "lib/lightfield/scene_setup.h"

#include <cmath>
#include <utility>

#include "lib/lightfield/camera.h"

namespace lumislab {
namespace {

SceneSetup PlaneSetup(const SceneRequest& request, const SlabInfo& info) {
  SceneSetup s;
  s.plane = true;
  s.plane_z = request.receiver_plane_mm > 0 ? request.receiver_plane_mm : info.distance_mm;
  s.extent = request.extent_mm > 0 ? request.extent_mm
                                   : info.layout.window_w_mm * s.plane_z / info.distance_mm;
  s.mesh = MakeReceiverPlane(s.plane_z, 1.2 * s.extent);
  return s;
}

// A built-in room: the luminaire hangs at `pose`, shining down; the camera looks in from above.
SceneSetup RoomSetup(Mesh mesh, const std::vector<double>& pose, double camera_distance) {
  SceneSetup s;
  s.mesh = std::move(mesh);
  s.pose = PoseFromValues(pose);
  s.camera_target = {0, 500, 0};
  s.camera_distance = camera_distance;
  s.camera_yaw_deg = 35;
  s.camera_pitch_deg = 38;
  s.closed_room = true;
  return s;
}

// A scene file: the camera frames its bounding box, the luminaire hangs near its top, centred.
SceneSetup FileSetup(const std::string& path) {
  SceneSetup s;
  s.mesh = LoadSceneFile(path);
  Eigen::Vector3f lo = s.mesh.positions[0], hi = lo;
  for (const auto& p : s.mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  s.camera_target = (0.5f * (lo + hi)).cast<double>();
  s.camera_distance = 1.5 * (hi - lo).norm();
  s.pose = PoseFromValues(
      {s.camera_target.x(), hi.y() - 0.05 * (hi.y() - lo.y()), s.camera_target.z(), 90, 0, 0});
  return s;
}

}  // namespace

SceneSetup MakeSceneSetup(const SceneRequest& request, const SlabInfo& info) {
  SceneSetup s;
  if (request.name == "plane") {
    s = PlaneSetup(request, info);
  } else if (request.name == "crypt") {
    s = RoomSetup(MakeCrypt(), {250, 2300, -150, 90, 0, 0}, 3900);
  } else if (request.name == "cloister") {
    s = RoomSetup(MakeCloister(), {900, 3700, 900, 90, 0, 0}, 9000);
  } else {
    s = FileSetup(request.name);
  }
  if (!request.pose.empty()) s.pose = PoseFromValues(request.pose);
  return s;
}

SceneSetup MakeSceneSetup(const std::string& name, const SlabInfo& info) {
  SceneRequest request;
  request.name = name;
  return MakeSceneSetup(request, info);
}

Eigen::Matrix4f OrbitCamera(const SceneSetup& s, double aspect) {
  const double yaw = s.camera_yaw_deg * M_PI / 180, pitch = s.camera_pitch_deg * M_PI / 180;
  const Eigen::Vector3d eye =
      s.camera_target + s.camera_distance * Eigen::Vector3d(std::cos(pitch) * std::sin(yaw),
                                                            std::sin(pitch),
                                                            std::cos(pitch) * std::cos(yaw));
  return Perspective(70, aspect, 20, 100000) * LookAt(eye, s.camera_target, {0, 1, 0});
}

}  // namespace lumislab
