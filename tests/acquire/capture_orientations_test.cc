// lumislab-acquire capture --orientations (acquire/capture_orientations.h) in a virtual lab run in
// this process: the GRBL emulator with a fourth, rotary axis A on a pseudo-terminal, the PTP/IP
// camera emulator that the real libgphoto2 drives, photographing the small scene where the stage
// holds it (virtual_lab.h), and the tests' scripted operator (lab_operator.sh). A plan of three
// orientations (two reached by the axis on mount 0, one on mount 1) gives three complete
// datasets, the A moves in order, and one operator request to remount; a stop inside the second
// orientation resumes there; without an axis the operator is asked for every orientation. And
// the plan's errors: orientations the axis cannot reach, an axis that stops short.
#include "acquire/capture_orientations.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "acquire/capture.h"
#include "acquire/devices/grbl_stage.h"
#include "acquire_test_util.h"
#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/json.h"
#include "core/luminaire_set.h"
#include "core/stop_signal.h"
#include "grbl_emulator.h"
#include "ptpip_camera_emulator.h"
#include "virtual_lab.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

const std::string kLabOperator =
    std::string(LUMISLAB_SOURCE_DIR) + "/tests/acquire/lab_operator.sh";

// The grid's centre at (150, 150) on X Y, the slides on Z, one photo per slide; with `axis` the
// luminaire on a rotary A about the capture frame's y.
std::string LabJson(bool axis) {
  return std::string(R"({"stage": {"origin_mm": [150, 150], "travel_mm": {"X": [0, 300],
    "Y": [0, 300], "Z": [0, 100])") +
         (axis ? R"(, "A": [-180, 180])" : "") +
         R"(}, "feed_mm_min": 6000, "reply_timeout_s": 2, "move_timeout_s": 20},
    "slides": {"axis": "Z", "p_mm": 10, "n_mm": 60},)" +
         (axis ? R"("rotation_axis": {"stage_axis": "A", "about": "y"},)" : "") +
         R"("camera": {"brackets": 1, "delete_from_card": true}})";
}

// Two orientations on the axis (mount 0, A at 0 and 90 degrees: a turn about y), one remounted.
const char* kPlan = R"({"schema_version": 1, "coverage": "sphere", "orientations": [
  {"name": "o00", "dataset": "o00", "rotation_deg": [0, 0, 0], "centre_mm": [0, 0, 0],
   "mount": 0, "axis_deg": 0},
  {"name": "o01", "dataset": "o01", "rotation_deg": [0, 90, 0], "centre_mm": [0, 0, 0],
   "mount": 0, "axis_deg": 90},
  {"name": "o02", "dataset": "o02", "rotation_deg": [90, 0, 0], "centre_mm": [0, 0, 0],
   "mount": 1, "axis_deg": 0}]})";

