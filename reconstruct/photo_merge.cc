#include "reconstruct/photo_merge.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <cstring>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>

#include "core/error.h"
#include "lib/photo/photo_allocator.h"
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
// in for LinearReader): linear transfer, unity white balance, 16-bit or float RGB. (A JPEG's
// fractional codes go through the code tables, which share the reader's clipping rule.)
bool CodesAreLinear(const Photo& photo) {
  const int type = photo.pixels.type();
  // A dark map, hot pixels or a flat field (calib/) differ per pixel: only LinearReader has them.
  return photo.transfer == Transfer::kLinear && photo.UnityWhiteBalance() &&
         !photo.PixelCorrections() && !photo.fractional_codes &&
         (type == CV_16UC3 || type == CV_32FC3);
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
                             const MergeOptions& options, const cv::Rect& region) {
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
  return MergeFullResolution(photos, gain, downsample, options, region);
}

namespace {

// A clipped value in the merge's rows: NaN, which fails every comparison, so that a clipped value
// is neither well exposed nor near-black, and x == x tells whether a value is unclipped.
constexpr float kClipped = std::numeric_limits<float>::quiet_NaN();

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

// The entry of Exposure::quant_var (kQuantTable entries, 1025) at curve value l: the nearest
// 1/1024 step, the last at l >= 1, the first at l <= 0 and NaN (an unused lane of the merge).
inline int QuantTableEntry(float l) {
  constexpr int kLast = 1024;
  return l >= 1.f ? kLast : l > 0.f ? int(l * kLast + 0.5f) : 0;
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
  // 8-bit photos: u per code and channel, [c * 256 + code] for c = R, G, B, NaN where clipped,
  // read through the reader from a 256-pixel photo holding every code, so the table is the
  // decoder's own linearisation. Valid because LinearReader maps a code the same way at every
  // pixel. Empty for other photos.
  std::vector<float> code_u;
  // A JPEG's fractional codes: code_u of R, G, B read between codes (ReadBetweenCodes) at every
  // fractional code (FractionalCodeTable), for ReadFractionalCodes; equal tables are one, shared
  // by the channels and exposures that have them (MakeExposures). Null for other photos.
  std::array<std::shared_ptr<const std::vector<float>>, 3> fractional_u;
  int slide = 0;        // 0: p, 1: n
  float recorded = 1;   // exposure in dataset.json
  float effective = 1;  // the exposure the merge divides by (recorded, or from the ratios)
  // Well exposed: not clipped, u >= floor_u and u > 0; unclipped below that: near-black.
  float floor_u = 0;
  float read_var = 0;   // (read noise / full well)^2, u^2
  float code_step = 0;  // one code in u units at curve slope 1 (0: float photo)
  Transfer transfer = Transfer::kLinear;
  float black = 0, range = 1;                  // curve value = u * range + black
  static constexpr int kQuantTable = 1025;     // (QuantTableEntry)
  std::array<float, kQuantTable> quant_var{};  // q^2 / 12 at curve value k / (kQuantTable - 1)
  // The table varies (sRGB, or a calibrated response curve); otherwise entry 0 holds for all.
  bool curved = false;

  static_assert(kQuantTable == 1025, "Exposure: QuantTableEntry's last entry is 1024");
  explicit Exposure(const DecodedPhoto& p, const NoiseModel& noise, double near_black_codes)
      : reader(p.photo) {
    const Photo& photo = p.photo;
    slide = p.entry.positive ? 0 : 1;
    recorded = effective = float(photo.spec.exposure);
    source = &photo;
    linear_codes = CodesAreLinear(photo);
    // The tables assume a code means the same at every pixel: not so with calib/'s dark map,
    // hot pixels or flat field (such photos are read through the reader, pixel by pixel).
    if (photo.EightBitCodes() && !photo.PixelCorrections()) {
      Photo codes = photo;
      codes.pixels.create(1, 256, photo.pixels.type());
      for (int v = 0; v < 256; ++v)
        for (int c = 0; c < codes.pixels.channels(); ++c) {
          const int i = v * codes.pixels.channels() + c;
          if (photo.fractional_codes)
            codes.pixels.ptr<uint16_t>(0)[i] = uint16_t(v * kFractionalCodeOne);
          else
            codes.pixels.ptr<uint8_t>(0)[i] = uint8_t(v);
        }
      const LinearReader code_reader(codes);
      code_u.resize(3 * 256);
      for (int v = 0; v < 256; ++v) {
        float rgb[3];
        bool clipped[3];
        code_reader.Read(0, v, rgb, clipped);
        for (int c = 0; c < 3; ++c) {
          const float value = rgb[c] * recorded;
          const bool ok = !clipped[c] && std::isfinite(value);
          code_u[c * 256 + v] = ok ? value : kClipped;
        }
      }
    }
    u_gain = float(photo.Gain() * photo.spec.exposure);
    u_offset = float(photo.Offset() * photo.spec.exposure);
    saturation_code = float(photo.SaturationCode());
    transfer = photo.transfer;
    black = float(photo.spec.black_level);
    range = float(photo.spec.white_level - photo.spec.black_level);
    code_step = photo.CodeBits() == 32 ? 0.f : float(1.0 / (photo.CodeMax() * range));
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
    return u * inv_full_well + read_var + quant_var[QuantTableEntry(u * range + black)];
  }
};

std::vector<Exposure> MakeExposures(const std::vector<DecodedPhoto>& photos,
                                    const MergeOptions& options) {
  std::vector<Exposure> exposures;
  exposures.reserve(photos.size());
  for (const auto& p : photos) exposures.emplace_back(p, options.noise, options.near_black_codes);
  // The fractional-code tables, one per distinct per-code table: with sRGB and no calibration the
  // channels' tables are equal, and so are the exposures' where the exposures' ratios are powers
  // of 2 (u = value / exposure x exposure). One table (256 kB) stays in the cache, and is built
  // once.
  std::vector<std::pair<const float*, std::shared_ptr<const std::vector<float>>>> built;
  for (Exposure& e : exposures) {
    if (e.code_u.empty() || !e.source->fractional_codes) continue;
    for (int c = 0; c < 3; ++c) {
      const float* table = e.code_u.data() + c * 256;
      for (const auto& [other, entries] : built)
        if (std::memcmp(other, table, 256 * sizeof(float)) == 0) e.fractional_u[c] = entries;
      if (e.fractional_u[c]) continue;
      e.fractional_u[c] = std::make_shared<const std::vector<float>>(FractionalCodeTable(table));
      built.emplace_back(table, e.fractional_u[c]);
    }
  }
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

// The merge's readers: `pixels` pixels of row y from x0 into uk as the recorded value above black
// u (R, G, B; NaN where clipped). 16-bit or float linear codes (CodesAreLinear):
template <typename T>
void ReadLinear(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  const Photo& photo = *e.source;
  const T* __restrict row = photo.pixels.ptr<T>(y) + 3 * x0;
  const float gain = e.u_gain, offset = e.u_offset, saturation = e.saturation_code;
  // In storage order first (a plain loop that vectorises), then blue and red swapped.
  for (int j = 0; j < 3 * pixels; ++j) {
    const float code = float(row[j]);
    const float value = code * gain - offset;
    const bool ok = (code < saturation) & (std::abs(value) <= FLT_MAX);  // NaN: clipped
    uk[j] = ok ? value : kClipped;
  }
  if (!photo.rgb_order)
    for (int j = 0; j < 3 * pixels; j += 3) std::swap(uk[j], uk[j + 2]);
}

// 8-bit codes (1 or 3 channels) through the exposure's per-code tables:
void ReadCodes(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  const cv::Mat& m = e.source->pixels;
  const float* __restrict table = e.code_u.data();
  if (m.channels() == 1) {
    const uint8_t* __restrict row = m.ptr<uint8_t>(y) + x0;
    for (int x = 0; x < pixels; ++x)
      for (int c = 0; c < 3; ++c) uk[3 * x + c] = table[c * 256 + row[x]];
    return;
  }
  const uint8_t* __restrict row = m.ptr<uint8_t>(y) + 3 * x0;
  const int ri = e.source->rgb_order ? 0 : 2;  // storage position of red (blue: 2 - ri)
  for (int x = 0; x < pixels; ++x, row += 3, uk += 3) {
    uk[0] = table[row[ri]];
    uk[1] = table[256 + row[1]];
    uk[2] = table[512 + row[2 - ri]];
  }
}

// A JPEG's fractional codes (RGB order) through the same tables, read linearly between codes;
// NaN (clipped) when the next whole code up is, as LinearReader has it:
void ReadFractionalCodes(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  const uint16_t* __restrict row = e.source->pixels.ptr<uint16_t>(y) + 3 * x0;
  const float* __restrict r = e.fractional_u[0]->data();
  const float* __restrict g = e.fractional_u[1]->data();
  const float* __restrict b = e.fractional_u[2]->data();
  if (r == g && g == b) {
    for (int j = 0; j < 3 * pixels; ++j) uk[j] = r[row[j]];
    return;
  }
  for (int x = 0; x < pixels; ++x, row += 3, uk += 3) {
    uk[0] = r[row[0]];
    uk[1] = g[row[1]];
    uk[2] = b[row[2]];
  }
}

// Any other photo (calib/'s dark map, hot pixels or flat field), pixel by pixel:
void ReadPixels(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  for (int x = 0; x < pixels; ++x) {
    float v[3];
    bool c[3];
    e.reader.Read(y, x0 + x, v, c);
    for (int ch = 0; ch < 3; ++ch) {
      const float value = v[ch] * e.recorded;
      uk[x * 3 + ch] = !c[ch] && std::isfinite(value) ? value : kClipped;
    }
  }
}

// `pixels` pixels of row y from x0 into uk through the exposure's reader above.
void ReadRow(const Exposure& e, int y, int x0, int pixels, float* __restrict uk) {
  if (e.linear_codes && e.source->pixels.depth() == CV_16U)
    ReadLinear<uint16_t>(e, y, x0, pixels, uk);
  else if (e.linear_codes)
    ReadLinear<float>(e, y, x0, pixels, uk);
  else if (!e.code_u.empty() && e.source->fractional_codes)
    ReadFractionalCodes(e, y, x0, pixels, uk);
  else if (!e.code_u.empty())
    ReadCodes(e, y, x0, pixels, uk);
  else
    ReadPixels(e, y, x0, pixels, uk);
}

// The k-th smallest of n non-negative floats (k < n), the value std::nth_element would put at
// k: their bit patterns order as unsigned integers, so two counting passes, over the upper 16
// bits and then the lower 16 bits of the values in the upper bits' bin, find it (cheaper than
// nth_element's partitions for the ~790 k ratios per pair of EstimateRatios).
float KthSmallestNonNegative(const float* v, size_t n, size_t k) {
  std::vector<uint32_t> count(65536, 0);
  auto bits = [](float f) {
    uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    return b;
  };
  for (size_t i = 0; i < n; ++i) ++count[bits(v[i]) >> 16];
  uint32_t high = 0;
  size_t below = 0;  // values in the bins before `high`
  while (below + count[high] <= k) below += count[high++];
  std::fill(count.begin(), count.end(), 0);
  for (size_t i = 0; i < n; ++i)
    if (bits(v[i]) >> 16 == high) ++count[bits(v[i]) & 0xFFFF];
  uint32_t low = 0;
  while (below + count[low] <= k) below += count[low++];
  const uint32_t b = high << 16 | low;
  float value;
  std::memcpy(&value, &b, sizeof value);
  return value;
}

std::vector<BracketRatio> EstimateRatios(std::vector<Exposure>& exposures, int w, int h) {
  // A grid of at most ~2^18 pixels: the median of that many ratios is precise to ~1e-4.
  const int stride = std::max(1, int(std::ceil(std::sqrt(double(w) * h / 262144.0))));
  const size_t grid = size_t((h - stride / 2 + stride - 1) / stride) *
                      size_t((w - stride / 2 + stride - 1) / stride);
  std::vector<BracketRatio> ratios;
  for (int slide : {0, 1}) {
    const std::vector<size_t> order = SlideOrder(exposures, slide);
    if (order.size() < 2) continue;
    // The ratios long / short; their median is taken, then its log (the median of the logs,
    // as the log is monotonic, with one log instead of one per sample).
    // At most 3 per grid pixel; plain arrays with a count (push_back was not inlined: a call
    // per sample, ~10 ms per merge at 6000 x 4000).
    std::vector<std::unique_ptr<float[]>> sample_ratios(order.size() - 1);
    std::vector<size_t> samples(order.size() - 1, 0);
    for (auto& v : sample_ratios) v.reset(new float[3 * grid]);
    std::vector<float> u(order.size() * 3);  // NaN where clipped
    for (int y = stride / 2; y < h; y += stride)
      for (int x = stride / 2; x < w; x += stride) {
        for (size_t k = 0; k < order.size(); ++k)
          ReadRow(exposures[order[k]], y, x, 1, &u[k * 3]);  // the values the merge reads
        for (size_t k = 0; k + 1 < order.size(); ++k)
          for (int ch = 0; ch < 3; ++ch) {
            // Well exposed in both (not clipped: NaN fails the tests), and well above the
            // near-black floor: the ratio of two values a few codes above black is dominated by
            // their quantisation.
            const float a = u[k * 3 + ch], b = u[(k + 1) * 3 + ch];
            if (!(a >= 4 * exposures[order[k]].floor_u && a > 0)) continue;
            if (!(b >= 4 * exposures[order[k + 1]].floor_u && b > 0)) continue;
            sample_ratios[k][samples[k]++] = b / a;
          }
      }
    for (size_t k = 0; k + 1 < order.size(); ++k) {
      BracketRatio r;
      r.positive = slide == 0;
      r.recorded_short = exposures[order[k]].recorded;
      r.recorded_long = exposures[order[k + 1]].recorded;
      r.estimated = r.Recorded();
      const size_t n = samples[k];
      if (n >= size_t(kMinRatioSamples)) {
        // (The ratios are > 0: both values are.)
        const float median = KthSmallestNonNegative(sample_ratios[k].get(), n, n / 2);
        r.estimated = std::exp(double(std::log(median)));
        r.samples = (long long)n;
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

// GCC on x86-64: the row kernels below are compiled for the SSE2 baseline, AVX2 and x86-64-v4
// (AVX-512F, BW, DQ, VL), and the loader picks the best one the processor runs (glibc ifunc). All
// do the same IEEE operations in the same order (nothing is contracted into FMAs:
// -ffp-contract=off, reconstruct/CMakeLists.txt): the same numbers on every machine. (x86-64-v4:
// 16 values per operation and mask registers for the selects; with AVX-512F alone GCC kept the
// weighted pass, whose states are bytes, in 256-bit AVX, ~8 % slower on the AMD Zen 5
// development machine.)
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(LUMISLAB_NO_TARGET_CLONES)
#define LUMISLAB_ROW_KERNEL __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define LUMISLAB_ROW_KERNEL
#endif
#define LUMISLAB_INLINE inline __attribute__((always_inline))
// The quantisation term's table lookups (QuantLookups) have an AVX-512F version besides the plain
// one, chosen by the loader likewise (GCC's function multiversioning).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(LUMISLAB_NO_TARGET_CLONES)
#define LUMISLAB_QUANT_AVX512
#define LUMISLAB_QUANT_DEFAULT __attribute__((target("default")))
#else
#define LUMISLAB_QUANT_DEFAULT
#endif

// A row is merged in chunks of this many values (128 pixels x 3 channels), so that the
// per-exposure values and the scratch of the passes below stay in the L1 cache (48 kB on Zen 5;
// 256 pixels were ~4 % slower).
constexpr int kChunk = 3 * 128;
// Slides with up to this many exposures get kernels with the exposure loop unrolled (vectorised
// over the values); more take the same code with a run-time count.
constexpr int kMaxUnrolled = 4;

// One slide's exposures as the kernels read them, longest effective exposure first.
struct SlideParams {
  int n = 0;
  bool curved = false;  // some exposure's quantisation term varies (a table over the curve)
  float inv_full_well = 0;
  std::vector<float> eff, inv_eff, floor_u;
  // var(u) = (u / FW + constant) + table term: constant = read_var + quant_var[0] where the
  // term is constant (and the table term 0), read_var where it comes from the table.
  std::vector<float> constant, range, black;
  std::vector<const float*> quant_var;  // the exposure's table, nullptr where constant
};

// The per-chunk scratch of one slide: the pilot estimate, the longest unclipped value over its
// exposure, the sum of the well-exposed exposures (> 0: measured), whether any value was
// unclipped, and each exposure's table term of the variance.
struct SlideScratch {
  float pilot[kChunk], longest[kChunk], sum_e[kChunk], found[kChunk];
  float quant[kMaxUnrolled * kChunk];
  int entry[kChunk];
  std::vector<float> quant_more;  // [n * kChunk] for slides with more exposures
};

// A slide's per-exposure parameters, copied to the stack when the count is a constant: the
// loops over the values may then load them unconditionally (if-converted and vectorised) where
// they are only used under a condition.
template <int kN>
struct Local {
  float local[kN > 0 ? kN : 1];
  const float* values;
  explicit Local(const std::vector<float>& v) : values(kN > 0 ? local : v.data()) {
    if (kN > 0) std::copy_n(v.data(), kN, local);
  }
  float operator[](int k) const { return values[k]; }
};

// Pilot: over the well-exposed values (Exposure::floor_u), sum u / sum exposure, the
// maximum-likelihood estimate under shot noise alone (weights = exposures). Longest first, so
// the first unclipped value met is the longest exposure's (used where all are near-black).
// u: the slide's values, [k * kChunk + i], NaN where clipped.
template <int kN>
LUMISLAB_INLINE void PilotPass(const SlideParams& p, const float* __restrict u, int m,
                               SlideScratch& __restrict s) {
  const int n = kN > 0 ? kN : p.n;
  Local<kN> eff(p.eff), inv_eff(p.inv_eff), floor_u(p.floor_u);
  for (int i = 0; i < m; ++i) {
    float su = 0, se = 0, lg = 0, found = 0;
    for (int k = 0; k < n; ++k) {
      const float x = u[k * kChunk + i];
      const float unclipped = x == x ? 1.f : 0.f;
      const bool well = (x >= floor_u[k]) & (x > 0.f);  // false where clipped (NaN)
      su += well ? x : 0.f;
      se += well ? eff[k] : 0.f;
      // lg is 0 until the first unclipped value, then stays.
      lg += (1.f - found) * unclipped > 0.f ? x * inv_eff[k] : 0.f;
      found = std::max(found, unclipped);
    }
    s.pilot[i] = su / se;  // 0 / 0 where nothing is well exposed: never used
    s.longest[i] = lg;
    s.sum_e[i] = se;
    s.found[i] = found;
  }
}

// The table term of m values: table[entry] at the expected u = eff * pilot (Exposure's
// quant_var, the curve value's 1/1024 step, as Exposure::Variance). A NaN pilot (an unused lane)
// reads entry 0. The plain version: the entries first (vectorised), then the lookups.
LUMISLAB_QUANT_DEFAULT void QuantLookups(const float* __restrict table,
                                         const float* __restrict pilot, int m, float eff,
                                         float range, float black, int* __restrict entry,
                                         float* __restrict q) {
  for (int i = 0; i < m; ++i) entry[i] = QuantTableEntry(eff * pilot[i] * range + black);
  for (int i = 0; i < m; ++i) q[i] = table[entry[i]];
}

#ifdef LUMISLAB_QUANT_AVX512
// AVX-512F: 16 entries at a time, the same float operations in the same order. The lookups as
// permutes from windows of 32 consecutive table entries; the lanes outside them gathered. Lane j
// holds the channel of lane j % 3 (the values are R, G, B in turn from lane 0 of each chunk, and
// a vector is 16 values): three windows, one per channel, each from 16 below an entry of that
// channel (QuantBases). Any window gives the same values (the table's entries); the windows
// only decide how many lanes are gathered. `need`: the lanes whose entry is used; the others
// may hold any entry of the table.
__attribute__((target("avx512f"), always_inline)) inline __m512i QuantEntries16(__m512 pilot,
                                                                                float eff,
                                                                                float range,
                                                                                float black) {
  constexpr int kLast = Exposure::kQuantTable - 1;
  const __m512 l =
      _mm512_add_ps(_mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(eff), pilot), _mm512_set1_ps(range)),
                    _mm512_set1_ps(black));
  // l >= 1: the last entry; 0 < l < 1: int(l * kLast + 0.5); else (and NaN) 0.
  const __m512i e = _mm512_maskz_cvttps_epi32(
      _mm512_cmp_ps_mask(l, _mm512_setzero_ps(), _CMP_GT_OQ),
      _mm512_add_ps(_mm512_mul_ps(l, _mm512_set1_ps(float(kLast))), _mm512_set1_ps(0.5f)));
  return _mm512_mask_mov_epi32(e, _mm512_cmp_ps_mask(l, _mm512_set1_ps(1.f), _CMP_GE_OQ),
                               _mm512_set1_epi32(kLast));
}

// The windows' first entries from the entries e of a vector: for the same vector `first` = 0
// (lanes 0, 1, 2), for the next one `first` = 1 (its lanes 0, 1, 2 hold the channels of lanes 1,
// 2, 3 here, 5 pixels on): the fused merge takes the previous vector's, so that the table reads
// need not wait for this vector's entries.
__attribute__((target("avx512f"), always_inline)) inline void QuantBases(__m512i e, int first,
                                                                         int* base) {
  constexpr int kLast = Exposure::kQuantTable - 1, kWindow = 32;
  alignas(64) int entries[16];
  _mm512_store_si512(entries, e);
  for (int c = 0; c < 3; ++c) base[c] = std::clamp(entries[first + c] - 16, 0, kLast + 1 - kWindow);
}

__attribute__((target("avx512f"), always_inline)) inline __m512 QuantLookup16(
    const float* __restrict table, __m512i e, const int* base, __mmask16 need) {
  constexpr int kWindow = 32;
  constexpr __mmask16 kChannel1 = 0x2492, kChannel2 = 0x4924;  // lanes 1, 4, ...; 2, 5, ...
  const __m512i lane_base = _mm512_mask_mov_epi32(
      _mm512_mask_mov_epi32(_mm512_set1_epi32(base[0]), kChannel1, _mm512_set1_epi32(base[1])),
      kChannel2, _mm512_set1_epi32(base[2]));
  const __m512i d = _mm512_sub_epi32(e, lane_base);
  const __mmask16 outside = _mm512_cmpge_epu32_mask(d, _mm512_set1_epi32(kWindow)) & need;
  __m512 window[3];
  for (int c = 0; c < 3; ++c)
    window[c] = _mm512_permutex2var_ps(_mm512_loadu_ps(table + base[c]), d,
                                       _mm512_loadu_ps(table + base[c] + 16));
  __m512 v =
      _mm512_mask_mov_ps(_mm512_mask_mov_ps(window[0], kChannel1, window[1]), kChannel2, window[2]);
  if (outside) v = _mm512_mask_i32gather_ps(v, outside, e, table, 4);
  return v;
}

__attribute__((target("avx512f"))) void QuantLookups(const float* __restrict table,
                                                     const float* __restrict pilot, int m,
                                                     float eff, float range, float black,
                                                     int* __restrict, float* __restrict q) {
  for (int i = 0; i < m; i += 16) {
    const __mmask16 lanes = m - i >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << (m - i)) - 1);
    const __m512i e = QuantEntries16(_mm512_maskz_loadu_ps(lanes, pilot + i), eff, range, black);
    int base[3];
    QuantBases(e, 0, base);
    const __m512 v = QuantLookup16(table, e, base, lanes);
    _mm512_mask_storeu_ps(q + i, lanes, v);
  }
}
#endif

// The table term of each curved exposure's variance at the pilot's expected u = e * pilot; 0 for
// the others.
LUMISLAB_INLINE void QuantPass(const SlideParams& p, int m, SlideScratch& __restrict s,
                               float* __restrict quant) {
  for (int k = 0; k < p.n; ++k) {
    float* __restrict q = quant + k * kChunk;
    if (!p.quant_var[k]) {
      std::fill_n(q, m, 0.f);
      continue;
    }
    QuantLookups(p.quant_var[k], s.pilot, m, p.eff[k], p.range[k], p.black[k], s.entry, q);
  }
}

// Inverse-variance weights e^2 / var(u) at the pilot's expected u = e * pilot: the read-noise
// and quantisation terms favour the longer exposures more than the shot-noise weights do. (Each
// exposure's own u would bias the weights towards values that read low.) With one well-exposed
// value this is that value / its exposure. Computed on every lane and selected (where the value
// is not well exposed, 0 / 0 pilots and zero variances may give NaN or inf, never used). Then
// the merged value and state, and per lane the brightest and faintest measured values.
template <int kN, bool kCurved>
LUMISLAB_INLINE void WeightPass(const SlideParams& p, const float* __restrict u, int m,
                                const SlideScratch& __restrict s, const float* __restrict quant,
                                float* __restrict value, uint8_t* __restrict state,
                                float* __restrict brightest, float* __restrict faintest) {
  const int n = kN > 0 ? kN : p.n;
  Local<kN> eff(p.eff), floor_u(p.floor_u), constant(p.constant);
  const float inv_full_well = p.inv_full_well;
  for (int i = 0; i < m; ++i) {
    const float pilot = s.pilot[i];
    float sw = 0, swx = 0;
    for (int k = 0; k < n; ++k) {
      const float x = u[k * kChunk + i];
      const bool well = (x >= floor_u[k]) & (x > 0.f);
      const float u_expected = eff[k] * pilot;
      float variance = u_expected * inv_full_well + constant[k];
      if (kCurved) variance += quant[k * kChunk + i];
      // w / e = e / var(u), applied to u: sum_wx = sum w * (u / e).
      const float w_over_e = eff[k] / variance;
      sw += well ? w_over_e * eff[k] : 0.f;
      swx += well ? w_over_e * x : 0.f;
    }
    const bool measured = s.sum_e[i] > 0.f;
    const bool any = s.found[i] != 0.f;
    const float v = !any ? 0.f : measured ? swx / sw : s.longest[i];
    value[i] = v;
    state[i] = !any ? kClippedEverywhere : measured ? kMeasured : kNearBlackEverywhere;
    // As std::max / std::min, lane by lane (a NaN value is never taken).
    const float b = measured ? v : 0.f;
    brightest[i] = brightest[i] < b ? b : brightest[i];
    const float f = (measured & (v > 0.f)) ? v : faintest[i];
    faintest[i] = f < faintest[i] ? f : faintest[i];
  }
}

template <int kN>
LUMISLAB_INLINE void MergeSlideChunkN(const SlideParams& p, const float* u, int m, SlideScratch& s,
                                      float* value, uint8_t* state, float* brightest,
                                      float* faintest) {
  PilotPass<kN>(p, u, m, s);
  if (!p.curved) {
    WeightPass<kN, false>(p, u, m, s, nullptr, value, state, brightest, faintest);
    return;
  }
  float* quant = p.n <= kMaxUnrolled ? s.quant : s.quant_more.data();
  QuantPass(p, m, s, quant);
  WeightPass<kN, true>(p, u, m, s, quant, value, state, brightest, faintest);
}

// One slide over a chunk of m values (m <= kChunk): u as in PilotPass, value and state out,
// brightest and faintest updated lane by lane.
LUMISLAB_ROW_KERNEL void MergeSlideChunk(const SlideParams& p, const float* u, int m,
                                         SlideScratch& s, float* value, uint8_t* state,
                                         float* brightest, float* faintest) {
  static_assert(kMaxUnrolled == 4, "MergeSlideChunk: one case per unrolled count");
  switch (p.n) {
    case 1:
      return MergeSlideChunkN<1>(p, u, m, s, value, state, brightest, faintest);
    case 2:
      return MergeSlideChunkN<2>(p, u, m, s, value, state, brightest, faintest);
    case 3:
      return MergeSlideChunkN<3>(p, u, m, s, value, state, brightest, faintest);
    case 4:
      return MergeSlideChunkN<4>(p, u, m, s, value, state, brightest, faintest);
    default:
      return MergeSlideChunkN<0>(p, u, m, s, value, state, brightest, faintest);
  }
}

// The three passes above fused into one, 16 values at a time with AVX-512F intrinsics: each
// exposure's values are loaded once and the pilot, its sums and the table terms stay in
// registers (the passes' loops stored and re-read them, and QuantLookups was a call per exposure
// and chunk). The same IEEE operations in the same order on every lane as PilotPass, QuantPass
// and WeightPass, so the same numbers. The table is read only where the exposure's value is well
// exposed (elsewhere its weight is not used): fewer gathers. Slides of up to kMaxUnrolled
// exposures; false (nothing done) for more, and on processors without AVX-512F (the default
// version), where MergeSlideChunk does the work.
#ifdef LUMISLAB_QUANT_AVX512
template <int kN, bool kCurved>
__attribute__((target("avx512f"), always_inline)) inline void FusedSlideChunk(
    const SlideParams& p, const float* __restrict u, int m, float* __restrict value,
    uint8_t* __restrict state, float* __restrict brightest, float* __restrict faintest) {
  float eff[kN], inv_eff[kN], floor_u[kN], constant[kN], range[kN], black[kN];
  const float* quant_var[kN];
  for (int k = 0; k < kN; ++k) {
    eff[k] = p.eff[k], inv_eff[k] = p.inv_eff[k], floor_u[k] = p.floor_u[k];
    constant[k] = p.constant[k], range[k] = p.range[k], black[k] = p.black[k];
    quant_var[k] = p.quant_var[k];
  }
  const __m512 zero = _mm512_setzero_ps();
  const __m512 inv_full_well = _mm512_set1_ps(p.inv_full_well);
  int base[kN][3] = {};  // QuantLookup16's windows, from the previous vector's entries
  for (int i = 0; i < m; i += 16) {
    const __mmask16 lanes = m - i >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << (m - i)) - 1);
    // Pilot (PilotPass).
    __m512 x[kN];
    __mmask16 well[kN];
    __m512 su = zero, se = zero, lg = zero;
    __mmask16 found = 0;
    for (int k = 0; k < kN; ++k) {
      x[k] = _mm512_maskz_loadu_ps(lanes, u + k * kChunk + i);
      const __mmask16 unclipped = _mm512_cmp_ps_mask(x[k], x[k], _CMP_EQ_OQ);
      well[k] = _mm512_cmp_ps_mask(x[k], _mm512_set1_ps(floor_u[k]), _CMP_GE_OQ) &
                _mm512_cmp_ps_mask(x[k], zero, _CMP_GT_OQ);
      su = _mm512_add_ps(su, _mm512_maskz_mov_ps(well[k], x[k]));
      se = _mm512_add_ps(se, _mm512_maskz_mov_ps(well[k], _mm512_set1_ps(eff[k])));
      lg = _mm512_add_ps(lg, _mm512_maskz_mov_ps(__mmask16(unclipped & ~found),
                                                 _mm512_mul_ps(x[k], _mm512_set1_ps(inv_eff[k]))));
      found = __mmask16(found | unclipped);
    }
    const __m512 pilot = _mm512_div_ps(su, se);
    // Weights (QuantPass, WeightPass).
    __m512 sw = zero, swx = zero;
    for (int k = 0; k < kN; ++k) {
      const __m512 e = _mm512_set1_ps(eff[k]);
      __m512 variance = _mm512_add_ps(_mm512_mul_ps(_mm512_mul_ps(e, pilot), inv_full_well),
                                      _mm512_set1_ps(constant[k]));
      if (kCurved) {
        __m512 q = zero;
        if (quant_var[k]) {
          const __m512i entry = QuantEntries16(pilot, eff[k], range[k], black[k]);
          if (i == 0) QuantBases(entry, 0, base[k]);
          q = QuantLookup16(quant_var[k], entry, base[k], __mmask16(well[k] & lanes));
          QuantBases(entry, 1, base[k]);  // for the next vector
        }
        variance = _mm512_add_ps(variance, q);
      }
      const __m512 w_over_e = _mm512_div_ps(e, variance);
      sw = _mm512_add_ps(sw, _mm512_maskz_mov_ps(well[k], _mm512_mul_ps(w_over_e, e)));
      swx = _mm512_add_ps(swx, _mm512_maskz_mov_ps(well[k], _mm512_mul_ps(w_over_e, x[k])));
    }
    const __mmask16 measured = _mm512_cmp_ps_mask(se, zero, _CMP_GT_OQ);
    // !any: 0; measured: swx / sw; else the longest unclipped value.
    const __m512 v =
        _mm512_maskz_mov_ps(found, _mm512_mask_mov_ps(lg, measured, _mm512_div_ps(swx, sw)));
    _mm512_mask_storeu_ps(value + i, lanes, v);
    const __m512i st = _mm512_mask_mov_epi32(
        _mm512_set1_epi32(kClippedEverywhere), found,
        _mm512_maskz_mov_epi32(__mmask16(~measured), _mm512_set1_epi32(kNearBlackEverywhere)));
    _mm512_mask_cvtepi32_storeu_epi8(state + i, lanes, st);
    const __m512 b = _mm512_maskz_mov_ps(measured, v);
    const __m512 old_b = _mm512_maskz_loadu_ps(lanes, brightest + i);
    _mm512_mask_storeu_ps(brightest + i, lanes,
                          _mm512_mask_mov_ps(old_b, _mm512_cmp_ps_mask(old_b, b, _CMP_LT_OQ), b));
    const __m512 old_f = _mm512_maskz_loadu_ps(lanes, faintest + i);
    const __m512 f =
        _mm512_mask_mov_ps(old_f, __mmask16(measured & _mm512_cmp_ps_mask(v, zero, _CMP_GT_OQ)), v);
    _mm512_mask_storeu_ps(faintest + i, lanes,
                          _mm512_mask_mov_ps(old_f, _mm512_cmp_ps_mask(f, old_f, _CMP_LT_OQ), f));
  }
}
#endif

