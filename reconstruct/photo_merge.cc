#include "reconstruct/photo_merge.h"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/exr_io.h"

namespace lumislab {

namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t k = 0; k < suffix.size(); ++k)
    if (std::tolower(s[s.size() - suffix.size() + k]) != suffix[k]) return false;
  return true;
}

float SrgbToLinear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// Reads the linear RGB of one pixel of a decoded photo.
class LinearReader {
 public:
  explicit LinearReader(const DecodedPhoto& p) : m_(p.pixels), rgb_(p.rgb_order) {
    channels_ = m_.channels();
    if (m_.depth() == CV_8U)
      for (int v = 0; v < 256; ++v) lut8_[v] = SrgbToLinear(v / 255.f);
  }
  void Read(int y, int x, float out[3]) const {
    if (m_.depth() == CV_32F) {
      const float* p = m_.ptr<float>(y) + size_t(x) * channels_;
      Assign(p, out);
    } else if (m_.depth() == CV_16U) {
      const uint16_t* p = m_.ptr<uint16_t>(y) + size_t(x) * channels_;
      float v[4];
      for (int c = 0; c < std::min(channels_, 3); ++c) v[c] = p[c] * (1.f / 65535.f);
      Assign(v, out);
    } else {
      const uint8_t* p = m_.ptr<uint8_t>(y) + size_t(x) * channels_;
      float v[4];
      for (int c = 0; c < std::min(channels_, 3); ++c) v[c] = lut8_[p[c]];
      Assign(v, out);
    }
  }

 private:
  void Assign(const float* v, float out[3]) const {
    if (channels_ == 1) {
      out[0] = out[1] = out[2] = v[0];
    } else if (rgb_) {
      out[0] = v[0], out[1] = v[1], out[2] = v[2];
    } else {
      out[0] = v[2], out[1] = v[1], out[2] = v[0];
    }
  }
  const cv::Mat& m_;
  bool rgb_;
  int channels_ = 3;
  float lut8_[256] = {};
};

}  // namespace

DecodedPhoto DecodePhoto(const Dataset& dataset, const PhotoEntry& entry) {
  DecodedPhoto out;
  out.entry = entry;
  out.path = dataset.Path(entry.file);
  if (!std::filesystem::exists(out.path))
    throw BadInput(out.path + ": photo missing (listed in dataset.json photos)");
  if (EndsWith(out.path, ".exr")) {
    ImageF img;
    try {
      img = ReadExr(out.path, {"R", "G", "B"});
    } catch (const Error& e) {
      if (e.code() == ExitCode::kBadInput) throw;
      throw BadInput(out.path + ": cannot decode the photo (" + e.what() + ")");
    }
    out.pixels = cv::Mat(img.height, img.width, CV_32FC3, img.data.data()).clone();
    out.rgb_order = true;
  } else {
    out.pixels = cv::imread(out.path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
    if (out.pixels.empty())
      throw BadInput(out.path + ": cannot decode the photo (corrupt or unsupported format)");
    const int depth = out.pixels.depth();
    const int ch = out.pixels.channels();
    if ((depth != CV_8U && depth != CV_16U && depth != CV_32F) || (ch != 1 && ch < 3))
      throw BadInput(out.path + ": unsupported pixel format (expected 8/16-bit gray or RGB)");
  }
  return out;
}

void CheckPhotoSizes(const std::vector<DecodedPhoto>& photos, int width, int height,
                     const std::string& calibration_file) {
  for (const auto& p : photos)
    if (p.pixels.cols != width || p.pixels.rows != height)
      throw InputError(
          p.path, "image size",
          std::to_string(width) + "x" + std::to_string(height) + " as in " + calibration_file,
          std::to_string(p.pixels.cols) + "x" + std::to_string(p.pixels.rows));
}

namespace {

// Box average over factor x factor pixel blocks (exact: integer factor, cropped to a multiple).
cv::Mat Downsample(const cv::Mat& image, int factor) {
  if (factor == 1) return image;
  const int w = image.cols / factor, h = image.rows / factor;
  cv::Mat out;
  cv::resize(image(cv::Rect(0, 0, w * factor, h * factor)), out, cv::Size(w, h), 0, 0,
             cv::INTER_AREA);
  return out;
}

// Any value at or above the saturation level (or not a number) anywhere in the photo.
bool AnySaturated(const DecodedPhoto& p, double saturation_level) {
  const cv::Mat flat = p.pixels.reshape(1);
  double threshold = saturation_level;
  if (p.pixels.depth() == CV_16U) threshold = std::ceil(saturation_level * 65535 - 1e-9);
  if (p.pixels.depth() == CV_8U) return true;  // sRGB 8-bit: the general path
  if (p.pixels.depth() == CV_32F && !cv::checkRange(flat)) return true;  // NaN or Inf
  double max_value = 0;
  cv::minMaxLoc(flat, nullptr, &max_value);
  return max_value >= threshold;
}

// gain_p * P - gain_n * N for two 3-channel images of the same type, RGB output.
template <typename T>
void Difference(const cv::Mat& plus, bool plus_rgb, double gain_p, const cv::Mat& minus,
                bool minus_rgb, double gain_n, cv::Mat& out) {
  out.create(plus.rows, plus.cols, CV_32FC3);
  const float gp = float(gain_p), gn = float(gain_n);
  const int pr = plus_rgb ? 0 : 2, nr = minus_rgb ? 0 : 2;
  cv::parallel_for_(cv::Range(0, plus.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const T* p = plus.ptr<T>(y);
      const T* n = minus.ptr<T>(y);
      float* o = out.ptr<float>(y);
      for (int x = 0; x < plus.cols; ++x, p += 3, n += 3, o += 3) {
        o[0] = gp * float(p[pr]) - gn * float(n[nr]);
        o[1] = gp * float(p[1]) - gn * float(n[1]);
        o[2] = gp * float(p[2 - pr]) - gn * float(n[2 - nr]);
      }
    }
  });
}

}  // namespace

