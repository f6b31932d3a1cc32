// acquire synth --orientations: the luminaire folder (luminaire.json, one dataset per orientation,
// truth/), each orientation's truth slab against the analytic turned luminaire, the mounting
// errors, and the refusal of a pose that puts an emitter in front of S.
#include "acquire/synth_orientations.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>

#include "acquire/cli.h"
#include "acquire_test_util.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/json.h"
#include "core/slab.h"
#include "lib/synthetic/scene.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using acquire_test::FreshDir;
using acquire_test::SmallScene;
using acquire_test::SmallSynthOptions;

// o00 at the identity, then turned about y and x, all about a centre 100 mm behind S.
LuminaireSet ThreeOrientations(const std::string& folder) {
  LuminaireSet set;
  set.folder = folder;
  if (!folder.empty()) fs::create_directories(folder);
  set.coverage = "sphere";
  const Eigen::Vector3d turns[] = {{0, 0, 0}, {0, 25, 0}, {-20, 0, 10}};
  for (int k = 0; k < 3; ++k) {
    Orientation o;
    o.name = "o0" + std::to_string(k);
    o.dataset = o.name;
    o.rotation_deg = turns[k];
    o.centre_mm = {0, 0, -100};
    set.orientations.push_back(o);
  }
  return set;
}

double AngleDeg(const Eigen::Matrix3d& r) { return Eigen::AngleAxisd(r).angle() * 180 / kPi; }

// The whole folder: luminaire.json as given, each dataset complete, truth/orientations.json
// with the true poses (exactly nominal without mounting errors) and truth/luminaire.json the
// scene's luminaire in its own frame.
TEST(SynthOrientations, WritesTheLuminaireFolderAndTruth) {
  const std::string dir = FreshDir("orientations_folder");
  WriteLuminaireSet(ThreeOrientations(dir + "/plan"));
  SynthOrientationsOptions o;
  o.orientations_file = LuminaireJsonPath(dir + "/plan");
  const SynthScene scene = SmallScene();
  const std::string lum = dir + "/lum";
  const SynthOrientationsReport report = RunSynthOrientations(scene, SmallSynthOptions(lum), o);
  ASSERT_EQ(report.orientations.size(), 3u);
  EXPECT_TRUE(LuminaireFolderComplete(lum));
  const LuminaireSet set = LoadLuminaireSet(lum);
  ASSERT_EQ(set.orientations.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_TRUE(DatasetComplete(set.DatasetFolder(k))) << k;
    EXPECT_TRUE(set.orientations[k].rotation_deg.isApprox(
        ThreeOrientations("").orientations[k].rotation_deg));
  }
  const JsonDocument truth = JsonDocument::Load(lum + "/truth/orientations.json");
  EXPECT_EQ(truth.root()["schema_version"].Int(), kTrueOrientationsSchemaVersion);
  for (size_t k = 0; k < 3; ++k) {
    const JsonView t = truth.root()["orientations"][k];
    EXPECT_EQ(t["name"].String(), set.orientations[k].name);
    EXPECT_EQ(t["error_deg"].Number(), 0);
    Eigen::Matrix3d r;
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col)
        r(row, col) = t["rotation"][size_t(row)][size_t(col)].Number();
    EXPECT_LT((r - set.orientations[k].NominalRotation()).norm(), 1e-12) << k;
  }
  const Luminaire own = LoadLuminaire(lum + "/truth/luminaire.json");
  ASSERT_EQ(own.emitters.size(), scene.luminaire.emitters.size());
  for (size_t e = 0; e < own.emitters.size(); ++e)
    EXPECT_TRUE(own.emitters[e].position_mm.isApprox(scene.luminaire.emitters[e].position_mm));
  // A second run finds it complete and skips; nothing is left staged beside it.
  EXPECT_TRUE(RunSynthOrientations(scene, SmallSynthOptions(lum), o).skipped);
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_TRUE(entry.path().filename() == "lum" || entry.path().filename() == "plan")
        << entry.path();
}

