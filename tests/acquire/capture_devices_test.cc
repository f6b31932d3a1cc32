// The parts of `acquire capture` that need no emulator: the lab block of setup.json and its soft
// limits, the capture plan (order, serpentine rows, travel, lab time), the device URIs, and the
// devices lumislab drives through other programs (command: stage and camera, folder: camera,
// the operator program), each against a small shell script.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "acquire/capture.h"
#include "acquire/devices/command_camera.h"
#include "acquire/devices/command_stage.h"
#include "acquire/devices/operator.h"
#include "acquire/devices/uri.h"
#include "acquire/lab_setup.h"
#include "acquire_test_util.h"
#include "core/error.h"
#include "core/json.h"
#include "core/stop_signal.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/photo_write.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using acquire_test::FileBytes;
using acquire_test::FreshDir;

LabSetup Lab(const std::string& json) {
  return ParseLabSetup(JsonDocument::Parse("{\"lab\": " + json + "}", "setup.json").root()["lab"]);
}

const char* kLab = R"({"stage": {"origin_mm": [100, 50], "direction": [1, -1],
  "travel_mm": {"X": [0, 200], "Y": [0, 100], "Z": [0, 80]}},
  "slides": {"axis": "Z", "p_mm": 5, "n_mm": 70}, "camera": {"brackets": 2}})";

void ExpectBadInput(const std::function<void()>& f, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one naming " << text;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

std::string Script(const std::string& dir, const std::string& name, const std::string& body) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << "#!/bin/sh\n" << body;
  chmod(path.c_str(), 0755);
  return path;
}

TEST(LabSetup, GridPositionsOnTheStageAndTheSoftLimits) {
  const LabSetup lab = Lab(kLab);
  const SamplingGrid grid{5, 3, 10};  // u from -20 to 20, v from -10 to 10 mm
  const AxisTargets corner = lab.PositionTargets(grid, 0, 0);
  ASSERT_EQ(corner.size(), 2u);
  EXPECT_EQ(corner[0].first, 'X');
  EXPECT_DOUBLE_EQ(corner[0].second, 80);  // 100 + (-20)
  EXPECT_DOUBLE_EQ(corner[1].second, 60);  // 50 - (-10): the v axis runs the other way
  EXPECT_EQ(lab.SlideTargets(false), (AxisTargets{{'Z', 70}}));
  lab.CheckTravel(grid, "setup.json");
  // 25 positions of 10 mm reach X = 100 +- 120: beyond [0, 200].
  ExpectBadInput(
      [&] {
        lab.CheckTravel({25, 3, 10}, "setup.json");
      },
      "setup.json: lab.stage.travel_mm.X: expected a travel [0 mm, 200 mm]");
  // The slide axis' n position beyond Z's travel.
  ExpectBadInput(
      [&] {
        Lab(R"({"stage": {"origin_mm": [100, 50], "travel_mm": {"X": [0, 200], "Y": [0, 100],
              "Z": [0, 60]}}, "slides": {"axis": "Z", "p_mm": 5, "n_mm": 70}})")
            .CheckTravel(grid, "setup.json");
      },
      "lab.stage.travel_mm.Z");
  // An axis moved without a travel.
  ExpectBadInput(
      [&] {
        Lab(R"({"stage": {"origin_mm": [100, 50], "travel_mm": {"X": [0, 200]}}})")
            .CheckTravel(grid, "setup.json");
      },
      "lab.stage.travel_mm.Y: expected the travel of every axis");
}

TEST(LabSetup, FieldsAreChecked) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"stage": {"travel_mm": {}}})", "lab.stage.origin_mm"},
      {R"({"stage": {"origin_mm": [0, 0], "axes": ["X", "X"], "travel_mm": {}}})",
       "lab.stage.axes"},
      {R"({"stage": {"origin_mm": [0, 0], "axes": ["X", "Q"], "travel_mm": {}}})",
       "lab.stage.axes[1]"},
      {R"({"stage": {"origin_mm": [0, 0], "direction": [1, 2], "travel_mm": {}}})",
       "lab.stage.direction"},
      {R"({"stage": {"origin_mm": [0, 0], "travel_mm": {"X": [5, 1]}}})", "lab.stage.travel_mm.X"},
      {R"({"stage": {"origin_mm": [0, 0], "travel_mm": {}, "feed_mm_min": 0}})",
       "lab.stage.feed_mm_min"},
      {R"({"stage": {"origin_mm": [0, 0], "travel_mm": {}}, "slides": {"axis": "X", "p_mm": 0,
           "n_mm": 1}})",
       "lab.slides.axis"},
      {R"({"stage": {"origin_mm": [0, 0], "travel_mm": {}}, "slides": {"axis": "Z", "p_mm": 1,
           "n_mm": 1}})",
       "lab.slides.n_mm"},
      {R"({"stage": {"origin_mm": [0, 0], "travel_mm": {}}, "camera": {"brackets": 0}})",
       "lab.camera.brackets"},
      {R"({"stage": {"origin_mm": [0, 0], "travel_mm": {}}, "camera": {"shutter_s": [0.1, 0.05]}})",
       "lab.camera.shutter_s[1]"},
      {R"({"stage": {"origin_mm": [0, 0], "travel_mm": {}}, "camera": {"brackets": 3,
           "shutter_s": [0.1]}})",
       "lab.camera.shutter_s"},
  };
  for (const auto& c : cases) ExpectBadInput([&] { Lab(c.first); }, "setup.json: " + c.second);
}

