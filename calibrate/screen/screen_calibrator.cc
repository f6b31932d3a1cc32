#include "calibrate/screen/screen_calibrator.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/calib3d.hpp>

#include "calibrate/camera/camera_refiner.h"
#include "calibrate/gray_stretch.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/log.h"
#include "lib/photo/photo_io.h"

namespace lumislab {

namespace {

Eigen::Matrix3d ToEigen(const cv::Mat& h) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = h.at<double>(r, c);
  return m;
}

// Checks the starting homography describes a usable view of the board; fills the report.
void CheckView(const BoardCorners& corners, const Eigen::Matrix3d& h, const cv::Size& size,
               const CalibrationTarget& target, const std::string& photo,
               const ScreenCalibratorOptions& options, ScreenCalibrationReport* report) {
  const int nc = target.squares_x - 1, nr = target.squares_y - 1;
  const auto& p = corners.pixels;
  const Eigen::Vector2d quad[4] = {p[0], p[nc - 1], p[nc * nr - 1], p[nc * (nr - 1)]};
  double area = 0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d &a = quad[k], &b = quad[(k + 1) % 4];
    area += a.x() * b.y() - a.y() * b.x();
  }
  report->board_fraction = 0.5 * std::abs(area) / (double(size.width) * size.height);
  if (report->board_fraction < options.min_board_fraction)
    throw BadInput(photo + ": degenerate view: the board covers only " +
                   Num(100 * report->board_fraction) +
                   " % of the photo (need >= " + Num(100 * options.min_board_fraction) + " %)");

  double min_det = HUGE_VAL, max_det = 0, anisotropy = 0;
  int sign = 0;
  for (const auto& q : p) {
    const Eigen::Matrix2d j = HomographyJacobian(h, q);  // mm per pixel
    const double det = j.determinant();
    const int s = det > 0 ? 1 : det < 0 ? -1 : 0;
    if (s == 0 || !std::isfinite(det) || (sign != 0 && s != sign))
      throw BadInput(photo + ": degenerate view: the image -> screen mapping folds over the board");
    sign = s;
    const Eigen::Vector2d sv = Eigen::JacobiSVD<Eigen::Matrix2d>(j).singularValues();
    anisotropy = std::max(anisotropy, sv(0) / sv(1));
    min_det = std::min(min_det, std::abs(det));
    max_det = std::max(max_det, std::abs(det));
  }
  report->handedness = sign;
  report->anisotropy = anisotropy;
  report->scale_ratio = max_det / min_det;
  if (anisotropy > options.max_anisotropy || report->scale_ratio > options.max_scale_ratio)
    throw BadInput(photo + ": degenerate view: grazing angle (local stretch " + Num(anisotropy) +
                   ", need <= " + Num(options.max_anisotropy) + "; scale ratio over the board " +
                   Num(report->scale_ratio) + ", need <= " + Num(options.max_scale_ratio) + ")");

