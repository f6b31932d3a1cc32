#include "calibrate/camera/camera_calibrator.h"

#include <glob.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calibrate/gray_stretch.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/input_file.h"
#include "core/log.h"
#include "core/parallel.h"
#include "lib/photo/photo_io.h"

namespace lumislab {

namespace {

std::string SizeText(const cv::Size& s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

// The 8-bit image the detectors work on: an 8-bit photo's own codes (as a camera's JPEG shows
// the board), anything else as linear luminance stretched to 8 bits.
cv::Mat Gray8(const Photo& photo) {
  if (photo.EightBitCodes()) {
    const cv::Mat codes = Codes8(photo);
    if (codes.channels() == 1) return codes;
    cv::Mat gray;
    cv::cvtColor(codes, gray, photo.rgb_order ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
    return gray;
  }
  return StretchToGray8(LinearGray(photo));
}

struct Detection {
  cv::Size size;
  BoardView view;
};

// cv::calibrateCamera's answer on the used views (default flags: k1, k2, p1, p2, k3).
struct OpenCvStart {
  Eigen::Vector4d intrinsics;
  Vector5d distortion;
  std::vector<Vector6d> poses;
  std::vector<double> view_rms_px;
  double rms_px = 0;
};

OpenCvStart CalibrateWithOpenCv(const std::vector<Detection>& detections,
                                const std::vector<int>& used, const cv::Size& size) {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (int k : used) {
    object.push_back(detections[size_t(k)].view.board_mm);
    image.push_back(detections[size_t(k)].view.pixels);
  }
  cv::Mat camera_matrix, dist, std_intrinsics, std_extrinsics, view_errors;
  std::vector<cv::Mat> rvecs, tvecs;
  OpenCvStart start;
  try {
    start.rms_px = cv::calibrateCamera(object, image, size, camera_matrix, dist, rvecs, tvecs,
                                       std_intrinsics, std_extrinsics, view_errors);
  } catch (const cv::Exception& e) {
    throw BadInput("the views do not constrain the camera (cv::calibrateCamera: " +
                   std::string(e.err) + "); take the board from several different angles");
  }
  start.intrinsics = {camera_matrix.at<double>(0, 0), camera_matrix.at<double>(1, 1),
                      camera_matrix.at<double>(0, 2), camera_matrix.at<double>(1, 2)};
  for (int i = 0; i < 5; ++i) start.distortion[i] = dist.at<double>(i);
  for (size_t v = 0; v < used.size(); ++v) {
    Vector6d pose;
    for (int i = 0; i < 3; ++i) {
      pose[i] = rvecs[v].at<double>(i);
      pose[3 + i] = tvecs[v].at<double>(i);
    }
    start.poses.push_back(pose);
    start.view_rms_px.push_back(view_errors.at<double>(int(v)));
  }
  bool finite = std::isfinite(start.rms_px) && start.intrinsics.allFinite() &&
                start.distortion.allFinite() && start.intrinsics[0] > 0 && start.intrinsics[1] > 0;
  for (const auto& p : start.poses) finite = finite && p.allFinite();
  if (!finite)
    throw BadInput(
        "the views do not constrain the camera (cv::calibrateCamera gave no finite "
        "answer); take the board from several different angles");
  return start;
}

// Unit normal of the board (its z axis) in the camera frame.
Eigen::Vector3d BoardNormal(const Vector6d& pose) {
  return RotationFromVector(pose.head<3>()).col(2);
}

double TiltDeg(const Vector6d& pose) {
  return std::acos(std::min(1.0, std::abs(BoardNormal(pose).z()))) * 180 / kPi;
}

// Zhang's method needs boards that are not all parallel, and a board seen face-on everywhere
// only tells f times distance: refuse unless some board is tilted and two normals differ.
void CheckViewsConstrainFocal(const std::vector<Vector6d>& poses, double min_tilt_deg) {
  double max_tilt = 0, spread = 0;
  for (size_t a = 0; a < poses.size(); ++a) {
    max_tilt = std::max(max_tilt, TiltDeg(poses[a]));
    for (size_t b = a + 1; b < poses.size(); ++b) {
      const double c = BoardNormal(poses[a]).dot(BoardNormal(poses[b]));
      spread = std::max(spread, std::acos(std::clamp(c, -1.0, 1.0)) * 180 / kPi);
    }
  }
  if (max_tilt < min_tilt_deg)
    throw BadInput(
        "the views do not constrain the focal length: every board faces the camera "
        "(largest tilt " +
        Num(max_tilt) + " deg, need >= " + Num(min_tilt_deg) +
        " deg); photograph the board tilted, from several angles");
  if (spread < min_tilt_deg)
    throw BadInput(
        "the views do not constrain the focal length: the boards are all parallel "
        "(largest angle between two board normals " +
        Num(spread) + " deg, need >= " + Num(min_tilt_deg) +
        " deg); tilt the board in different directions");
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string RejectedList(const std::vector<CameraViewReport>& reports) {
  std::string out;
  for (const auto& r : reports)
    if (!r.rejected.empty()) out += "; " + r.photo + ": " + r.rejected;
  return out;
}

}  // namespace

void CameraCalibratorOptions::Check() const {
  refiner.Check();
  auto fail = [](const std::string& field, const std::string& expected, double got) {
    throw BadInput("camera calibrator options: " + field + ": expected " + expected + ", got " +
                   Num(got));
  };
  if (min_views < 3) fail("min_views", ">= 3", min_views);
  if (!(outlier_factor >= 1 && std::isfinite(outlier_factor)))
    fail("outlier_factor", ">= 1", outlier_factor);
  if (!(outlier_floor_px > 0 && std::isfinite(outlier_floor_px)))
    fail("outlier_floor_px", "> 0", outlier_floor_px);
  if (!(min_tilt_deg >= 0 && min_tilt_deg < 90)) fail("min_tilt_deg", "in [0, 90)", min_tilt_deg);
  if (!(max_focal_sigma > 0 && std::isfinite(max_focal_sigma)))
    fail("max_focal_sigma", "> 0", max_focal_sigma);
  if (threads < 1) fail("threads", ">= 1", threads);
}

std::vector<std::string> ExpandPhotoArguments(const std::vector<std::string>& arguments) {
  std::vector<std::string> photos;
  for (const std::string& arg : arguments) {
    if (std::filesystem::is_directory(arg)) {
      for (const std::string& name : FolderFiles(arg)) {
        const std::string path = (std::filesystem::path(arg) / name).string();
        try {
          DetectPhotoFormat(path);
        } catch (const Error&) {
          LogInfo(path, ": not a photo, skipped");
          continue;
        }
        photos.push_back(path);
      }
    } else if (arg.find_first_of("*?[") != std::string::npos) {
      glob_t matches{};
      const int rc = ::glob(arg.c_str(), 0, nullptr, &matches);
      std::vector<std::string> found;
      if (rc == 0)
        for (size_t i = 0; i < matches.gl_pathc; ++i) found.emplace_back(matches.gl_pathv[i]);
      ::globfree(&matches);
      if (found.empty()) throw BadInput("--photos: no file matches \"" + arg + "\"");
      std::sort(found.begin(), found.end());
      photos.insert(photos.end(), found.begin(), found.end());
    } else {
      CheckInputFile(arg, "photo");
      photos.push_back(arg);
    }
  }
  if (photos.empty()) throw BadInput("--photos: no photos found");
  return photos;
}

CameraCalibration CalibrateCamera(const std::vector<std::string>& photos, const CameraBoard& board,
                                  const CameraCalibratorOptions& options) {
  options.Check();
  board.Check();
  if (photos.empty()) throw BadInput("--photos: no photos given");
  const int n = int(photos.size());
  std::vector<Detection> detections(photos.size());
  ParallelFor(n, options.threads, [&](int k) {
    const Photo photo = DecodePhoto(photos[size_t(k)]);
    detections[size_t(k)].size = photo.pixels.size();
    detections[size_t(k)].view = DetectBoardView(Gray8(photo), board);
  });
  const cv::Size size = detections[0].size;
  for (int k = 1; k < n; ++k)
    if (detections[size_t(k)].size != size)
      throw BadInput(photos[size_t(k)] + ": image size " + SizeText(detections[size_t(k)].size) +
                     " differs from " + photos[0] + "'s " + SizeText(size) +
                     " (one camera calibration needs photos of one size)");

  std::vector<CameraViewReport> reports(photos.size());
  std::vector<int> used;
  for (int k = 0; k < n; ++k) {
    CameraViewReport& r = reports[size_t(k)];
    const BoardView& v = detections[size_t(k)].view;
    r.photo = photos[size_t(k)];
    r.corners = int(v.pixels.size());
    if (v.found) {
      used.push_back(k);
    } else {
      r.rejected = v.reason;
    }
  }
  if (used.empty())
    throw BadInput("the board was found in none of the " + std::to_string(n) + " photo(s)" +
                   RejectedList(reports));

  // OpenCV's calibration, dropping outlier views until none is left.
  OpenCvStart start;
  for (;;) {
    if (int(used.size()) < options.min_views)
      throw BadInput("only " + std::to_string(used.size()) + " usable view(s) of " +
                     std::to_string(n) + " photo(s), need >= " + std::to_string(options.min_views) +
                     RejectedList(reports));
    start = CalibrateWithOpenCv(detections, used, size);
    const double limit =
        std::max(options.outlier_factor * Median(start.view_rms_px), options.outlier_floor_px);
    std::vector<int> kept;
    for (size_t v = 0; v < used.size(); ++v) {
      if (start.view_rms_px[v] <= limit) {
        kept.push_back(used[v]);
      } else {
        reports[size_t(used[v])].rejected = "outlier: RMS " + Num(start.view_rms_px[v]) +
                                            " px under OpenCV's calibration, limit " + Num(limit) +
                                            " px";
        LogWarning(photos[size_t(used[v])], ": ", reports[size_t(used[v])].rejected);
      }
    }
    if (kept.size() == used.size()) break;
    used = kept;
  }
  CheckViewsConstrainFocal(start.poses, options.min_tilt_deg);

  std::vector<CameraViewData> views;
  for (size_t v = 0; v < used.size(); ++v) {
    const BoardView& b = detections[size_t(used[v])].view;
    CameraViewData d;
    for (size_t i = 0; i < b.pixels.size(); ++i) {
      d.pixels.emplace_back(b.pixels[i].x, b.pixels[i].y);
      d.board_mm.emplace_back(b.board_mm[i].x, b.board_mm[i].y, b.board_mm[i].z);
    }
    d.pose = start.poses[v];
    views.push_back(d);
  }
  const CameraRefinement refined =
      RefineCamera(views, start.intrinsics, start.distortion, options.refiner);
  LogDebug("ceres: ", refined.message);
  bool finite = refined.intrinsics.allFinite() && refined.distortion.allFinite() &&
                std::isfinite(refined.rms_px);
  for (const auto& p : refined.poses) finite = finite && p.allFinite();
  if (!finite) throw Failure("camera refinement gave a non-finite answer");

  CameraCalibration c;
  c.image_width = size.width;
  c.image_height = size.height;
  c.fx = refined.intrinsics[0];
  c.fy = refined.intrinsics[1];
  c.cx = refined.intrinsics[2];
  c.cy = refined.intrinsics[3];
  c.k1 = refined.distortion[0];
  c.k2 = refined.distortion[1];
  c.p1 = refined.distortion[2];
  c.p2 = refined.distortion[3];
  c.k3 = refined.distortion[4];
  c.rms_px = refined.rms_px;
  c.opencv_rms_px = start.rms_px;
  c.sigma = refined.sigma;
  c.board = board.Info();
  if (c.sigma.empty()) {
    LogWarning("the parameters' covariance is rank deficient: no uncertainties");
  } else if (c.sigma[0] / c.fx > options.max_focal_sigma ||
             c.sigma[1] / c.fy > options.max_focal_sigma) {
    throw BadInput("the views do not constrain the focal length: fx = " + Num(c.fx) + " +- " +
                   Num(c.sigma[0]) + " px, fy = " + Num(c.fy) + " +- " + Num(c.sigma[1]) +
                   " px (need sigma <= " + Num(100 * options.max_focal_sigma) +
                   " %); add views of the board from different angles");
  }
  for (size_t v = 0; v < used.size(); ++v) {
    CameraViewReport& r = reports[size_t(used[v])];
    r.used = true;
    r.rms_px = refined.view_rms_px[v];
    r.tilt_deg = TiltDeg(refined.poses[v]);
    r.rotation = refined.poses[v].head<3>();
    r.translation_mm = refined.poses[v].tail<3>();
  }
  c.views = reports;
  return c;
}

void WriteCameraYaml(const CameraCalibration& c, const std::string& path) {
  WriteAtomically(path, [&](const std::string& tmp) {
    try {
      cv::FileStorage fs(tmp, cv::FileStorage::WRITE);
      if (!fs.isOpened()) throw IoError(path, "cannot write");
      const cv::Mat camera_matrix =
          (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
      const cv::Mat distortion = (cv::Mat_<double>(5, 1) << c.k1, c.k2, c.p1, c.p2, c.k3);
      std::vector<double> view_errors;
      for (const auto& v : c.views)
        if (v.used) view_errors.push_back(v.rms_px);
      fs << "nr_of_frames" << c.ViewsUsed();
      fs << "image_width" << c.image_width;
      fs << "image_height" << c.image_height;
      fs << "board_width" << c.board.inner_cols;
      fs << "board_height" << c.board.inner_rows;
      fs << "square_size" << c.board.square_mm;
      fs << "camera_matrix" << camera_matrix;
      fs << "distortion_coefficients" << distortion;
      fs << "avg_reprojection_error" << c.rms_px;
      fs << "per_view_reprojection_errors" << cv::Mat(view_errors, true);
      fs.release();
    } catch (const cv::Exception& e) {
      throw IoError(path, std::string("cannot write (") + e.err + ")");
    }
  });
}

}  // namespace lumislab