LUMISLAB_QUANT_DEFAULT bool MergeSlideChunkFused(const SlideParams&, const float*, int, float*,
                                                 uint8_t*, float*, float*) {
  return false;
}

#ifdef LUMISLAB_QUANT_AVX512
__attribute__((target("avx512f"))) bool MergeSlideChunkFused(const SlideParams& p, const float* u,
                                                             int m, float* value, uint8_t* state,
                                                             float* brightest, float* faintest) {
  static_assert(kMaxUnrolled == 4, "MergeSlideChunkFused: one case per unrolled count");
#define LUMISLAB_FUSED_CASE(kN)                                               \
  case kN:                                                                    \
    if (p.curved)                                                             \
      FusedSlideChunk<kN, true>(p, u, m, value, state, brightest, faintest);  \
    else                                                                      \
      FusedSlideChunk<kN, false>(p, u, m, value, state, brightest, faintest); \
    return true;
  switch (p.n) {
    LUMISLAB_FUSED_CASE(1)
    LUMISLAB_FUSED_CASE(2)
    LUMISLAB_FUSED_CASE(3)
    LUMISLAB_FUSED_CASE(4)
    default:
      return false;
  }
#undef LUMISLAB_FUSED_CASE
}
#endif

// Both slides of `pixels` pixels into gain * (v+ - v-) per value, 0 where the pixel is saturated
// (a channel of a slide clipped in every exposure: the states are bits, so one OR over the six
// channels tells), and 1 / 0 per pixel for saturated; counts the saturated and the near-black
// pixels.
LUMISLAB_ROW_KERNEL void CombineSlides(const float* __restrict v0, const float* __restrict v1,
                                       const uint8_t* __restrict s0, const uint8_t* __restrict s1,
                                       int pixels, float gain, float* __restrict difference,
                                       float* __restrict saturated, int* saturated_count,
                                       int* near_black_count) {
  int n_saturated = 0, n_near_black = 0;
  for (int x = 0; x < pixels; ++x) {
    const int i = 3 * x;
    const int any = s0[i] | s0[i + 1] | s0[i + 2] | s1[i] | s1[i + 1] | s1[i + 2];
    const bool sat = any & kClippedEverywhere;
    n_saturated += sat;
    n_near_black += !sat & ((any & kNearBlackEverywhere) != 0);
    saturated[x] = sat ? 1.f : 0.f;
    for (int c = 0; c < 3; ++c) difference[i + c] = sat ? 0.f : gain * (v0[i + c] - v1[i + c]);
  }
  *saturated_count += n_saturated;
  *near_black_count += n_near_black;
}