  // Condition number in coordinates normalised like the refinement's.
  Eigen::Vector2d lo = p[0], hi = p[0];
  for (const auto& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  const Eigen::Vector2d c = 0.5 * (lo + hi);
  const double s = std::max(0.5 * (hi - lo).maxCoeff(), 1.0);
  Eigen::Matrix3d t_image = Eigen::Matrix3d::Identity();
  t_image.topLeftCorner<2, 2>() /= s;
  t_image.topRightCorner<2, 1>() = -c / s;
  const double w = target.squares_x * target.square_mm, ht = target.squares_y * target.square_mm;
  Eigen::Matrix3d t_screen = Eigen::Matrix3d::Identity();
  const double ss = 0.5 * std::max(w, ht);
  t_screen.topLeftCorner<2, 2>() /= ss;
  t_screen.topRightCorner<2, 1>() = -(target.origin_mm + 0.5 * Eigen::Vector2d(w, ht)) / ss;
  const Eigen::Vector3d sv =
      Eigen::JacobiSVD<Eigen::Matrix3d>(t_screen * h * t_image.inverse()).singularValues();
  report->condition = sv(0) / sv(2);
  if (!(report->condition <= options.max_condition))
    throw BadInput(photo + ": degenerate view: homography condition number " +
                   Num(report->condition) + " (need <= " + Num(options.max_condition) + ")");
}

// True when p_u(r) = r (1 + k1 r^2 + k2 r^4) increases over [0, r_max].
bool Monotonic(double k1, double k2, double r_max) {
  for (int k = 0; k <= 100; ++k) {
    const double r2 = std::pow(r_max * k / 100.0, 2);
    if (1 + 3 * k1 * r2 + 5 * k2 * r2 * r2 < 0.2) return false;
  }
  return true;
}

double RmsPx(const ScreenCalibration& c, const BoardCorners& corners) {
  double sum = 0;
  for (size_t i = 0; i < corners.pixels.size(); ++i)
    sum += (c.ImageFromScreen(corners.screen_mm[i]) - corners.pixels[i]).squaredNorm();
  return std::sqrt(sum / double(corners.pixels.size()));
}

double RmsMm(const ScreenCalibration& c, const BoardCorners& corners) {
  double sum = 0;
  for (size_t i = 0; i < corners.pixels.size(); ++i)
    sum += (c.ScreenFromImage(corners.pixels[i]) - corners.screen_mm[i]).squaredNorm();
  return std::sqrt(sum / double(corners.pixels.size()));
}

// Refines the mapping with 0, 1 and 2 distortion terms (as far as the board's reach allows) and
// keeps the simplest model that fits nearly as well as the next richer one.
void FitDistortionModel(const BoardCorners& corners, const Eigen::Matrix3d& initial,
                        const ScreenCalibratorOptions& options, const std::string& photo_name,
                        ScreenCalibration* result, ScreenCalibrationReport* report) {
  for (const auto& p : corners.pixels)
    report->board_radius = std::max(report->board_radius, (p - result->centre_px).norm());
  report->board_radius /= result->scale_px;
  const int supported = report->board_radius >= options.min_radius_k2   ? 2
                        : report->board_radius >= options.min_radius_k1 ? 1
                                                                        : 0;
  const int allowed = std::min(options.refiner.distortion_terms, supported);
  if (allowed < options.refiner.distortion_terms)
    LogInfo("the board reaches ", report->board_radius,
            " half-diagonals from the photo centre: at most ", allowed, " distortion term(s)");
  // Fit 0..allowed terms; a fit that bends back inside the photo is not a candidate.
  std::vector<RefinementResult> fits;
  std::vector<double> rms;
  for (int terms = 0; terms <= allowed; ++terms) {
    RefinerOptions refiner = options.refiner;
    refiner.distortion_terms = terms;
    try {
      fits.push_back(RefineScreenMapping(corners.pixels, corners.screen_mm, initial,
                                         result->centre_px, result->scale_px, refiner));
    } catch (const Error& e) {
      throw BadInput(photo_name + ": degenerate view: " + e.what());
    }
    ScreenCalibration candidate = *result;
    candidate.screen_from_image = fits.back().screen_from_image;
    candidate.k1 = fits.back().k1;
    candidate.k2 = fits.back().k2;
    rms.push_back(Monotonic(candidate.k1, candidate.k2, 1.0) ? RmsPx(candidate, corners)
                                                             : HUGE_VAL);
    if (rms.back() == HUGE_VAL)
      LogWarning("distortion with ", terms,
                 " term(s) is not monotonic over the photo (k1 = ", candidate.k1,
                 ", k2 = ", candidate.k2, "); not used");
  }
  int chosen = allowed;
  while (chosen > 0 &&
         (rms[chosen] == HUGE_VAL || rms[chosen - 1] <= options.keep_term_rms_ratio * rms[chosen]))
    --chosen;
  report->rms_px_by_terms = rms;
  report->refinement = fits[chosen];
  report->distortion_terms = chosen;
  result->screen_from_image = report->refinement.screen_from_image;
  result->k1 = report->refinement.k1;
  result->k2 = report->refinement.k2;
  result->rms_px = rms[chosen] == HUGE_VAL ? RmsPx(*result, corners) : rms[chosen];
}

// The screen's pose under the known camera: cv::solvePnP from the distorted corners (OpenCV
// undistorts them with the same model), then Ceres on the 6 pose parameters with the Huber loss
// of the screen refinement. The mapping is then the camera's lens followed by the plane's
// homography H = (K [r1 r2 t])^-1 (core/screen_calibration.h, model "opencv5").
void SolveScreenPose(const BoardCorners& corners, const CameraModel& camera,
                     const ScreenCalibratorOptions& options, const std::string& photo_name,
                     ScreenCalibration* result, ScreenCalibrationReport* report) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  CameraViewData view;
  for (size_t i = 0; i < corners.pixels.size(); ++i) {
    object.emplace_back(corners.screen_mm[i].x(), corners.screen_mm[i].y(), 0.0);
    image.emplace_back(corners.pixels[i].x(), corners.pixels[i].y());
    view.pixels.push_back(corners.pixels[i]);
    view.board_mm.emplace_back(corners.screen_mm[i].x(), corners.screen_mm[i].y(), 0.0);
  }
  const cv::Mat k =
      (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  const cv::Mat d =
      (cv::Mat_<double>(5, 1) << camera.k1, camera.k2, camera.p1, camera.p2, camera.k3);
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(object, image, k, d, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE))
      throw BadInput(photo_name + ": degenerate view (no screen pose under the calibrated camera)");
  } catch (const cv::Exception& e) {
    throw BadInput(photo_name + ": degenerate view (" + e.what() + ")");
  }
  for (int i = 0; i < 3; ++i) {
    view.pose[i] = rvec.at<double>(i);
    view.pose[3 + i] = tvec.at<double>(i);
  }
  const Eigen::Vector4d intrinsics(camera.fx, camera.fy, camera.cx, camera.cy);
  Vector5d distortion;
  distortion << camera.k1, camera.k2, camera.p1, camera.p2, camera.k3;
  {
    double sum = 0;
    for (const auto& r : CameraResiduals(view, intrinsics, distortion, view.pose))
      sum += r.squaredNorm();
    report->pnp_rms_px = std::sqrt(sum / double(view.pixels.size()));
  }
  CameraRefinerOptions refiner;
  refiner.huber_px = options.refiner.huber_px;
  refiner.max_iterations = options.refiner.max_iterations;
  refiner.threads = options.refiner.threads;
  PoseRefinement pose;
  try {
    pose = RefinePose(view, intrinsics, distortion, refiner);
  } catch (const Error& e) {
    throw BadInput(photo_name + ": degenerate view: " + e.what());
  }
  report->camera_known = true;
  report->pose = pose.pose;
  report->refinement.converged = pose.converged;
  report->refinement.message = pose.message;
  if (!(pose.pose[5] > 0))
    throw BadInput(photo_name + ": degenerate view (the screen's pose puts it behind the camera)");
  // Camera point of screen point (x, y): R (x, y, 0) + t = [r1 r2 t] (x, y, 1).
  const Eigen::Matrix3d r = RotationFromVector(pose.pose.head<3>());
  Eigen::Matrix3d plane;
  plane.col(0) = r.col(0);
  plane.col(1) = r.col(1);
  plane.col(2) = pose.pose.tail<3>();
  Eigen::Matrix3d kk = Eigen::Matrix3d::Identity();
  kk(0, 0) = camera.fx;
  kk(1, 1) = camera.fy;
  kk(0, 2) = camera.cx;
  kk(1, 2) = camera.cy;
  const Eigen::Matrix3d image_from_screen = kk * plane;
  result->screen_from_image = image_from_screen.inverse();
  result->screen_from_image /= result->screen_from_image(2, 2);
  result->camera = camera;
  result->camera_file = "calib/camera.json";
  result->method = "camera+pose";
  result->rms_px = RmsPx(*result, corners);
}

}  // namespace

