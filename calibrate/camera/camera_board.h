// The board of lumislab-calibrate camera and its detection in one photo: a classic chessboard
// (cv::findChessboardCorners + cornerSubPix, cv::findChessboardCornersSB as the fallback), which
// must be wholly in view, or a ChArUco board (OpenCV 4.6 aruco module), whose corners are named
// by their markers and so may be only partly in view. Board frame: corner (0, 0) at the origin,
// x along the columns, y along the rows, z = 0 (mm).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera_calibration.h"

namespace lumislab {

struct CameraBoard {
  int inner_cols = 0;  // inner corners per row, as OpenCV counts them (9 for a 10-square row)
  int inner_rows = 0;
  double square_mm = 0;
  std::string charuco_dictionary;  // empty: a classic chessboard; else e.g. "DICT_5X5_100"
  double marker_mm = 0;            // ChArUco marker side
  bool IsCharuco() const { return !charuco_dictionary.empty(); }
  void Check() const;  // BadInput naming the option (--board, --square-mm, --charuco, ...)
  CameraBoardInfo Info() const;
};

// "9x6" -> 9, 6 (inner corners); BadInput naming --board otherwise.
void ParseBoardSize(const std::string& text, CameraBoard* board);

struct BoardView {
  bool found = false;
  std::string reason;                 // why not found
  std::string detector;               // "classic", "sb" or "charuco"
  std::vector<cv::Point2f> pixels;    // OpenCV pixel centres
  std::vector<cv::Point3f> board_mm;  // the same corners on the board
};

// `gray8`: the photo as 8-bit codes (CV_8UC1). Never throws for a photo without the board.
BoardView DetectBoardView(const cv::Mat& gray8, const CameraBoard& board);

}  // namespace lumislab