// The built-in full-sphere scene (lobes along every axis, a side lobe and an asymmetric one) with
// a 3 x 3 grid and a small camera.
SynthScene SmallFullSphereScene() {
  SynthScene scene = LoadScene("full-sphere");
  scene.grid.nu = scene.grid.nv = 3;
  scene.camera.width = 160;
  scene.camera.height = 120;
  scene.camera.focal_px /= 10;
  return scene;
}

// Orientation k's truth slab is the luminaire turned by its true pose, written here from the
// emitters of the luminaire's own frame: a point x = R (p - centre) + centre_k, intensity
// I0 Shape(R^T w) towards w (the lobe about its own axis), through the filter at c_ij where the
// ray crosses S.
TEST(SynthOrientations, TruthSlabIsTheAnalyticTurnedLuminaire) {
  const std::string dir = FreshDir("orientations_truth");
  WriteLuminaireSet(ThreeOrientations(dir + "/plan"));
  SynthOrientationsOptions o;
  o.orientations_file = LuminaireJsonPath(dir + "/plan");
  o.mount_error_deg = 2;
  const SynthScene scene = SmallFullSphereScene();
  const std::string lum = dir + "/lum";
  RunSynthOrientations(scene, SmallSynthOptions(lum), o);
  const LuminaireSet set = LoadLuminaireSet(lum);
  const std::vector<TruePose> poses = TruePoses(set, o.mount_error_deg, o.seed);
  for (size_t k : {size_t(1), size_t(2)}) {
    const std::string truth_dir = set.DatasetFolder(k) + "/truth";
    const SlabInfo info = SlabInfo::Load(truth_dir);
    const DualFilter f = info.filter.Filter();
    const double h = info.grid.spacing_mm, d = info.distance_mm;
    const Eigen::Matrix3d& r = poses[k].rotation;
    double peak = 0;
    int compared = 0;
    for (const auto& [i, j] : {std::pair{1, 1}, std::pair{0, 2}}) {
      const SlabPosition p = ReadSlabPosition(truth_dir, info, i, j);
      const Eigen::Vector2d c = info.grid.Centre(i, j);
      for (int row = 0; row < info.layout.res_y; row += 2)
        for (int col = 0; col < info.layout.res_x; col += 2) {
          const Eigen::Vector2d st = info.layout.TexelCentre(col, row);
          Eigen::Vector3d expected = Eigen::Vector3d::Zero();
          for (const Emitter& e : scene.luminaire.emitters) {
            const Eigen::Vector3d x =
                r * (e.position_mm - scene.luminaire.centre_mm) + poses[k].centre_mm;
            const Eigen::Vector3d ray = Eigen::Vector3d(st.x(), st.y(), d) - x;
            const double dist = ray.norm();
            const Eigen::Vector3d w = ray / dist;
            const double a = -x.z() / ray.z();  // where the ray crosses S
            const double u = x.x() + a * ray.x(), v = x.y() + a * ray.y();
            const double g = w.z() * 1e6 / (dist * dist);
            expected +=
                e.Intensity(r.transpose() * w) * g * f.Eval2D((u - c.x()) / h, (v - c.y()) / h);
          }
          peak = std::max(peak, expected.cwiseAbs().maxCoeff());
          for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(p.irradiance.at(col, row, ch), expected[ch],
                        1e-5 * std::abs(expected[ch]) + 1e-9)
                << "orientation " << k << " position " << i << "," << j << " texel " << col << ","
                << row;
          ++compared;
        }
    }
    EXPECT_GT(peak, 0) << k;
    EXPECT_GT(compared, 100);
  }
}

// The errors: o00 exact, the others by an angle in [A/2, A]; the same seed gives the same poses,
// another seed others.
TEST(SynthOrientations, MountErrorsWithinRangeAndReproducibleBySeed) {
  LuminaireSet set;
  set.coverage = "sphere";
  for (int k = 0; k < 8; ++k) {
    Orientation o;
    o.name = "o0" + std::to_string(k);
    o.dataset = o.name;
    o.rotation_deg = {0, 45.0 * k, 0};
    o.centre_mm = {0, 0, -60};
    set.orientations.push_back(o);
  }
  const std::vector<TruePose> a = TruePoses(set, 2, 7), b = TruePoses(set, 2, 7),
                              c = TruePoses(set, 2, 8);
  EXPECT_EQ(a[0].error_deg, 0);
  EXPECT_LT((a[0].rotation - a[0].nominal).norm(), 1e-15);
  for (size_t k = 1; k < a.size(); ++k) {
    EXPECT_GE(a[k].error_deg, 1) << k;
    EXPECT_LE(a[k].error_deg, 2) << k;
    EXPECT_NEAR(AngleDeg(a[k].rotation * a[k].nominal.transpose()), a[k].error_deg, 1e-9) << k;
    EXPECT_EQ(a[k].rotation, b[k].rotation) << k;
    EXPECT_GT((a[k].rotation - c[k].rotation).norm(), 1e-6) << k;
  }
}

