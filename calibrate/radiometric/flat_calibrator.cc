#include "calibrate/radiometric/flat_calibrator.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "calibrate/radiometric/calibration_checks.h"
#include "core/error.h"
#include "core/log.h"

namespace lumislab {

namespace {

// A flat frame's gain (vignetting times the screen's non-uniformity) varies over tens of pixels;
// a light pattern, a shadow's edge or an object in view varies over a few. The fraction of the
// screen pixels (those that count, kBorderPx in from the screen's outline, where a pixel sees
// part screen and part surround) whose gain differs from its Gaussian-smoothed neighbourhood
// (sigma kSmoothFraction of the image width) by more than kStructureTolerance in some channel.
// The frames' noise (about 1 % per pixel for 8-bit flats) stays far below the tolerance.
constexpr double kStructureTolerance = 0.2;
constexpr double kSmoothFraction = 0.01;
constexpr int kBorderPx = 3;

double StructuredFraction(const ImageF& gain, const std::vector<uint8_t>& on_screen,
                          const DarkMap* dark, int w, int h) {
  cv::Mat mask(h, w, CV_32FC1, 0.f);
  for (size_t p = 0; p < on_screen.size(); ++p)
    if (on_screen[p] && !(dark && dark->hot[p])) mask.at<float>(int(p / w), int(p % w)) = 1.f;
  cv::Mat inner;
  cv::erode(mask, inner, cv::Mat(), cv::Point(-1, -1), kBorderPx);
  const double sigma = std::max(2.0, kSmoothFraction * w);
  cv::Mat g(h, w, CV_32FC3, const_cast<float*>(gain.data.data())), mask3, weighted, norm;
  cv::merge(std::vector<cv::Mat>{mask, mask, mask}, mask3);
  cv::GaussianBlur(g.mul(mask3), weighted, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
  cv::GaussianBlur(mask3, norm, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
  long long counted = 0, structured = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (inner.at<float>(y, x) == 0.f) continue;
      ++counted;
      for (int c = 0; c < 3; ++c) {
        const double smooth = weighted.at<cv::Vec3f>(y, x)[c] / norm.at<cv::Vec3f>(y, x)[c];
        if (std::abs(g.at<cv::Vec3f>(y, x)[c] / smooth - 1) > kStructureTolerance) {
          ++structured;
          break;
        }
      }
    }
  return counted ? double(structured) / double(counted) : 0.0;
}

}  // namespace

FlatMap CalibrateFlat(const std::vector<CalibrationFrame>& frames, const Dataset& dataset,
                      const ScreenCalibration& screen, nlohmann::json* report, double smooth_px,
                      CheckLog* checks) {
  const int w = frames[0].photo.pixels.cols, h = frames[0].photo.pixels.rows;
  const size_t n = size_t(w) * h;
  // Pixels that see the screen.
  std::vector<uint8_t> on_screen(n, 0);
  size_t screen_pixels = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2d mm = screen.ScreenFromImage({x, y});
      if (std::abs(mm.x()) <= 0.5 * dataset.screen_w_mm &&
          std::abs(mm.y()) <= 0.5 * dataset.screen_h_mm)
        on_screen[size_t(y) * w + x] = 1, ++screen_pixels;
    }
  if (screen_pixels == 0)
    throw InputError(dataset.Path("calib/screen.json"), "screen_from_image",
                     "a mapping under which some pixels see the screen", "none do");
  const std::shared_ptr<const PhotoCorrections>& corrections = frames[0].photo.spec.corrections;
  const DarkMap* dark = corrections ? corrections->dark.get() : nullptr;
  std::vector<double> sum(n * 3, 0), sum2(n * 3, 0);
  // Pixels clipped in some frame: isolated ones (hot pixels when no dark map is given, dust
  // glints) keep gain 1 and are reported; more than kMaxClippedFraction of the screen means the
  // frames are overexposed.
  constexpr double kMaxClippedFraction = 1e-3;
  std::vector<uint8_t> clipped_any(n, 0);
  // The frames' mean level on the screen at their own exposures (fraction of full scale): a
  // flat has light (calibration_checks.h, flat.has_signal).
  double level_sum = 0;
  long long level_n = 0;
  for (const auto& f : frames) {
    const LinearReader reader(f.photo);
    long long clipped_pixels = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * w + x;
        float v[3];
        bool clipped[3];
        reader.Read(y, x, v, clipped);
        if (on_screen[p] && !(dark && dark->hot[p]) && (clipped[0] || clipped[1] || clipped[2]))
          ++clipped_pixels, clipped_any[p] = 1;
        for (int c = 0; c < 3; ++c) sum[p * 3 + c] += v[c], sum2[p * 3 + c] += double(v[c]) * v[c];
        if (on_screen[p] && !(dark && dark->hot[p]))
          level_sum += (v[0] + v[1] + v[2]) / 3 * f.exposure, ++level_n;
      }
    if (double(clipped_pixels) > kMaxClippedFraction * double(screen_pixels)) {
      const Error error = InputError(
          f.photo.path, "pixel data",
          "a flat frame with at most 0.1 % of the screen's pixels clipped (lower "
          "the exposure)",
          std::to_string(clipped_pixels) + " clipped pixel(s) of " + std::to_string(screen_pixels));
      if (checks)
        checks->Fail("flat.clipped", error.what(),
                     {{"frame", f.photo.path},
                      {"clipped_pixels", clipped_pixels},
                      {"screen_pixels", screen_pixels},
                      {"max_clipped_fraction", kMaxClippedFraction}});
      throw error;
    }
  }
  long long clipped_left = 0;
  for (size_t p = 0; p < n; ++p)
    if (clipped_any[p]) on_screen[p] = 0, ++clipped_left;  // gain 1, out of the mean
  const double frames_n = double(frames.size());
  double mean[3] = {0, 0, 0};
  size_t used = 0;
  for (size_t p = 0; p < n; ++p) {
    if (!on_screen[p] || (dark && dark->hot[p])) continue;
    for (int c = 0; c < 3; ++c) mean[c] += sum[p * 3 + c] / frames_n;
    ++used;
  }
  const double mean_level = level_n ? level_sum / double(level_n) : 0.0;
  if (checks) CheckFlatSignal(frames[0].photo.path, mean_level, checks);
  for (double& m : mean) {
    m /= double(std::max<size_t>(used, 1));
    if (!(m > 0))
      throw InputError(frames[0].photo.path, "pixel data",
                       "a lit screen (mean linear value > 0 after dark subtraction)",
                       std::to_string(m));
  }
  FlatMap map;
  map.gain = ImageF(w, h, 3, 1.f);
  double lo = 1e30, hi = -1e30, noise2 = 0;
  long long clamped = 0, noise_n = 0;
  for (size_t p = 0; p < n; ++p) {
    if (!on_screen[p] || (dark && dark->hot[p])) continue;
    for (int c = 0; c < 3; ++c) {
      const double m = sum[p * 3 + c] / frames_n;
      double g = m / mean[c];
      // Vignetting and a screen's non-uniformity stay within a factor of a few; a gain below
      // 1/20 or above 20 is a defective pixel (dead, or dark-subtracted to nothing), and
      // dividing by it would multiply the pixel's error into the photos: it keeps gain 1.
      if (!(g >= 0.05 && g <= 20)) g = 1.0, ++clamped;
      map.gain.data[p * 3 + c] = float(g);
      lo = std::min(lo, g), hi = std::max(hi, g);
      if (frames.size() >= 2 && m > 0) {
        const double var = std::max(0.0, (sum2[p * 3 + c] - frames_n * m * m) / (frames_n - 1));
        noise2 += var / (m * m) / frames_n;  // relative variance of the mean
        ++noise_n;
      }
    }
  }
  const double structured = StructuredFraction(map.gain, on_screen, dark, w, h);
  // The spread of the gain over the screen (the channels' mean, 1st and 99th percentile): a
  // lens's vignetting times a screen's non-uniformity stays within a few stops; a pattern of
  // light leaves parts of the screen near zero (calibration_checks.h, flat.is_flat).
  std::vector<float> gains;
  for (size_t p = 0; p < n; ++p)
    if (on_screen[p] && !(dark && dark->hot[p]))
      gains.push_back((map.gain.data[p * 3] + map.gain.data[p * 3 + 1] + map.gain.data[p * 3 + 2]) /
                      3);
  const double gain_p01 = gains.empty() ? 1.0 : Percentile(gains, 0.01);
  const double gain_p99 = gains.empty() ? 1.0 : Percentile(gains, 0.99);
  if (smooth_px > 0) {
    // Normalised convolution: blur(gain * mask) / blur(mask) over the pixels that count.
    cv::Mat gain(h, w, CV_32FC3, map.gain.data.data()), mask(h, w, CV_32FC1, 0.f);
    for (size_t p = 0; p < n; ++p)
      if (on_screen[p] && !(dark && dark->hot[p])) mask.at<float>(int(p / w), int(p % w)) = 1.f;
    cv::Mat weighted, blurred_mask, mask3;
    cv::merge(std::vector<cv::Mat>{mask, mask, mask}, mask3);
    cv::GaussianBlur(gain.mul(mask3), weighted, cv::Size(), smooth_px, smooth_px,
                     cv::BORDER_REPLICATE);
    cv::GaussianBlur(mask3, blurred_mask, cv::Size(), smooth_px, smooth_px, cv::BORDER_REPLICATE);
    lo = 1e30, hi = -1e30;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (mask.at<float>(y, x) == 0.f) continue;  // hot, clipped and off-screen stay at 1
        for (int c = 0; c < 3; ++c) {
          const float m = blurred_mask.at<cv::Vec3f>(y, x)[c];
          const float g = std::clamp(weighted.at<cv::Vec3f>(y, x)[c] / m, 1e-3f, 1e3f);
          gain.at<cv::Vec3f>(y, x)[c] = g;
          lo = std::min(lo, double(g)), hi = std::max(hi, double(g));
        }
      }
  }
  nlohmann::json& r = *report;
  r["smooth_px"] = smooth_px;
  r["frames"] = nlohmann::json::array();
  for (const auto& f : frames)
    r["frames"].push_back({{"file", f.photo.path}, {"exposure", f.exposure}});
  r["screen_pixels"] = screen_pixels;
  r["mean_value_rgb"] = {mean[0], mean[1], mean[2]};
  r["min_gain"] = lo;
  r["max_gain"] = hi;
  r["clamped_values"] = clamped;
  r["clipped_pixels_at_gain_1"] = clipped_left;
  r["structured_fraction"] = structured;
  r["mean_level"] = mean_level;
  r["gain_percentiles_1_99"] = {gain_p01, gain_p99};
  r["noise_rms"] = noise_n ? nlohmann::json(std::sqrt(noise2 / noise_n)) : nlohmann::json();
  r["corrections_applied"] = {{"dark", dark != nullptr},
                              {"response", corrections && corrections->response != nullptr}};
  return map;
}

}  // namespace lumislab
