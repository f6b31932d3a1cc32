#include "calibrate/radiometric/response_calibrator.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "calibrate/radiometric/response_fit.h"
#include "core/error.h"
#include "core/log.h"

namespace lumislab {

void ResponseOptions::Check() const {
  if (samples < 50 || samples > 1000000)
    throw BadInput("--samples: expected 50 .. 1000000, got " + std::to_string(samples));
  if (!(lambda > 0 && lambda <= 1000))
    throw BadInput("--lambda: expected a number in (0, 1000], got " + std::to_string(lambda));
}

namespace {

// The frames' codes as 3-channel BGR (OpenCV's order; a gray frame's one channel thrice).
std::vector<cv::Mat> BgrCodes(const std::vector<CalibrationFrame>& frames) {
  std::vector<cv::Mat> out;
  for (const auto& f : frames) {
    cv::Mat bgr = Codes8(f.photo);
    if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
    if (f.photo.rgb_order) cv::cvtColor(bgr, bgr, cv::COLOR_RGB2BGR);
    out.push_back(bgr);
  }
  return out;
}

// The observations of channel `channel` (BGR index) for the fit (response_fit.h):
// up to `count` pixels, taken in a fixed scattered order so that they cover the image, in smooth
// regions only (the channel's codes range over at most kMaxLocalRange in the pixel's 5 x 5
// neighbourhood of the middle frame: JPEG's chroma subsampling and block artefacts move codes
// near edges between frames in ways no response curve explains). A sample's code in a frame is
// its 3 x 3 mean, unrounded (JPEG's and the sensor's per-pixel errors average out; in a smooth
// region the mean code is the code of the mean light to well under a code), usable when no code
// of the 5 x 5 neighbourhood is clipped or black in that frame (JPEG's error spreads a clipped
// 255, or a black 0, over the nearby codes: a clipped code says only "at least", which the
// least squares would read as "equal"). A pixel whose code hardly changes over the series sees
// no light (the dark level, off the screen) and is left out.
std::vector<float> Observations(const std::vector<cv::Mat>& codes, int channel, int count,
                                size_t* samples) {
  const int w = codes[0].cols, h = codes[0].rows, frames = int(codes.size());
  const size_t n = size_t(w) * h;
  const cv::Mat& middle = codes[codes.size() / 2];
  constexpr int kMaxLocalRange = 12;
  constexpr int kLowestCode = 3, kHighestCode = 252;
  std::vector<float> out;
  *samples = 0;
  const size_t stride = 7919;  // a prime: visits every pixel once, scattered
  std::vector<float> z(frames);
  for (size_t k = 0, p = 0; k < n && int(*samples) < count; ++k, p = (p + stride) % n) {
    const int x = int(p % w), y = int(p / w);
    if (x < 2 || y < 2 || x >= w - 2 || y >= h - 2) continue;
    int lo = 255, hi = 0;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) {
        const int v = middle.at<cv::Vec3b>(y + dy, x + dx)[channel];
        lo = std::min(lo, v), hi = std::max(hi, v);
      }
    if (hi - lo > kMaxLocalRange) continue;
    int usable = 0;
    float zmin = 255, zmax = 0;
    for (int j = 0; j < frames; ++j) {
      int flo = 255, fhi = 0, sum = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int v = codes[j].at<cv::Vec3b>(y + dy, x + dx)[channel];
          flo = std::min(flo, v), fhi = std::max(fhi, v);
          if (std::abs(dx) <= 1 && std::abs(dy) <= 1) sum += v;
        }
      z[j] = flo >= kLowestCode && fhi <= kHighestCode ? float(sum) / 9 : -1.f;
      if (z[j] >= 0) ++usable, zmin = std::min(zmin, z[j]), zmax = std::max(zmax, z[j]);
    }
    if (usable < 2 || zmax - zmin < 8) continue;
    out.insert(out.end(), z.begin(), z.end());
    ++*samples;
  }
  return out;
}

// RMS and mean of log((v_b / e_b) / (v_a / e_a)) over the channel values whose codes are in
// [32, 245] in consecutive frames a, b: 0 when the curve makes the frames consistent. (Below
// code 32 a dark offset, which the curve absorbs (docs/formats.md §14), and noise dominate.)
// `pairs` (optional) gets the same per consecutive pair, with the exposure ratio the linearised
// frames imply, stated ratio x exp(mean): what the curve says of each bracket step; and the mean
// over the values whose code in the darker frame is kResponseBrightCode or more.
nlohmann::json Consistency(const std::vector<cv::Mat>& codes, const std::vector<double>& exposure,
                           const std::array<std::array<float, 256>, 3>& curve_rgb,
                           const std::vector<std::string>& files = {},
                           nlohmann::json* pairs = nullptr) {
  double sum = 0, sum2 = 0;
  long long n = 0;
  if (pairs) *pairs = nlohmann::json::array();
  for (size_t a = 0; a + 1 < codes.size(); ++a) {
    const size_t b = a + 1;
    if (exposure[a] == exposure[b]) continue;
    double pair_sum = 0, pair_sum2 = 0, bright_sum = 0;
    long long pair_n = 0, bright_n = 0;
    for (int y = 0; y < codes[a].rows; ++y)
      for (int x = 0; x < codes[a].cols; ++x) {
        const cv::Vec3b ca = codes[a].at<cv::Vec3b>(y, x), cb = codes[b].at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) {  // BGR -> curve index 2 - c
          if (ca[c] < 32 || ca[c] > 245 || cb[c] < 32 || cb[c] > 245) continue;
          const double va = curve_rgb[2 - c][ca[c]] / exposure[a];
          const double vb = curve_rgb[2 - c][cb[c]] / exposure[b];
          const double r = std::log(vb / va);
          pair_sum += r, pair_sum2 += r * r, ++pair_n;
          if (ca[c] >= kResponseBrightCode) bright_sum += r, ++bright_n;
        }
      }
    sum += pair_sum, sum2 += pair_sum2, n += pair_n;
    if (!pairs) continue;
    const double mean = pair_n ? pair_sum / pair_n : 0.0;
    pairs->push_back({{"darker", files[a]},
                      {"brighter", files[b]},
                      {"samples", pair_n},
                      {"stated_ratio", exposure[b] / exposure[a]},
                      {"implied_ratio", exposure[b] / exposure[a] * std::exp(mean)},
                      {"mean_log_ratio", mean},
                      {"rms_log_ratio", pair_n ? std::sqrt(pair_sum2 / pair_n) : 0.0},
                      {"bright_samples", bright_n},
                      {"bright_mean_log_ratio", bright_n ? bright_sum / bright_n : 0.0}});
  }
  nlohmann::json j;
  j["samples"] = n;
  j["mean_log_ratio"] = n ? sum / n : 0.0;
  j["rms_log_ratio"] = n ? std::sqrt(sum2 / n) : 0.0;
  return j;
}

}  // namespace

