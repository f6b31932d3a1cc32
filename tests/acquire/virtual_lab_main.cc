// virtual_lab: the lab `acquire capture` is tested in, as a program (virtual_lab.h): a GRBL stage
// on a pseudo-terminal and a PTP/IP camera on 127.0.0.1 that photographs a synthetic scene's
// luminaire where the stage holds it. Bounded in time (--seconds).
//
//   virtual_lab --scene default --lab lab.json --dir <folder> [--speed-factor 1] [--seconds 600]
//
// <folder>/setup.json   the setup to capture with (the scene's, its scale, the lab block)
// <folder>/grbl         a link to the stage's serial port (grbl:<folder>/grbl)
// <folder>/camera       the camera's libgphoto2 port (gphoto2@$(cat <folder>/camera))
// <folder>/control/     the operator's actions (slide, board; tests/acquire/lab_operator.sh) and
//                       faults to inject: a file "fault" holding stage-silent, stage-alarm <N>,
//                       camera-gone, camera-stall or camera-delay <s>, taken (and removed) within
//                       50 ms
// <folder>/ready        written last, once both devices listen
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "acquire/lab_setup.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json.h"
#include "grbl_emulator.h"
#include "lib/synthetic/scene.h"
#include "ptpip_camera_emulator.h"
#include "virtual_lab.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

volatile sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

int Run(int argc, char** argv) {
  CLI::App app{"virtual_lab: an emulated GRBL stage and PTP/IP camera photographing a scene"};
  std::string scene_source = "default", lab_file, dir;
  double speed_factor = 1, seconds = 600;
  app.add_option("--scene", scene_source, "scene file or default")->capture_default_str();
  app.add_option("--lab", lab_file, "the lab block (JSON) of the setup")->required();
  app.add_option("--dir", dir, "folder for the setup, the port link and the control files")
      ->required();
  app.add_option("--speed-factor", speed_factor, "the stage's simulated time runs this faster")
      ->check(CLI::Range(0.01, 1e4));
  app.add_option("--seconds", seconds, "serve this long at most")->check(CLI::Range(1, 86400));
  CLI11_PARSE(app, argc, argv);

  const SynthScene scene = LoadScene(scene_source);
  const std::string lab_json = ReadTextFile(lab_file);
  const JsonDocument lab_doc = JsonDocument::Parse(lab_json, lab_file);
  const LabSetup lab = ParseLabSetup(lab_doc.root());
  MakeDirectories(dir + "/control");
  std::error_code ec;
  fs::remove(dir + "/ready", ec);
  fs::remove(dir + "/control/fault", ec);
  WriteTextAtomically(dir + "/control/slide", "none\n");
  WriteTextAtomically(dir + "/control/board", "off\n");

  virtual_lab::Optics optics(scene, lab, dir + "/control");
  WriteTextAtomically(dir + "/setup.json",
                      virtual_lab::SetupJson(scene, optics.radiometric_scale(), lab_json));

  GrblEmulatorOptions grbl_options;
  grbl_options.speed_factor = speed_factor;
  for (const LabSetup::Travel& t : lab.travel) {
    const int axis = t.axis == 'X'   ? 0
                     : t.axis == 'Y' ? 1
                     : t.axis == 'Z' ? 2
                     : t.axis == 'A' ? 3
                                     : -1;
    if (axis < 0) continue;
    if (axis == 3) grbl_options.axes = 4;  // a rotary axis (lab.rotation_axis)
    grbl_options.travel_min_mm[axis] = t.min_mm;
    grbl_options.travel_max_mm[axis] = t.max_mm;
    // The linear axes start and home at their travel's low end, the rotary one at 0 degrees.
    const double rest = axis == 3 ? std::clamp(0.0, t.min_mm, t.max_mm) : t.min_mm;
    grbl_options.start_mm[axis] = rest;
    grbl_options.home_mm[axis] = rest;
  }
  grbl_options.require_homing = lab.stage.home;
  GrblEmulator stage(grbl_options);
  stage.Link(dir + "/grbl");

  PtpipCameraEmulator camera(0, [&](const PtpipCameraEmulator::ShotSettings& shot) {
    const GrblAxes p = stage.Position();
    const virtual_lab::LabPhoto photo =
        optics.Shoot({{'X', p[0]}, {'Y', p[1]}, {'Z', p[2]}, {'A', p[3]}}, shot.exposure_time_s);
    return PtpipCameraEmulator::Photo{photo.extension, photo.bytes};
  });
  WriteTextAtomically(dir + "/camera", camera.ptpip_path() + "\n");
  WriteTextAtomically(dir + "/ready", std::to_string(getpid()) + "\n");
  std::fprintf(stderr, "virtual_lab: stage grbl:%s/grbl, camera gphoto2@%s, scale %g W/m^2\n",
               dir.c_str(), camera.ptpip_path().c_str(), optics.radiometric_scale());

  signal(SIGINT, OnSignal);
  signal(SIGTERM, OnSignal);
  const auto start = std::chrono::steady_clock::now();
  while (!g_stop &&
         std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
             seconds) {
    usleep(50000);
    std::ifstream fault_file(dir + "/control/fault");
    if (!fault_file) continue;
    std::string fault;
    double value = 0;
    fault_file >> fault >> value;
    fault_file.close();
    fs::remove(dir + "/control/fault", ec);
    std::fprintf(stderr, "virtual_lab: fault %s %g\n", fault.c_str(), value);
    if (fault == "stage-silent")
      stage.SetSilent(true);
    else if (fault == "stage-alarm")
      stage.InjectAlarm(int(value));
    else if (fault == "camera-gone")
      camera.Disappear();
    else if (fault == "camera-stall")
      camera.Stall();
    else if (fault == "camera-delay")
      camera.SetCaptureDelay(value);
  }
  std::fprintf(stderr, "virtual_lab: %d photos taken; stopping\n", optics.photos_taken());
  return 0;
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) {
  return lumislab::RunMain("virtual_lab", [&] { return lumislab::Run(argc, argv); });
}
