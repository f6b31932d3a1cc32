#include "calibrate/colour/colour_calibrator.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <opencv2/mcc/checker_detector.hpp>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#include <sanitizer/lsan_interface.h>
#define LUMISLAB_LEAK_SANITIZER 1
#endif
#endif

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json.h"
#include "core/log.h"

namespace lumislab {
namespace {

constexpr int kPatches = 24;
// cv::mcc's classic chart model (modules/mcc/src/dictionary.hpp): the box getBox() returns is
// the image of (0, 0), (16.75, 0), (16.75, 11.25), (0, 11.25); patch k's centre is
// (1.5 + 2.75 (k % 6), 1.5 + 2.75 (k / 6)), its side 2.5.
constexpr double kModelW = 16.75, kModelH = 11.25, kPitch = 2.75, kHalfSample = 0.625;

// OpenCV 4.6 builds its 8-bit BGR -> Lab tables on the first conversion and never frees them
// (fuzz/sanitizers/lsan.supp says how that was shown); cv::mcc's detector converts on OpenCV's
// worker threads, where LeakSanitizer's fast unwinder loses the stack a suppression would match.
// In a sanitized build the tables are built here first, on this thread, with LeakSanitizer told
// to ignore them; elsewhere this does nothing.
void BuildOpenCvLabTables() {
#ifdef LUMISLAB_LEAK_SANITIZER
  static std::once_flag once;
  std::call_once(once, [] {
    __lsan::ScopedDisabler ignore;
    cv::Mat lab;
    cv::cvtColor(cv::Mat(1, 1, CV_8UC3, cv::Scalar(1, 2, 3)), lab, cv::COLOR_BGR2Lab);
  });
#endif
}

Eigen::Vector2d ModelCentre(int k) { return {1.5 + kPitch * (k % 6), 1.5 + kPitch * (k / 6)}; }

// The photo's linear RGB (values per unit exposure) and a mask of pixels with a clipped channel.
void ReadLinear(const Photo& photo, cv::Mat* rgb, cv::Mat* clipped) {
  const int w = photo.pixels.cols, h = photo.pixels.rows;
  *rgb = cv::Mat(h, w, CV_32FC3);
  *clipped = cv::Mat(h, w, CV_8U);
  const LinearReader reader(photo);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float v[3];
      bool c[3];
      reader.Read(y, x, v, c);
      cv::Vec3f& out = rgb->at<cv::Vec3f>(y, x);
      for (int ch = 0; ch < 3; ++ch) out[ch] = std::isfinite(v[ch]) ? v[ch] : 0.f;
      clipped->at<uint8_t>(y, x) = (c[0] || c[1] || c[2]) ? 255 : 0;
    }
}

// An 8-bit BGR picture for the detector: the linear values scaled so the 99th percentile is 0.9,
// through the sRGB curve (the detector is tuned to ordinary camera pictures).
cv::Mat DetectorImage(const cv::Mat& rgb) {
  std::vector<float> values;
  for (int y = 0; y < rgb.rows; y += 4)
    for (int x = 0; x < rgb.cols; x += 4) {
      const cv::Vec3f& v = rgb.at<cv::Vec3f>(y, x);
      values.push_back(std::max({v[0], v[1], v[2]}));
    }
  std::nth_element(values.begin(), values.begin() + values.size() * 99 / 100, values.end());
  const float top = std::max(values[values.size() * 99 / 100], 1e-12f);
  cv::Mat bgr(rgb.rows, rgb.cols, CV_8UC3);
  for (int y = 0; y < rgb.rows; ++y)
    for (int x = 0; x < rgb.cols; ++x) {
      const cv::Vec3f& v = rgb.at<cv::Vec3f>(y, x);
      for (int ch = 0; ch < 3; ++ch) {
        const double t = std::clamp(0.9 * v[ch] / top, 0.0, 1.0);
        const double s = t <= 0.0031308 ? 12.92 * t : 1.055 * std::pow(t, 1 / 2.4) - 0.055;
        bgr.at<cv::Vec3b>(y, x)[2 - ch] = cv::saturate_cast<uint8_t>(255 * s);
      }
    }
  return bgr;
}

// The patches sampled with the model box mapped onto `box` (4 image points).
ChartPatches Sample(const cv::Mat& rgb, const cv::Mat& clipped,
                    const std::vector<cv::Point2f>& box) {
  const std::vector<cv::Point2f> model = {
      {0, 0}, {float(kModelW), 0}, {float(kModelW), float(kModelH)}, {0, float(kModelH)}};
  const cv::Matx33d h = cv::getPerspectiveTransform(model, box);
  auto map = [&](double u, double v) {
    const cv::Vec3d p = h * cv::Vec3d(u, v, 1);
    return cv::Point(int(std::lround(p[0] / p[2])), int(std::lround(p[1] / p[2])));
  };
  const cv::Rect image(0, 0, rgb.cols, rgb.rows);
  ChartPatches patches;
  for (int k = 0; k < kPatches; ++k) {
    const Eigen::Vector2d c = ModelCentre(k);
    const double a = kHalfSample;
    std::vector<cv::Point> quad = {map(c.x() - a, c.y() - a), map(c.x() + a, c.y() - a),
                                   map(c.x() + a, c.y() + a), map(c.x() - a, c.y() + a)};
    const cv::Rect roi = cv::boundingRect(quad) & image;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double n = 0, n_clipped = 0;
    if (roi.area() > 0) {
      for (cv::Point& p : quad) p -= roi.tl();
      cv::Mat mask = cv::Mat::zeros(roi.size(), CV_8U);
      cv::fillConvexPoly(mask, quad, 255);
      const cv::Scalar m = cv::mean(rgb(roi), mask);
      mean = {m[0], m[1], m[2]};
      n = cv::countNonZero(mask);
      n_clipped = cv::countNonZero(clipped(roi) & mask);
    }
    patches.rgb.push_back(mean);
    patches.clipped_fraction.push_back(n > 0 ? n_clipped / n : 1.0);
    const cv::Vec3d centre = h * cv::Vec3d(c.x(), c.y(), 1);
    patches.centre_px.emplace_back(centre[0] / centre[2], centre[1] / centre[2]);
  }
  return patches;
}

double MeanDeltaE(const std::vector<Eigen::Vector3d>& rgb, const std::vector<Eigen::Vector3d>& xyz,
                  const Eigen::Matrix3d& m, const Eigen::Vector3d& white,
                  std::vector<double>* each = nullptr) {
  double sum = 0;
  for (size_t k = 0; k < rgb.size(); ++k) {
    const double e = DeltaE76(XyzToLab(m * rgb[k], white), XyzToLab(xyz[k], white));
    if (each) each->push_back(e);
    sum += e;
  }
  return sum / rgb.size();
}

}  // namespace

