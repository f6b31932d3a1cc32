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

// A built-in room seen from inside: the luminaire at `pose` (x, y, z, rx, ry, rz: tilted down
// by rx, turned about the vertical by ry), the orbit camera around `target` from a point in the
// room.
SceneSetup RoomSetup(Mesh mesh, const std::vector<double>& pose, const Eigen::Vector3d& target,
                     double distance, double yaw_deg, double pitch_deg) {
  SceneSetup s;
  s.mesh = std::move(mesh);
  s.pose = PoseFromValues(pose);
  s.camera_target = target;
  s.camera_distance = distance;
  s.camera_yaw_deg = yaw_deg;
  s.camera_pitch_deg = pitch_deg;
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
    // 0.6 m from the west wall, 1.5 m high, aimed east and 6 degrees down along the crypt: the
    // first columns (1.6 m ahead) throw their shadows over floor, columns and east wall, the
    // window's cone reaches up into the vaults; the camera in the north-west corner, looking
    // over the light's shoulder.
    s = RoomSetup(MakeCrypt(), {-2700, 1500, 0, 6, 90, 0}, {0, 900, 0}, 4119, -49, 15.5);
  } else if (request.name == "cloister") {
    // In the garth 2.5 m before the north arcade, 1.2 m high, aimed at it and 10 degrees up: the
    // columns' shadows across the gallery's floor and outer wall, its vaults lit through the
    // arches; the camera further back in the garth.
    s = RoomSetup(MakeCloister(), {0, 1200, 2500, -10, 0, 0}, {200, 2000, 6000}, 6600, -160, -3);
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