class VirtualLab {
 public:
  VirtualLab(const std::string& root, bool axis) : root_(root) {
    // libgphoto2 keeps its PTP/IP GUID in $HOME/.gphoto/settings: the test's own.
    fs::create_directories(root + "/home");
    setenv("HOME", (root + "/home").c_str(), 1);
    fs::create_directories(root + "/control");
    setenv("LUMISLAB_LAB_CONTROL", (root + "/control").c_str(), 1);
    WriteTextAtomically(root + "/control/board", "off\n");
    const std::string lab_json = LabJson(axis);
    const LabSetup lab = ParseLabSetup(JsonDocument::Parse(lab_json, "lab.json").root());
    // The small scene on a 2 x 2 grid: 8 shots an orientation.
    std::string scene = acquire_test::SmallSceneJson();
    scene.replace(scene.find(R"("nu": 3, "nv": 3)"), 16, R"("nu": 2, "nv": 2)");
    optics_ = std::make_unique<virtual_lab::Optics>(ParseScene(scene, "small.json"), lab,
                                                    root + "/control");
    WriteTextAtomically(
        root + "/setup.json",
        virtual_lab::SetupJson(optics_->scene(), optics_->radiometric_scale(), lab_json));
    GrblEmulatorOptions grbl;
    grbl.speed_factor = 200;
    grbl.axes = axis ? 4 : 3;
    grbl.travel_min_mm = {0, 0, 0, -180};
    grbl.travel_max_mm = {300, 300, 100, 180};
    stage_ = std::make_unique<GrblEmulator>(grbl);
    camera_ = std::make_unique<PtpipCameraEmulator>(
        0, [this](const PtpipCameraEmulator::ShotSettings& shot) {
          const GrblAxes p = stage_->Position();
          const virtual_lab::LabPhoto photo = optics_->Shoot(
              {{'X', p[0]}, {'Y', p[1]}, {'Z', p[2]}, {'A', p[3]}}, shot.exposure_time_s);
          // Ctrl-C, as a photo of the second orientation is taken (once the first is listed).
          if (stop_in_second_ && fs::exists(root_ + "/lum/luminaire.json") && ++photos_ == 4) {
            stop_in_second_ = false;
            RequestStop();
          }
          return PtpipCameraEmulator::Photo{photo.extension, photo.bytes};
        });
    WriteTextAtomically(root + "/plan.json", kPlan);
  }

  CaptureOptions Options() const {
    CaptureOptions o;
    o.setup_file = root_ + "/setup.json";
    o.stage_uri = "grbl:" + stage_->SlavePath();
    o.camera_uri = "gphoto2@" + camera_->ptpip_path();
    o.out_dir = root_ + "/lum";
    o.operator_program = kLabOperator;
    o.orientations_file = root_ + "/plan.json";
    return o;
  }
  // The operator's requests so far ("<action> <argument>" a line).
  std::string Asked() const { return acquire_test::FileBytes(root_ + "/control/asked"); }
  // The rotary moves the stage received, in order.
  std::vector<std::string> AxisMoves() const {
    std::vector<std::string> moves;
    for (const GrblEmulator::Event& e : stage_->Events())
      if (e.text.find(" A") != std::string::npos && e.text.rfind("> G", 0) == 0)
        moves.push_back(e.text.substr(2));
    return moves;
  }
  void StopInSecondOrientation() { stop_in_second_ = true; }

 private:
  std::string root_;
  std::unique_ptr<virtual_lab::Optics> optics_;
  std::unique_ptr<GrblEmulator> stage_;
  std::unique_ptr<PtpipCameraEmulator> camera_;
  std::atomic<int> photos_{0};
  std::atomic<bool> stop_in_second_{false};
};

void ExpectComplete(const std::string& lum, size_t orientations) {
  const LuminaireSet set = LoadLuminaireSet(lum);
  ASSERT_EQ(set.orientations.size(), orientations);
  for (size_t k = 0; k < orientations; ++k) {
    const Dataset ds = Dataset::Load(set.DatasetFolder(k));
    EXPECT_FALSE(ds.Partial()) << set.DatasetFolder(k);
    EXPECT_EQ(ds.photos.size(), 8u) << set.DatasetFolder(k);  // 2 x 2 positions, 2 slides
  }
}

TEST(CaptureOrientations, AxisTurnsTheLuminaireAndTheOperatorRemountsIt) {
  const std::string root = acquire_test::FreshDir("orientations_axis");
  VirtualLab lab(root, true);
  const CaptureReport report = RunCapture(lab.Options());
  EXPECT_EQ(report.orientations_done, 3);
  ExpectComplete(root + "/lum", 3);
  const LuminaireSet set = LoadLuminaireSet(root + "/lum");
  EXPECT_EQ(set.coverage, "sphere");
  EXPECT_EQ(set.orientations[1].axis_deg.value_or(-1), 90);
  EXPECT_EQ(set.orientations[2].mount.value_or(-1), 1);
  // The axis moved to each orientation's angle in order, as rapids.
  EXPECT_EQ(lab.AxisMoves(), (std::vector<std::string>{"G0 A0.000", "G0 A90.000", "G0 A0.000"}));
  // The board once (every orientation takes its photo over), the remount once, no slide (axis Z).
  EXPECT_EQ(lab.Asked(), "board on\nboard off\nmount 1\n");
  for (const char* name : {"o00", "o01", "o02"})
    EXPECT_TRUE(fs::exists(root + "/lum/" + name + "/photos/board.tif")) << name;
  // A second run finds it complete.
  EXPECT_TRUE(RunCapture(lab.Options()).skipped);
}