void ScreenCalibratorOptions::Check() const {
  detection.Check();
  refiner.Check();
  auto positive = [](double v, const char* name) {
    if (!(v > 0 && std::isfinite(v)))
      throw BadInput(std::string("calibrator options: ") + name + ": expected > 0, got " +
                     std::to_string(v));
  };
  positive(max_rms_px, "max_rms_px");
  positive(min_board_fraction, "min_board_fraction");
  positive(max_anisotropy, "max_anisotropy");
  positive(max_scale_ratio, "max_scale_ratio");
  positive(max_condition, "max_condition");
  positive(keep_term_rms_ratio, "keep_term_rms_ratio");
  if (!(min_radius_k1 >= 0 && min_radius_k2 >= min_radius_k1))
    throw BadInput(
        "calibrator options: min_radius_k1, min_radius_k2: expected 0 <= k1 <= k2, got " +
        std::to_string(min_radius_k1) + ", " + std::to_string(min_radius_k2));
}

ScreenCalibration CalibrateScreenPhoto(const cv::Mat& photo, const CalibrationTarget& target,
                                       const std::string& photo_name,
                                       const ScreenCalibratorOptions& options,
                                       ScreenCalibrationReport* report_out,
                                       const CameraModel* camera) {
  options.Check();
  target.Check(photo_name, "calibration.target");
  ScreenCalibrationReport report;
  double contrast = 0;
  const cv::Mat gray8 = StretchToGray8(photo, &contrast);
  if (!(contrast > 0))
    throw BadInput(photo_name + ": blank calibration photo (no contrast, no checkerboard)");
  report.corners = DetectBoard(gray8, target, photo_name, options.detection);
  const BoardCorners& corners = report.corners;

  std::vector<cv::Point2d> image_pts, screen_pts;
  for (size_t i = 0; i < corners.pixels.size(); ++i) {
    image_pts.emplace_back(corners.pixels[i].x(), corners.pixels[i].y());
    screen_pts.emplace_back(corners.screen_mm[i].x(), corners.screen_mm[i].y());
  }
  cv::Mat h0;
  try {
    h0 = cv::findHomography(image_pts, screen_pts, 0);
  } catch (const cv::Exception& e) {
    throw BadInput(photo_name + ": degenerate view (" + e.what() + ")");
  }
  if (h0.empty() || !cv::checkRange(h0))
    throw BadInput(photo_name + ": degenerate view (no finite homography)");
  const Eigen::Matrix3d initial = ToEigen(h0);
  CheckView(corners, initial, photo.size(), target, photo_name, options, &report);

  ScreenCalibration result;
  result.image_width = photo.cols;
  result.image_height = photo.rows;
  result.centre_px = {0.5 * (photo.cols - 1), 0.5 * (photo.rows - 1)};
  result.scale_px = 0.5 * std::hypot(photo.cols, photo.rows);  // half-diagonal: r <= ~1
  result.photo = photo_name;
  result.corners_used = int(corners.pixels.size());
  {
    ScreenCalibration start = result;
    start.screen_from_image = initial;
    report.initial_rms_px = RmsPx(start, corners);
  }
  if (camera) {
    SolveScreenPose(corners, *camera, options, photo_name, &result, &report);
  } else {
    FitDistortionModel(corners, initial, options, photo_name, &result, &report);
    result.method = "homography+radial2";
  }
  result.rms_mm = RmsMm(result, corners);
  if (!(result.rms_px <= options.max_rms_px))
    throw BadInput(photo_name + ": reprojection RMS " + Num(result.rms_px) + " px exceeds " +
                   Num(options.max_rms_px) +
                   " px (blurred photo, grazing view, or the board is not flat)");
  if (report_out) *report_out = report;
  return result;
}