// A pose that turns an emitter onto or in front of S is refused naming the file, the orientation
// and the field, and nothing is written.
TEST(SynthOrientations, RefusesAnEmitterInFrontOfS) {
  const std::string dir = FreshDir("orientations_refused");
  LuminaireSet set = ThreeOrientations(dir + "/plan");
  set.orientations[2].rotation_deg = {180, 0, 0};  // z -20 -> +20, 10 mm behind S: in front
  set.orientations[2].centre_mm = {0, 0, -10};
  WriteLuminaireSet(set);
  SynthOrientationsOptions o;
  o.orientations_file = LuminaireJsonPath(dir + "/plan");
  try {
    RunSynthOrientations(SmallScene(), SmallSynthOptions(dir + "/lum"), o);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    const std::string message = e.what();
    EXPECT_NE(message.find(o.orientations_file + ": orientations[2] (o02): centre_mm: expected"),
              std::string::npos)
        << message;
  }
  EXPECT_FALSE(fs::exists(dir + "/lum"));
}

int RunTool(std::vector<std::string> args) {
  args.insert(args.begin(), {"lumislab-acquire", "synth"});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return RunMain("acquire", [&] { return RunAcquire(int(argv.size()), argv.data()); });
}

// The command line: --orientations makes the luminaire folder; a mounting error without it, and
// a missing orientations file, are bad input (exit 2).
TEST(SynthOrientations, CommandLine) {
  const std::string dir = FreshDir("orientations_cli");
  const std::string scene = dir + "/scene.json";
  WriteTextAtomically(scene, acquire_test::SmallSceneJson());
  WriteLuminaireSet(ThreeOrientations(dir + "/plan"));
  EXPECT_EQ(RunTool({"--scene", scene, "--out", dir + "/x", "--mount-error-deg", "1"}), 2);
  EXPECT_EQ(RunTool({"--scene", scene, "--out", dir + "/x", "--orientations", dir + "/none.json"}),
            2);
  EXPECT_FALSE(fs::exists(dir + "/x"));
  EXPECT_EQ(RunTool({"--scene", scene, "--out", dir + "/lum", "--orientations",
                     LuminaireJsonPath(dir + "/plan"), "--mount-error-deg", "1.5", "--seed", "3",
                     "--truth-resolution", "10", "--threads", "2"}),
            0);
  EXPECT_TRUE(LuminaireFolderComplete(dir + "/lum"));
  // A plan under another name reads the same; its errors name it.
  const std::string plan = dir + "/plan.json";
  WriteTextAtomically(plan, ReadTextFile(LuminaireJsonPath(dir + "/plan")));
  EXPECT_EQ(LoadOrientationsFile(plan).orientations.size(), 3u);
  std::string text = ReadTextFile(plan);
  text.replace(text.find("\"sphere\""), 8, "\"cube\"");
  WriteTextAtomically(plan, text);
  try {
    LoadOrientationsFile(plan);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(plan + ": coverage: expected", 0), 0u) << e.what();
  }
  for (const auto& entry : fs::directory_iterator(dir))  // no private folder left
    EXPECT_EQ(entry.path().string().find(".d"), std::string::npos) << entry.path();
  const JsonDocument truth = JsonDocument::Load(dir + "/lum/truth/orientations.json");
  EXPECT_EQ(truth.root()["seed"].Int(), 3);
  EXPECT_GE(truth.root()["orientations"][2]["error_deg"].Number(), 0.75);
}

}  // namespace
}  // namespace lumislab
