#include "reconstruct/photo_merge.h"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace lumislab {

DecodedPhoto DecodeDatasetPhoto(const Dataset& dataset, const PhotoEntry& entry,
                                std::shared_ptr<const PhotoCorrections> corrections) {
  PhotoSpec spec = PhotoSpecOf(dataset, entry);
  spec.corrections = std::move(corrections);
  return {entry, DecodePhoto(dataset.PhotoPath(entry.file), spec)};
}

void CheckPhotoSizes(const std::vector<DecodedPhoto>& photos, int width, int height,
                     const std::string& calibration_file) {
  for (const auto& p : photos)
    if (p.photo.pixels.cols != width || p.photo.pixels.rows != height)
      throw InputError(
          p.photo.path, "image size (calib/screen.json image_size)",
          std::to_string(width) + "x" + std::to_string(height) + " as in " + calibration_file,
          std::to_string(p.photo.pixels.cols) + "x" + std::to_string(p.photo.pixels.rows));
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
bool FusedDifference(const Photo& plus, double gain_p, const Photo& minus, double gain_n, int f,
                     double saturation_threshold, cv::Mat& out) {
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

MergedPosition MergePosition(const std::vector<DecodedPhoto>& photos, double gain, int downsample) {
  LUMISLAB_CHECK(downsample >= 1, "MergePosition: downsample >= 1");
  // Fast path: one linear photo per slide without black level, white balance or per-pixel
  // calibration (dark, flat), same 16-bit or float 3-channel type, nothing saturated. Averaging is
  // linear, so averaging first and merging after gives the same numbers.
  if (photos.size() == 2 && photos[0].entry.positive != photos[1].entry.positive) {
    const Photo& p = (photos[0].entry.positive ? photos[0] : photos[1]).photo;
    const Photo& n = (photos[0].entry.positive ? photos[1] : photos[0]).photo;
    const int type = p.pixels.type();
    const bool linear = p.transfer == Transfer::kLinear && n.transfer == Transfer::kLinear &&
                        p.Offset() == 0 && n.Offset() == 0 && p.UnityWhiteBalance() &&
                        n.UnityWhiteBalance() && p.SaturationCode() == n.SaturationCode() &&
                        // dark map, hot pixels and flat field are per pixel: LinearReader's
                        !p.PixelCorrections() && !n.PixelCorrections();
    if (linear && type == n.pixels.type() && (type == CV_16UC3 || type == CV_32FC3) &&
        n.pixels.size() == p.pixels.size()) {
      MergedPosition out;
      const double gp = gain * p.Gain(), gn = gain * n.Gain();
      const bool ok = type == CV_16UC3
                          ? FusedDifference<uint16_t, uint32_t>(p, gp, n, gn, downsample,
                                                                p.SaturationCode(), out.signal)
                          : FusedDifference<float, float>(p, gp, n, gn, downsample,
                                                          p.SaturationCode(), out.signal);
      if (ok) {
        out.fast_path = true;
        return out;
      }
    }
  }
  MergedPosition out = MergeFullResolution(photos, gain);
  out.signal = Downsample(out.signal, downsample);
  return out;
}

MergedPosition MergeFullResolution(const std::vector<DecodedPhoto>& photos, double gain) {
  LUMISLAB_CHECK(!photos.empty(), "MergePosition: no photos");
  const int w = photos[0].photo.pixels.cols, h = photos[0].photo.pixels.rows;
  std::vector<LinearReader> readers;
  std::vector<float> exposure;
  std::vector<bool> positive;
  readers.reserve(photos.size());
  for (const auto& p : photos) {
    readers.emplace_back(p.photo);
    exposure.push_back(float(p.photo.spec.exposure));
    positive.push_back(p.entry.positive);
  }
  MergedPosition out;
  out.signal.create(h, w, CV_32FC4);
  std::atomic<int> saturated{0};
  const float g = float(gain);
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    int local_saturated = 0;
    for (int y = rows.start; y < rows.end; ++y) {
      float* o = out.signal.ptr<float>(y);
      for (int x = 0; x < w; ++x, o += 4) {
        // [slide][channel]: sum of unsaturated values (at their exposure) and of the exposures.
        float sum_v[2][3] = {}, sum_e[2][3] = {};
        for (size_t k = 0; k < readers.size(); ++k) {
          float v[3];
          bool clipped[3];
          readers[k].Read(y, x, v, clipped);
          const int s = positive[k] ? 0 : 1;
          for (int c = 0; c < 3; ++c)
            if (!clipped[c]) sum_v[s][c] += v[c] * exposure[k], sum_e[s][c] += exposure[k];
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
