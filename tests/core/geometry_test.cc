#include "core/geometry.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/grid.h"

namespace lumislab {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(GridTest, CentresAreSymmetricAndSpaced) {
  const SamplingGrid g{9, 7, 5.0};
  EXPECT_EQ(g.count(), 63);
  EXPECT_DOUBLE_EQ(g.Centre(4, 3).x(), 0.0);
  EXPECT_DOUBLE_EQ(g.Centre(4, 3).y(), 0.0);
  EXPECT_DOUBLE_EQ(g.Centre(0, 0).x(), -20.0);
  EXPECT_DOUBLE_EQ(g.Centre(0, 0).y(), -15.0);
  EXPECT_DOUBLE_EQ(g.Centre(8, 6).x(), 20.0);
  const SamplingGrid even{2, 2, 7.5};
  EXPECT_DOUBLE_EQ(even.Centre(0, 0).x(), -3.75);
}

TEST(GridTest, TexelLayoutRowZeroOnTop) {
  const SlabLayout l{1200, 1200, 300, 300};
  EXPECT_DOUBLE_EQ(l.TexelW(), 4.0);
  EXPECT_DOUBLE_EQ(l.TexelCentre(0, 0).x(), -598.0);
  EXPECT_DOUBLE_EQ(l.TexelCentre(0, 0).y(), 598.0);
  EXPECT_DOUBLE_EQ(l.TexelCentre(299, 299).x(), 598.0);
  EXPECT_DOUBLE_EQ(l.TexelCentre(299, 299).y(), -598.0);
  const Eigen::Vector2d back = l.ToTexel(l.TexelCentre(17, 211).x(), l.TexelCentre(17, 211).y());
  EXPECT_NEAR(back.x(), 17, 1e-12);
  EXPECT_NEAR(back.y(), 211, 1e-12);
}

TEST(GeometryTest, GeometryTermIsCos2OverR2) {
  const double d = 750;
  EXPECT_DOUBLE_EQ(GeometryTerm(d, 0, 0, 0, 0), 1.0 / (d * d));
  // At 45 degrees: R = d sqrt 2, cos^2 = 1/2 -> g = 1 / (4 d^2).
  EXPECT_NEAR(GeometryTerm(d, 10, 0, 10 + d, 0), 1.0 / (4 * d * d), 1e-18);
  EXPECT_DOUBLE_EQ(ShiftInvariantGeometry(d, {5, -5}, 5, -5), 1.0 / (d * d));
}

TEST(GeometryTest, IntersectPlane) {
  const Eigen::Vector2d p = IntersectPlaneZ({1, -2, -20}, {39.5, 75, 750}, 0);
  // Parameter t = 20/770 along the line.
  EXPECT_NEAR(p.x(), 1 + 38.5 * 20 / 770, 1e-12);
  EXPECT_NEAR(p.y(), -2 + 77 * 20 / 770, 1e-12);
}

// Paper Fig. 3: maxima of 2.0 %, 8.0 %, 20 % at 45 degrees for relative widths 0.01, 0.04, 0.1.
TEST(ShiftInvariantErrorTest, ReproducesPaperFigure3) {
  const struct {
    double width, expected_max;
  } cases[] = {{0.01, 0.020}, {0.04, 0.080}, {0.1, 0.20}};
  for (const auto& c : cases) {
    double best = 0, best_theta = 0;
    for (double deg = 0; deg <= 85; deg += 0.05) {
      const double e = ShiftInvariantError(deg * kDeg, c.width);
      if (e > best) best = e, best_theta = deg;
    }
    EXPECT_NEAR(best, c.expected_max, 0.001 * (1 + 10 * c.width)) << c.width;
    EXPECT_NEAR(best_theta, 45.0, 1.0) << c.width;
    EXPECT_NEAR(ShiftInvariantError(45 * kDeg, c.width), c.expected_max, 0.0015) << c.width;
  }
  // On axis the error is second order only.
  EXPECT_LT(ShiftInvariantError(0, 0.04), 0.001);
  // Grazing angles stay finite.
  EXPECT_TRUE(std::isfinite(ShiftInvariantError(89.9 * kDeg, 0.04)));
}

// Rz Ry Rx: x about X first. Ry(90) Rx(90) takes Y to Z (Rx) and then Z to X (Ry), and X to -Z.
TEST(GeometryTest, RotationZyxDegreesAppliesXThenYThenZ) {
  const Eigen::Matrix3d r = RotationZyxDegrees(Eigen::Vector3d(90, 90, 0));
  EXPECT_TRUE(r.col(1).isApprox(Eigen::Vector3d(1, 0, 0), 1e-12)) << r;
  EXPECT_TRUE(r.col(0).isApprox(Eigen::Vector3d(0, 0, -1), 1e-12)) << r;
  const Eigen::Matrix3d z = RotationZyxDegrees(Eigen::Vector3d(0, 0, 30));
  const double c = std::cos(kPi / 6), s = std::sin(kPi / 6);
  EXPECT_TRUE(z.isApprox((Eigen::Matrix3d() << c, -s, 0, s, c, 0, 0, 0, 1).finished(), 1e-12)) << z;
}

// Type C in the luminaire frame (docs/formats.md §17, "Orientation"): gamma = 0 along +z, C = 0
// towards +x, C = 90 towards -y, so C turns counter-clockwise seen looking along +z (from +x
// through -y to -x and +y), as LM-63 counts it looking down along gamma = 0. Radiance's
// source.cal (since 2008: atan2(-Dy, -Dx), D the ray towards the source) with nadir -Z puts
// C = 90 along its +Y; turning its frame so that the nadir is our +z (x kept) takes its +Y to
// our -y.
TEST(GeometryTest, TypeCDirectionTurnsFromPlusXThroughMinusY) {
  EXPECT_TRUE(TypeCDirection(0, 0).isApprox(Eigen::Vector3d(0, 0, 1), 1e-12));
  EXPECT_TRUE(TypeCDirection(0, 90).isApprox(Eigen::Vector3d(1, 0, 0), 1e-12));
  EXPECT_TRUE(TypeCDirection(90, 90).isApprox(Eigen::Vector3d(0, -1, 0), 1e-12));
  EXPECT_TRUE(TypeCDirection(180, 90).isApprox(Eigen::Vector3d(-1, 0, 0), 1e-12));
  EXPECT_TRUE(TypeCDirection(270, 90).isApprox(Eigen::Vector3d(0, 1, 0), 1e-12));
  // A turn from a to b looks counter-clockwise to a viewer looking along v when its axis a x b
  // points back at the viewer, (a x b) . v < 0: here x x -y = -z, for v = +z.
  EXPECT_LT(TypeCDirection(0, 90).cross(TypeCDirection(90, 90)).dot(Eigen::Vector3d::UnitZ()), 0);
  // The inverse, over the sphere, with C in [0, 360) and the length of w ignored.
  for (double c = 0; c < 360; c += 30)
    for (double g = 10; g < 180; g += 40) {
      const Eigen::Vector2d back = TypeCAngles(2.5 * TypeCDirection(c, g));
      EXPECT_NEAR(back.x(), c, 1e-9) << c << " " << g;
      EXPECT_NEAR(back.y(), g, 1e-9) << c << " " << g;
    }
  // Radiance's reading of the same directions: its frame is ours turned 180 degrees about x (a
  // rotation, not a mirror: the nadir -Z is our +z, X is x), the ray D points back towards the
  // source, and source.cal 2.10 takes phi = Atan2(-Dy, -Dx), theta = Acos(Dz).
  const Eigen::Matrix3d radiance_from_luminaire = Eigen::Vector3d(1, -1, -1).asDiagonal();
  ASSERT_NEAR(radiance_from_luminaire.determinant(), 1, 1e-12);
  for (double c = 15; c < 360; c += 45) {
    const Eigen::Vector3d d = -(radiance_from_luminaire * TypeCDirection(c, 35));
    const double phi = std::atan2(-d.y(), -d.x()) * 180 / kPi, theta = std::acos(d.z()) * 180 / kPi;
    EXPECT_NEAR(phi < 0 ? phi + 360 : phi, c, 1e-9);
    EXPECT_NEAR(theta, 35, 1e-9);
  }
  EXPECT_EQ(TypeCAngles(Eigen::Vector3d(0, 0, 1)), Eigen::Vector2d(0, 0));
  EXPECT_NEAR(TypeCAngles(Eigen::Vector3d(-1, -0.0, 0)).x(), 180, 1e-12);
}

}  // namespace
}  // namespace lumislab
