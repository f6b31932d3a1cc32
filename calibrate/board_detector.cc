#include "calibrate/board_detector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calibrate/saddle_refiner.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/log.h"

namespace lumislab {

namespace {

// Bilinear sample of an 8-bit image; NaN outside.
double Sample(const cv::Mat& gray8, const cv::Point2d& p) {
  const int x0 = int(std::floor(p.x)), y0 = int(std::floor(p.y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= gray8.cols || y0 + 1 >= gray8.rows) return std::nan("");
  const double fx = p.x - x0, fy = p.y - y0;
  auto v = [&](int x, int y) { return double(gray8.at<uchar>(y, x)); };
  return (1 - fy) * ((1 - fx) * v(x0, y0) + fx * v(x0 + 1, y0)) +
         fy * ((1 - fx) * v(x0, y0 + 1) + fx * v(x0 + 1, y0 + 1));
}

cv::Point2d Apply(const cv::Matx33d& h, double x, double y) {
  const cv::Vec3d q = h * cv::Vec3d(x, y, 1);
  return {q[0] / q[2], q[1] / q[2]};
}

// Mean over circles of radii `radii` (in squares) around board point (cx, cy); NaN if any
// sample falls outside the photo.
double RingMean(const cv::Mat& gray8, const cv::Matx33d& image_from_board, double cx, double cy,
                std::initializer_list<double> radii) {
  double sum = 0;
  int n = 0;
  for (double r : radii) {
    const int count = r == 0 ? 1 : 16;
    for (int k = 0; k < count; ++k) {
      const double a = 2 * kPi * k / count;
      sum += Sample(gray8, Apply(image_from_board, cx + r * std::cos(a), cy + r * std::sin(a)));
      ++n;
    }
  }
  return sum / n;
}

std::string SizeText(const CalibrationTarget& t) {
  return std::to_string(t.squares_x - 1) + "x" + std::to_string(t.squares_y - 1);
}

// FAST_CHECK: without it the classic detector spends many seconds on a photo of noise.
bool FindCorners(const cv::Mat& image, const cv::Size& pattern, bool sb_fallback,
                 std::vector<cv::Point2f>* corners, std::string* detector) {
  try {
    if (cv::findChessboardCorners(image, pattern, *corners,
                                  cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE |
                                      cv::CALIB_CB_FAST_CHECK)) {
      *detector = "classic";
      return true;
    }
    if (sb_fallback &&
        cv::findChessboardCornersSB(image, pattern, *corners,
                                    cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE)) {
      *detector = "sb";
      return true;
    }
  } catch (const cv::Exception& e) {
    LogDebug("chessboard detection raised: ", e.what());
  }
  return false;
}

}  // namespace

void DetectionOptions::Check() const {
  if (max_detection_px < 200)
    throw BadInput("detection options: max_detection_px: expected >= 200, got " +
                   std::to_string(max_detection_px));
  if (!(min_dot_contrast > 0 && min_dot_contrast < 1))
    throw BadInput("detection options: min_dot_contrast: expected a value in (0, 1), got " +
                   std::to_string(min_dot_contrast));
}

namespace {

// OpenCV's corner grid on a copy at most max_detection_px long, then sub-pixel corners on the
// full photo (cv::cornerSubPix, then the saddle-point fit). Fills detector, square_px and
// saddle_refined.
std::vector<cv::Point2f> FindGrid(const cv::Mat& gray8, const CalibrationTarget& target,
                                  const std::string& photo, const DetectionOptions& options,
                                  BoardCorners* out) {
  const int nc = target.squares_x - 1, nr = target.squares_y - 1;
  const double scale =
      std::min(1.0, double(options.max_detection_px) / std::max(gray8.cols, gray8.rows));
  cv::Mat small = gray8;
  if (scale < 1) cv::resize(gray8, small, cv::Size(), scale, scale, cv::INTER_AREA);
  std::vector<cv::Point2f> corners;
  if (!FindCorners(small, cv::Size(nc, nr), options.sb_fallback, &corners, &out->detector) ||
      int(corners.size()) != nc * nr)
    throw BadInput(photo + ": no checkerboard with " + SizeText(target) +
                   " inner corners found (blank photo, board not in view, or too small)");
  for (auto& c : corners) c = cv::Point2f((c.x + 0.5f) / scale - 0.5f, (c.y + 0.5f) / scale - 0.5f);

  std::vector<double> spacing;
  for (int r = 0; r < nr; ++r)
    for (int c = 0; c + 1 < nc; ++c)
      spacing.push_back(cv::norm(corners[r * nc + c + 1] - corners[r * nc + c]));
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  out->square_px = spacing[spacing.size() / 2];
  const int win = std::clamp(int(0.4 * out->square_px), 2, 15);
  try {
    cv::cornerSubPix(gray8, corners, cv::Size(win, win), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  } catch (const cv::Exception& e) {
    throw Failure(photo + ": corner refinement failed: " + e.what());
  }
  out->saddle_refined = RefineSaddlePoints(gray8, out->square_px, &corners);
  if (out->saddle_refined < int(corners.size()))
    LogDebug(photo, ": ", int(corners.size()) - out->saddle_refined,
             " corner(s) kept cv::cornerSubPix positions (no saddle fit)");
  return corners;
}

// Homography from board-index coordinates (square units, OpenCV's grid taken as is) to pixels.
cv::Matx33d ImageFromIndex(const std::vector<cv::Point2f>& corners, int nc, int nr,
                           const std::string& photo) {
  std::vector<cv::Point2d> index_pts, image_pts;
  for (int k = 0; k < nc * nr; ++k) {
    index_pts.emplace_back(k % nc + 1, k / nc + 1);
    image_pts.emplace_back(corners[k].x, corners[k].y);
  }
  cv::Mat h;
  try {
    h = cv::findHomography(index_pts, image_pts, 0);
  } catch (const cv::Exception& e) {
    throw BadInput(photo + ": degenerate checkerboard view (" + e.what() + ")");
  }
  if (h.empty()) throw BadInput(photo + ": degenerate checkerboard view (no homography)");
  return cv::Matx33d(h);
}

// Black/white contrast from the centres of the squares that are not corner squares.
double SquareContrast(const cv::Mat& gray8, const cv::Matx33d& image_from_index,
                      const CalibrationTarget& target) {
  const int nc = target.squares_x - 1, nr = target.squares_y - 1;
  double sum[2] = {0, 0};
  int count[2] = {0, 0};
  for (int b = 0; b < target.squares_y; ++b)
    for (int a = 0; a < target.squares_x; ++a) {
      const bool corner_square = (a == 0 || a == nc) && (b == 0 || b == nr);
      const double v = RingMean(gray8, image_from_index, a + 0.5, b + 0.5, {0.0, 0.25});
      if (corner_square || std::isnan(v)) continue;
      sum[(a + b) % 2] += v;
      ++count[(a + b) % 2];
    }
  return (count[0] && count[1]) ? std::abs(sum[0] / count[0] - sum[1] / count[1]) : 0.0;
}

// The dot: a bright disk (radius 0.2 square) in a dark square, in one of the four corners.
// Returns which corner holds it (0 identity, 1 flip_x, 2 flip_y, 3 rotate_180); fills the
// contrasts; BadInput when there is no clear winner.
int FindDot(const cv::Mat& gray8, const cv::Matx33d& image_from_index,
            const CalibrationTarget& target, const std::string& photo,
            const DetectionOptions& options, BoardCorners* out) {
  const int nc = target.squares_x - 1, nr = target.squares_y - 1;
  const double contrast = SquareContrast(gray8, image_from_index, target);
  const std::array<std::pair<int, int>, 4> corner_squares = {{{0, 0}, {nc, 0}, {0, nr}, {nc, nr}}};
  std::array<double, 4> score;
  for (int k = 0; k < 4; ++k) {
    const double cx = corner_squares[k].first + 0.5, cy = corner_squares[k].second + 0.5;
    const double dot = RingMean(gray8, image_from_index, cx, cy, {0.0, 0.06, 0.12});
    const double ring = RingMean(gray8, image_from_index, cx, cy, {0.3, 0.38});
    score[k] =
        (std::isnan(dot) || std::isnan(ring) || !(contrast > 0)) ? 0.0 : (dot - ring) / contrast;
  }
  std::array<int, 4> order = {0, 1, 2, 3};
  std::sort(order.begin(), order.end(), [&](int x, int y) { return score[x] > score[y]; });
  out->dot_contrast = score[order[0]];
  out->runner_up_contrast = score[order[1]];
  if (!(out->dot_contrast >= options.min_dot_contrast) ||
      out->runner_up_contrast > 0.5 * out->dot_contrast)
    throw BadInput(photo + ": the orientation dot in board square (0, 0) was not found (best " +
                   Num(out->dot_contrast, 3) + ", runner-up " + Num(out->runner_up_contrast, 3) +
                   " of the black/white contrast; need >= " + Num(options.min_dot_contrast, 3) +
                   " and a clear winner)");
  return order[0];
}

}  // namespace

BoardCorners DetectBoard(const cv::Mat& gray8, const CalibrationTarget& target,
                         const std::string& photo, const DetectionOptions& options) {
  options.Check();
  CV_Assert(gray8.type() == CV_8UC1);
  const int nc = target.squares_x - 1, nr = target.squares_y - 1;
  BoardCorners out;
  const std::vector<cv::Point2f> corners = FindGrid(gray8, target, photo, options, &out);
  const cv::Matx33d image_from_index = ImageFromIndex(corners, nc, nr, photo);
  const int found = FindDot(gray8, image_from_index, target, photo, options, &out);
  const std::array<const char*, 4> names = {"identity", "flip_x", "flip_y", "rotate_180"};
  out.orientation = names[found];
  const bool flip_x = found == 1 || found == 3, flip_y = found == 2 || found == 3;
  for (int k = 0; k < nc * nr; ++k) {
    const int a = flip_x ? target.squares_x - (k % nc + 1) : k % nc + 1;
    const int b = flip_y ? target.squares_y - (k / nc + 1) : k / nc + 1;
    out.pixels.emplace_back(corners[k].x, corners[k].y);
    out.screen_mm.push_back(target.origin_mm + target.square_mm * Eigen::Vector2d(a, b));
  }
  return out;
}

}  // namespace lumislab
