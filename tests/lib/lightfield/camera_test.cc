// Camera and pose matrices, and the scene set-up that uses them.
#include "lib/lightfield/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "lib/lightfield/scene_setup.h"

namespace lumislab {
namespace {

Eigen::Vector3d Ndc(const Eigen::Matrix4f& m, const Eigen::Vector3d& p) {
  const Eigen::Vector4d clip = m.cast<double>() * p.homogeneous();
  return clip.head<3>() / clip.w();
}

SlabInfo TestInfo() {
  SlabInfo info;
  info.distance_mm = 750;
  info.grid = {9, 7, 5};
  info.layout = {1200, 1200, 300, 300};
  return info;
}

TEST(LightFieldCamera, PlaneViewMapsThePlaneCornersToClipCorners) {
  const double d = 1500, w = 3000;
  const Eigen::Matrix4f m = PlaneView(d, w);
  for (double sx : {-1.0, 1.0}) {
    for (double sy : {-1.0, 1.0}) {
      const Eigen::Vector3d ndc = Ndc(m, {0.5 * w * sx, 0.5 * w * sy, d});
      EXPECT_NEAR(ndc.x(), sx, 1e-6);  // column 0 at -x
      EXPECT_NEAR(ndc.y(), sy, 1e-6);  // top row at +y
      EXPECT_NEAR(ndc.z(), 0.0, 1e-6);
    }
  }
  // Anything between the luminaire and the plane is farther in depth: it never hides the plane.
  for (double z : {0.0, 0.5 * d, 0.99 * d}) EXPECT_GT(Ndc(m, {0, 0, z}).z(), 0.0) << z;
  EXPECT_LT(Ndc(m, {0, 0, 0}).z(), 1.0);  // and still inside the depth range
}

TEST(LightFieldCamera, PerspectiveAndLookAtFollowGlConventions) {
  const Eigen::Vector3d eye(100, 2000, 3000), target(0, 500, 0);
  const Eigen::Matrix4f view = LookAt(eye, target, {0, 1, 0});
  EXPECT_LE((view.cast<double>() * eye.homogeneous()).head<3>().norm(), 1e-3);
  const Eigen::Vector3d t = (view.cast<double>() * target.homogeneous()).head<3>();
  EXPECT_NEAR(t.x(), 0, 1e-3);
  EXPECT_NEAR(t.y(), 0, 1e-3);
  EXPECT_NEAR(t.z(), -(target - eye).norm(), 1e-2);  // looking down -z
  const Eigen::Matrix4f proj = Perspective(60, 2.0, 10, 1000);
  EXPECT_NEAR(Ndc(proj, {0, 0, -10}).z(), -1, 1e-6);
  EXPECT_NEAR(Ndc(proj, {0, 0, -1000}).z(), 1, 1e-5);
  // The top of the field of view at distance 100 is y = 100 tan(30 deg); x spans twice as far.
  EXPECT_NEAR(Ndc(proj, {0, 100 * std::tan(M_PI / 6), -100}).y(), 1, 1e-6);
  EXPECT_NEAR(Ndc(proj, {200 * std::tan(M_PI / 6), 0, -100}).x(), 1, 1e-6);
}

Eigen::Matrix3d Rx(double a) {
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return r;
}
Eigen::Matrix3d Ry(double a) {
  Eigen::Matrix3d r;
  r << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return r;
}
Eigen::Matrix3d Rz(double a) {
  Eigen::Matrix3d r;
  r << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return r;
}

TEST(LightFieldCamera, PoseFromValuesComposesRzRyRx) {
  const double k = M_PI / 180;
  const Eigen::Isometry3d pose = PoseFromValues({10, -20, 30, 25, -40, 70});
  const Eigen::Matrix3d expected = Rz(70 * k) * Ry(-40 * k) * Rx(25 * k);
  EXPECT_LE((pose.linear() - expected).norm(), 1e-12);
  EXPECT_LE((pose.translation() - Eigen::Vector3d(10, -20, 30)).norm(), 1e-12);
  // Not another order (each angle alone would not tell).
  EXPECT_GT((pose.linear() - Rx(25 * k) * Ry(-40 * k) * Rz(70 * k)).norm(), 0.1);
  // The preview's hanging luminaire (rx = 90): its +z (shining direction) is the scene's -y.
  const Eigen::Isometry3d hanging = PoseFromValues({250, 2300, -150, 90, 0, 0});
  EXPECT_LE((hanging.linear() * Eigen::Vector3d::UnitZ() + Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_THROW(PoseFromValues({1, 2, 3, 4, 5}), Error);
}

TEST(LightFieldSceneSetup, PlaneDefaultsFollowTheSlab) {
  const SlabInfo info = TestInfo();
  const SceneSetup at_d = MakeSceneSetup("plane", info);
  EXPECT_TRUE(at_d.plane);
  EXPECT_EQ(at_d.plane_z, 750);
  EXPECT_EQ(at_d.extent, 1200);
  EXPECT_TRUE(at_d.pose.isApprox(Eigen::Isometry3d::Identity()));
  ASSERT_EQ(at_d.mesh.triangles(), 2u);
  EXPECT_NEAR(at_d.mesh.normals[0].z(), -1, 1e-6);  // facing the luminaire
  SceneRequest far;
  far.name = "plane";
  far.receiver_plane_mm = 3000;  // the window's cone, 4x as wide
  EXPECT_EQ(MakeSceneSetup(far, info).extent, 4800);
  far.extent_mm = 2000;
  EXPECT_EQ(MakeSceneSetup(far, info).extent, 2000);
}

TEST(LightFieldSceneSetup, RoomsAimTheLuminaireAndTheCameraLooksAtTheTarget) {
  const SlabInfo info = TestInfo();
  for (const char* name : {"crypt", "cloister"}) {
    const SceneSetup s = MakeSceneSetup(name, info);
    EXPECT_TRUE(s.closed_room) << name;
    EXPECT_FALSE(s.plane);
    // Within 15 degrees of level (what it lights is checked in scenes_test.cc).
    EXPECT_LE(std::abs((s.pose.linear() * Eigen::Vector3d::UnitZ()).y()), std::sin(M_PI / 12))
        << name;
    const Eigen::Vector3d target_ndc = Ndc(OrbitCamera(s, 1.5), s.camera_target);
    EXPECT_NEAR(target_ndc.x(), 0, 1e-5) << name;
    EXPECT_NEAR(target_ndc.y(), 0, 1e-5) << name;
  }
  SceneRequest posed;
  posed.pose = {1, 2, 3, 0, 0, 0};
  const SceneSetup s = MakeSceneSetup(posed, info);
  EXPECT_TRUE(s.pose.isApprox(PoseFromValues({1, 2, 3, 0, 0, 0})));
}

// The window shows a pose as the six --luminaire-pose values; they must give the pose back.
TEST(LightFieldCamera, ValuesFromPoseInvertsPoseFromValues) {
  const std::vector<std::vector<double>> cases = {{10, -20, 30, 25, -40, 70},
                                                  {250, 2300, -150, 90, 0, 0},
                                                  {0, 0, 0, -170, 80, 179},
                                                  {1, 2, 3, 0, 90, 30},  // gimbal lock
                                                  {1, 2, 3, 0, -90, -30}};
  for (const auto& values : cases) {
    const std::vector<double> back = ValuesFromPose(PoseFromValues(values));
    ASSERT_EQ(back.size(), 6u);
    const Eigen::Isometry3d a = PoseFromValues(values), b = PoseFromValues(back);
    EXPECT_LT((a.matrix() - b.matrix()).norm(), 1e-9) << values[3] << " " << values[4];
    if (std::abs(values[4]) < 90) {
      for (int k = 0; k < 6; ++k) EXPECT_NEAR(back[k], values[k], 1e-9) << k;
    }
  }
}

}  // namespace
}  // namespace lumislab