TEST(CapturePlan, SlidePassIsSerpentineAndComesBackPositionAlternatesSlides) {
  const SamplingGrid grid{3, 2, 5};
  LabModel model;
  model.move_s = 2;
  model.exposure_s = 0.5;
  LabSetup lab = Lab(kLab);
  lab.brackets = 2;
  const CapturePlan pass = PlanCapture(grid, lab, "slide-pass", model);
  std::vector<std::tuple<int, int, bool>> shots;
  for (const CaptureShot& s : pass.shots) shots.emplace_back(s.i, s.j, s.positive);
  const std::vector<std::tuple<int, int, bool>> expected = {
      {0, 0, true},  {1, 0, true},  {2, 0, true},  {2, 1, true},  {1, 1, true},  {0, 1, true},
      {0, 1, false}, {1, 1, false}, {2, 1, false}, {2, 0, false}, {1, 0, false}, {0, 0, false}};
  EXPECT_EQ(shots, expected);
  EXPECT_EQ(pass.moves, 11);  // the second pass starts where the first ended
  EXPECT_EQ(pass.slide_swaps, 2);
  EXPECT_EQ(pass.photos, 24);
  EXPECT_DOUBLE_EQ(pass.lab_s, 11 * 2 + 24 * 0.5);
  // Grid travel 2 x 5 x 5 mm, and one slide change of 65 mm on Z.
  EXPECT_DOUBLE_EQ(pass.travel_mm, 50 + 65);

  const CapturePlan position = PlanCapture(grid, lab, "auto", model);
  EXPECT_EQ(position.order, "position");  // a slide axis: both slides at each position
  EXPECT_EQ(position.moves, 6);
  EXPECT_EQ(position.slide_swaps, 7);  // the first slide, then one change per position
  EXPECT_EQ(position.shots[1].positive, false);
  EXPECT_EQ(position.shots[2].positive, false);  // n stays in for the next position
  // With every position once, the lab time is lumislab-plan's: positions x (move + 2 x 2 x t).
  model.brackets = 2;
  EXPECT_DOUBLE_EQ(position.lab_s, model.Seconds(grid.count()));
  lab.slide_axis.reset();
  EXPECT_EQ(PlanCapture(grid, lab, "auto", model).order, "slide-pass");
}

TEST(DeviceUri, SchemesAndMalformedUris) {
  ExpectBadInput([] { MakeStage("usb:/dev/ttyUSB0"); }, "--stage: expected a stage URI");
  ExpectBadInput([] { MakeStage("grbl:"); }, "--stage");
  ExpectBadInput([] { MakeStage("grbl:/dev/ttyUSB0?baud=12"); }, "baud");
  ExpectBadInput([] { MakeStage("grbl:/dev/ttyUSB0?speed=9600"); }, "baud");
  ExpectBadInput([] { MakeStage("command:"); }, "command:<program>");
  ExpectBadInput([] { MakeCamera("webcam:0"); }, "--camera: expected a camera URI");
  ExpectBadInput([] { MakeCamera("folder:"); }, "folder:<dir>");
  ExpectBadInput([] { MakeCamera("gphoto2@"); }, "gphoto2[:<model>][@<port>]");
  EXPECT_EQ(MakeStage("grbl:/dev/ttyACM0?baud=250000")->uri(), "grbl:/dev/ttyACM0?baud=250000");
  EXPECT_EQ(MakeStage("manual")->uri(), "manual");
  EXPECT_EQ(MakeCamera("folder:/tmp")->uri(), "folder:/tmp");
}