// Merges one photo row of both slides. Each exposure's values of a chunk of the row are read
// once (linear codes or per-code tables, NaN where clipped), then each slide is merged: with
// AVX-512F in one fused pass (MergeSlideChunkFused), else in three passes over the chunk (pilot,
// the table term of curved photos, weighted sums) whose loops over the slide's exposures are
// unrolled so that the compiler vectorises over the values.
struct MergeRows {
  const std::vector<Exposure>& exposures;
  int width, n3;  // n3 = 3 * width
  SlideParams params[2];
  std::vector<int> slot_of;  // exposure -> its row of `u`: slide 0's, then slide 1's, longest first
  int first_slot[2] = {0, 0};
  std::vector<float> u;  // [slot * kChunk + i]: recorded value above black, NaN where clipped
  std::unique_ptr<SlideScratch> scratch;
  // Per slide: the merged exposure-normalised value and how it was merged, the whole row.
  std::vector<float> value[2];
  std::vector<uint8_t> state[2];
  // The row's gain * (v+ - v-) (0 where saturated) and saturated flags, for the box average.
  std::vector<float> difference, saturated;
  // Per lane of a chunk: the brightest and the faintest measured value so far.
  std::vector<float> brightest, faintest;

  MergeRows(const std::vector<Exposure>& e, const std::vector<int>* members, int w,
            float inv_full_well)
      : exposures(e), width(w), n3(3 * w), slot_of(e.size()), scratch(new SlideScratch) {
    int slot = 0;
    for (int sl = 0; sl < 2; ++sl) {
      first_slot[sl] = slot;
      SlideParams& p = params[sl];
      p.n = int(members[sl].size());
      p.inv_full_well = inv_full_well;
      for (const int k : members[sl]) {
        const Exposure& x = e[k];
        slot_of[k] = slot++;
        p.eff.push_back(x.effective);
        p.inv_eff.push_back(1.f / x.effective);
        p.floor_u.push_back(x.floor_u);
        p.constant.push_back(x.curved ? x.read_var : x.read_var + x.quant_var[0]);
        p.range.push_back(x.range);
        p.black.push_back(x.black);
        p.quant_var.push_back(x.curved ? x.quant_var.data() : nullptr);
        p.curved |= x.curved;
      }
      if (p.curved && p.n > kMaxUnrolled)  // (the scratch serves both slides)
        scratch->quant_more.resize(std::max(scratch->quant_more.size(), size_t(p.n) * kChunk));
    }
    u.resize(e.size() * kChunk);
    for (int s = 0; s < 2; ++s) value[s].resize(n3), state[s].resize(n3);
    difference.resize(n3), saturated.resize(w);
    brightest.assign(kChunk, 0.f);
    faintest.assign(kChunk, std::numeric_limits<float>::infinity());
  }

