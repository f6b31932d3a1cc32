#include "calibrate/screen/saddle_refiner.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace lumislab {

namespace {

// One Newton-like step: fits v = a x^2 + b xy + c y^2 + d x + e y + f (x, y relative to
// (cx, cy)) to the pixels around (cx, cy) with Gaussian weights of width `spread` centred there,
// and returns the offset to the saddle point; false when not a saddle or too near the border.
// Pixels are used as they are (no interpolation, which would bias the result by a few hundredths
// of a pixel); smooth weights on a blurred image make the sum an accurate stand-in for the
// integral, and the fit of a point-symmetric image centred on its centre has no linear term.
bool SaddleStep(const cv::Mat& image, double cx, double cy, double spread, Eigen::Vector2d* step) {
  const double extent = 4 * spread;  // weight exp(-8) at the cut: no step for pixels to alias
  const int x0 = int(std::floor(cx - extent)), x1 = int(std::ceil(cx + extent));
  const int y0 = int(std::floor(cy - extent)), y1 = int(std::ceil(cy + extent));
  if (x0 < 0 || y0 < 0 || x1 >= image.cols || y1 >= image.rows) return false;
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  for (int py = y0; py <= y1; ++py) {
    const float* row = image.ptr<float>(py);
    for (int px = x0; px <= x1; ++px) {
      const double x = px - cx, y = py - cy;
      const double r2 = x * x + y * y;
      if (r2 > extent * extent) continue;
      const double w = std::exp(-0.5 * r2 / (spread * spread));
      Eigen::Matrix<double, 6, 1> basis;
      basis << x * x, x * y, y * y, x, y, 1;
      ata += w * basis * basis.transpose();
      atb += w * basis * double(row[px]);
    }
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
  // 3 blur + 4 weight width < 0.45 square.
  const double sigma = std::clamp(0.05 * square_px, 0.8, 3.0);
  const double spread = std::clamp(0.06 * square_px, 0.8, 4.0);
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
      if (!SaddleStep(image, c.x(), c.y(), spread, &step)) break;
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