ResponseCurve CalibrateResponse(const std::vector<CalibrationFrame>& frames,
                                const ResponseOptions& options, nlohmann::json* report,
                                CheckLog* checks) {
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
  std::vector<double> log_exposure;
  for (double e : sorted_exposure) log_exposure.push_back(std::log(e));
  // Each channel's samples. A JPEG engine applies one tone curve to the three channels (after
  // white balance): by default one curve is fitted to all of them. It has three times the data,
  // and above all it is normalised at code 255 alike in every channel: that normalisation is
  // an extrapolation beyond the last unclipped codes, and separate fits extrapolate differently,
  // a colour error (1-2 % between channels on noisy frames) that no later step removes (the
  // flat is normalised per channel, the scale is one number). --per-channel fits each alone.
  const int n_frames = int(codes.size());
  std::array<std::vector<float>, 3> obs;
  size_t sample_count[3];
  for (int c = 0; c < 3; ++c)  // R, G, B; the frames are BGR
    obs[c] = Observations(codes, 2 - c, options.samples, &sample_count[c]);
  const auto fit = [&](const std::vector<float>& o, size_t count) {
    size_t used = 0;
    std::array<double, 256> g{};
    if (count >= 20) g = FitLogInverseResponse(o, n_frames, log_exposure, options.lambda, &used);
    if (used < 20) {
      const Error error =
          InputError(frames[0].photo.path, "frames",
                     "at least 20 pixels unclipped in two frames or more and changing over the "
                     "series (use exposures closer together, or a scene with more mid-tones)",
                     std::to_string(used));
      if (checks)
        checks->Fail("response.samples", error.what(),
                     {{"samples", used}, {"min_samples", 20}, {"frames", n_frames}});
      throw error;
    }
    return g;
  };
  std::array<std::array<double, 256>, 3> g;
  if (options.per_channel) {
    for (int c = 0; c < 3; ++c) g[c] = fit(obs[c], sample_count[c]);
  } else {
    std::vector<float> all;
    for (const auto& o : obs) all.insert(all.end(), o.begin(), o.end());
    g[0] = g[1] = g[2] = fit(all, sample_count[0] + sample_count[1] + sample_count[2]);
  }
  ResponseCurve curve;
  nlohmann::json deviation = nlohmann::json::array();
  for (int c = 0; c < 3; ++c) {
    std::array<float, 256>& out = curve.linear_of_code[c];
    for (int k = 0; k < 256; ++k) out[k] = float(std::exp(g[c][k]));
    out[255] = 1;
    // Strictly increasing from the top down (the curve is pinned to 1 at code 255).
    for (int k = 254; k >= 0; --k)
      if (!(out[k] < out[k + 1]) || !std::isfinite(out[k])) out[k] = out[k + 1] * (1 - 1e-6f);
    // How far the channel's own data sit from its curve: the largest mean log residual over
    // 16-code bins from code 32 on that hold at least 100 observations.
    const ResidualBins bins = ResidualsByCode(obs[c], n_frames, log_exposure, g[c], 16);
    double worst = 0;
    for (size_t b = 2; b < bins.mean.size(); ++b)
      if (bins.count[b] >= 100) worst = std::max(worst, std::abs(bins.mean[b]));
    deviation.push_back(worst);
  }
  std::array<std::array<float, 256>, 3> srgb{};
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 256; ++k) {
      const double v = k / 255.0;
      srgb[c][k] = float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
    }
  nlohmann::json& r = *report;
  r["method"] = "debevec-continuous";
  r["solver"] = "weighted least squares of ln(inverse response), continuous codes";
  r["curves"] = options.per_channel ? "per channel" : "one for R, G, B";
  r["samples"] = {sample_count[0], sample_count[1], sample_count[2]};
  r["lambda"] = options.lambda;
  r["channel_deviation"] = deviation;
  r["frames"] = nlohmann::json::array();
  for (size_t k = 0; k < sorted.size(); ++k)
    r["frames"].push_back({{"file", sorted[k]->photo.path}, {"exposure", sorted_exposure[k]}});
  std::vector<std::string> files;
  for (const auto* f : sorted) files.push_back(f->photo.path);
  r["consistency"] = Consistency(codes, sorted_exposure, curve.linear_of_code, files, &r["pairs"]);
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