TEST(CommandStage, CallsTheProgramWithTheTargetsAndReportsItsFailure) {
  const std::string dir = FreshDir("command_stage");
  const std::string mover =
      Script(dir, "mover.sh",
             "echo \"$@\" >> " + dir +
                 "/calls\n"
                 "[ \"$2\" = X=999.000 ] && { echo 'out of range' >&2; exit 3; }\n"
                 "exit 0\n");
  DeviceLog log(dir + "/devices.log");
  auto stage = MakeStage("command:" + mover);
  StageSettings settings;
  settings.move_timeout_s = 5;
  stage->Connect(settings, &log);
  stage->Home();
  EXPECT_EQ(stage->MoveTo({{'X', 12.5}, {'Y', -3}}), (AxisTargets{{'X', 12.5}, {'Y', -3}}));
  EXPECT_EQ(FileBytes(dir + "/calls"), "home\nmove X=12.500 Y=-3.000\n");
  try {
    stage->MoveTo({{'X', 999}});
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kFailure);
    EXPECT_NE(std::string(e.what()).find("moving to X=999.000"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exit 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
  EXPECT_NE(FileBytes(dir + "/devices.log").find("< out of range"), std::string::npos);
  ExpectBadInput([&] { MakeStage("command:" + dir + "/missing.sh")->Connect(settings, &log); },
                 "missing.sh is not an executable program");
}

TEST(CommandStage, AProgramThatHangsIsKilledAtTheTimeout) {
  const std::string dir = FreshDir("command_stage_hang");
  const std::string mover = Script(dir, "hang.sh", "sleep 30\n");
  auto stage = MakeStage("command:" + mover);
  StageSettings settings;
  settings.move_timeout_s = 0.5;
  stage->Connect(settings, nullptr);
  const auto start = std::chrono::steady_clock::now();
  try {
    stage->MoveTo({{'X', 1}});
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did not finish within"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 3);
}

// A photo for the cameras below to deliver.
std::string TestPhoto(const std::string& dir) {
  ImageF image(16, 8, 3);
  for (size_t k = 0; k < image.data.size(); ++k) image.data[k] = float(k % 7) / 8;
  const std::string path = dir + "/source.png";
  WritePhoto(path, image, PhotoEncoding::kLinear16Png);
  return path;
}

TEST(CommandCamera, TheProgramWritesThePhotoItsExtensionFromItsContent) {
  const std::string dir = FreshDir("command_camera");
  const std::string source = TestPhoto(dir);
  const std::string shooter =
      Script(dir, "shoot.sh", "echo \"$2 $3\" >> " + dir + "/calls\ncp " + source + " \"$2\"\n");
  auto camera = MakeCamera("command:" + shooter);
  CameraSettings settings;
  settings.capture_timeout_s = 5;
  camera->Connect(settings, nullptr);
  EXPECT_TRUE(camera->ShutterSpeeds().empty());
  camera->SetShutterSpeed(0.25);
  const std::string path = camera->Capture(dir + "/pos_0_0_p_0");
  EXPECT_EQ(path, dir + "/pos_0_0_p_0.png");
  EXPECT_EQ(FileBytes(path), FileBytes(source));
  EXPECT_NE(FileBytes(dir + "/calls").find(" 0.25\n"), std::string::npos);
  // A program that exits 0 without a photo, and one that writes no image.
  auto lazy = MakeCamera("command:" + Script(dir, "lazy.sh", "exit 0\n"));
  lazy->Connect(settings, nullptr);
  EXPECT_THROW(lazy->Capture(dir + "/x"), Error);
  auto garbage = MakeCamera("command:" + Script(dir, "garbage.sh", "echo hello > \"$2\"\n"));
  garbage->Connect(settings, nullptr);
  ExpectBadInput([&] { garbage->Capture(dir + "/y"); }, "");
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_NE(e.path().filename().string()[0], '.') << "temporary left: " << e.path();
}

TEST(FolderCamera, EachPhotoIsTheNextNewFileOnceItStopsGrowing) {
  const std::string dir = FreshDir("folder_camera");
  const std::string source = TestPhoto(dir);
  fs::create_directories(dir + "/tether");
  fs::copy_file(source, dir + "/tether/OLD_0001.PNG");  // there before: not a photo of ours
  auto camera = MakeCamera("folder:" + dir + "/tether");
  CameraSettings settings;
  settings.capture_timeout_s = 5;
  camera->Connect(settings, nullptr);
  std::thread tether([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    fs::copy_file(source, dir + "/tether/IMG_0002.PNG");
  });
  const std::string path = camera->Capture(dir + "/pos_1_0_n_0");
  tether.join();
  EXPECT_EQ(path, dir + "/pos_1_0_n_0.png");
  EXPECT_EQ(FileBytes(path), FileBytes(source));
  // Nothing new: a DeviceError at the timeout.
  settings.capture_timeout_s = 1;
  camera->Connect(settings, nullptr);
  try {
    camera->Capture(dir + "/none");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kFailure);
    EXPECT_NE(std::string(e.what()).find("no new photo"), std::string::npos) << e.what();
  }
  ExpectBadInput([&] { MakeCamera("folder:" + dir + "/nowhere")->Connect(settings, nullptr); },
                 "folder not found");
}

TEST(Operator, AProgramCarriesOutTheStepsAndTheTerminalNeedsAnAnswer) {
  const std::string dir = FreshDir("operator");
  const std::string program = Script(dir, "op.sh", "echo \"$1 $2\" >> " + dir + "/steps\n");
  DeviceLog log(dir + "/devices.log");
  Operator automated(&log, program, 5);
  automated.Ask("slide", "n", "Put slide T- (n) in the holder", "changing to slide n");
  EXPECT_EQ(FileBytes(dir + "/steps"), "slide n\n");
  // The terminal operator with stdin at its end (as under a pipeline with no one there).
  const int saved_stdin = dup(0);
  const int null_fd = open("/dev/null", O_RDONLY);
  dup2(null_fd, 0);
  close(null_fd);
  Operator terminal(&log);
  try {
    terminal.Ask("board", "on", "Put the board on the screen", "placing the board");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("standard input ended"), std::string::npos) << e.what();
  }
  dup2(saved_stdin, 0);
  close(saved_stdin);
}

}  // namespace
}  // namespace lumislab
