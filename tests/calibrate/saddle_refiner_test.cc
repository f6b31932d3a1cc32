// RefineSaddlePoints on rendered X-junctions at known sub-pixel positions and angles.
#include "calibrate/screen/saddle_refiner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace lumislab {
namespace {

// Two straight edges through (cx, cy) at angles a1, a2 (radians); opposite wedges share a
// colour. Each pixel averages 89 samples on a Fibonacci lattice (an n x n grid would quantise
// axis-aligned edges to 1/n pixel).
cv::Mat XJunction(double cx, double cy, double a1, double a2, int size = 61) {
  cv::Mat image(size, size, CV_32FC1);
  const int n = 89, stride = 55;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double sum = 0;
      for (int k = 0; k < n; ++k) {
        const double px = x - 0.5 + (k + 0.5) / n - cx;
        const double py = y - 0.5 + ((k * stride) % n + 0.5) / n - cy;
        const bool s1 = -std::sin(a1) * px + std::cos(a1) * py > 0;
        const bool s2 = -std::sin(a2) * px + std::cos(a2) * py > 0;
        sum += s1 == s2 ? 0.9 : 0.05;
      }
      image.at<float>(y, x) = float(sum / n);
    }
  return image;
}

TEST(SaddleRefiner, SubPixelCornersWithinTwoHundredthsOfAPixel) {
  double worst_saddle = 0, worst_subpix = 0;
  for (double f : {0.0, 0.13, 0.29, 0.5, 0.71, 0.88})
    for (auto angles : {std::pair<double, double>{0.0, M_PI / 2}, {0.2, 1.9}, {-0.4, 0.6}}) {
      const double cx = 30 + f, cy = 30.37 - 0.5 * f;
      const cv::Mat image = XJunction(cx, cy, angles.first, angles.second);
      std::vector<cv::Point2f> corners = {cv::Point2f(30.6f, 29.8f)};
      EXPECT_EQ(RefineSaddlePoints(image, 40, &corners), 1);
      worst_saddle = std::max(worst_saddle, std::hypot(corners[0].x - cx, corners[0].y - cy));
      std::vector<cv::Point2f> subpix = {cv::Point2f(30.6f, 29.8f)};
      cv::cornerSubPix(
          image, subpix, cv::Size(8, 8), cv::Size(-1, -1),
          cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-5));
      worst_subpix = std::max(worst_subpix, std::hypot(subpix[0].x - cx, subpix[0].y - cy));
    }
  std::printf("worst corner error: saddle fit %.4f px, cv::cornerSubPix %.4f px\n", worst_saddle,
              worst_subpix);
  EXPECT_LT(worst_saddle, 0.02);
  EXPECT_LT(worst_saddle, 0.5 * worst_subpix);
}

TEST(SaddleRefiner, LeavesCornersWithoutASaddleAlone) {
  const cv::Mat flat(61, 61, CV_32FC1, cv::Scalar(0.5));
  std::vector<cv::Point2f> corners = {cv::Point2f(30.3f, 29.6f), cv::Point2f(1.0f, 1.0f)};
  EXPECT_EQ(RefineSaddlePoints(flat, 40, &corners), 0);
  EXPECT_EQ(corners[0], cv::Point2f(30.3f, 29.6f));
  EXPECT_EQ(corners[1], cv::Point2f(1.0f, 1.0f));
}

}  // namespace
}  // namespace lumislab
