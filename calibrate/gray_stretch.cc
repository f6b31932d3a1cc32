#include "calibrate/gray_stretch.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace lumislab {

cv::Mat StretchToGray8(const cv::Mat& gray, double* contrast) {
  CV_Assert(gray.type() == CV_32FC1 && !gray.empty());
  // Quantiles from a subsample (at most ~1M pixels).
  const int step = std::max(1, int(std::sqrt(double(gray.total()) / 1e6)));
  std::vector<float> values;
  values.reserve(gray.total() / (step * step) + gray.rows + gray.cols);
  for (int y = 0; y < gray.rows; y += step) {
    const float* row = gray.ptr<float>(y);
    for (int x = 0; x < gray.cols; x += step) values.push_back(row[x]);
  }
  auto quantile = [&](double q) {
    const size_t k = std::min(values.size() - 1, size_t(q * double(values.size() - 1)));
    std::nth_element(values.begin(), values.begin() + k, values.end());
    return double(values[k]);
  };
  const double lo = quantile(0.005);
  const double hi = quantile(0.995);
  const double span = hi - lo;
  if (contrast) *contrast = span;
  cv::Mat out;
  if (!(span > 0)) {
    out = cv::Mat(gray.size(), CV_8UC1, cv::Scalar(0));
    return out;
  }
  gray.convertTo(out, CV_8U, 255.0 / span, -lo * 255.0 / span);  // saturating
  return out;
}

}  // namespace lumislab
