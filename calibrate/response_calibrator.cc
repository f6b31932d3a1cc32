#include "calibrate/response_calibrator.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include "core/error.h"
#include "core/log.h"

namespace lumislab {

void ResponseOptions::Check() const {
  if (samples < 50 || samples > 1000)
    throw BadInput("--samples: expected 50 .. 1000, got " + std::to_string(samples));
  if (!(lambda > 0 && lambda <= 1000))
    throw BadInput("--lambda: expected a number in (0, 1000], got " + std::to_string(lambda));
}

namespace {

// The frames' codes as 3-channel BGR (OpenCV's order; a gray frame's one channel thrice).
std::vector<cv::Mat> BgrCodes(const std::vector<CalibrationFrame>& frames) {
  std::vector<cv::Mat> out;
  for (const auto& f : frames) {
    cv::Mat bgr = f.photo.pixels;
    if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
    if (f.photo.rgb_order) cv::cvtColor(bgr, bgr, cv::COLOR_RGB2BGR);
    out.push_back(bgr);
  }
  return out;
}

// Sample pixels for channel `channel` (BGR index; the solver's other channels are not used):
// its code in [1, 254] in every frame (a clipped code says only "at least", which the least squares
// would read as "equal") and a code that changes over the series (a pixel the same in every frame
// sees no light), spread evenly over the channel's code range in the middle frame, in a fixed
// scattered order so that they cover the image; bins left short are topped up from the others.
std::vector<cv::Point> ChooseSamples(const std::vector<cv::Mat>& codes, int channel, int count) {
  const int w = codes[0].cols, h = codes[0].rows;
  const size_t n = size_t(w) * h;
  const cv::Mat& middle = codes[codes.size() / 2];
  constexpr int kBins = 32;
  constexpr int kMaxLocalRange = 12;  // codes over the 5 x 5 neighbourhood
  // A clipped code says only "at least", which the least squares would read as "equal"; JPEG's
  // error spreads a clipped 255 (or a black 0) over the nearby codes, so those count as clipped.
  constexpr int kLowestCode = 5, kHighestCode = 245;
  std::vector<std::vector<cv::Point>> bins(kBins);
  const size_t stride = 7919;  // a prime: visits every pixel once, scattered
  for (size_t k = 0, p = 0; k < n; ++k, p = (p + stride) % n) {
    const int x = int(p % w), y = int(p / w);
    if (x < 2 || y < 2 || x >= w - 2 || y >= h - 2) continue;
    // In a smooth region only: JPEG's chroma subsampling and block artefacts move codes near
    // edges (the screen's border) between frames in ways no response curve explains.
    int lo = 255, hi = 0;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) {
        const int v = middle.at<cv::Vec3b>(y + dy, x + dx)[channel];
        lo = std::min(lo, v), hi = std::max(hi, v);
      }
    if (hi - lo > kMaxLocalRange) continue;
    bool ok = true;
    for (const cv::Mat& m : codes) {
      const int v = m.at<cv::Vec3b>(y, x)[channel];
      ok &= v >= kLowestCode && v <= kHighestCode;
    }
    const int first = codes.front().at<cv::Vec3b>(y, x)[channel];
    const int last = codes.back().at<cv::Vec3b>(y, x)[channel];
    if (ok && std::abs(last - first) >= 4)
      bins[middle.at<cv::Vec3b>(y, x)[channel] * kBins / 256].push_back({x, y});
  }
  // Round robin over the bins: as even as the codes allow.
  std::vector<cv::Point> out;
  for (size_t round = 0; int(out.size()) < count; ++round) {
    bool any = false;
    for (const auto& b : bins)
      if (round < b.size() && int(out.size()) < count) out.push_back(b[round]), any = true;
    if (!any) break;
  }
  return out;
}

// RMS and mean of log((v_b / e_b) / (v_a / e_a)) over pixels with every channel's code in
// [10, 245] in consecutive frames a, b: 0 when the curve makes the frames consistent.
nlohmann::json Consistency(const std::vector<cv::Mat>& codes, const std::vector<double>& exposure,
                           const std::array<std::array<float, 256>, 3>& curve_rgb) {
  double sum = 0, sum2 = 0;
  long long n = 0;
  for (size_t a = 0; a + 1 < codes.size(); ++a) {
    const size_t b = a + 1;
    if (exposure[a] == exposure[b]) continue;
    for (int y = 0; y < codes[a].rows; ++y)
      for (int x = 0; x < codes[a].cols; ++x) {
        const cv::Vec3b ca = codes[a].at<cv::Vec3b>(y, x), cb = codes[b].at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) {  // BGR -> curve index 2 - c
          if (ca[c] < 10 || ca[c] > 245 || cb[c] < 10 || cb[c] > 245) continue;
          const double va = curve_rgb[2 - c][ca[c]] / exposure[a];
          const double vb = curve_rgb[2 - c][cb[c]] / exposure[b];
          const double r = std::log(vb / va);
          sum += r, sum2 += r * r, ++n;
        }
      }
  }
  nlohmann::json j;
  j["samples"] = n;
  j["mean_log_ratio"] = n ? sum / n : 0.0;
  j["rms_log_ratio"] = n ? std::sqrt(sum2 / n) : 0.0;
  return j;
}

}  // namespace

