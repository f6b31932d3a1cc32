// core/luminaire_set.h: the luminaire folder's files, the cone of one orientation, the blend
// taper and the coverage of a set of orientations (docs/formats.md §19).
#include "core/luminaire_set.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/geometry.h"

namespace lumislab {
namespace {

// A 2000 mm screen at 750 mm, positions within 15 mm: 52.6 degrees either side of the axis.
OrientationCone WideCone() { return {750, 1000 - 15, 1000 - 15}; }
// The default scene's 1200 mm screen: 38.1 degrees.
OrientationCone DefaultCone() { return {750, 600 - 25, 600 - 20}; }

std::vector<Eigen::Matrix3d> CubeFaces() {
  std::vector<Eigen::Matrix3d> poses;
  for (const Eigen::Vector3d& deg :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 90, 0), Eigen::Vector3d(0, 180, 0),
        Eigen::Vector3d(0, -90, 0), Eigen::Vector3d(90, 0, 0), Eigen::Vector3d(-90, 0, 0)})
    poses.push_back(RotationZyxDegrees(deg));
  return poses;
}

std::string TempFolder(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("lumislab_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

TEST(LuminaireSet, ConeMarginAndTaper) {
  const OrientationCone cone = WideCone();
  const double limit = std::atan2(985.0, 750.0) * 180 / kPi;
  EXPECT_NEAR(cone.MarginDeg({0, 0, 1}), limit, 1e-9);
  EXPECT_EQ(cone.MarginDeg({0, 0, -1}), -90);
  const Eigen::Vector3d edge(std::sin(limit * kPi / 180), 0, std::cos(limit * kPi / 180));
  EXPECT_NEAR(cone.MarginDeg(edge), 0, 1e-9);
  EXPECT_EQ(ConeTaper(cone, {0, 0, 1}), 1);
  EXPECT_EQ(ConeTaper(cone, {1, 0, 0.1}), 0);
  // Half-way into the taper: smoothstep(0.5) = 0.5.
  const double a = (limit - 0.5 * kDefaultTaperDeg) * kPi / 180;
  EXPECT_NEAR(ConeTaper(cone, {std::sin(a), 0, std::cos(a)}), 0.5, 1e-9);
}

TEST(LuminaireSet, CubeFacesCoverTheSphereOnlyWithAWideScreen) {
  std::vector<OrientationCone> wide(6, WideCone()), narrow(6, DefaultCone());
  const CoverageReport ok = AnalyseCoverage(CubeFaces(), wide, false);
  EXPECT_EQ(ok.covered_fraction, 1);
  EXPECT_TRUE(ok.overlap_problem.empty()) << ok.overlap_problem;
  // Each face overlaps its four neighbours, not its opposite: 12 pairs.
  EXPECT_EQ(ok.pairs.size(), 12u);
  for (const PairOverlap& p : ok.pairs) EXPECT_GT(p.overlap_sr, kMinOverlapSr);
  const CoverageReport gaps =
      AnalyseCoverage(CubeFaces(), narrow, false, 20000, {"o0", "o1", "o2", "o3", "o4", "o5"});
  EXPECT_LT(gaps.covered_fraction, 0.8);
  EXPECT_TRUE(gaps.pairs.empty());
  EXPECT_NE(gaps.overlap_problem.find("o1 does not connect to o0"), std::string::npos)
      << gaps.overlap_problem;
  // One orientation covers the hemisphere's cap only.
  const CoverageReport one = AnalyseCoverage({Eigen::Matrix3d::Identity()}, {WideCone()}, true);
  EXPECT_GT(one.covered_fraction, 0.4);
  EXPECT_LT(one.covered_fraction, 0.8);
  EXPECT_TRUE(one.overlap_problem.empty());
}

TEST(LuminaireSet, WritesReadsAndAppliesTheRegistration) {
  const std::string dir = TempFolder("luminaire_set");
  LuminaireSet set;
  set.folder = dir;
  set.coverage = "sphere";
  for (int k = 0; k < 2; ++k) {
    Orientation o;
    o.name = "o0" + std::to_string(k);
    o.dataset = o.name;
    o.rotation_deg = {0, 90.0 * k, 0};
    o.centre_mm = {0, 0, -40};
    if (k == 1) o.axis_deg = 90, o.mount = 0;
    set.orientations.push_back(o);
  }
  WriteLuminaireSet(set);
  ASSERT_TRUE(IsLuminaireFolder(dir));
  LuminaireSet read = LoadLuminaireSet(dir);
  ASSERT_EQ(read.orientations.size(), 2u);
  EXPECT_EQ(read.DatasetFolder(1), dir + "/o01");
  EXPECT_FALSE(read.orientations[1].registered);
  EXPECT_TRUE(read.orientations[1].rotation.isApprox(RotationZyxDegrees({0, 90, 0})));
  EXPECT_EQ(*read.orientations[1].axis_deg, 90);

  const Eigen::Matrix3d refined = RotationZyxDegrees({0.5, 91, 0});
  std::ofstream(dir + "/registration.json")
      << R"({"schema_version": 1, "orientations": [
    {"name": "o00", "rotation_matrix": [[1,0,0],[0,1,0],[0,0,1]], "sigma_deg": [0, 0, 0]},
    {"name": "o01", "rotation_matrix": [)"
      << "[" << refined(0, 0) << "," << refined(0, 1) << "," << refined(0, 2) << "],["
      << refined(1, 0) << "," << refined(1, 1) << "," << refined(1, 2) << "],[" << refined(2, 0)
      << "," << refined(2, 1) << "," << refined(2, 2) << "]"
      << R"(], "sigma_deg": [0.01, null, 0.02]}]})";
  read = LoadLuminaireSet(dir);
  EXPECT_TRUE(read.orientations[1].registered);
  EXPECT_TRUE(read.orientations[1].rotation.isApprox(refined, 1e-5));
  EXPECT_TRUE(std::isinf(read.orientations[1].sigma_deg.y()));

  // A registration naming an orientation luminaire.json does not have: exit 2 naming it.
  std::ofstream(dir + "/registration.json") << R"({"schema_version": 1, "orientations": [
    {"name": "o07", "rotation_matrix": [[1,0,0],[0,1,0],[0,0,1]]}]})";
  try {
    LoadLuminaireSet(dir);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("registration.json"), std::string::npos) << e.what();
    EXPECT_EQ(e.exit_code(), 2);
  }
  std::filesystem::remove_all(dir);
}

TEST(LuminaireSet, RefusesDatasetsOutsideTheFolder) {
  const std::string dir = TempFolder("luminaire_set_bad");
  std::ofstream(dir + "/luminaire.json") << R"({"schema_version": 1, "coverage": "sphere",
    "orientations": [{"name": "a", "dataset": "../x", "rotation_deg": [0,0,0],
                      "centre_mm": [0,0,-40]}]})";
  try {
    LoadLuminaireSet(dir);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("dataset"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(Geometry, RotationZyxDegreesRoundTrips) {
  for (const Eigen::Vector3d& deg :
       {Eigen::Vector3d(10, -20, 30), Eigen::Vector3d(-170, 80, 5), Eigen::Vector3d(0, 0, 0)})
    EXPECT_TRUE(RotationZyxDegreesOf(RotationZyxDegrees(deg)).isApprox(deg, 1e-9)) << deg;
  const Eigen::Matrix3d locked = RotationZyxDegrees({20, 90, 50});
  EXPECT_TRUE(RotationZyxDegrees(RotationZyxDegreesOf(locked)).isApprox(locked, 1e-9));
}

}  // namespace
}  // namespace lumislab
