#include "calibrate/radiometric/dark_calibrator.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/core.hpp>

#include "core/error.h"

namespace lumislab {

void DarkOptions::Check() const {
  if (!(hot_threshold > 0 && hot_threshold <= 1))
    throw BadInput("--hot-threshold: expected a number in (0, 1], got " +
                   std::to_string(hot_threshold));
}

namespace {

// Frames of one exposure: per pixel and channel the mean and the variance between frames.
struct Group {
  double exposure = 0;
  int count = 0;
  std::vector<double> sum, sum2;  // w * h * 3
};

void Accumulate(const Photo& photo, Group* g) {
  const LinearReader reader(photo);
  const int w = photo.pixels.cols, h = photo.pixels.rows;
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      for (int x = 0; x < w; ++x) {
        float v[3];
        bool clipped[3];
        reader.Read(y, x, v, clipped);
        for (int c = 0; c < 3; ++c) {
          const size_t k = (size_t(y) * w + x) * 3 + c;
          g->sum[k] += v[c];
          g->sum2[k] += double(v[c]) * v[c];
        }
      }
  });
}

double Median(std::vector<float> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

DarkMap CalibrateDark(const std::vector<CalibrationFrame>& frames, const DarkOptions& options,
                      nlohmann::json* report) {
  const int w = frames[0].photo.pixels.cols, h = frames[0].photo.pixels.rows;
  const size_t n = size_t(w) * h * 3;
  std::map<double, Group> groups;  // by exposure
  for (const auto& f : frames) {
    Group& g = groups[f.exposure];
    if (g.count == 0) g.exposure = f.exposure, g.sum.assign(n, 0), g.sum2.assign(n, 0);
    Accumulate(f.photo, &g);
    ++g.count;
  }
  DarkMap map;
  map.offset = ImageF(w, h, 3);
  const bool fit = groups.size() >= 2;
  if (fit) map.current = ImageF(w, h, 3);
  // Per pixel and channel: the mean of one exposure, or the weighted least-squares line through
  // the exposures' means (weights: frame counts).
  double se = 0, see = 0, sw = 0;
  for (const auto& [e, g] : groups) sw += g.count, se += g.count * e, see += g.count * e * e;
  const double det = sw * see - se * se;
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    for (size_t k = size_t(rows.start) * w * 3; k < size_t(rows.end) * w * 3; ++k) {
      double sv = 0, sev = 0;
      for (const auto& [e, g] : groups) sv += g.sum[k], sev += e * g.sum[k];
      if (!fit) {
        map.offset.data[k] = float(sv / sw);
      } else {
        map.current.data[k] = float((sw * sev - se * sv) / det);
        map.offset.data[k] = float((see * sv - se * sev) / det);
      }
    }
  });
  // Hot pixels: dark level at the longest exposure (largest channel) well above the median's.
  const Group& longest = groups.rbegin()->second;
  std::vector<float> level(size_t(w) * h);
  for (size_t p = 0; p < level.size(); ++p) {
    float m = -1e30f;
    for (int c = 0; c < 3; ++c) m = std::max(m, float(longest.sum[p * 3 + c] / longest.count));
    level[p] = m;
  }
  const double median = Median(level);
  map.hot.assign(level.size(), 0);
  for (size_t p = 0; p < level.size(); ++p)
    if (level[p] > median + options.hot_threshold) map.hot[p] = 1, ++map.hot_count;
  // Report over the pixels that are not hot: mean level, dark current, temporal noise.
  double offset_sum = 0, current_sum = 0, var_sum = 0;
  long long used = 0, var_used = 0;
  for (size_t p = 0; p < level.size(); ++p) {
    if (map.hot[p]) continue;
    for (int c = 0; c < 3; ++c) {
      offset_sum += map.offset.data[p * 3 + c];
      if (fit) current_sum += map.current.data[p * 3 + c];
      ++used;
      for (const auto& [e, g] : groups)
        if (g.count >= 2) {
          const double mean = g.sum[p * 3 + c] / g.count;
          var_sum += std::max(0.0, (g.sum2[p * 3 + c] - g.count * mean * mean) / (g.count - 1));
          ++var_used;
        }
    }
  }
  nlohmann::json& r = *report;
  r["frames"] = nlohmann::json::array();
  for (const auto& f : frames)
    r["frames"].push_back({{"file", f.photo.path}, {"exposure", f.exposure}});
  r["exposures"] = nlohmann::json::array();
  for (const auto& [e, g] : groups) r["exposures"].push_back(e);
  r["mean_black_level"] = used ? offset_sum / used : 0.0;
  if (fit) r["mean_dark_current"] = used ? current_sum / used : 0.0;
  r["dark_noise"] = var_used ? nlohmann::json(std::sqrt(var_sum / var_used)) : nlohmann::json();
  r["median_level_longest_exposure"] = median;
  r["hot_pixels"] = map.hot_count;
  r["hot_threshold"] = options.hot_threshold;
  for (float v : map.offset.data)
    if (!std::isfinite(v))
      throw BadInput(frames[0].photo.path + ": dark frames hold non-finite values");
  return map;
}

}  // namespace lumislab
