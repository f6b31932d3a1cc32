#include "calibrate/cli_screen.h"

#include <filesystem>
#include <sstream>

#include "core/atomic_file.h"
#include "core/checks.h"
#include "core/error.h"
#include "core/log.h"

namespace lumislab {

namespace {

// "screen.board_mirrored": a board seen the other way round from the usual set-up (camera behind
// the screen) is legitimate (a camera on the luminaire's side, a board pinned mirrored on
// purpose) but turns the slab over if the lab did not mean it: a warning, recorded.
void CheckBoardHandedness(const Dataset& dataset, const ScreenCalibration& c,
                          const ScreenCalibrationReport& report) {
  CheckLog checks(dataset.dir, "calibrate screen");
  const nlohmann::json values = {{"handedness", report.handedness},
                                 {"usual_handedness", kUsualHandedness}};
  if (MirroredBoard(report))
    checks.Warn("screen.board_mirrored",
                dataset.Path(c.photo) +
                    ": the calibration board is seen mirrored (its corners turn the other way "
                    "round from the usual set-up, the board pinned the right way round and the "
                    "camera behind the screen): the board is pinned mirrored, or the camera is on "
                    "the luminaire's side of the screen; the slab comes out mirrored unless the "
                    "lab meant that",
                values);
  else
    checks.Pass("screen.board_mirrored",
                "the board is seen as in the usual set-up (the camera behind the screen)", values);
  checks.Save();
}

int RunScreen(const ScreenCommand& command, int threads) {
  std::ostringstream params;
  params << "dataset=" << command.dataset_dir << " force=" << (command.force ? "yes" : "no")
         << " threads=" << threads << " huber_px=" << command.options.refiner.huber_px
         << " distortion_terms=" << command.options.refiner.distortion_terms
         << " max_rms_px=" << command.options.max_rms_px
         << " max_detection_px=" << command.options.detection.max_detection_px;
  LogInfo("parameters: ", params.str());
  const Dataset dataset = Dataset::Load(command.dataset_dir);
  const std::string out = dataset.Path("calib/screen.json");
  if (std::filesystem::exists(out) && !command.force) {
    LogInfo(out, " exists, skipping (use --force to recalibrate)");
    return 0;
  }
  ScreenCalibrationReport report;
  const ScreenCalibration c = CalibrateScreen(dataset, command.options, &report);
  MakeDirectories(dataset.Path("calib"));
  RemoveOrphanedTemporaries(dataset.Path("calib"));
  c.Save(out);
  LogInfo("board: ", c.corners_used, " corners (", report.corners.detector, " detector, grid ",
          report.corners.orientation, ", squares ", report.corners.square_px, " px, dot contrast ",
          report.corners.dot_contrast, ")");
  LogInfo("view: board covers ", 100 * report.board_fraction,
          " % of the photo, local stretch <= ", report.anisotropy, ", condition ",
          report.condition);
  LogDebug("ceres: ", report.refinement.message);
  if (c.camera) {
    const CameraModel& m = *c.camera;
    LogInfo("model: camera+pose: the lens of ", c.camera_file, " (fx = ", m.fx, ", fy = ", m.fy,
            ", cx = ", m.cx, ", cy = ", m.cy, " px; k1 = ", m.k1, ", k2 = ", m.k2, ", p1 = ", m.p1,
            ", p2 = ", m.p2, ", k3 = ", m.k3, "), the screen's pose solved (rotation ",
            report.pose.head<3>().transpose(), " rad, translation ",
            report.pose.tail<3>().transpose(), " mm; solvePnP ", report.pnp_rms_px,
            " px before Ceres)");
  } else {
    std::ostringstream by_terms;
    for (size_t t = 0; t < report.rms_px_by_terms.size(); ++t)
      by_terms << (t ? ", " : "") << t << ": " << report.rms_px_by_terms[t] << " px";
    LogInfo("model: homography+radial2 from the board photo alone (no ",
            dataset.Path("calib/camera.json"), "): k1 = ", c.k1, ", k2 = ", c.k2, " (",
            report.distortion_terms, " term(s) chosen; RMS by terms ", by_terms.str(), "; scale ",
            c.scale_px, " px)");
  }
  LogInfo("rms: ", c.rms_px, " px, ", c.rms_mm, " mm on the screen (", c.method,
          "; OpenCV homography alone: ", report.initial_rms_px, " px) -> ", out);
  CheckBoardHandedness(dataset, c, report);
  return 0;
}

}  // namespace

void AddScreenCommand(CLI::App* app, CommonOptions* common, ScreenCommand* command) {
  ScreenCommand& screen = *command;
  CLI::App* sub = app->add_subcommand(
      "screen",
      "photo of the checkerboard on the screen -> calib/screen.json (image -> screen mm, "
      "homography + radial distortion)");
  screen.sub = sub;
  sub->add_option("--dataset", screen.dataset_dir, "dataset folder (with dataset.json)")
      ->required();
  sub->add_flag("--force", screen.force, "recalibrate even if calib/screen.json exists");
  AddCommonOptions(sub, common);
  sub->add_option("--huber-px", screen.options.refiner.huber_px,
                  "scale of the robust (Huber) loss, pixels")
      ->check(FiniteIn(1e-3, 1e3))
      ->capture_default_str();
  sub->add_option("--distortion-terms", screen.options.refiner.distortion_terms,
                  "radial terms to fit: 0, 1 (k1) or 2 (k1, k2)")
      ->check(CLI::Range(0, 2))
      ->capture_default_str();
  sub->add_option("--max-rms-px", screen.options.max_rms_px,
                  "refuse the calibration when the reprojection RMS exceeds this (pixels)")
      ->check(FiniteIn(1e-3, 1e3))
      ->capture_default_str();
  sub->add_option("--max-detection-px", screen.options.detection.max_detection_px,
                  "find corners on a copy whose long side is at most this (pixels)")
      ->check(CLI::Range(200, 100000))
      ->capture_default_str();
}

int RunScreenCommand(ScreenCommand* command, int threads) {
  ScreenCommand& screen = *command;
  screen.options.refiner.threads = threads;
  screen.options.Check();
  screen.dataset_dir = TrimTrailingSlashes(screen.dataset_dir);
  return RunScreen(screen, threads);
}

}  // namespace lumislab
