#include "reconstruct/photo_merge.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <utility>

#include "core/error.h"
#include "lib/photo/photo_allocator.h"
#include "reconstruct/bracket_ratios.h"
#include "reconstruct/merge_exposure.h"
#include "reconstruct/merge_kernels.h"

namespace lumislab {

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
    const bool linear = merge::CodesAreLinear(p) && merge::CodesAreLinear(n) && p.Offset() == 0 &&
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

namespace merge {
namespace {

// What one band of rows found, combined under a lock.
struct MergeStats {
  int saturated = 0, near_black = 0;
  float brightest = 0, faintest = std::numeric_limits<float>::infinity();
};

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
}  // namespace merge

MergedPosition MergeFullResolution(const std::vector<DecodedPhoto>& photos, double gain,
                                   int downsample, const MergeOptions& options,
                                   const cv::Rect& region) {
  LUMISLAB_CHECK(!photos.empty(), "MergePosition: no photos");
  LUMISLAB_CHECK(downsample >= 1, "MergePosition: downsample >= 1");
  const int w = photos[0].photo.pixels.cols, h = photos[0].photo.pixels.rows;
  LUMISLAB_CHECK(
      region.empty() || (region & cv::Rect(0, 0, w / downsample, h / downsample)) == region,
      "MergePosition: region inside the averaged image");
  std::vector<merge::Exposure> exposures = merge::MakeExposures(photos, options);
  MergedPosition out;
  for (int slide : {0, 1})
    out.exposures = std::max(out.exposures, int(merge::SlideOrder(exposures, slide).size()));
  if (out.exposures > 1) {
    out.ratios = merge::EstimateRatios(exposures, w, h);
    if (options.bracket_ratios == BracketRatios::kEstimated)
      merge::ApplyRatios(exposures, out.ratios);
  }
  const size_t n = exposures.size();
  const float inv_full_well = float(1.0 / options.noise.full_well_e);
  // F x F blocks of the top-left multiple of F make the output pixels; the rows and columns
  // beyond are merged for the counts only. With a region, only its output pixels' blocks are
  // merged (and counted), the rest of the signal is 0.
  const int f = downsample, ow = w / f, oh = h / f;
  // In huge pages (24 MB at 6000 x 4000, F = 4): fresh 4 kB pages are slow to first touch
  // (lib/photo/photo_allocator.h).
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
  merge::MergeStats total;
  std::mutex total_mutex;
  cv::parallel_for_(cv::Range(band0, band1), [&](const cv::Range& range) {
    merge::MergeStats stats;
    merge::MergeRows rows(exposures, members, w, inv_full_well);
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
