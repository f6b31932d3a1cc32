#include "lib/lightfield/tone_map.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace lumislab {

double ExposureFactor(const ImageF& image, double stops, bool automatic) {
  double factor = std::pow(2.0, stops);
  if (!automatic || image.empty()) return factor;
  std::vector<float> values;
  values.reserve(size_t(image.width) * image.height);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      values.push_back(std::max({image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)}));
    }
  }
  std::nth_element(values.begin(), values.begin() + values.size() * 99 / 100, values.end());
  const double p99 = values[values.size() * 99 / 100];
  if (p99 > 0) factor *= 0.8 / p99;
  return factor;
}

uint8_t SrgbByte(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  const double encoded = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
  return uint8_t(std::clamp(encoded * 255.0 + 0.5, 0.0, 255.0));
}

std::vector<uint8_t> EncodeSrgb8(const ImageF& image, double exposure_factor) {
  if (image.channels != 3) throw BadInput("sRGB encoding needs a 3-channel image");
  std::vector<uint8_t> out(image.data.size());
  for (size_t k = 0; k < image.data.size(); ++k) {
    out[k] = SrgbByte(image.data[k] * exposure_factor);
  }
  return out;
}

ImageDifference CompareImages(const ImageF& image, const ImageF& reference) {
  if (image.data.size() != reference.data.size() || reference.channels != 3) {
    throw BadInput("images to compare differ in size or are not 3-channel");
  }
  ImageDifference out;
  if (reference.empty()) return out;
  double diff = 0, norm = 0;
  const double floor = 1e-3 * *std::max_element(reference.data.begin(), reference.data.end());
  for (size_t px = 0; px < reference.data.size() / 3; ++px) {
    double peak = 0, error = 0;
    for (size_t c = 3 * px; c < 3 * px + 3; ++c) {
      const double e = double(image.data[c]) - reference.data[c];
      diff += e * e;
      norm += double(reference.data[c]) * reference.data[c];
      peak = std::max(peak, std::abs(double(reference.data[c])));
      error = std::max(error, std::abs(e));
    }
    if (peak > floor) out.worst_pixel = std::max(out.worst_pixel, error / peak);
  }
  out.relative_l2 = norm > 0 ? std::sqrt(diff / norm) : (diff > 0 ? INFINITY : 0.0);
  return out;
}

}  // namespace lumislab
