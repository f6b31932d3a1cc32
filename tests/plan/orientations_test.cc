// lumislab-plan orientations: the sphere covered by the 6 cube faces with a 2 m screen at 750 mm
// and by more with the default 1.2 m one, every orientation connected; the plan file loads as a
// luminaire.json; unreachable coverage and a set that cannot connect are refused with the reason.
#include "plan/orientations.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/luminaire_set.h"
#include "plan/cli.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// d = 750 mm, a 3 x 3 grid of 10 mm, K = 1, a square screen of this side.
OrientationPlanInput Input(double screen_mm) {
  Dataset ds;
  ds.distance_mm = 750;
  ds.screen_w_mm = ds.screen_h_mm = screen_mm;
  ds.grid = {3, 3, 10};
  ds.filter = FilterInfo::Of(DualFilter::Truncated(1), 10);
  OrientationPlanInput in;
  in.cone = ConeOfDataset(ds);
  return in;
}

// Every orientation has a neighbour it overlaps by kMinOverlapSr (AnalyseCoverage's pairs).
void ExpectEveryOrientationHasANeighbour(const OrientationPlan& plan) {
  for (size_t k = 0; k < plan.orientations.size(); ++k) {
    bool found = false;
    for (const PairOverlap& p : plan.coverage.pairs)
      found |= (p.a == int(k) || p.b == int(k)) && p.overlap_sr >= kMinOverlapSr;
    EXPECT_TRUE(found) << "orientation " << k;
  }
}

// +-52 degrees a capture: the cube's 6 faces, o00 at the identity, on 2 mounts.
TEST(PlanOrientations, SixCubeFacesCoverTheSphereWithA2000mmScreen) {
  const OrientationPlan plan = PlanOrientations(Input(2000));
  EXPECT_TRUE(plan.problem.empty()) << plan.problem;
  ASSERT_EQ(plan.orientations.size(), 6u);
  EXPECT_TRUE(plan.orientations[0].rotation.isIdentity(1e-12));
  EXPECT_GE(plan.coverage.covered_fraction, 0.999);
  EXPECT_TRUE(plan.coverage.overlap_problem.empty()) << plan.coverage.overlap_problem;
  ExpectEveryOrientationHasANeighbour(plan);
  // What each sees at the screen's centre: the 6 axes of the luminaire frame, once each.
  std::vector<Eigen::Vector3d> axes;
  for (int a = 0; a < 3; ++a)
    for (int s : {1, -1}) axes.push_back(s * Eigen::Vector3d::Unit(a));
  for (const PlannedOrientation& o : plan.orientations) {
    const Eigen::Vector3d centre = o.rotation.transpose() * Eigen::Vector3d::UnitZ();
    const auto it = std::find_if(axes.begin(), axes.end(), [&](const Eigen::Vector3d& a) {
      return (a - centre).norm() < 1e-9;
    });
    ASSERT_NE(it, axes.end()) << centre.transpose();
    axes.erase(it);
    // The pose is the axis angle after the mount's tilt.
    EXPECT_TRUE(o.rotation.isApprox(
        RotationZyxDegrees({0, o.axis_deg, 0}) * RotationZyxDegrees({o.mount_tilt_deg, 0, 0}),
        1e-12));
  }
  int mounts = 0;
  for (const PlannedOrientation& o : plan.orientations) mounts = std::max(mounts, o.mount + 1);
  EXPECT_EQ(mounts, 2);
}

// +-37 degrees a capture (the default 1.2 m screen): more orientations, all connected; the
// hemisphere needs fewer than the sphere.
TEST(PlanOrientations, DefaultScreenNeedsMoreAndTheHemisphereFewer) {
  const OrientationPlan sphere = PlanOrientations(Input(1200));
  EXPECT_TRUE(sphere.problem.empty()) << sphere.problem;
  EXPECT_GT(sphere.orientations.size(), 6u);
  EXPECT_GE(sphere.coverage.covered_fraction, 0.999);
  EXPECT_TRUE(sphere.coverage.overlap_problem.empty()) << sphere.coverage.overlap_problem;
  ExpectEveryOrientationHasANeighbour(sphere);
  OrientationPlanInput in = Input(1200);
  in.hemisphere = true;
  const OrientationPlan hemisphere = PlanOrientations(in);
  EXPECT_TRUE(hemisphere.problem.empty()) << hemisphere.problem;
  EXPECT_LT(hemisphere.orientations.size(), sphere.orientations.size());
}

