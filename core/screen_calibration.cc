#include "core/screen_calibration.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>

#include "core/error.h"
#include "core/json.h"

namespace lumislab {

Eigen::Vector2d ScreenCalibration::Undistort(const Eigen::Vector2d& pixel) const {
  if (camera) return camera->PinholePixel(camera->UndistortToNormalised(pixel));
  const Eigen::Vector2d d = pixel - centre_px;
  const double r2 = d.squaredNorm() / (scale_px * scale_px);
  return centre_px + d * (1.0 + k1 * r2 + k2 * r2 * r2);
}

Eigen::Vector2d ScreenCalibration::Distort(const Eigen::Vector2d& undistorted) const {
  if (camera) {
    const Eigen::Vector2d d = camera->Distort(camera->Normalised(undistorted));
    return camera->PinholePixel(d);
  }
  if (k1 == 0 && k2 == 0) return undistorted;
  // Solve Undistort(p) = q by Newton on the radius (the model is radial).
  const Eigen::Vector2d q = undistorted - centre_px;
  const double rq = q.norm() / scale_px;
  if (rq == 0) return undistorted;
  double r = rq;
  for (int it = 0; it < 20; ++it) {
    const double r2 = r * r;
    const double f = r * (1 + k1 * r2 + k2 * r2 * r2) - rq;
    const double df = 1 + 3 * k1 * r2 + 5 * k2 * r2 * r2;
    if (std::abs(df) < 1e-12) break;
    const double step = f / df;
    r -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return centre_px + q * (r / rq);
}

Eigen::Vector2d ScreenCalibration::ScreenFromImage(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector3d h = screen_from_image * Undistort(pixel).homogeneous();
  return h.hnormalized();
}

Eigen::Vector2d ScreenCalibration::ImageFromScreen(const Eigen::Vector2d& screen_mm) const {
  const Eigen::Vector3d h = screen_from_image.inverse() * screen_mm.homogeneous();
  return Distort(h.hnormalized());
}

ScreenCalibration ScreenCalibration::Load(const std::string& path) {
  const JsonDocument doc = JsonDocument::Load(path);
  doc.CheckSchemaVersion(kScreenCalibrationSchemaVersion);
  const JsonView root = doc.root();
  ScreenCalibration c;
  c.image_width = root["image_size"][0].IntIn(1, 1 << 16);
  c.image_height = root["image_size"][1].IntIn(1, 1 << 16);
  const std::vector<double> h = root["screen_from_image"].Numbers(9);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.screen_from_image(r, k) = h[r * 3 + k];
  const double det = c.screen_from_image.determinant();
  if (!std::isfinite(det) || std::abs(det) < 1e-300)
    root["screen_from_image"].Fail("an invertible 3x3 homography");
  const JsonView dist = root["distortion"];
  if (dist["model"].OneOf({"radial2", "opencv5"}) == "opencv5") {
    CameraModel m;  // as calib/camera.json holds it
    m.image_width = c.image_width;
    m.image_height = c.image_height;
    ReadCameraModel(dist["camera_matrix"], dist, &m);
    c.camera = m;
    c.camera_file = dist.StringOr("camera_file", "");
  } else {
    // |k| beyond 10 over a radius of one half-diagonal is no lens: a corrupt file.
    c.k1 = dist["k1"].NumberIn(-10, 10);
    c.k2 = dist["k2"].NumberIn(-10, 10);
    const std::vector<double> centre = dist["centre_px"].Numbers(2);
    c.centre_px = {centre[0], centre[1]};
    c.scale_px = dist["scale_px"].NumberIn(1, 1e6);
  }
  const JsonView report = root["report"];
  c.rms_px = report["rms_px"].NumberIn(0, 1e9);
  c.rms_mm = report["rms_mm"].NumberIn(0, 1e9);
  c.corners_used = report["corners_used"].IntAtLeast(0);
  c.photo = report.StringOr("photo", "");
  c.method = report.StringOr("method", "");
  return c;
}

void ScreenCalibration::Save(const std::string& path) const {
  nlohmann::json j;
  j["schema_version"] = kScreenCalibrationSchemaVersion;
  j["image_size"] = {image_width, image_height};
  std::vector<double> h;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) h.push_back(screen_from_image(r, k));
  j["screen_from_image"] = h;
  j["screen_from_image_note"] = "row-major; undistorted pixel (OpenCV centres) -> lab mm on screen";
  if (camera) {
    j["distortion"] = DistortionJson(*camera);
    j["distortion"]["camera_matrix"] = CameraMatrixJson(*camera);
    j["distortion"]["camera_file"] = camera_file;
    j["screen_from_image_note"] =
        "row-major; ideal pinhole pixel (fx x + cx, fy y + cy of the undistorted ray) -> lab mm "
        "on screen";
  } else {
    j["distortion"] = {{"model", "radial2"},
                       {"k1", k1},
                       {"k2", k2},
                       {"centre_px", {centre_px.x(), centre_px.y()}},
                       {"scale_px", scale_px}};
  }
  j["report"] = {
      {"rms_px", rms_px}, {"rms_mm", rms_mm}, {"corners_used", corners_used}, {"photo", photo}};
  if (!method.empty()) j["report"]["method"] = method;
  WriteJsonAtomically(path, j);
}

}  // namespace lumislab