  // Row y, pixels [xa, xb): value, state, difference and saturated; stats counted.
  void Merge(int y, int xa, int xb, float gain, MergeStats* stats) {
    for (int x0 = xa; x0 < xb; x0 += kChunk / 3) {
      const int pixels = std::min(kChunk / 3, xb - x0), m = 3 * pixels;
      for (size_t k = 0; k < exposures.size(); ++k) {
        const Exposure& e = exposures[k];
        ReadRow(e, y, x0, pixels, u.data() + size_t(slot_of[k]) * kChunk);
      }
      for (int s = 0; s < 2; ++s) {
        const float* us = u.data() + size_t(first_slot[s]) * kChunk;
        float* vs = value[s].data() + 3 * x0;
        uint8_t* ss = state[s].data() + 3 * x0;
        if (!MergeSlideChunkFused(params[s], us, m, vs, ss, brightest.data(), faintest.data()))
          MergeSlideChunk(params[s], us, m, *scratch, vs, ss, brightest.data(), faintest.data());
      }
      CombineSlides(value[0].data() + 3 * x0, value[1].data() + 3 * x0, state[0].data() + 3 * x0,
                    state[1].data() + 3 * x0, pixels, gain, difference.data() + 3 * x0,
                    saturated.data() + x0, &stats->saturated, &stats->near_black);
    }
  }

