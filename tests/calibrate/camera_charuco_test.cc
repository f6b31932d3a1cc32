// ChArUco boards for lumislab-calibrate camera: views of a board drawn by OpenCV, seen through a
// known pinhole camera, several of them only partly in the photo (which a classic chessboard
// cannot use), must give the true camera.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calibrate/camera/camera_calibrator.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kFocal = 620;
constexpr double kSquareMm = 25, kMarkerMm = 18;

TEST(CameraCharuco, PartlyVisibleBoardsGiveTheTrueCamera) {
  const std::string dir =
      (fs::path(::testing::TempDir()) / ("lumislab_charuco_" + std::to_string(::getpid())))
          .string();
  fs::remove_all(dir);
  fs::create_directories(dir);

  CameraBoard board;
  board.inner_cols = 9;  // 10 x 7 squares
  board.inner_rows = 6;
  board.square_mm = kSquareMm;
  board.charuco_dictionary = "DICT_5X5_100";
  board.marker_mm = kMarkerMm;
  const auto dictionary = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_5X5_100);
  const auto charuco =
      cv::aruco::CharucoBoard::create(10, 7, float(kSquareMm), float(kMarkerMm), dictionary);
  // The board drawn at 80 px per square with a white margin; where its corners are in that
  // drawing is measured, not assumed (OpenCV's board axes have changed between versions).
  cv::Mat drawing;
  charuco->draw(cv::Size(960, 720), drawing, 80, 1);
  std::vector<int> ids;
  std::vector<std::vector<cv::Point2f>> markers;
  cv::aruco::detectMarkers(drawing, dictionary, markers, ids);
  std::vector<cv::Point2f> drawn;
  std::vector<int> corner_ids;
  cv::aruco::interpolateCornersCharuco(markers, ids, drawing, charuco, drawn, corner_ids);
  ASSERT_EQ(corner_ids.size(), 54u);
  std::vector<cv::Point2f> board_xy;
  for (int id : corner_ids)
    board_xy.emplace_back(charuco->chessboardCorners[size_t(id)].x,
                          charuco->chessboardCorners[size_t(id)].y);
  const cv::Mat drawing_from_board = cv::findHomography(board_xy, drawn);

  // Camera looking at the board centre (125, 87.5) mm from several directions; the look-at
  // shifts push parts of the board out of the photo in half of the views.
  const cv::Mat k = (cv::Mat_<double>(3, 3) << kFocal, 0, 0.5 * (kWidth - 1), 0, kFocal,
                     0.5 * (kHeight - 1), 0, 0, 1);
  const Eigen::Vector3d centre(125, 87.5, 0);
  const std::pair<Eigen::Vector3d, Eigen::Vector3d> views[] = {
      {{150, 0, -330}, {0, 0, 0}},       {{-150, 20, -340}, {0, 0, 0}},
      {{0, 140, -330}, {0, 0, 0}},       {{10, -150, -340}, {0, 0, 0}},
      {{120, 110, -250}, {70, 40, 0}},   {{-110, -100, -250}, {-70, -40, 0}},
      {{130, -100, -240}, {80, -40, 0}}, {{-120, 110, -240}, {-80, 50, 0}}};
  std::vector<std::string> photos;
  int partial = 0;
  for (const auto& [offset, shift] : views) {
    const Eigen::Vector3d position = centre + offset;
    const Eigen::Vector3d z = (centre + shift - position).normalized();
    const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized() * -1;
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d camera_from_board;
    camera_from_board << x.transpose(), y.transpose(), z.transpose();
    const Eigen::Vector3d t = -camera_from_board * position;
    cv::Mat rt = (cv::Mat_<double>(3, 3) << camera_from_board(0, 0), camera_from_board(0, 1), t.x(),
                  camera_from_board(1, 0), camera_from_board(1, 1), t.y(), camera_from_board(2, 0),
                  camera_from_board(2, 1), t.z());
    const cv::Mat image_from_board = k * rt;
    const cv::Mat image_from_drawing = image_from_board * drawing_from_board.inv();
    cv::Mat photo;
    cv::warpPerspective(drawing, photo, image_from_drawing, cv::Size(kWidth, kHeight),
                        cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(255));
    // Count the views with board corners outside the photo.
    std::vector<cv::Point2f> corners;
    cv::perspectiveTransform(board_xy, corners, image_from_board);
    for (const auto& c : corners)
      if (c.x < 0 || c.y < 0 || c.x > kWidth - 1 || c.y > kHeight - 1) {
        ++partial;
        break;
      }
    photos.push_back(dir + "/view" + std::to_string(photos.size()) + ".png");
    ASSERT_TRUE(cv::imwrite(photos.back(), photo));
  }
  EXPECT_GE(partial, 3);

  CameraCalibratorOptions options;
  options.threads = 2;
  const CameraCalibration c = CalibrateCamera(photos, board, options);
  std::printf(
      "ChArUco (8 views, %d partly out of the photo, f = %.0f px): fx %.3f fy %.3f cx "
      "%.3f cy %.3f (truth %.1f %.1f), rms %.4f px\n",
      partial, kFocal, c.fx, c.fy, c.cx, c.cy, 0.5 * (kWidth - 1), 0.5 * (kHeight - 1), c.rms_px);
  EXPECT_EQ(c.ViewsUsed(), 8);
  EXPECT_EQ(c.board.type, "charuco");
  EXPECT_NEAR(c.fx / kFocal, 1.0, 0.003);
  EXPECT_NEAR(c.fy / kFocal, 1.0, 0.003);
  EXPECT_NEAR(c.cx, 0.5 * (kWidth - 1), 1.5);
  EXPECT_NEAR(c.cy, 0.5 * (kHeight - 1), 1.5);
  int fewer = 0;
  for (const auto& v : c.views) fewer += v.corners < 54 ? 1 : 0;
  EXPECT_GE(fewer, 3);  // the partial views were used with the corners they show
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
