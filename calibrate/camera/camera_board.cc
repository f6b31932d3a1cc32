#include "calibrate/camera/camera_board.h"

#include <algorithm>
#include <cmath>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <utility>

#include "core/error.h"

namespace lumislab {

namespace {

// OpenCV 4.6's predefined ArUco dictionaries by name.
const std::pair<const char*, cv::aruco::PREDEFINED_DICTIONARY_NAME> kDictionaries[] = {
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
    {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
    {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
    {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
    {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
    {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
    {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
    {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
    {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
    {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
};

// Corners are found on a copy whose long side is at most this (findChessboardCorners is slow on
// large photos), then refined on the photo itself.
constexpr int kMaxDetectionPx = 2000;
// A ChArUco view needs this many corners (and not all on one line) to give a homography.
constexpr int kMinCharucoCorners = 8;

// Smallest distance between neighbouring corners of a found grid (pixels).
double MinCornerSpacing(const std::vector<cv::Point2f>& p, int cols, int rows) {
  double best = HUGE_VAL;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const cv::Point2f q = p[size_t(r * cols + c)];
      if (c + 1 < cols) best = std::min(best, double(cv::norm(q - p[size_t(r * cols + c + 1)])));
      if (r + 1 < rows) best = std::min(best, double(cv::norm(q - p[size_t((r + 1) * cols + c)])));
    }
  return best;
}

BoardView DetectChessboard(const cv::Mat& gray8, const CameraBoard& board) {
  BoardView view;
  const cv::Size pattern(board.inner_cols, board.inner_rows);
  const double scale = std::min(1.0, double(kMaxDetectionPx) / std::max(gray8.cols, gray8.rows));
  cv::Mat small = gray8;
  if (scale < 1) cv::resize(gray8, small, cv::Size(), scale, scale, cv::INTER_AREA);
  std::vector<cv::Point2f> corners;
  if (cv::findChessboardCorners(small, pattern, corners,
                                cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    for (auto& c : corners)
      c = (c + cv::Point2f(0.5f, 0.5f)) / float(scale) - cv::Point2f(0.5f, 0.5f);
    // Window half-size: up to 11 px (OpenCV's calibration sample) but within 0.4 of the
    // smallest square. A fixed 11 px on the foreshortened squares (~20 px) of OpenCV's own
    // left02.jpg gives corners with a 1.2 px RMS; 0.4 of a square gives 0.16 px.
    const int half =
        std::clamp(int(0.4 * MinCornerSpacing(corners, pattern.width, pattern.height)), 2, 11);
    cv::cornerSubPix(gray8, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 1e-4));
    view.detector = "classic";
  } else if (cv::findChessboardCornersSB(small, pattern, corners, cv::CALIB_CB_ACCURACY)) {
    // The sector-based detector places corners to sub-pixel accuracy itself.
    for (auto& c : corners)
      c = (c + cv::Point2f(0.5f, 0.5f)) / float(scale) - cv::Point2f(0.5f, 0.5f);
    view.detector = "sb";
  } else {
    view.reason = "board not found (" + std::to_string(board.inner_cols) + "x" +
                  std::to_string(board.inner_rows) + " inner corners)";
    return view;
  }
  view.found = true;
  view.pixels = corners;
  for (int r = 0; r < board.inner_rows; ++r)
    for (int c = 0; c < board.inner_cols; ++c)
      view.board_mm.emplace_back(float(c * board.square_mm), float(r * board.square_mm), 0.f);
  return view;
}

cv::Ptr<cv::aruco::Dictionary> Dictionary(const std::string& name) {
  for (const auto& [n, id] : kDictionaries)
    if (name == n) return cv::aruco::getPredefinedDictionary(id);
  return nullptr;
}

BoardView DetectCharuco(const cv::Mat& gray8, const CameraBoard& board) {
  BoardView view;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = Dictionary(board.charuco_dictionary);
  // OpenCV counts ChArUco boards in squares: one more than the inner corners.
  const cv::Ptr<cv::aruco::CharucoBoard> charuco =
      cv::aruco::CharucoBoard::create(board.inner_cols + 1, board.inner_rows + 1,
                                      float(board.square_mm), float(board.marker_mm), dictionary);
  std::vector<int> marker_ids;
  std::vector<std::vector<cv::Point2f>> marker_corners;
  cv::aruco::detectMarkers(gray8, dictionary, marker_corners, marker_ids);
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  if (!marker_ids.empty())
    cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray8, charuco, corners, ids);
  if (int(ids.size()) < kMinCharucoCorners) {
    view.reason = "board not found (" + std::to_string(marker_ids.size()) + " ChArUco markers, " +
                  std::to_string(ids.size()) +
                  " corners; need >= " + std::to_string(kMinCharucoCorners) + " corners)";
    return view;
  }
  // Corners all in one row or column of the board give no homography.
  int min_col = board.inner_cols, max_col = -1, min_row = board.inner_rows, max_row = -1;
  for (int id : ids) {
    min_col = std::min(min_col, id % board.inner_cols);
    max_col = std::max(max_col, id % board.inner_cols);
    min_row = std::min(min_row, id / board.inner_cols);
    max_row = std::max(max_row, id / board.inner_cols);
  }
  if (min_col == max_col || min_row == max_row) {
    view.reason = "board not found (ChArUco corners on one line only)";
    return view;
  }
  view.found = true;
  view.detector = "charuco";
  view.pixels = corners;
  for (int id : ids) view.board_mm.push_back(charuco->chessboardCorners[size_t(id)]);
  return view;
}

}  // namespace

void ParseBoardSize(const std::string& text, CameraBoard* board) {
  static const std::regex pattern("([0-9]{1,4})x([0-9]{1,4})");
  std::smatch m;
  if (!std::regex_match(text, m, pattern))
    throw BadInput("--board: expected <cols>x<rows> inner corners (e.g. 9x6), got \"" + text +
                   "\"");
  board->inner_cols = std::stoi(m[1]);
  board->inner_rows = std::stoi(m[2]);
}

void CameraBoard::Check() const {
  if (inner_cols < 2 || inner_rows < 2 || inner_cols > 1000 || inner_rows > 1000)
    throw BadInput("--board: expected at least 2x2 and at most 1000x1000 inner corners, got " +
                   std::to_string(inner_cols) + "x" + std::to_string(inner_rows));
  if (!(square_mm > 0 && std::isfinite(square_mm)))
    throw BadInput("--square-mm: expected a side > 0 in mm, got " + std::to_string(square_mm));
  if (IsCharuco()) {
    if (!Dictionary(charuco_dictionary)) {
      std::string names;
      for (const auto& entry : kDictionaries)
        names += std::string(names.empty() ? "" : ", ") + entry.first;
      throw BadInput("--charuco: expected one of " + names + ", got \"" + charuco_dictionary +
                     "\"");
    }
    if (!(marker_mm > 0 && marker_mm < square_mm))
      throw BadInput("--marker-mm: expected a marker side in (0, --square-mm) mm, got " +
                     std::to_string(marker_mm));
    const int markers = ((inner_cols + 1) * (inner_rows + 1)) / 2;
    if (markers > Dictionary(charuco_dictionary)->bytesList.rows)
      throw BadInput("--charuco: " + charuco_dictionary + " has " +
                     std::to_string(Dictionary(charuco_dictionary)->bytesList.rows) +
                     " markers; a board of " + std::to_string(inner_cols + 1) + "x" +
                     std::to_string(inner_rows + 1) + " squares needs " + std::to_string(markers));
  } else if (marker_mm != 0) {
    throw BadInput("--marker-mm: only with --charuco");
  }
}

CameraBoardInfo CameraBoard::Info() const {
  CameraBoardInfo info;
  info.type = IsCharuco() ? "charuco" : "chessboard";
  info.inner_cols = inner_cols;
  info.inner_rows = inner_rows;
  info.square_mm = square_mm;
  info.dictionary = charuco_dictionary;
  info.marker_mm = marker_mm;
  return info;
}

BoardView DetectBoardView(const cv::Mat& gray8, const CameraBoard& board) {
  CV_Assert(gray8.type() == CV_8UC1);
  return board.IsCharuco() ? DetectCharuco(gray8, board) : DetectChessboard(gray8, board);
}

}  // namespace lumislab