ResponseCurve CalibrateResponse(const std::vector<CalibrationFrame>& frames,
                                const ResponseOptions& options, nlohmann::json* report) {
  std::vector<double> exposure;
  for (const auto& f : frames) {
    if (!f.exposure_known)
      throw InputError(f.photo.path, "exposure",
                       "an exposure from EXIF (time, f-number, ISO) or --exposures", "none");
    exposure.push_back(f.exposure);
  }
  if (*std::min_element(exposure.begin(), exposure.end()) ==
      *std::max_element(exposure.begin(), exposure.end()))
    throw InputError(frames[0].photo.path, "exposure", "frames of at least two different exposures",
                     "one exposure for all");
  // Darkest frame first: the sample choice reads the series in exposure order.
  std::vector<size_t> order(frames.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return exposure[a] < exposure[b]; });
  std::vector<CalibrationFrame const*> sorted;
  std::vector<double> sorted_exposure;
  for (size_t k : order) sorted.push_back(&frames[k]), sorted_exposure.push_back(exposure[k]);
  std::vector<CalibrationFrame> copies;
  for (const auto* f : sorted) copies.push_back(*f);
  const std::vector<cv::Mat> codes = BgrCodes(copies);
  // The solver sees each sample's 3 x 3 mean (rounded to a code): JPEG's per-pixel error
  // averages out, and samples lie in smooth regions (ChooseSamples), where the mean code is the
  // code of the mean light to well under a code.
  std::vector<cv::Mat> smooth(codes.size());
  for (size_t k = 0; k < codes.size(); ++k) cv::blur(codes[k], smooth[k], cv::Size(3, 3));
  // Per channel: its own samples, spread over its codes. OpenCV's solver samples a grid;
  // handed a 1-row image of our samples with `samples` equal to its width, it takes exactly
  // every one of them.
  ResponseCurve curve;
  size_t sample_count[3];
  for (int c = 0; c < 3; ++c) {  // R, G, B; OpenCV's images and response are BGR
    const int bgr = 2 - c;
    const std::vector<cv::Point> samples = ChooseSamples(codes, bgr, options.samples);
    sample_count[c] = samples.size();
    if (samples.size() < 20)
      throw InputError(frames[0].photo.path, "frames",
                       "at least 20 pixels unclipped in every frame and changing over the series "
                       "(use exposures closer together, or a scene with more mid-tones)",
                       std::to_string(samples.size()));
    std::vector<cv::Mat> rows;
    for (const cv::Mat& m : smooth) {
      cv::Mat row(1, int(samples.size()), CV_8UC3);
      for (size_t k = 0; k < samples.size(); ++k)
        row.at<cv::Vec3b>(0, int(k)) = m.at<cv::Vec3b>(samples[k]);
      rows.push_back(row);
    }
    std::vector<float> times(sorted_exposure.begin(), sorted_exposure.end());
    cv::Mat response;
    cv::createCalibrateDebevec(int(samples.size()), float(options.lambda), false)
        ->process(rows, response, times);
    std::array<float, 256>& out = curve.linear_of_code[c];
    const double top = response.at<cv::Vec3f>(255, 0)[bgr];
    if (!(top > 0) || !std::isfinite(top))
      throw Failure("response: the solver returned no usable curve (value at code 255: " +
                    std::to_string(top) + ")");
    for (int k = 0; k < 256; ++k) out[k] = float(response.at<cv::Vec3f>(k, 0)[bgr] / top);
    out[255] = 1;
    // Strictly increasing from the top down (the curve is pinned to 1 at code 255).
    for (int k = 254; k >= 0; --k)
      if (!(out[k] < out[k + 1]) || !std::isfinite(out[k])) out[k] = out[k + 1] * (1 - 1e-6f);
  }
  std::array<std::array<float, 256>, 3> srgb{};
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 256; ++k) {
      const double v = k / 255.0;
      srgb[c][k] = float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
    }
  nlohmann::json& r = *report;
  r["method"] = "debevec";
  r["solver"] = "OpenCV CalibrateDebevec on chosen samples";
  r["samples"] = {sample_count[0], sample_count[1], sample_count[2]};
  r["lambda"] = options.lambda;
  r["frames"] = nlohmann::json::array();
  for (size_t k = 0; k < sorted.size(); ++k)
    r["frames"].push_back({{"file", sorted[k]->photo.path}, {"exposure", sorted_exposure[k]}});
  r["consistency"] = Consistency(codes, sorted_exposure, curve.linear_of_code);
  r["consistency_srgb_curve"] = Consistency(codes, sorted_exposure, srgb);
  return curve;
}

