#include "calibrate/cli_camera.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

namespace lumislab {

namespace {

std::string Fixed(double v, int decimals) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

// "name = value +- sigma" for the report.
std::string WithSigma(const CameraCalibration& c, const char* name, double value, int index,
                      int decimals) {
  std::string s = std::string(name) + " = " + Fixed(value, decimals);
  if (c.sigma.size() == 9) s += " +- " + Fixed(c.sigma[size_t(index)], decimals);
  return s;
}

void LogReport(const CameraCalibration& c) {
  for (const auto& v : c.views) {
    if (v.used)
      LogInfo("view ", v.photo, ": ", v.corners, " corners, RMS ", Fixed(v.rms_px, 3), " px, tilt ",
              Fixed(v.tilt_deg, 1), " deg");
    else
      LogInfo("view ", v.photo, ": rejected: ", v.rejected);
  }
  LogInfo("camera: ", WithSigma(c, "fx", c.fx, 0, 2), ", ", WithSigma(c, "fy", c.fy, 1, 2), ", ",
          WithSigma(c, "cx", c.cx, 2, 2), ", ", WithSigma(c, "cy", c.cy, 3, 2), " px");
  LogInfo("distortion: ", WithSigma(c, "k1", c.k1, 4, 5), ", ", WithSigma(c, "k2", c.k2, 5, 5),
          ", ", WithSigma(c, "p1", c.p1, 6, 5), ", ", WithSigma(c, "p2", c.p2, 7, 5), ", ",
          WithSigma(c, "k3", c.k3, 8, 5));
  LogInfo("rms: ", Fixed(c.rms_px, 4), " px over ", c.ViewsUsed(), " of ", c.views.size(),
          " views (OpenCV's calibrateCamera: ", Fixed(c.opencv_rms_px, 4), " px)");
}

}  // namespace

void AddCameraCommand(CLI::App* app, CommonOptions* common, CameraCommand* command) {
  CLI::App* sub = app->add_subcommand(
      "camera",
      "photos of a board from many angles -> calib/camera.json and calib/camera.yaml (intrinsics "
      "fx fy cx cy, distortion k1 k2 p1 p2 k3 in OpenCV's model, per-view report)");
  command->sub = sub;
  sub->add_option("--photos", command->photos,
                  "the board photos: folders (their photo files), glob patterns or files")
      ->required();
  sub->add_option("--board", command->board_size,
                  "inner corners of the board, <cols>x<rows> as OpenCV counts them (9x6 for a "
                  "board of 10 x 7 squares)")
      ->required();
  sub->add_option("--square-mm", command->board.square_mm, "side of one board square, mm")
      ->required()
      ->check(FiniteIn(1e-3, 1e5));
  sub->add_option("--charuco", command->board.charuco_dictionary,
                  "the board is a ChArUco board with markers of this OpenCV dictionary (e.g. "
                  "DICT_5X5_100); its corners may be partly out of view");
  sub->add_option("--marker-mm", command->board.marker_mm, "ChArUco marker side, mm")
      ->check(FiniteIn(1e-3, 1e5));
  CLI::Option* dataset = sub->add_option("--dataset", command->dataset_dir,
                                         "dataset folder: writes calib/camera.json and .yaml");
  CLI::Option* out =
      sub->add_option("--out", command->out, "or write this .json file and the .yaml beside it");
  dataset->excludes(out);
  sub->add_flag("--force", command->force, "recalibrate even if the outputs exist");
  AddCommonOptions(sub, common);
  sub->add_option("--huber-px", command->options.refiner.huber_px,
                  "scale of the robust (Huber) loss, pixels")
      ->check(FiniteIn(1e-3, 1e3))
      ->capture_default_str();
  sub->add_option("--min-views", command->options.min_views, "usable views needed (>= 3)")
      ->check(CLI::Range(3, 100000))
      ->capture_default_str();
  sub->add_option("--outlier-factor", command->options.outlier_factor,
                  "drop a view whose RMS exceeds this times the median view RMS (and "
                  "--outlier-floor-px)")
      ->check(FiniteIn(1, 1e6))
      ->capture_default_str();
  sub->add_option("--outlier-floor-px", command->options.outlier_floor_px,
                  "never drop a view whose RMS is below this, pixels")
      ->check(FiniteIn(1e-3, 1e6))
      ->capture_default_str();
  sub->add_option("--min-tilt-deg", command->options.min_tilt_deg,
                  "some board must be tilted by this from facing the camera, and two boards "
                  "by this from each other (else the focal length is unknown)")
      ->check(FiniteIn(0, 89))
      ->capture_default_str();
  sub->footer(
      "Every photo must have the same size. Views where the board is not found, and views whose "
      "RMS is an outlier, are left out and listed in the report. Exit 2 for fewer than "
      "--min-views usable views, a board found nowhere, photos of mixed sizes, or views that "
      "do not constrain the focal length (all boards facing the camera or all parallel).");
}

int RunCameraCommand(CameraCommand* command, int threads) {
  CameraCommand& c = *command;
  if (c.dataset_dir.empty() && c.out.empty())
    throw BadInput("calibrate camera: one of --dataset or --out is required");
  ParseBoardSize(c.board_size, &c.board);
  c.board.Check();
  c.options.threads = threads;
  c.options.refiner.threads = threads;
  c.options.Check();

  std::string json_path, yaml_path;
  if (!c.dataset_dir.empty()) {
    c.dataset_dir = TrimTrailingSlashes(c.dataset_dir);
    if (!std::filesystem::is_directory(c.dataset_dir))
      throw BadInput(c.dataset_dir + ": dataset folder not found");
    json_path = c.dataset_dir + "/calib/camera.json";
    yaml_path = c.dataset_dir + "/calib/camera.yaml";
  } else {
    const std::filesystem::path out(c.out);
    if (out.extension() != ".json" || out.stem().empty())
      throw BadInput("--out: expected a file name ending in .json, got \"" + c.out + "\"");
    json_path = c.out;
    yaml_path = std::filesystem::path(out).replace_extension(".yaml").string();
  }
  std::ostringstream params;
  params << "photos=";
  for (size_t i = 0; i < c.photos.size(); ++i) params << (i ? "," : "") << c.photos[i];
  params << " board=" << c.board.inner_cols << "x" << c.board.inner_rows
         << " square_mm=" << c.board.square_mm;
  if (c.board.IsCharuco())
    params << " charuco=" << c.board.charuco_dictionary << " marker_mm=" << c.board.marker_mm;
  params << " out=" << json_path << " force=" << (c.force ? "yes" : "no") << " threads=" << threads
         << " huber_px=" << c.options.refiner.huber_px << " min_views=" << c.options.min_views
         << " outlier_factor=" << c.options.outlier_factor
         << " outlier_floor_px=" << c.options.outlier_floor_px
         << " min_tilt_deg=" << c.options.min_tilt_deg;
  LogInfo("parameters: ", params.str());
  if (std::filesystem::exists(json_path) && std::filesystem::exists(yaml_path) && !c.force) {
    LogInfo(json_path, " exists, skipping (use --force to recalibrate)");
    return 0;
  }

  const std::vector<std::string> photos = ExpandPhotoArguments(c.photos);
  LogInfo("calibrating from ", photos.size(), " photo(s)");
  const CameraCalibration camera = CalibrateCamera(photos, c.board, c.options);
  LogReport(camera);

  const std::string dir = std::filesystem::path(json_path).parent_path().string();
  if (!dir.empty()) {
    MakeDirectories(dir);
    RemoveOrphanedTemporaries(dir);
  }
  // The YAML first: camera.json is the one a resumed run looks for.
  WriteCameraYaml(camera, yaml_path);
  camera.Save(json_path);
  LogInfo("wrote ", json_path, " and ", yaml_path);
  return 0;
}

}  // namespace lumislab
