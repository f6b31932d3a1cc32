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

// One pass over both photos of a position: F x F box sums of T+ and T-, their weighted
// difference (RGB out), and the largest value seen (for the saturation check). Rows are summed
// first (contiguous, vectorised), then groups of F pixels within the summed row.
template <typename T, typename Acc>
bool FusedDifference(const DecodedPhoto& plus, double gain_p, const DecodedPhoto& minus,
                     double gain_n, int f, double saturation_threshold, cv::Mat& out) {
  const int w = plus.pixels.cols / f, h = plus.pixels.rows / f;
  const size_t len = size_t(w) * f * 3;
  out.create(h, w, CV_32FC3);
  const float gp = float(gain_p / (f * f)), gn = float(gain_n / (f * f));
  const int pr = plus.rgb_order ? 0 : 2, nr = minus.rgb_order ? 0 : 2;
  std::atomic<bool> saturated{false};
  if (f == 1) {
    // No block averaging: one pass straight from both photos to the difference.
    cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
      T max_value = 0;
      bool finite = true;
      for (int y = rows.start; y < rows.end; ++y) {
        const T* a = plus.pixels.template ptr<T>(y);
        const T* b = minus.pixels.template ptr<T>(y);
        float* o = out.ptr<float>(y);
        for (int x = 0; x < w; ++x, a += 3, b += 3, o += 3) {
          max_value = std::max({max_value, a[0], a[1], a[2], b[0], b[1], b[2]});
          o[0] = gp * float(a[pr]) - gn * float(b[nr]);
          o[1] = gp * float(a[1]) - gn * float(b[1]);
          o[2] = gp * float(a[2 - pr]) - gn * float(b[2 - nr]);
          finite &= std::isfinite(o[0] + o[1] + o[2]);
        }
      }
      if (!finite || double(max_value) >= saturation_threshold) saturated = true;
    });
    return !saturated;
  }
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    std::vector<Acc> ap(len), an(len);
    T max_value = 0;
    for (int oy = rows.start; oy < rows.end; ++oy) {
      for (const auto& [img, acc] : {std::pair(&plus.pixels, &ap), std::pair(&minus.pixels, &an)}) {
        Acc* a = acc->data();
        const T* r = img->template ptr<T>(oy * f);
        for (size_t k = 0; k < len; ++k) {
          a[k] = Acc(r[k]);
          max_value = std::max(max_value, r[k]);
        }
        for (int dy = 1; dy < f; ++dy) {
          r = img->template ptr<T>(oy * f + dy);
          for (size_t k = 0; k < len; ++k) {
            a[k] += Acc(r[k]);
            max_value = std::max(max_value, r[k]);
          }
        }
      }
      float* o = out.ptr<float>(oy);
      for (int ox = 0; ox < w; ++ox, o += 3) {
        Acc sp[3] = {}, sn[3] = {};
        const size_t k0 = size_t(ox) * f * 3;
        for (int dx = 0; dx < f; ++dx)
          for (int c = 0; c < 3; ++c) {
            sp[c] += ap[k0 + size_t(dx) * 3 + c];
            sn[c] += an[k0 + size_t(dx) * 3 + c];
          }
        o[0] = gp * float(sp[pr]) - gn * float(sn[nr]);
        o[1] = gp * float(sp[1]) - gn * float(sn[1]);
        o[2] = gp * float(sp[2 - pr]) - gn * float(sn[2 - nr]);
        // NaN/Inf in float photos propagate into the sums: treat as saturated.
        if (!(std::isfinite(o[0]) && std::isfinite(o[1]) && std::isfinite(o[2]))) saturated = true;
      }
    }
    if (double(max_value) >= saturation_threshold) saturated = true;
  });
  return !saturated;
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
        n.pixels.size() == p.pixels.size()) {
      MergedPosition out;
      const bool ok = type == CV_16UC3 ? FusedDifference<uint16_t, uint32_t>(
                                             p, gain / 65535 / p.entry.exposure, n,
                                             gain / 65535 / n.entry.exposure, downsample,
                                             std::ceil(saturation_level * 65535 - 1e-9), out.signal)
                                       : FusedDifference<float, float>(
                                             p, gain / p.entry.exposure, n, gain / n.entry.exposure,
                                             downsample, saturation_level, out.signal);
      if (ok) {
        out.fast_path = true;
        return out;
      }
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