nlohmann::json CheckLinearity(const std::vector<CalibrationFrame>& frames) {
  std::vector<size_t> order(frames.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return frames[a].exposure < frames[b].exposure; });
  const CalibrationFrame& ref = frames[order[order.size() / 2]];
  const LinearReader ref_reader(ref.photo);
  nlohmann::json r;
  r["method"] = "linearity";
  r["reference_frame"] = ref.photo.path;
  r["frames"] = nlohmann::json::array();
  double worst = 0;
  for (size_t k : order) {
    const CalibrationFrame& f = frames[k];
    const LinearReader reader(f.photo);
    double sum = 0, sum2 = 0;
    long long n = 0;
    for (int y = 0; y < f.photo.pixels.rows; ++y)
      for (int x = 0; x < f.photo.pixels.cols; ++x) {
        float v[3], u[3];
        bool cv_[3], cu[3];
        reader.Read(y, x, v, cv_);
        ref_reader.Read(y, x, u, cu);
        for (int c = 0; c < 3; ++c) {
          if (cv_[c] || cu[c] || !(v[c] > 0.02f) || !(u[c] > 0.02f)) continue;
          const double ratio = (v[c] / f.exposure) / (u[c] / ref.exposure);
          sum += ratio, sum2 += ratio * ratio, ++n;
        }
      }
    const double mean = n ? sum / n : 1.0;
    const double rms = n ? std::sqrt(std::max(0.0, sum2 / n - mean * mean)) : 0.0;
    if (n) worst = std::max(worst, std::abs(mean - 1));
    r["frames"].push_back({{"file", f.photo.path},
                           {"exposure", f.exposure},
                           {"pixels", n},
                           {"mean_ratio", mean},
                           {"ratio_spread", rms}});
  }
  r["max_deviation"] = worst;
  return r;
}

}  // namespace lumislab