TEST(CaptureOrientations, AStopInsideAnOrientationResumesThere) {
  const std::string root = acquire_test::FreshDir("orientations_resume");
  VirtualLab lab(root, true);
  lab.StopInSecondOrientation();
  try {
    RunCapture(lab.Options());
    ADD_FAILURE() << "the stop did not stop the capture";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kFailure) << e.what();
    EXPECT_NE(std::string(e.what()).find("lists 1 of 3 orientations"), std::string::npos)
        << e.what();
  }
  ExpectComplete(root + "/lum", 1);
  EXPECT_TRUE(Dataset::Load(root + "/lum/o01").Partial());
  const CaptureReport report = RunCapture(lab.Options());
  EXPECT_EQ(report.orientations_resumed, 1);
  EXPECT_EQ(report.orientations_done, 2);
  EXPECT_GT(report.shots_resumed, 0);  // o01 went on after its finished shots
  ExpectComplete(root + "/lum", 3);
  // The resumed run turned the axis back to o01 without asking; the remount was asked once.
  EXPECT_EQ(lab.AxisMoves(),
            (std::vector<std::string>{"G0 A0.000", "G0 A90.000", "G0 A90.000", "G0 A0.000"}));
  EXPECT_EQ(lab.Asked(), "board on\nboard off\nmount 1\n");
}

TEST(CaptureOrientations, WithoutAnAxisTheOperatorTurnsEveryOrientation) {
#ifdef LUMISLAB_SANITIZED
  // The paths of the axis' tests less the moves; the sanitized build's time goes elsewhere.
  GTEST_SKIP() << "the Release build's";
#endif
  const std::string root = acquire_test::FreshDir("orientations_no_axis");
  VirtualLab lab(root, false);
  const CaptureReport report = RunCapture(lab.Options());
  EXPECT_EQ(report.orientations_done, 3);
  ExpectComplete(root + "/lum", 3);
  EXPECT_TRUE(lab.AxisMoves().empty());
  EXPECT_EQ(lab.Asked(),
            "orientation o00\nboard on\nboard off\norientation o01\norientation o02\n");
}