MergedPosition MergePosition(const std::vector<DecodedPhoto>& photos, double saturation_level,
                             double gain, int downsample) {
  LUMISLAB_CHECK(downsample >= 1, "MergePosition: downsample >= 1");
  // Fast path: one photo per slide, same 16-bit or float 3-channel type, nothing saturated.
  // Averaging is linear, so averaging first and merging after gives the same numbers.
  if (photos.size() == 2 && photos[0].entry.positive != photos[1].entry.positive) {
    const DecodedPhoto& p = photos[0].entry.positive ? photos[0] : photos[1];
    const DecodedPhoto& n = photos[0].entry.positive ? photos[1] : photos[0];
    const int type = p.pixels.type();
    if (type == n.pixels.type() && (type == CV_16UC3 || type == CV_32FC3) &&
        !AnySaturated(p, saturation_level) && !AnySaturated(n, saturation_level)) {
      MergedPosition out;
      out.fast_path = true;
      const double unit = type == CV_16UC3 ? 1.0 / 65535 : 1.0;
      const cv::Mat lp = Downsample(p.pixels, downsample), ln = Downsample(n.pixels, downsample);
      if (type == CV_16UC3)
        Difference<uint16_t>(lp, p.rgb_order, gain * unit / p.entry.exposure, ln, n.rgb_order,
                             gain * unit / n.entry.exposure, out.signal);
      else
        Difference<float>(lp, p.rgb_order, gain / p.entry.exposure, ln, n.rgb_order,
                          gain / n.entry.exposure, out.signal);
      return out;
    }
  }
  MergedPosition out = MergeFullResolution(photos, saturation_level, gain);
  out.signal = Downsample(out.signal, downsample);
  return out;
}

MergedPosition MergeFullResolution(const std::vector<DecodedPhoto>& photos, double saturation_level,
                                   double gain) {
  LUMISLAB_CHECK(!photos.empty(), "MergePosition: no photos");
  const int w = photos[0].pixels.cols, h = photos[0].pixels.rows;
  std::vector<LinearReader> readers;
  std::vector<float> exposure;
  std::vector<bool> positive;
  readers.reserve(photos.size());
  for (const auto& p : photos) {
    readers.emplace_back(p);
    exposure.push_back(float(p.entry.exposure));
    positive.push_back(p.entry.positive);
  }
  MergedPosition out;
  out.signal.create(h, w, CV_32FC4);
  std::atomic<int> saturated{0};
  const float sat = float(saturation_level), g = float(gain);
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    int local_saturated = 0;
    for (int y = rows.start; y < rows.end; ++y) {
      float* o = out.signal.ptr<float>(y);
      for (int x = 0; x < w; ++x, o += 4) {
        // [slide][channel]: sum of unsaturated values and of their exposures.
        float sum_v[2][3] = {}, sum_e[2][3] = {};
        for (size_t k = 0; k < readers.size(); ++k) {
          float v[3];
          readers[k].Read(y, x, v);
          const int s = positive[k] ? 0 : 1;
          for (int c = 0; c < 3; ++c)
            if (v[c] < sat) sum_v[s][c] += v[c], sum_e[s][c] += exposure[k];
        }
        bool is_saturated = false;
        for (int c = 0; c < 3; ++c) {
          if (sum_e[0][c] <= 0 || sum_e[1][c] <= 0) {
            is_saturated = true;
            break;
          }
          o[c] = g * (sum_v[0][c] / sum_e[0][c] - sum_v[1][c] / sum_e[1][c]);
        }
        if (is_saturated) {
          o[0] = o[1] = o[2] = 0.f;
          ++local_saturated;
        }
        o[3] = is_saturated ? 1.f : 0.f;
      }
    }
    saturated += local_saturated;
  });
  out.saturated_pixels = saturated;
  return out;
}

}  // namespace lumislab