int Plan(std::vector<std::string> args) {
  args.insert(args.begin(), {"lumislab-plan", "orientations"});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  return RunPlan(int(argv.size()), argv.data());
}

// --out writes luminaire.json's format: it loads with LoadLuminaireSet, o00 ... in datasets of
// their names, each with its mount and axis angle and the full pose they make.
TEST(PlanOrientationsCli, PlanLoadsAsALuminaireSet) {
  const fs::path dir = fs::temp_directory_path() / "lumislab_plan_orientations_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(Plan({"--distance-mm", "750", "--screen-mm", "2000", "2000", "--grid", "3", "3", "10",
                  "--centre-depth-mm", "80", "--out", (dir / "luminaire.json").string()}),
            0);
  const LuminaireSet set = LoadLuminaireSet(dir.string());
  EXPECT_EQ(set.coverage, "sphere");
  ASSERT_EQ(set.orientations.size(), 6u);
  for (size_t k = 0; k < set.orientations.size(); ++k) {
    const Orientation& o = set.orientations[k];
    EXPECT_EQ(o.name, "o0" + std::to_string(k));
    EXPECT_EQ(o.dataset, o.name);
    EXPECT_TRUE(o.centre_mm.isApprox(Eigen::Vector3d(0, 0, -80)));
    ASSERT_TRUE(o.mount && o.axis_deg) << k;
    const Eigen::Matrix3d on_axis = RotationZyxDegrees({0, *o.axis_deg, 0});
    // The mount's tilt is about x only: what the pose is after taking the axis angle off.
    const Eigen::Vector3d tilt = RotationZyxDegreesOf(on_axis.transpose() * o.NominalRotation());
    EXPECT_NEAR(tilt.y(), 0, 1e-9) << k;
    EXPECT_NEAR(tilt.z(), 0, 1e-9) << k;
  }
  // Without a rotation axis every orientation is its own mount, without axis_deg.
  ASSERT_EQ(Plan({"--distance-mm", "750", "--screen-mm", "2000", "2000", "--grid", "3", "3", "10",
                  "--axis", "none", "--out", (dir / "luminaire.json").string()}),
            0);
  const LuminaireSet hand = LoadLuminaireSet(dir.string());
  for (size_t k = 0; k < hand.orientations.size(); ++k) {
    EXPECT_EQ(hand.orientations[k].mount, int(k));
    EXPECT_FALSE(hand.orientations[k].axis_deg);
  }
  // The setup from a dataset.json (its photos not read), for the hemisphere.
  ASSERT_EQ(
      Plan({"--dataset-setup", std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/v1/dataset.json",
            "--hemisphere", "--out", (dir / "luminaire.json").string()}),
      0);
  EXPECT_EQ(LoadLuminaireSet(dir.string()).coverage, "hemisphere");
}

std::string Refusal(const std::vector<std::string>& args) {
  try {
    Plan(args);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

// A screen whose cone is smaller than the overlap a registration needs cannot connect a second
// orientation (AnalyseCoverage's reason); a limit below what covers is said; a centre that lets
// the luminaire reach S is refused.
TEST(PlanOrientationsCli, RefusesWhatCannotCoverOrConnect) {
  const std::string tiny =
      Refusal({"--distance-mm", "750", "--screen-mm", "120", "120", "--grid", "3", "3", "10"});
  EXPECT_NE(tiny.find("no plan: "), std::string::npos) << tiny;
  EXPECT_NE(tiny.find("overlaps the chosen ones enough"), std::string::npos) << tiny;
  const std::string limit = Refusal({"--distance-mm", "750", "--screen-mm", "2000", "2000",
                                     "--grid", "3", "3", "10", "--max-orientations", "4"});
  EXPECT_NE(limit.find("the limit of 4 orientations"), std::string::npos) << limit;
  const std::string centre =
      Refusal({"--distance-mm", "750", "--screen-mm", "2000", "2000", "--grid", "3", "3", "10",
               "--luminaire-radius-mm", "100", "--centre-depth-mm", "90"});
  EXPECT_NE(centre.find("--centre-depth-mm: expected more than"), std::string::npos) << centre;
  const std::string both = Refusal({"--dataset-setup", "dataset.json", "--distance-mm", "750"});
  EXPECT_NE(both.find("--dataset-setup: give the setup by a file"), std::string::npos) << both;
}

}  // namespace
}  // namespace lumislab
