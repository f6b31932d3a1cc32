#include "reconstruct/photo_merge.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>

#include "core/error.h"
#include "lib/photo/radiometric_calibration.h"

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

void MergeOptions::Check() const {
  if (!(noise.full_well_e >= 1 && noise.full_well_e <= 1e9))
    throw BadInput("--full-well: expected electrons in [1, 1e9], got " +
                   std::to_string(noise.full_well_e));
  if (!(noise.read_noise_e >= 0 && noise.read_noise_e <= 1e9))
    throw BadInput("--read-noise: expected electrons in [0, 1e9], got " +
                   std::to_string(noise.read_noise_e));
  if (!(near_black_codes >= 0 && near_black_codes <= 1000))
    throw BadInput("near_black_codes: expected [0, 1000], got " + std::to_string(near_black_codes));
}

namespace {

// The stored codes of `photo` map to linear values as code * Gain() - Offset(), with nothing
// else applied per pixel (the condition under which Photo's Gain/Offset/SaturationCode may stand
// in for LinearReader): linear transfer, unity white balance, 16-bit or float RGB.
bool CodesAreLinear(const Photo& photo) {
  const int type = photo.pixels.type();
  // A dark map, hot pixels or a flat field (calib/) differ per pixel: only LinearReader has them.
  return photo.transfer == Transfer::kLinear && photo.UnityWhiteBalance() &&
         !photo.PixelCorrections() && (type == CV_16UC3 || type == CV_32FC3);
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

MergedPosition MergePosition(const std::vector<DecodedPhoto>& photos, double gain, int downsample,
                             const MergeOptions& options) {
  LUMISLAB_CHECK(downsample >= 1, "MergePosition: downsample >= 1");
  // Fast path: one linear photo per slide without black level, white balance or per-pixel
  // calibration (dark, flat), same 16-bit or float 3-channel type, nothing saturated. Averaging is
  // linear, so averaging first and merging after gives the same numbers.
  if (photos.size() == 2 && photos[0].entry.positive != photos[1].entry.positive) {
    const Photo& p = (photos[0].entry.positive ? photos[0] : photos[1]).photo;
    const Photo& n = (photos[0].entry.positive ? photos[1] : photos[0]).photo;
    const int type = p.pixels.type();
    const bool linear = CodesAreLinear(p) && CodesAreLinear(n) && p.Offset() == 0 &&
                        n.Offset() == 0 && p.SaturationCode() == n.SaturationCode();
    if (linear && type == n.pixels.type() && n.pixels.size() == p.pixels.size()) {
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
  return MergeFullResolution(photos, gain, downsample, options);
}

namespace {

// d(curve value) / d(code / code_max) of the photo's transfer curve at curve value l: the size
// of one code step in curve units is this / code_max.
float TransferSlope(Transfer transfer, float l) {
  if (transfer != Transfer::kSrgb) return 1.f;  // (kResponse: ResponseSlope)
  // sRGB decoding: l = c / 12.92 below c = 0.04045 (l = 0.0031308), else ((c + 0.055) / 1.055)^2.4,
  // whose slope is 2.4 / 1.055 * l^(1.4 / 2.4).
  return l <= 0.0031308f ? 1.f / 12.92f : 2.4f / 1.055f * std::pow(l, 1.4f / 2.4f);
}

// The slope d linear / d (code / 255) of a calibrated 8-bit response (green) at linear value l:
// central differences of the table at the code whose value is nearest above l.
float ResponseSlope(const ResponseCurve& response, float l) {
  const auto& g = response.linear_of_code[1];
  const int k = int(std::lower_bound(g.begin(), g.end(), l) - g.begin());
  const int a = std::clamp(k - 1, 0, 254), b = std::clamp(k + 1, 1, 255);
  return std::max(0.f, (g[b] - g[a]) * 255.f / float(b - a));
}

// One photo in the merge, with what the noise model and the near-black test need. u is the
// recorded value above black in units of the white level (the reader's value times the
// recorded exposure), the same whatever exposure the merge assumes.
struct Exposure {
  LinearReader reader;
  // CodesAreLinear: u = code * u_gain - u_offset, clipped at code >= saturation_code (or NaN),
  // read a row at a time instead of through the reader.
  const Photo* source = nullptr;
  bool linear_codes = false;
  float u_gain = 0, u_offset = 0, saturation_code = 0;
  // 8-bit photos: u and clipped per code and channel (R, G, B), read through the reader from a
  // 256-pixel photo holding every code, so the table is the decoder's own linearisation. Valid
  // because LinearReader maps a code the same way at every pixel.
  std::vector<float> code_u[3];
  std::vector<uint8_t> code_clipped[3];
  int slide = 0;        // 0: p, 1: n
  float recorded = 1;   // exposure in dataset.json
  float effective = 1;  // the exposure the merge divides by (recorded, or from the ratios)
  // Well exposed: not clipped, u >= floor_u and u > 0; unclipped below that: near-black.
  float floor_u = 0;
  float read_var = 0;   // (read noise / full well)^2, u^2
  float code_step = 0;  // one code in u units at curve slope 1 (0: float photo)
  Transfer transfer = Transfer::kLinear;
  float black = 0, range = 1;  // curve value = u * range + black
  static constexpr int kQuantTable = 1025;
  std::array<float, kQuantTable> quant_var{};  // q^2 / 12 at curve value k / (kQuantTable - 1)
  // The table varies (sRGB, or a calibrated response curve); otherwise entry 0 holds for all.
  bool curved = false;

  explicit Exposure(const DecodedPhoto& p, const NoiseModel& noise, double near_black_codes)
      : reader(p.photo) {
    const Photo& photo = p.photo;
    slide = p.entry.positive ? 0 : 1;
    recorded = effective = float(photo.spec.exposure);
    source = &photo;
    linear_codes = CodesAreLinear(photo);
    // The tables assume a code means the same at every pixel: not so with calib/'s dark map,
    // hot pixels or flat field (such photos are read through the reader, pixel by pixel).
    if (photo.pixels.depth() == CV_8U && !photo.PixelCorrections()) {
      Photo codes = photo;
      codes.pixels.create(1, 256, photo.pixels.type());
      for (int v = 0; v < 256; ++v)
        for (int c = 0; c < codes.pixels.channels(); ++c)
          codes.pixels.ptr<uint8_t>(0)[v * codes.pixels.channels() + c] = uint8_t(v);
      const LinearReader code_reader(codes);
      for (int c = 0; c < 3; ++c) code_u[c].resize(256), code_clipped[c].resize(256);
      for (int v = 0; v < 256; ++v) {
        float rgb[3];
        bool clipped[3];
        code_reader.Read(0, v, rgb, clipped);
        for (int c = 0; c < 3; ++c) {
          const float value = rgb[c] * recorded;
          const bool ok = !clipped[c] && std::isfinite(value);
          code_u[c][v] = ok ? value : 0.f;
          code_clipped[c][v] = !ok;
        }
      }
    }
    u_gain = float(photo.Gain() * photo.spec.exposure);
    u_offset = float(photo.Offset() * photo.spec.exposure);
    saturation_code = float(photo.SaturationCode());
    transfer = photo.transfer;
    black = float(photo.spec.black_level);
    range = float(photo.spec.white_level - photo.spec.black_level);
    code_step = photo.pixels.depth() == CV_32F ? 0.f : float(1.0 / (photo.CodeMax() * range));
    read_var = float(std::pow(noise.read_noise_e / noise.full_well_e, 2));
    // n codes above black (the curve's slope at black: exact for sRGB up to code 10), or three
    // read-noise sigmas, whichever is larger.
    const ResponseCurve* response = transfer == Transfer::kResponse && photo.spec.corrections
                                        ? photo.spec.corrections->response.get()
                                        : nullptr;
    auto slope = [&](float l) {
      return response ? ResponseSlope(*response, l) : TransferSlope(transfer, l);
    };
    floor_u =
        std::max(float(near_black_codes) * code_step * slope(black), 3.f * std::sqrt(read_var));
    curved = transfer == Transfer::kSrgb || response != nullptr;
    for (int k = 0; k < kQuantTable; ++k) {
      const float q = code_step * slope(float(k) / (kQuantTable - 1));
      quant_var[k] = q * q / 12;
    }
  }
  // Variance of u at an expected value u (NoiseModel); the quantisation term from a table over
  // the curve value (1/1024 steps: the weights need not be exact, and a pow per value and
  // exposure would cost more than decoding the photo).
  float Variance(float u, float inv_full_well) const {
    if (!curved) return u * inv_full_well + read_var + quant_var[0];
    const float l = u * range + black;  // NaN (an unused lane of the merge) reads entry 0
    const int k = l >= 1.f ? kQuantTable - 1 : l > 0.f ? int(l * (kQuantTable - 1) + 0.5f) : 0;
    return u * inv_full_well + read_var + quant_var[k];
  }
};

std::vector<Exposure> MakeExposures(const std::vector<DecodedPhoto>& photos,
                                    const MergeOptions& options) {
  std::vector<Exposure> exposures;
  exposures.reserve(photos.size());
  for (const auto& p : photos) exposures.emplace_back(p, options.noise, options.near_black_codes);
  return exposures;
}

// Indices of one slide's photos, shortest recorded exposure first (ties in listing order).
std::vector<size_t> SlideOrder(const std::vector<Exposure>& exposures, int slide) {
  std::vector<size_t> order;
  for (size_t k = 0; k < exposures.size(); ++k)
    if (exposures[k].slide == slide) order.push_back(k);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return exposures[a].recorded < exposures[b].recorded;
  });
  return order;
}

std::vector<BracketRatio> EstimateRatios(std::vector<Exposure>& exposures, int w, int h) {
  // A grid of at most ~2^18 pixels: the median of that many ratios is precise to ~1e-4.
  const int stride = std::max(1, int(std::ceil(std::sqrt(double(w) * h / 262144.0))));
  std::vector<BracketRatio> ratios;
  for (int slide : {0, 1}) {
    const std::vector<size_t> order = SlideOrder(exposures, slide);
    if (order.size() < 2) continue;
    std::vector<std::vector<float>> log_ratios(order.size() - 1);
    std::vector<float> u(order.size() * 3);
    std::vector<char> clipped(order.size() * 3);
    for (int y = stride / 2; y < h; y += stride)
      for (int x = stride / 2; x < w; x += stride) {
        for (size_t k = 0; k < order.size(); ++k) {
          const Exposure& e = exposures[order[k]];
          float v[3];
          bool c[3];
          e.reader.Read(y, x, v, c);
          for (int ch = 0; ch < 3; ++ch)
            u[k * 3 + ch] = v[ch] * e.recorded, clipped[k * 3 + ch] = c[ch];
        }
        for (size_t k = 0; k + 1 < order.size(); ++k)
          for (int ch = 0; ch < 3; ++ch) {
            // Well exposed in both, and well above the near-black floor: the ratio of two
            // values a few codes above black is dominated by their quantisation.
            const float a = u[k * 3 + ch], b = u[(k + 1) * 3 + ch];
            if (clipped[k * 3 + ch] || clipped[(k + 1) * 3 + ch]) continue;
            if (!(a >= 4 * exposures[order[k]].floor_u && a > 0)) continue;
            if (!(b >= 4 * exposures[order[k + 1]].floor_u && b > 0)) continue;
            log_ratios[k].push_back(std::log(b / a));
          }
      }
    for (size_t k = 0; k + 1 < order.size(); ++k) {
      BracketRatio r;
      r.positive = slide == 0;
      r.recorded_short = exposures[order[k]].recorded;
      r.recorded_long = exposures[order[k + 1]].recorded;
      r.estimated = r.Recorded();
      std::vector<float>& v = log_ratios[k];
      if (v.size() >= size_t(kMinRatioSamples)) {
        std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
        r.estimated = std::exp(double(v[v.size() / 2]));
        r.samples = (long long)v.size();
      }
      ratios.push_back(r);
    }
  }
  return ratios;
}

// Effective exposures from the estimated ratios: the middle exposure of each slide (the lower
// of the two middle ones) keeps its recorded value, the others are chained from it.
void ApplyRatios(std::vector<Exposure>& exposures, const std::vector<BracketRatio>& ratios) {
  size_t r0 = 0;
  for (int slide : {0, 1}) {
    const std::vector<size_t> order = SlideOrder(exposures, slide);
    if (order.size() < 2) continue;
    const size_t m = (order.size() - 1) / 2;
    for (size_t k = m + 1; k < order.size(); ++k)
      exposures[order[k]].effective =
          float(exposures[order[k - 1]].effective * ratios[r0 + k - 1].estimated);
    for (size_t k = m; k-- > 0;)
      exposures[order[k]].effective =
          float(exposures[order[k + 1]].effective / ratios[r0 + k].estimated);
    r0 += order.size() - 1;
  }
}

// What one band of rows found, combined under a lock.
struct MergeStats {
  int saturated = 0, near_black = 0;
  float brightest = 0, faintest = std::numeric_limits<float>::infinity();
};

// How a slide's channel at a pixel was merged.
// Bits, so that the states of a pixel's channels combine with OR.
enum : uint8_t { kMeasured = 0, kNearBlackEverywhere = 1, kClippedEverywhere = 2 };

// Merges one photo row of both slides, channel by channel, in passes over the row (one per
// exposure) that the compiler vectorises, rather than branching per pixel and exposure.
struct MergeRows {
  const std::vector<Exposure>& exposures;
  const std::vector<int>* members;  // [2]: each slide's photos, longest exposure first
  int n3;                           // 3 * width
  // [photo][x * 3 + c]: recorded value above black, and 1 where clipped (0 otherwise). All
  // per-row arrays are float, so that the passes below vectorise without conversions.
  std::vector<std::vector<float>> u, clip;
  // Per slide: the merged exposure-normalised value and how it was merged.
  std::vector<float> value[2];
  std::vector<uint8_t> state[2];
  // Scratch: pilot sums, the longest unclipped value and whether one was met, weighted sums.
  std::vector<float> sum_u, sum_e, longest, found, sum_w, sum_wx;

  MergeRows(const std::vector<Exposure>& e, const std::vector<int>* m, int width)
      : exposures(e), members(m), n3(3 * width) {
    u.assign(e.size(), std::vector<float>(n3));
    clip.assign(e.size(), std::vector<float>(n3));
    for (int s = 0; s < 2; ++s) value[s].resize(n3), state[s].resize(n3);
    for (auto* v : {&sum_u, &sum_e, &longest, &found, &sum_w, &sum_wx}) v->resize(n3);
  }

  // One row of 16-bit or float linear codes (CodesAreLinear) into u and clip, RGB order.
  template <typename T>
  void ReadLinearRow(const Exposure& e, int y, float* __restrict uk, float* __restrict ck) {
    const Photo& photo = *e.source;
    const T* __restrict row = photo.pixels.ptr<T>(y);
    const int r = photo.rgb_order ? 0 : 2;
    const float gain = e.u_gain, offset = e.u_offset, saturation = e.saturation_code;
    // In storage order first (a plain loop that vectorises), then blue and red swapped.
    for (int j = 0; j < n3; ++j) {
      const float code = float(row[j]);
      const float value = code * gain - offset;
      const bool ok = (code < saturation) & (std::abs(value) <= FLT_MAX);  // NaN: clipped
      uk[j] = ok ? value : 0.f;
      ck[j] = ok ? 0.f : 1.f;
    }
    if (r != 0)
      for (int j = 0; j < n3; j += 3) std::swap(uk[j], uk[j + 2]), std::swap(ck[j], ck[j + 2]);
  }

  // One row of 8-bit codes through the exposure's tables, RGB order (1 or 3 channels).
  void ReadCodeRow(const Exposure& e, int y, float* __restrict uk, float* __restrict ck) {
    const cv::Mat& m = e.source->pixels;
    const uint8_t* row = m.ptr<uint8_t>(y);
    const int channels = m.channels();
    const int offsets[3] = {channels == 1         ? 0
                            : e.source->rgb_order ? 0
                                                  : 2,
                            channels == 1 ? 0 : 1,
                            channels == 1         ? 0
                            : e.source->rgb_order ? 2
                                                  : 0};
    for (int c = 0; c < 3; ++c) {
      const float* table = e.code_u[c].data();
      const uint8_t* clipped = e.code_clipped[c].data();
      for (int x = 0; x < n3 / 3; ++x) {
        const uint8_t code = row[x * channels + offsets[c]];
        uk[x * 3 + c] = table[code];
        ck[x * 3 + c] = clipped[code];
      }
    }
  }

  void Merge(int y, float inv_full_well, MergeStats* stats) {
    for (size_t k = 0; k < exposures.size(); ++k) {
      const Exposure& e = exposures[k];
      float* uk = u[k].data();
      float* ck = clip[k].data();
      if (e.linear_codes) {
        if (e.source->pixels.depth() == CV_16U)
          ReadLinearRow<uint16_t>(e, y, uk, ck);
        else
          ReadLinearRow<float>(e, y, uk, ck);
        continue;
      }
      if (!e.code_u[0].empty()) {
        ReadCodeRow(e, y, uk, ck);
        continue;
      }
      for (int x = 0; x < n3 / 3; ++x) {
        float v[3];
        bool c[3];
        e.reader.Read(y, x, v, c);
        for (int ch = 0; ch < 3; ++ch) {
          const float value = v[ch] * e.recorded;
          const bool ok = !c[ch] && std::isfinite(value);
          uk[x * 3 + ch] = ok ? value : 0.f;
          ck[x * 3 + ch] = ok ? 0.f : 1.f;
        }
      }
    }
    for (int s = 0; s < 2; ++s) MergeSlide(s, inv_full_well, stats);
  }

  void MergeSlide(int s, float inv_full_well, MergeStats* stats) {
    float* __restrict su = sum_u.data();
    float* __restrict se = sum_e.data();
    float* __restrict lg = longest.data();
    float* __restrict fd = found.data();
    float* __restrict sw = sum_w.data();
    float* __restrict swx = sum_wx.data();
    std::fill_n(su, n3, 0.f);
    std::fill_n(se, n3, 0.f);
    std::fill_n(lg, n3, 0.f);
    std::fill_n(fd, n3, 0.f);
    // Pilot: over the well-exposed values (Exposure::floor_u), sum u / sum exposure, the
    // maximum-likelihood estimate under shot noise alone (weights = exposures). Longest first,
    // so the first unclipped value met is the longest exposure's (used where all are
    // near-black).
    for (const int k : members[s]) {
      const Exposure& e = exposures[k];
      const float* __restrict uk = u[k].data();
      const float* __restrict ck = clip[k].data();
      const float floor_u = e.floor_u, eff = e.effective, inv_eff = 1.f / e.effective;
      // 0/1 masks multiplied in (u is finite, 0 where clipped), no branches.
      for (int i = 0; i < n3; ++i) {
        const float unclipped = 1.f - ck[i];
        const float well = (uk[i] >= floor_u) & (uk[i] > 0.f) ? unclipped : 0.f;
        su[i] += well * uk[i];
        se[i] += well * eff;
        lg[i] += (1.f - fd[i]) * unclipped * uk[i] * inv_eff;  // lg is 0 until the first
        fd[i] = std::max(fd[i], unclipped);
      }
    }
    // Inverse-variance weights e^2 / var(u) at the pilot's expected u = e * pilot: the
    // read-noise and quantisation terms favour the longer exposures more than the shot-noise
    // weights do. (Each exposure's own u would bias the weights towards values that read low.)
    // With one well-exposed value this is that value / its exposure. Computed on every lane and
    // selected (a value that is not well exposed may give inf or NaN here, never used).
    std::fill_n(sw, n3, 0.f);
    std::fill_n(swx, n3, 0.f);
    for (int i = 0; i < n3; ++i) su[i] /= se[i];  // su: the pilot from here on
    for (const int k : members[s]) {
      const Exposure& e = exposures[k];
      const float* __restrict uk = u[k].data();
      const float* __restrict ck = clip[k].data();
      const float floor_u = e.floor_u, eff = e.effective;
      const float constant = e.read_var + e.quant_var[0];
      const auto accumulate = [&](auto variance) {
        for (int i = 0; i < n3; ++i) {
          const bool well = (ck[i] == 0.f) & (uk[i] >= floor_u) & (uk[i] > 0.f);
          // A select, not a product: where the pixel is not well exposed, 0 / 0 pilots and
          // zero variances may give NaN or inf here.
          // w / e = e / var(u), applied to u: sum_wx = sum w * (u / e).
          const float w_over_e = eff / variance(eff * su[i]);
          sw[i] += well ? w_over_e * eff : 0.f;
          swx[i] += well ? w_over_e * uk[i] : 0.f;
        }
      };
      if (e.curved)
        accumulate([&](float u_expected) { return e.Variance(u_expected, inv_full_well); });
      else  // the quantisation term is a constant: Variance without the table
        accumulate([&](float u_expected) { return u_expected * inv_full_well + constant; });
    }
    float* v = value[s].data();
    uint8_t* st = state[s].data();
    float brightest = stats->brightest, faintest = stats->faintest;
    for (int i = 0; i < n3; ++i) {
      const bool measured = se[i] > 0;
      const bool any = fd[i] != 0.f;
      v[i] = !any ? 0.f : measured ? swx[i] / sw[i] : lg[i];
      st[i] = !any ? kClippedEverywhere : measured ? kMeasured : kNearBlackEverywhere;
      brightest = std::max(brightest, measured ? v[i] : 0.f);
      faintest = std::min(faintest, measured & (v[i] > 0) ? v[i] : faintest);
    }
    stats->brightest = brightest, stats->faintest = faintest;
  }
};

}  // namespace

std::vector<BracketRatio> EstimateBracketRatios(const std::vector<DecodedPhoto>& photos,
                                                const MergeOptions& options) {
  LUMISLAB_CHECK(!photos.empty(), "EstimateBracketRatios: no photos");
  std::vector<Exposure> exposures = MakeExposures(photos, options);
  return EstimateRatios(exposures, photos[0].photo.pixels.cols, photos[0].photo.pixels.rows);
}

MergedPosition MergeFullResolution(const std::vector<DecodedPhoto>& photos, double gain,
                                   int downsample, const MergeOptions& options) {
  LUMISLAB_CHECK(!photos.empty(), "MergePosition: no photos");
  LUMISLAB_CHECK(downsample >= 1, "MergePosition: downsample >= 1");
  const int w = photos[0].photo.pixels.cols, h = photos[0].photo.pixels.rows;
  std::vector<Exposure> exposures = MakeExposures(photos, options);
  MergedPosition out;
  for (int slide : {0, 1})
    out.exposures = std::max(out.exposures, int(SlideOrder(exposures, slide).size()));
  if (out.exposures > 1) {
    out.ratios = EstimateRatios(exposures, w, h);
    if (options.bracket_ratios == BracketRatios::kEstimated) ApplyRatios(exposures, out.ratios);
  }
  const size_t n = exposures.size();
  const float inv_full_well = float(1.0 / options.noise.full_well_e);
  // F x F blocks of the top-left multiple of F make the output pixels; the rows and columns
  // beyond are merged for the counts only.
  const int f = downsample, ow = w / f, oh = h / f;
  out.signal.create(oh, ow, CV_32FC4);
  const float g = float(gain), inv_area = 1.f / float(f * f);
  // Each slide's photos, longest effective exposure first.
  std::vector<int> members[2];
  for (int k = 0; k < int(n); ++k) members[exposures[k].slide].push_back(k);
  for (auto& m : members)
    std::stable_sort(m.begin(), m.end(),
                     [&](int a, int b) { return exposures[a].effective > exposures[b].effective; });
  MergeStats total;
  std::mutex total_mutex;
  const int bands = (h + f - 1) / f;
  cv::parallel_for_(cv::Range(0, bands), [&](const cv::Range& range) {
    MergeStats stats;
    MergeRows rows(exposures, members, w);
    std::vector<float> acc(size_t(ow) * 4);
    for (int band = range.start; band < range.end; ++band) {
      std::fill(acc.begin(), acc.end(), 0.f);
      for (int y = band * f; y < std::min(h, (band + 1) * f); ++y) {
        rows.Merge(y, inv_full_well, &stats);
        const float* v0 = rows.value[0].data();
        const float* v1 = rows.value[1].data();
        const uint8_t* s0 = rows.state[0].data();
        const uint8_t* s1 = rows.state[1].data();
        const bool in_band = band < oh;
        for (int x = 0, ox = 0, dx = 0; x < w; ++x) {
          // A pixel is saturated (near-black) when a channel of a slide is, in every exposure:
          // the states are bits, so one OR over the six channels tells.
          const int i = x * 3;
          const uint8_t any = s0[i] | s0[i + 1] | s0[i + 2] | s1[i] | s1[i + 1] | s1[i + 2];
          const bool saturated = any & kClippedEverywhere;
          stats.saturated += saturated;
          stats.near_black += !saturated && (any & kNearBlackEverywhere);
          if (in_band && ox < ow) {
            float* o = &acc[size_t(ox) * 4];
            if (saturated)
              o[3] += 1.f;
            else
              for (int ch = 0; ch < 3; ++ch) o[ch] += g * (v0[i + ch] - v1[i + ch]);
          }
          if (++dx == f) dx = 0, ++ox;  // the output pixel of x (x / f, without dividing)
        }
      }
      if (band >= oh) continue;
      float* o = out.signal.ptr<float>(band);
      for (size_t k = 0; k < acc.size(); ++k) o[k] = acc[k] * inv_area;
    }
    std::lock_guard<std::mutex> lock(total_mutex);
    total.saturated += stats.saturated;
    total.near_black += stats.near_black;
    total.brightest = std::max(total.brightest, stats.brightest);
    total.faintest = std::min(total.faintest, stats.faintest);
  });
  out.saturated_pixels = total.saturated;
  out.near_black_pixels = total.near_black;
  if (total.brightest > 0 && std::isfinite(total.faintest)) {
    out.brightest = total.brightest;
    out.faintest = total.faintest;
    out.dynamic_range_stops = std::log2(double(total.brightest) / total.faintest);
  }
  return out;
}

}  // namespace lumislab
