#include "core/camera_calibration.h"

#include <cmath>

#include "core/error.h"
#include "core/json.h"

namespace lumislab {

namespace {

// |coefficient| beyond this is no lens a board calibration can describe: a corrupt file.
constexpr double kMaxDistortion = 1e3;

const char* const kSigmaNames[9] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};

}  // namespace

Eigen::Vector2d CameraModel::Distort(const Eigen::Vector2d& n) const {
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d CameraModel::Project(const Eigen::Vector3d& point_camera) const {
  const Eigen::Vector2d d = Distort(point_camera.head<2>() / point_camera.z());
  return {fx * d.x() + cx, fy * d.y() + cy};
}

namespace {

// d Distort / d (x, y) of the five-coefficient model.
Eigen::Matrix2d DistortionJacobian(const CameraModel& m, double x, double y) {
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (m.k1 + r2 * (m.k2 + r2 * m.k3));
  const double dradial_dr2 = m.k1 + r2 * (2 * m.k2 + 3 * r2 * m.k3);
  Eigen::Matrix2d j;
  j(0, 0) = radial + 2 * x * x * dradial_dr2 + 2 * m.p1 * y + 6 * m.p2 * x;
  j(0, 1) = 2 * x * y * dradial_dr2 + 2 * m.p1 * x + 2 * m.p2 * y;
  j(1, 0) = 2 * x * y * dradial_dr2 + 2 * m.p1 * x + 2 * m.p2 * y;
  j(1, 1) = radial + 2 * y * y * dradial_dr2 + 6 * m.p1 * y + 2 * m.p2 * x;
  return j;
}

}  // namespace

Eigen::Vector2d CameraModel::UndistortToNormalised(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  // Newton from x = x_d: a few steps to machine precision where the model is invertible. The
  // synthetic lens undistorts every sample of every photo through here, so speed matters.
  Eigen::Vector2d n = d;
  for (int it = 0; it < 20; ++it) {
    const Eigen::Vector2d residual = Distort(n) - d;
    if (residual.squaredNorm() < 1e-30) return n;
    const Eigen::Matrix2d j = DistortionJacobian(*this, n.x(), n.y());
    const double det = j(0, 0) * j(1, 1) - j(0, 1) * j(1, 0);
    if (!(std::abs(det) > 1e-12)) break;
    const Eigen::Vector2d step((j(1, 1) * residual.x() - j(0, 1) * residual.y()) / det,
                               (j(0, 0) * residual.y() - j(1, 0) * residual.x()) / det);
    n -= step;
    if (step.squaredNorm() < 1e-30) return n;
  }
  // Fallback: x = (x_d - tangential(x)) / radial(x), iterated from x = x_d (cv::undistortPoints'
  // scheme, with more iterations and a stop on convergence).
  n = d;
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

void ReadCameraModel(const JsonView& camera_matrix, const JsonView& distortion, CameraModel* m) {
  m->fx = camera_matrix["fx"].NumberIn(1, 1e7);
  m->fy = camera_matrix["fy"].NumberIn(1, 1e7);
  // The principal point may lie off the photo (a shifted lens) but not far from it.
  m->cx = camera_matrix["cx"].NumberIn(-m->image_width, 2.0 * m->image_width);
  m->cy = camera_matrix["cy"].NumberIn(-m->image_height, 2.0 * m->image_height);
  distortion["model"].OneOf({"opencv5"});
  m->k1 = distortion["k1"].NumberIn(-kMaxDistortion, kMaxDistortion);
  m->k2 = distortion["k2"].NumberIn(-kMaxDistortion, kMaxDistortion);
  m->p1 = distortion["p1"].NumberIn(-kMaxDistortion, kMaxDistortion);
  m->p2 = distortion["p2"].NumberIn(-kMaxDistortion, kMaxDistortion);
  m->k3 = distortion["k3"].NumberIn(-kMaxDistortion, kMaxDistortion);
}

nlohmann::json CameraMatrixJson(const CameraModel& m) {
  return {{"fx", m.fx}, {"fy", m.fy}, {"cx", m.cx}, {"cy", m.cy}};
}

nlohmann::json DistortionJson(const CameraModel& m) {
  return {{"model", "opencv5"}, {"k1", m.k1}, {"k2", m.k2},
          {"p1", m.p1},         {"p2", m.p2}, {"k3", m.k3}};
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
  ReadCameraModel(root["camera_matrix"], root["distortion"], &c);

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
  j["camera_matrix"] = CameraMatrixJson(*this);
  j["distortion"] = DistortionJson(*this);
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