  // The brightest and faintest measured values of every row merged (std::max / std::min over
  // the lanes: the same as in pixel order).
  void Finish(MergeStats* stats) const {
    for (int i = 0; i < kChunk; ++i) {
      stats->brightest = std::max(stats->brightest, brightest[i]);
      stats->faintest = std::min(stats->faintest, faintest[i]);
    }
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
                                   int downsample, const MergeOptions& options,
                                   const cv::Rect& region) {
  LUMISLAB_CHECK(!photos.empty(), "MergePosition: no photos");
  LUMISLAB_CHECK(downsample >= 1, "MergePosition: downsample >= 1");
  const int w = photos[0].photo.pixels.cols, h = photos[0].photo.pixels.rows;
  LUMISLAB_CHECK(
      region.empty() || (region & cv::Rect(0, 0, w / downsample, h / downsample)) == region,
      "MergePosition: region inside the averaged image");
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
  // beyond are merged for the counts only. With a region, only its output pixels' blocks are
  // merged (and counted), the rest of the signal is 0.
  const int f = downsample, ow = w / f, oh = h / f;
  // In huge pages (24 MB at 6000 x 4000, F = 4): fresh 4 kB pages cost 15 - 50 us each to first
  // touch on the development VM (docs/design.md 8.3).
  out.signal = NewPhotoImage(oh, ow, CV_32FC4);
  const bool whole = region.empty();
  if (!whole) out.signal.setTo(0);
  const int band0 = whole ? 0 : region.y, band1 = whole ? (h + f - 1) / f : region.br().y;
  const int ox0 = whole ? 0 : region.x, ox1 = whole ? ow : region.br().x;
  const int xa = ox0 * f, xb = whole ? w : ox1 * f;
  const float g = float(gain), inv_area = 1.f / float(f * f);
  // Each slide's photos, longest effective exposure first.
  std::vector<int> members[2];
  for (int k = 0; k < int(n); ++k) members[exposures[k].slide].push_back(k);
  for (auto& m : members)
    std::stable_sort(m.begin(), m.end(),
                     [&](int a, int b) { return exposures[a].effective > exposures[b].effective; });
  MergeStats total;
  std::mutex total_mutex;
  cv::parallel_for_(cv::Range(band0, band1), [&](const cv::Range& range) {
    MergeStats stats;
    MergeRows rows(exposures, members, w, inv_full_well);
    std::vector<float> acc(size_t(ow) * 4);
    for (int band = range.start; band < range.end; ++band) {
      std::fill(acc.begin(), acc.end(), 0.f);
      for (int y = band * f; y < std::min(h, (band + 1) * f); ++y) {
        rows.Merge(y, xa, xb, g, &stats);
        if (band >= oh) continue;  // merged for the counts only
        // The F x F box sums, in the order of the pixels (x, then y).
        const float* d = rows.difference.data();
        const float* sat = rows.saturated.data();
        for (int ox = ox0; ox < ox1; ++ox) {
          float* o = &acc[size_t(ox) * 4];
          for (int x = ox * f; x < (ox + 1) * f; ++x) {
            for (int ch = 0; ch < 3; ++ch) o[ch] += d[x * 3 + ch];
            o[3] += sat[x];
          }
        }
      }
      if (band >= oh) continue;
      float* o = out.signal.ptr<float>(band);
      for (size_t k = size_t(ox0) * 4; k < size_t(ox1) * 4; ++k) o[k] = acc[k] * inv_area;
    }
    rows.Finish(&stats);
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