Eigen::Matrix3d FitRgbToXyz(const std::vector<Eigen::Vector3d>& rgb,
                            const std::vector<Eigen::Vector3d>& xyz) {
  Eigen::MatrixXd a(rgb.size(), 3), b(rgb.size(), 3);
  for (size_t k = 0; k < rgb.size(); ++k) {
    a.row(k) = rgb[k].transpose();
    b.row(k) = xyz[k].transpose();
  }
  // Each row of the matrix is a linear least-squares problem: X = a r, Y = a r', Z = a r''.
  return a.colPivHouseholderQr().solve(b).transpose();
}

Eigen::Vector3d ReferenceWhite(const std::string& illuminant) {
  const Spectrum light = *IlluminantByName(illuminant);
  const Eigen::Vector3d white = SpectrumToXyz(light);
  return white / white.y();
}

std::vector<Eigen::Vector3d> ChartReferenceXyz(const std::string& illuminant) {
  const Spectrum light = *IlluminantByName(illuminant);
  const double white_y = SpectrumToXyz(light).y();
  std::vector<Eigen::Vector3d> xyz;
  for (int k = 0; k < kPatches; ++k)
    xyz.push_back(SpectrumToXyz(ColorCheckerReflectance(k).cwiseProduct(light)) / white_y);
  return xyz;
}

void ColourOptions::Check() const {
  if (!IlluminantByName(illuminant))
    throw BadInput("--illuminant: expected D50 or D65, got '" + illuminant + "'");
}

ChartPatches FindColourChart(const Photo& photo, const std::vector<Eigen::Vector3d>& reference,
                             const Eigen::Vector3d& white) {
  cv::Mat rgb, clipped;
  ReadLinear(photo, &rgb, &clipped);
  const cv::Mat picture = DetectorImage(rgb);
  BuildOpenCvLabTables();
  cv::Ptr<cv::mcc::CCheckerDetector> detector = cv::mcc::CCheckerDetector::create();
  if (!detector->process(picture, cv::mcc::MCC24, 1) || detector->getListColorChecker().empty())
    throw BadInput(photo.path +
                   ": no ColorChecker Classic 24 found (OpenCV mcc); the whole chart must be in "
                   "the photo, evenly lit, its patches at least ~20 px");
  const std::vector<cv::Point2f> box = detector->getBestColorChecker()->getBox();
  if (box.size() != 4)
    throw Failure("cv::mcc returned a chart box of " + std::to_string(box.size()) + " corners");
  // Which corner of the box is the chart's dark-skin corner, and which way round: the one of the
  // eight whose patches fit the reference best (the neutral row alone tells them apart).
  ChartPatches best;
  double best_error = INFINITY;
  for (int start = 0; start < 4; ++start)
    for (int step : {1, 3}) {
      std::vector<cv::Point2f> turned(4);
      for (int i = 0; i < 4; ++i) turned[i] = box[(start + step * i) % 4];
      const ChartPatches p = Sample(rgb, clipped, turned);
      const double error = MeanDeltaE(p.rgb, reference, FitRgbToXyz(p.rgb, reference), white);
      if (error < best_error) best_error = error, best = p;
    }
  return best;
}