std::optional<CameraCalibration> LoadDatasetCamera(const Dataset& dataset, int photo_width,
                                                   int photo_height, const std::string& photo) {
  const std::string path = dataset.Path("calib/camera.json");
  if (!std::filesystem::exists(path)) return std::nullopt;
  CameraCalibration camera = CameraCalibration::Load(path);
  if (camera.image_width != photo_width || camera.image_height != photo_height)
    throw InputError(
        path, "image_size",
        "the board photo's size " + std::to_string(photo_width) + "x" +
            std::to_string(photo_height) + " (" + photo + ")",
        std::to_string(camera.image_width) + "x" + std::to_string(camera.image_height));
  return camera;
}

ScreenCalibration CalibrateScreen(const Dataset& dataset, const ScreenCalibratorOptions& options,
                                  ScreenCalibrationReport* report) {
  if (dataset.calibration.photo.empty())
    throw InputError(dataset.Path("dataset.json"), "calibration.photo", "a photo file", "\"\"");
  const std::string path = dataset.PhotoPath(dataset.calibration.photo);
  const cv::Mat photo = LinearGray(DecodePhoto(path, CalibrationPhotoSpec(dataset)));
  const std::optional<CameraCalibration> camera =
      LoadDatasetCamera(dataset, photo.cols, photo.rows, path);
  ScreenCalibration c = CalibrateScreenPhoto(photo, dataset.calibration, path, options, report,
                                             camera ? &*camera : nullptr);
  c.photo = dataset.calibration.photo;  // relative to the dataset folder
  return c;
}

}  // namespace lumislab
