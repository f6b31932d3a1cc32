#include "core/camera_calibration.h"

#include <cmath>

#include "core/error.h"
#include "core/json.h"

namespace lumislab {

namespace {

const char* const kSigmaNames[9] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};

// |coefficient| beyond this is no lens a board calibration can describe: a corrupt file.
constexpr double kMaxDistortion = 1e3;

}  // namespace

Eigen::Vector2d CameraCalibration::Distort(const Eigen::Vector2d& n) const {
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d CameraCalibration::Project(const Eigen::Vector3d& point_camera) const {
  const Eigen::Vector2d d = Distort(point_camera.head<2>() / point_camera.z());
  return {fx * d.x() + cx, fy * d.y() + cy};
}

Eigen::Vector2d CameraCalibration::UndistortToNormalised(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  // x = (x_d - tangential(x)) / radial(x), iterated from x = x_d (cv::undistortPoints' scheme,
  // with more iterations and a stop on convergence).
  Eigen::Vector2d n = d;
  for (int it = 0; it < 100; ++it) {
    const double x = n.x(), y = n.y();
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const Eigen::Vector2d tangential(2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                                     p1 * (r2 + 2 * y * y) + 2 * p2 * x * y);
    const Eigen::Vector2d next = (d - tangential) / radial;
    const double step = (next - n).norm();
    n = next;
    if (step < 1e-15) break;
  }
  return n;
}

int CameraCalibration::ViewsUsed() const {
  int n = 0;
  for (const auto& v : views) n += v.used ? 1 : 0;
  return n;
}

CameraCalibration CameraCalibration::Load(const std::string& path) {
  const JsonDocument doc = JsonDocument::Load(path);
  doc.CheckSchemaVersion(kCameraCalibrationSchemaVersion);
  const JsonView root = doc.root();
  CameraCalibration c;
  c.image_width = root["image_size"][0].IntIn(1, 1 << 16);
  c.image_height = root["image_size"][1].IntIn(1, 1 << 16);
  const JsonView k = root["camera_matrix"];
  c.fx = k["fx"].NumberIn(1, 1e7);
  c.fy = k["fy"].NumberIn(1, 1e7);
  // The principal point may lie off the photo (a shifted lens) but not far from it.
  c.cx = k["cx"].NumberIn(-c.image_width, 2.0 * c.image_width);
  c.cy = k["cy"].NumberIn(-c.image_height, 2.0 * c.image_height);
  const JsonView dist = root["distortion"];
  dist["model"].OneOf({"opencv5"});
  c.k1 = dist["k1"].NumberIn(-kMaxDistortion, kMaxDistortion);
  c.k2 = dist["k2"].NumberIn(-kMaxDistortion, kMaxDistortion);
  c.p1 = dist["p1"].NumberIn(-kMaxDistortion, kMaxDistortion);
  c.p2 = dist["p2"].NumberIn(-kMaxDistortion, kMaxDistortion);
  c.k3 = dist["k3"].NumberIn(-kMaxDistortion, kMaxDistortion);

  const JsonView board = root["board"];
  c.board.type = board["type"].OneOf({"chessboard", "charuco"});
  c.board.inner_cols = board["inner_corners"][0].IntIn(2, 1000);
  c.board.inner_rows = board["inner_corners"][1].IntIn(2, 1000);
  c.board.square_mm = board["square_mm"].NumberIn(1e-3, 1e5);
  if (c.board.type == "charuco") {
    c.board.dictionary = board["dictionary"].String();
    c.board.marker_mm = board["marker_mm"].NumberIn(1e-3, c.board.square_mm);
  }

  const JsonView report = root["report"];
  c.rms_px = report["rms_px"].NumberIn(0, 1e9);
  c.opencv_rms_px = report["opencv_rms_px"].NumberIn(0, 1e9);
  if (report.Has("sigma")) {
    const JsonView sigma = report["sigma"];
    for (const char* name : kSigmaNames) c.sigma.push_back(sigma[name].NumberIn(0, 1e9));
  }
  const JsonView views = report["views"];
  for (size_t i = 0; i < views.Size(); ++i) {
    const JsonView v = views[i];
    CameraViewReport view;
    view.photo = v["photo"].String();
    view.used = v["used"].Bool();
    view.corners = v["corners"].IntAtLeast(0);
    if (view.used) {
      view.rms_px = v["rms_px"].NumberIn(0, 1e9);
      view.tilt_deg = v["tilt_deg"].NumberIn(0, 180);
      const std::vector<double> r = v["rotation"].Numbers(3);
      const std::vector<double> t = v["translation_mm"].Numbers(3);
      view.rotation = {r[0], r[1], r[2]};
      view.translation_mm = {t[0], t[1], t[2]};
    } else {
      view.rejected = v["rejected"].String();
    }
    c.views.push_back(view);
  }
  if (c.ViewsUsed() < 1) report["views"].Fail("at least one view with \"used\": true");
  return c;
}

void CameraCalibration::Save(const std::string& path) const {
  nlohmann::json j;
  j["schema_version"] = kCameraCalibrationSchemaVersion;
  j["image_size"] = {image_width, image_height};
  j["camera_matrix"] = {{"fx", fx}, {"fy", fy}, {"cx", cx}, {"cy", cy}};
  j["distortion"] = {{"model", "opencv5"}, {"k1", k1}, {"k2", k2},
                     {"p1", p1},           {"p2", p2}, {"k3", k3}};
  j["distortion_note"] =
      "OpenCV's model; distortion_coefficients in calib/camera.yaml are (k1, k2, p1, p2, k3)";
  nlohmann::json b = {{"type", board.type},
                      {"inner_corners", {board.inner_cols, board.inner_rows}},
                      {"square_mm", board.square_mm}};
  if (board.type == "charuco") {
    b["dictionary"] = board.dictionary;
    b["marker_mm"] = board.marker_mm;
  }
  j["board"] = b;
  nlohmann::json report = {{"rms_px", rms_px}, {"opencv_rms_px", opencv_rms_px}};
  if (sigma.size() == 9) {
    nlohmann::json s;
    for (int i = 0; i < 9; ++i) s[kSigmaNames[i]] = sigma[i];
    report["sigma"] = s;
  }
  nlohmann::json views_json = nlohmann::json::array();
  for (const auto& v : views) {
    nlohmann::json e = {{"photo", v.photo}, {"used", v.used}, {"corners", v.corners}};
    if (v.used) {
      e["rms_px"] = v.rms_px;
      e["tilt_deg"] = v.tilt_deg;
      e["rotation"] = {v.rotation.x(), v.rotation.y(), v.rotation.z()};
      e["translation_mm"] = {v.translation_mm.x(), v.translation_mm.y(), v.translation_mm.z()};
    } else {
      e["rejected"] = v.rejected;
    }
    views_json.push_back(e);
  }
  report["views"] = views_json;
  j["report"] = report;
  WriteJsonAtomically(path, j);
}

}  // namespace lumislab
