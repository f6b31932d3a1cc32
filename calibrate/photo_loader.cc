#include "calibrate/photo_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/error.h"
#include "core/exr_io.h"

namespace lumislab {

namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

cv::Mat ReadExrGray(const std::string& path) {
  const ImageF rgb = ReadExr(path, {"R", "G", "B"});
  cv::Mat gray(rgb.height, rgb.width, CV_32FC1);
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x)
      gray.at<float>(y, x) =
          0.2126f * rgb.at(x, y, 0) + 0.7152f * rgb.at(x, y, 1) + 0.0722f * rgb.at(x, y, 2);
  return gray;
}

}  // namespace

cv::Mat LoadGrayPhoto(const std::string& path) {
  if (!std::filesystem::exists(path)) throw BadInput(path + ": calibration photo missing");
  cv::Mat gray;
  try {
    if (Lower(std::filesystem::path(path).extension().string()) == ".exr") {
      gray = ReadExrGray(path);
    } else {
      const cv::Mat image = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
      if (image.empty())
        throw BadInput(path + ": calibration photo unreadable (not a valid image file)");
      cv::Mat one;
      if (image.channels() == 3) {
        cv::cvtColor(image, one, cv::COLOR_BGR2GRAY);
      } else if (image.channels() == 4) {
        cv::cvtColor(image, one, cv::COLOR_BGRA2GRAY);
      } else if (image.channels() == 1) {
        one = image;
      } else {
        throw BadInput(path + ": calibration photo has " + std::to_string(image.channels()) +
                       " channels, expected 1, 3 or 4");
      }
      one.convertTo(gray, CV_32F);
    }
  } catch (const cv::Exception& e) {
    throw BadInput(path + ": calibration photo unreadable: " + e.what());
  }
  if (gray.empty()) throw BadInput(path + ": calibration photo is empty");
  for (int y = 0; y < gray.rows; ++y) {
    const float* row = gray.ptr<float>(y);
    for (int x = 0; x < gray.cols; ++x)
      if (!std::isfinite(row[x]))
        throw BadInput(path + ": calibration photo holds non-finite values");
  }
  return gray;
}

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
