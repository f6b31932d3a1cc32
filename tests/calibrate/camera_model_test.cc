// The camera model three ways must agree: the Ceres functor (camera_projection_cost.h),
// core/camera_calibration.h, and OpenCV's projectPoints; calib/camera.json round-trips and its
// reader names file and field.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>

#include "calibrate/camera/camera_projection_cost.h"
#include "core/camera_calibration.h"
#include "core/error.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

CameraCalibration StrongLens() {
  CameraCalibration c;
  c.image_width = 1200;
  c.image_height = 800;
  c.fx = 1010;
  c.fy = 1004;
  c.cx = 612.5;
  c.cy = 391.25;
  c.k1 = -0.25;
  c.k2 = 0.08;
  c.p1 = 0.0012;
  c.p2 = -0.0007;
  c.k3 = -0.01;
  return c;
}

TEST(CameraModel, FunctorAndCoreAgreeWithOpenCvProjectPoints) {
  const CameraCalibration c = StrongLens();
  const double rvec[3] = {0.3, -0.2, 0.1}, tvec[3] = {-40, 25, 600};
  std::vector<cv::Point3d> board;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 9; ++x) board.emplace_back(30.0 * x - 120, 30.0 * y - 75, 0);
  std::vector<cv::Point2d> expected;
  const cv::Mat k = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  const cv::Mat d = (cv::Mat_<double>(5, 1) << c.k1, c.k2, c.p1, c.p2, c.k3);
  cv::projectPoints(board, cv::Mat(3, 1, CV_64F, const_cast<double*>(rvec)),
                    cv::Mat(3, 1, CV_64F, const_cast<double*>(tvec)), k, d, expected);
  const double intrinsics[4] = {c.fx, c.fy, c.cx, c.cy};
  const double distortion[5] = {c.k1, c.k2, c.p1, c.p2, c.k3};
  const double pose[6] = {rvec[0], rvec[1], rvec[2], tvec[0], tvec[1], tvec[2]};
  cv::Mat r;
  cv::Rodrigues(cv::Mat(3, 1, CV_64F, const_cast<double*>(rvec)), r);
  for (size_t i = 0; i < board.size(); ++i) {
    const Eigen::Vector2d seen(expected[i].x + 0.25, expected[i].y - 0.5);
    const CameraProjectionCost cost(seen, {board[i].x, board[i].y, 0});
    double residual[2];
    ASSERT_TRUE(cost(intrinsics, distortion, pose, residual));
    EXPECT_NEAR(residual[0], -0.25, 1e-9);
    EXPECT_NEAR(residual[1], 0.5, 1e-9);

    const cv::Mat x = r * (cv::Mat_<double>(3, 1) << board[i].x, board[i].y, 0);
    const Eigen::Vector3d camera(x.at<double>(0) + tvec[0], x.at<double>(1) + tvec[1],
                                 x.at<double>(2) + tvec[2]);
    const Eigen::Vector2d p = c.Project(camera);
    EXPECT_NEAR(p.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(p.y(), expected[i].y, 1e-9);
    // And back: the undistorted ray is the camera point's.
    const Eigen::Vector2d n = c.UndistortToNormalised(p);
    EXPECT_NEAR(n.x(), camera.x() / camera.z(), 1e-10);
    EXPECT_NEAR(n.y(), camera.y() / camera.z(), 1e-10);
  }
}

class CameraJson : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (fs::path(::testing::TempDir()) /
             ("lumislab_camera_json_" + std::to_string(::getpid()) + ".json"))
                .string();
  }
  void TearDown() override { fs::remove(path_); }
  std::string path_;
};

TEST_F(CameraJson, RoundTrips) {
  CameraCalibration c = StrongLens();
  c.rms_px = 0.31;
  c.opencv_rms_px = 0.32;
  c.sigma = {1, 2, 3, 4, 0.01, 0.02, 0.001, 0.002, 0.03};
  c.board.inner_cols = 9;
  c.board.inner_rows = 6;
  c.board.square_mm = 25;
  CameraViewReport used;
  used.photo = "a.jpg";
  used.used = true;
  used.corners = 54;
  used.rms_px = 0.2;
  used.tilt_deg = 31;
  used.rotation = {0.1, 0.2, 0.3};
  used.translation_mm = {1, 2, 300};
  CameraViewReport rejected;
  rejected.photo = "b.jpg";
  rejected.rejected = "board not found";
  c.views = {used, rejected};
  c.Save(path_);
  const CameraCalibration back = CameraCalibration::Load(path_);
  EXPECT_EQ(back.image_width, 1200);
  EXPECT_EQ(back.fx, c.fx);
  EXPECT_EQ(back.cy, c.cy);
  EXPECT_EQ(back.p2, c.p2);
  EXPECT_EQ(back.k3, c.k3);
  EXPECT_EQ(back.sigma, c.sigma);
  EXPECT_EQ(back.board.inner_cols, 9);
  ASSERT_EQ(back.views.size(), 2u);
  EXPECT_EQ(back.views[0].translation_mm, used.translation_mm);
  EXPECT_EQ(back.views[1].rejected, "board not found");
  EXPECT_EQ(back.ViewsUsed(), 1);
}

TEST_F(CameraJson, ErrorsNameFileAndField) {
  CameraCalibration c = StrongLens();
  c.board.inner_cols = 9;
  c.board.inner_rows = 6;
  c.board.square_mm = 25;
  CameraViewReport v;
  v.photo = "a.jpg";
  v.used = true;
  c.views = {v};
  c.Save(path_);
  auto edit = [&](const std::string& from, const std::string& to) {
    std::ifstream in(path_);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(path_) << text;
  };
  edit("\"fx\": 1010.0", "\"fx\": -3");
  try {
    CameraCalibration::Load(path_);
    FAIL() << "a negative focal length was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find(path_ + ": camera_matrix.fx: expected"), std::string::npos)
        << e.what();
  }
  edit("\"fx\": -3", "\"fx\": 1010.0");
  edit("\"opencv5\"", "\"fisheye\"");
  EXPECT_THROW(CameraCalibration::Load(path_), Error);
  edit("\"fisheye\"", "\"opencv5\"");
  edit("\"schema_version\": 1", "\"schema_version\": 2");
  EXPECT_THROW(CameraCalibration::Load(path_), Error);
}

}  // namespace
}  // namespace lumislab
