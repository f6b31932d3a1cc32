#include "calibrate/saddle_refiner.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace lumislab {

namespace {

// Bilinear sample; false outside the image.
bool Sample(const cv::Mat& image, double x, double y, double* value) {
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= image.cols || y0 + 1 >= image.rows) return false;
  const double fx = x - x0, fy = y - y0;
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y0 + 1);
  *value =
      (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  return true;
}

// One Newton-like step: fits v = a x^2 + b xy + c y^2 + d x + e y + f on a disk of radius
// `radius` around (cx, cy) and returns the offset to the saddle point; false when not a saddle.
bool SaddleStep(const cv::Mat& image, double cx, double cy, double radius, Eigen::Vector2d* step) {
  const int k = int(std::ceil(radius));
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  for (int j = -k; j <= k; ++j)
    for (int i = -k; i <= k; ++i) {
      const double x = i * radius / k, y = j * radius / k;
      if (x * x + y * y > radius * radius) continue;
      double v;
      if (!Sample(image, cx + x, cy + y, &v)) return false;
      Eigen::Matrix<double, 6, 1> row;
      row << x * x, x * y, y * y, x, y, 1;
      ata += row * row.transpose();
      atb += row * v;
    }
  const Eigen::Matrix<double, 6, 1> p = ata.ldlt().solve(atb);
  Eigen::Matrix2d hessian;
  hessian << 2 * p(0), p(1), p(1), 2 * p(2);
  const double det = hessian.determinant();
  if (!(det < 0) || !std::isfinite(det)) return false;
  *step = -hessian.inverse() * Eigen::Vector2d(p(3), p(4));
  return step->allFinite();
}

}  // namespace

int RefineSaddlePoints(const cv::Mat& gray, double square_px, std::vector<cv::Point2f>* corners) {
  // Blur and window grow with the squares but stay clear of the neighbours and the dot:
  // radius + 3 sigma < 0.45 square.
  const double sigma = std::clamp(0.07 * square_px, 0.8, 4.0);
  const double radius = std::max(1.5, std::min(2 * sigma, 0.45 * square_px - 3 * sigma));
  cv::Mat image;
  gray.convertTo(image, CV_32F);
  cv::GaussianBlur(image, image, cv::Size(0, 0), sigma);
  int refined = 0;
  for (auto& corner : *corners) {
    Eigen::Vector2d c(corner.x, corner.y);
    const Eigen::Vector2d start = c;
    bool ok = false;
    for (int it = 0; it < 20; ++it) {
      Eigen::Vector2d step;
      if (!SaddleStep(image, c.x(), c.y(), radius, &step)) break;
      step = step.cwiseMax(-1.0).cwiseMin(1.0);  // trust region: one pixel per iteration
      c += step;
      if ((c - start).norm() > std::max(2.0, 0.25 * square_px)) break;
      if (step.norm() < 1e-4) {
        ok = true;
        break;
      }
    }
    if (!ok) continue;
    corner = cv::Point2f(float(c.x()), float(c.y()));
    ++refined;
  }
  return refined;
}

}  // namespace lumislab