ColourCalibration CalibrateColour(const ChartPatches& patches, const ColourOptions& options,
                                  const std::string& photo, nlohmann::json* report,
                                  CheckLog* checks) {
  const std::vector<Eigen::Vector3d> reference = ChartReferenceXyz(options.illuminant);
  const Eigen::Vector3d white = ReferenceWhite(options.illuminant);
  std::vector<std::string> clipped;
  for (int k = 0; k < kPatches; ++k)
    if (patches.clipped_fraction[k] > 0.01) clipped.push_back(ColorCheckerPatchName(k));
  if (!clipped.empty()) {
    std::string names;
    for (const std::string& n : clipped) names += (names.empty() ? "" : ", ") + n;
    checks->Fail("colour.fit",
                 photo + ": chart patches clipped (" + names +
                     "): expected every patch below the sensor's saturation; lower the exposure",
                 {{"clipped_patches", clipped}});
  }
  ColourCalibration c;
  c.rgb_to_xyz = FitRgbToXyz(patches.rgb, reference);
  c.chart = "ColorChecker Classic 24";
  c.illuminant = options.illuminant;
  c.photo = photo;
  std::vector<double> delta_e;
  c.mean_delta_e = MeanDeltaE(patches.rgb, reference, c.rgb_to_xyz, white, &delta_e);
  c.max_delta_e = *std::max_element(delta_e.begin(), delta_e.end());
  nlohmann::json list = nlohmann::json::array();
  for (int k = 0; k < kPatches; ++k) {
    const Eigen::Vector3d& r = patches.rgb[k];
    list.push_back({{"name", ColorCheckerPatchName(k)},
                    {"rgb", {r.x(), r.y(), r.z()}},
                    {"reference_xyz", {reference[k].x(), reference[k].y(), reference[k].z()}},
                    {"centre_px", {patches.centre_px[k].x(), patches.centre_px[k].y()}},
                    {"delta_e", delta_e[k]}});
  }
  (*report)["patches"] = list;
  const nlohmann::json values = {{"mean_delta_e", c.mean_delta_e},
                                 {"max_delta_e", c.max_delta_e},
                                 {"limit_mean", options.max_mean_delta_e},
                                 {"limit_max", options.max_delta_e},
                                 {"illuminant", options.illuminant}};
  // The detector can lock onto 24 squares that are not a ColorChecker, and a chart under another
  // light than stated fits badly: either shows as a residual no camera's 3x3 fit has.
  if (!(c.mean_delta_e <= options.max_mean_delta_e) || !(c.max_delta_e <= options.max_delta_e))
    checks->Fail("colour.fit",
                 photo + ": fit to the ColorChecker's reference colours under " +
                     options.illuminant + ": expected a residual Delta E*ab of at most " +
                     Num(options.max_mean_delta_e) + " mean and " + Num(options.max_delta_e) +
                     " max, got " + Num(c.mean_delta_e) + " and " + Num(c.max_delta_e) +
                     " (not a ColorChecker Classic 24, or unevenly lit or glared)",
                 values);
  checks->Pass("colour.fit",
               "RGB -> XYZ fit to the ColorChecker under " + options.illuminant +
                   ": Delta E*ab mean " + Num(c.mean_delta_e) + ", max " + Num(c.max_delta_e),
               values);
  return c;
}

void SaveColourCalibration(const std::string& path, const ColourCalibration& c,
                           const nlohmann::json& report) {
  nlohmann::json j;
  j["schema_version"] = kColourSchemaVersion;
  j["kind"] = "colour";
  nlohmann::json m = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    m.push_back({c.rgb_to_xyz(r, 0), c.rgb_to_xyz(r, 1), c.rgb_to_xyz(r, 2)});
  j["rgb_to_xyz"] = m;
  const Eigen::Vector3d w = c.LuminanceWeights();
  j["luminance_weights"] = {w.x(), w.y(), w.z()};
  j["chart"] = c.chart;
  j["reference"] = "Ohta 1997 spectral reflectances x CIE " + c.illuminant +
                   " x CIE 1931 2-degree, Y(white) = 1";
  j["illuminant"] = c.illuminant;
  j["photo"] = c.photo;
  j["residual_delta_e"] = {
      {"mean", c.mean_delta_e}, {"max", c.max_delta_e}, {"formula", "CIE 1976"}};
  j["report"] = report;
  WriteJsonAtomically(path, j);
}

}  // namespace lumislab
