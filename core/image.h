// A plain float image (row-major, interleaved channels) used by core IO; stages use OpenCV.
#pragma once

#include <cstddef>
#include <vector>

namespace lumislab {

struct ImageF {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> data;  // data[(y * width + x) * channels + c]

  ImageF() = default;
  ImageF(int w, int h, int c, float fill = 0.f)
      : width(w), height(h), channels(c), data(size_t(w) * h * c, fill) {}
  float& at(int x, int y, int c) { return data[(size_t(y) * width + x) * channels + c]; }
  float at(int x, int y, int c) const { return data[(size_t(y) * width + x) * channels + c]; }
  bool empty() const { return data.empty(); }
};

}  // namespace lumislab