void ExpectRefused(const std::function<void()>& f, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one naming " << text;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(CaptureOrientations, APlanTheAxisCannotReachIsRefused) {
  const std::string root = acquire_test::FreshDir("orientations_refused");
  const LabSetup lab = ParseLabSetup(JsonDocument::Parse(LabJson(true), "s.json").root());
  const LabSetup no_axis = ParseLabSetup(JsonDocument::Parse(LabJson(false), "s.json").root());
  const auto plan = [&](const std::string& o01) {
    std::string text = kPlan;
    const size_t at = text.find(R"({"name": "o01")");
    text.replace(at, text.find('}', at) + 1 - at, o01);
    WriteTextAtomically(root + "/plan.json", text);
    return LoadOrientationPlan(root + "/plan.json");
  };
  const std::string plan_file = root + "/plan.json";
  // The plan as given: the axis reaches it; without an axis the operator does.
  CheckPlanAgainstLab(plan(R"({"name": "o01", "dataset": "o01", "rotation_deg": [0, 90, 0],
      "centre_mm": [0, 0, 0], "mount": 0, "axis_deg": 90})"),
                      plan_file, lab, "setup.json");
  // lumislab-plan orientations' poses, R = Ry(axis_deg) Rx(mount tilt): a second orientation on
  // the tilted mount 1, turned 45 degrees further by the axis.
  LuminaireSet planned = plan(R"({"name": "o01", "dataset": "o01", "rotation_deg": [0, -60, 0],
      "centre_mm": [0, 0, 0], "mount": 0, "axis_deg": -60})");
  Orientation tilted = planned.orientations[2];  // [90, 0, 0] on mount 1 at axis 0
  tilted.name = tilted.dataset = "o03";
  tilted.rotation_deg = {90, 45, 0};
  tilted.axis_deg = 45;
  planned.orientations.push_back(tilted);
  CheckPlanAgainstLab(planned, plan_file, lab, "setup.json");
  planned.orientations.back().rotation_deg = {90, 0, 45};  // turned about z instead
  ExpectRefused([&] { CheckPlanAgainstLab(planned, plan_file, lab, "setup.json"); },
                "orientations[3].rotation_deg: expected orientations[2] turned");
  // Turned about x where the lab's axis turns about y.
  const LuminaireSet about_x = plan(R"({"name": "o01", "dataset": "o01",
      "rotation_deg": [90, 0, 0], "centre_mm": [0, 0, 0], "mount": 0, "axis_deg": 90})");
  ExpectRefused([&] { CheckPlanAgainstLab(about_x, plan_file, lab, "setup.json"); },
                plan_file +
                    ": orientations[1].rotation_deg: expected orientations[0] turned by "
                    "axis_deg's difference, 90 deg, about y");
  CheckPlanAgainstLab(about_x, plan_file, no_axis, "setup.json");
  // Beyond the axis' travel.
  ExpectRefused(
      [&] {
        CheckPlanAgainstLab(plan(R"({"name": "o01", "dataset": "o01", "rotation_deg": [0, 270, 0],
            "centre_mm": [0, 0, 0], "mount": 0, "axis_deg": 270})"),
                            plan_file, lab, "setup.json");
      },
      plan_file +
          ": orientations[1].axis_deg: expected an angle within the rotation axis' "
          "travel [-180, 180] deg");
  // A plan file's own errors name it.
  ExpectRefused([&] { plan(R"({"name": "o01", "dataset": "o01", "rotation_deg": [0, 90]})"); },
                plan_file + ": orientations[1].rotation_deg");
  // The lab block's field.
  ExpectRefused(
      [&] {
        ParseLabSetup(JsonDocument::Parse(R"({"stage": {"origin_mm": [0, 0], "travel_mm": {}},
            "rotation_axis": {"stage_axis": "A", "about": "w"}})",
                                          "s.json")
                          .root());
      },
      "s.json: rotation_axis.about");
}

TEST(CaptureOrientations, ARotaryAxisThatStopsShortIsADeviceError) {
  GrblEmulatorOptions options;
  options.axes = 4;
  options.speed_factor = 200;
  options.a_shortfall_deg = 0.5;
  GrblEmulator emulator(options);
  const std::unique_ptr<Stage> stage =
      MakeGrblStage("grbl:" + emulator.SlavePath(), emulator.SlavePath(), 115200);
  StageSettings settings;
  settings.rotary_axis = 'A';
  settings.reply_timeout_s = 2;
  settings.move_timeout_s = 10;
  DeviceLog log;
  stage->Connect(settings, &log);
  // The linear axes as ever: a G1 at the feed rate, in mm.
  EXPECT_EQ(stage->MoveTo({{'X', 10}}), (AxisTargets{{'X', 10}}));
  try {
    stage->MoveTo({{'A', 90}});
    ADD_FAILURE() << "A stopped short, unnoticed";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kFailure);
    EXPECT_NE(std::string(e.what()).find("A is at 89.500 deg, not at its target 90.000 deg "
                                         "(lab.rotation_axis.tolerance_deg 0.05)"),
              std::string::npos)
        << e.what();
  }
  stage->Close();
}

}  // namespace
}  // namespace lumislab
