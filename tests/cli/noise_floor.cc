#include "noise_floor.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "core/dataset.h"
#include "core/exr_io.h"
#include "core/screen_calibration.h"
#include "core/slab.h"

namespace lumislab::testing {

double SensorNoiseModel::Variance(double s) const {
  const double q = code_step(s);
  return (std::max(0.0, s) * full_well_e + read_noise_e * read_noise_e) /
             (full_well_e * full_well_e) +
         q * q / 12;
}

namespace {

// The photos of one position, read once: each slide's exposures and sensor values.
struct SlidePhotos {
  std::vector<double> exposure;
  std::vector<ImageF> image;
  std::vector<JpegCodingModel> jpeg;  // per exposure, for a JPEG camera
};

// Merged variance of one slide's channel at pixel (x, y), exposure-normalised (exposure 1):
// the inverse-variance merge of the unclipped exposures. Where every exposure is clipped the
// merge has nothing (the pixel is masked as saturated): 0.
// For a JPEG camera (`spectrum` given), the merge keeps its weights (reconstruct knows the
// sensor's noise and one code's rounding, not the coding), and each exposure's variance is what
// JpegCodingModel predicts for the texel's mean, as a per-pixel variance in sensor values:
// var = sum_k w_k^2 var_k / (sum_k w_k t_k)^2 with w_k = t_k / V_k.
double MergedVariance(const SlidePhotos& slide, int x, int y, int ch,
                      const SensorNoiseModel& sensor, const JpegSpectrum* spectrum = nullptr) {
  double information = 0, jpeg = 0;
  for (size_t k = 0; k < slide.image.size(); ++k) {
    const double s = slide.image[k].at(x, y, ch);
    if (s >= sensor.saturation) continue;
    const double t = slide.exposure[k], model = sensor.Variance(s);
    information += t * t / model;
    if (spectrum) {
      const double step = sensor.code_step(s);  // sensor value per code
      const double coded = slide.jpeg[k].WhiteEquivalentVariance(x, y, *spectrum)[ch] * step * step;
      jpeg += t * t * coded / (model * model);
    }
  }
  if (information <= 0) return 0;
  return spectrum ? jpeg / (information * information) : 1 / information;
}

// Channel of the RGGB mosaic's sample at pixel (x, y): R at even x and y, B at odd ones.
int BayerChannel(int x, int y) { return (y & 1) ? ((x & 1) ? 2 : 1) : ((x & 1) ? 1 : 0); }

// For a weighted sum of the photo's pixels (channel ch), the sum of the squared weights of the
// sensor's samples behind it: each sample's noise is independent, so this is the sum's variance
// per unit sample variance. With a mosaic, a pixel's value of a channel it does not sample is
// the mean of that channel's samples in its 3 x 3 (lib/photo's demosaic).
double SampleWeightSquares(const PixelWeights& pixels, int ch, bool bayer) {
  PixelWeights samples;
  for (const auto& [p, w] : pixels) {
    const auto [x, y] = p;
    if (!bayer || BayerChannel(x, y) == ch) {
      samples[p] += w;
      continue;
    }
    std::vector<std::pair<int, int>> own;
    for (int yy = y - 1; yy <= y + 1; ++yy)
      for (int xx = x - 1; xx <= x + 1; ++xx)
        if (BayerChannel(xx, yy) == ch) own.emplace_back(xx, yy);
    for (const auto& q : own) samples[q] += w / double(own.size());
  }
  double sum = 0;
  for (const auto& [p, w] : samples) sum += w * w;
  return sum;
}

// The variance of a texel's value per unit sample variance (SampleWeightSquares) for a square
// texel of side `side` photo pixels, as reconstruct forms it: F x F pixel means (F = round(side
// / 3), at least 1), K x K bilinear samples at ((a + 0.5) / K, (b + 0.5) / K) of the texel
// (K = ceil(side / F), in [2, 12]), averaged; over 16 sub-pixel offsets of the texel and, with
// a mosaic, its 4 phases. Cached per side (to 1/20 px) and channel.
// The pixel weights of such a texel (side to 1/20 px) at each of the 16 offsets and, with a
// mosaic, 4 phases.
std::vector<PixelWeights> TexelPixelWeights(double side, bool bayer) {
  std::vector<PixelWeights> patterns;
  const int f = std::max(1, int(std::lround(side / 3)));
  const int k = std::clamp(int(std::ceil(side / f)), 2, 12);
  for (int phase = 0; phase < (bayer ? 4 : 1); ++phase)
    for (int oy = 0; oy < 4; ++oy)
      for (int ox = 0; ox < 4; ++ox) {
        // A texel corner at an even coarse pixel (64 F), shifted by a quarter-pixel offset and the
        // mosaic's phase.
        const double x0 = 64 * f + (phase & 1) + 0.25 * ox * f;
        const double y0 = 64 * f + (phase >> 1) + 0.25 * oy * f;
        PixelWeights coarse, pixels;
        for (int b = 0; b < k; ++b)
          for (int a = 0; a < k; ++a) {
            // The sample in photo pixels, then in the F x F mean's pixels (centre of pixel q at
            // q F + (F - 1) / 2).
            const double u = (x0 + (a + 0.5) * side / k - 0.5 * (f - 1)) / f;
            const double v = (y0 + (b + 0.5) * side / k - 0.5 * (f - 1)) / f;
            const int qx = int(std::floor(u)), qy = int(std::floor(v));
            const double fx = u - qx, fy = v - qy, w = 1.0 / (k * k);
            coarse[{qx, qy}] += w * (1 - fx) * (1 - fy);
            coarse[{qx + 1, qy}] += w * fx * (1 - fy);
            coarse[{qx, qy + 1}] += w * (1 - fx) * fy;
            coarse[{qx + 1, qy + 1}] += w * fx * fy;
          }
        for (const auto& [q, w] : coarse)
          for (int dy = 0; dy < f; ++dy)
            for (int dx = 0; dx < f; ++dx)
              pixels[{q.first * f + dx, q.second * f + dy}] += w / (f * f);
        patterns.push_back(std::move(pixels));
      }
  return patterns;
}

double TexelVarianceFactor(double side, int ch, bool bayer) {
  static std::map<std::tuple<long, int, bool>, double> cache;
  const auto key = std::make_tuple(std::lround(side * 20), ch, bayer);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  double total = 0;
  const std::vector<PixelWeights> patterns = TexelPixelWeights(std::get<0>(key) / 20.0, bayer);
  for (const PixelWeights& p : patterns) total += SampleWeightSquares(p, ch, bayer);
  return cache[key] = total / double(patterns.size());
}

// The JPEG spectrum of such a texel (no mosaic), cached per side.
const JpegSpectrum& TexelJpegSpectrum(double side) {
  static std::map<long, JpegSpectrum> cache;
  const long key = std::lround(side * 20);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  return cache[key] = JpegSpectrumOf(TexelPixelWeights(key / 20.0, false));
}

// Relative variance of calibrate scale's Y+ - Y- (docs/design.md §5.16): per slide, the
// photos unclipped over the fit's disc, their exposure-weighted mean of the quadratic fit's
// constant term, whose variance is [(A^T A)^-1]_00 x a pixel's over the disc's pixels.
double ScaleRelativeVariance(const ScreenCalibration& cal,
                             const std::map<bool, SlidePhotos>& slides, const ImageF* gain,
                             const ImageF* dark, const SensorNoiseModel& sensor,
                             const ChainNoiseModel& chain) {
  const Eigen::Vector2d at = cal.ImageFromScreen(chain.reference_mm);
  const int r = chain.reference_radius_px;
  const int x0 = int(std::round(at.x())), y0 = int(std::round(at.y()));
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<std::pair<int, int>> disc;
  std::vector<Eigen::Matrix<double, 6, 1>> rows;
  for (int y = y0 - r - 1; y <= y0 + r + 1; ++y)
    for (int x = x0 - r - 1; x <= x0 + r + 1; ++x) {
      const double dx = x - at.x(), dy = y - at.y();
      if (dx * dx + dy * dy > double(r) * r + 0.5) continue;
      Eigen::Matrix<double, 6, 1> row;
      row << 1, dx, dy, dx * dx, dx * dy, dy * dy;
      ata += row * row.transpose();
      disc.emplace_back(x, y);
      rows.push_back(row);
    }
  // The fit's constant term is sum_p w_p value_p with w = first row of (A^T A)^-1 A^T.
  const Eigen::Matrix<double, 6, 6> inverse = ata.inverse();
  PixelWeights fit_weights;
  for (size_t p = 0; p < disc.size(); ++p) fit_weights[disc[p]] = inverse.row(0).dot(rows[p]);
  double fit[3];
  for (int c = 0; c < 3; ++c) fit[c] = SampleWeightSquares(fit_weights, c, sensor.bayer_rggb);
  const double luminance[3] = {0.2126, 0.7152, 0.0722};
  const double g = gain ? gain->at(x0, y0, 0) : 1.0;
  double value[2] = {0, 0}, variance[2] = {0, 0};
  for (const auto& [positive, slide] : slides) {
    double t_sum = 0, sum[3] = {0, 0, 0}, var[3] = {0, 0, 0};
    for (size_t k = 0; k < slide.image.size(); ++k) {
      const ImageF& im = slide.image[k];
      bool clipped = false;
      for (const auto& [x, y] : disc)
        for (int c = 0; c < 3; ++c) clipped = clipped || im.at(x, y, c) >= sensor.saturation;
      if (clipped) continue;
      const double t = slide.exposure[k];
      const double d = dark ? dark->at(x0, y0, 0) + dark->at(x0, y0, 1) * t : 0.0;
      t_sum += t;
      for (int c = 0; c < 3; ++c) {
        const double s = im.at(x0, y0, c);
        sum[c] += s - d;
        var[c] += sensor.Variance(s);
      }
    }
    if (t_sum == 0) return 0;  // calibrate scale refuses it
    const int k = positive ? 0 : 1;
    for (int c = 0; c < 3; ++c) {
      value[k] += luminance[c] * sum[c] / t_sum / g;
      variance[k] += luminance[c] * luminance[c] * fit[c] * var[c] / (t_sum * t_sum * g * g);
    }
  }
  const double difference = value[0] - value[1];
  return (variance[0] + variance[1]) / (difference * difference);
}

}  // namespace

// ---- JPEG coding (JpegSpectrumOf, JpegCodingModel) ----

namespace {

// The orthonormal 8-point DCT-II: coefficient u of samples x is sum_x kDct[u][x] x.
const std::array<std::array<double, 8>, 8>& Dct8() {
  static const auto table = [] {
    std::array<std::array<double, 8>, 8> t{};
    for (int u = 0; u < 8; ++u)
      for (int x = 0; x < 8; ++x)
        t[u][x] = (u == 0 ? std::sqrt(0.125) : 0.5) * std::cos((2 * x + 1) * u * M_PI / 16);
    return t;
  }();
  return table;
}

// libjpeg's default quantisation tables (ITU-T T.81 Annex K, natural order), scaled for a
// quality as jpeg_set_quality does (jcparam.c: 5000 / q below 50, 200 - 2q above; entries
// (base x scale + 50) / 100 in [1, 255]).
std::array<int, 64> QuantTable(int quality, bool chroma) {
  static const int kLuma[64] = {16,  11,  10,  16,  24, 40, 51,  61,  12,  12,  14,  19,  26,
                                58,  60,  55,  14,  13, 16, 24,  40,  57,  69,  56,  14,  17,
                                22,  29,  51,  87,  80, 62, 18,  22,  37,  56,  68,  109, 103,
                                77,  24,  35,  55,  64, 81, 104, 113, 92,  49,  64,  78,  87,
                                103, 121, 120, 101, 72, 92, 95,  98,  112, 100, 103, 99};
  static const int kChroma[64] = {17, 18, 24, 47, 99, 99, 99, 99, 18, 21, 26, 66, 99, 99, 99, 99,
                                  24, 26, 56, 99, 99, 99, 99, 99, 47, 66, 99, 99, 99, 99, 99, 99,
                                  99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99,
                                  99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99};
  quality = std::clamp(quality, 1, 100);
  const long scale = quality < 50 ? 5000 / quality : 200 - 2 * quality;
  std::array<int, 64> q{};
  for (int i = 0; i < 64; ++i)
    q[i] = int(std::clamp((long(chroma ? kChroma[i] : kLuma[i]) * scale + 50) / 100, 1L, 255L));
  return q;
}

// E[(Q(s + n) - s)^2], E[(Q(s + n) - s) n] / sigma^2 and E[Q(s + n) - s] for n ~ N(0, sigma^2) and
// Q rounding to multiples of q: summed over the bins within 9 sigma of s.
void QuantisedMoments(double s, double sigma, double q, double* e2, double* beta, double* bias) {
  if (sigma < 1e-9 * q) {
    const double d = q * std::round(s / q) - s;
    *e2 = d * d, *beta = 0, *bias = d;
    return;
  }
  if (sigma > 50 * q) {  // dithered: the rounding adds q^2 / 12, uncorrelated with n
    *e2 = sigma * sigma + q * q / 12, *beta = 1, *bias = 0;
    return;
  }
  const auto pdf = [](double z) { return std::exp(-0.5 * z * z) / std::sqrt(2 * M_PI); };
  const auto cdf = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  const long j0 = std::lround(std::floor((s - 9 * sigma) / q));
  const long j1 = std::lround(std::ceil((s + 9 * sigma) / q));
  double sum2 = 0, sum_n = 0, sum1 = 0;
  for (long j = j0; j <= j1; ++j) {
    const double lo = (q * (j - 0.5) - s) / sigma, hi = (q * (j + 0.5) - s) / sigma;
    const double d = q * j - s;
    sum2 += (cdf(hi) - cdf(lo)) * d * d;
    sum1 += (cdf(hi) - cdf(lo)) * d;
    sum_n += d * sigma * (pdf(lo) - pdf(hi));  // E[d n; bin j]
  }
  *e2 = sum2, *beta = sum_n / (sigma * sigma), *bias = sum1;
}

// JFIF's RGB -> YCbCr matrix A and its inverse M (libjpeg's jccolor.c / jdcolor.c).
constexpr double kA[3][3] = {
    {0.299, 0.587, 0.114}, {-0.168735892, -0.331264108, 0.5}, {0.5, -0.418687589, -0.081312411}};
constexpr double kM[3][3] = {{1, 0, 1.402}, {1, -0.344136286, -0.714136286}, {1, 1.772, 0}};

// libjpeg's h2v2 fancy upsampling in one dimension: full-resolution sample x takes 3/4 of chroma
// sample x / 2 and 1/4 of its neighbour on x's side.
void UpsampleTaps(int x, int taps[2], double weights[2]) {
  const int j = x >> 1;  // floor for negatives too
  taps[0] = j, weights[0] = 0.75;
  taps[1] = (x & 1) ? j + 1 : j - 1, weights[1] = 0.25;
}

// Sum over 8 x 8 blocks (origin at multiples of 8 plus (ax, ay)) of <w, B_uv>^2, into k, and
// the square of the sum of <w, B_uv>, into coherent.
void AddBlockSpectrum(const PixelWeights& w, int ax, int ay, double scale,
                      std::array<double, 64>& k, std::array<double, 64>& coherent) {
  std::array<double, 64> sum{};
  std::map<std::pair<int, int>, std::array<double, 64>> blocks;  // block -> its samples
  for (const auto& [p, v] : w) {
    const int bx = (p.first - ax) >= 0 ? (p.first - ax) / 8 : -((7 - (p.first - ax)) / 8);
    const int by = (p.second - ay) >= 0 ? (p.second - ay) / 8 : -((7 - (p.second - ay)) / 8);
    auto& b = blocks[{bx, by}];
    b[(p.second - ay - 8 * by) * 8 + (p.first - ax - 8 * bx)] += v;
  }
  const auto& dct = Dct8();
  for (const auto& [key, b] : blocks)
    for (int v = 0; v < 8; ++v)
      for (int u = 0; u < 8; ++u) {
        double c = 0;
        for (int y = 0; y < 8; ++y)
          for (int x = 0; x < 8; ++x) c += dct[v][y] * dct[u][x] * b[y * 8 + x];
        k[v * 8 + u] += scale * c * c;
        sum[v * 8 + u] += c;
      }
  for (int i = 0; i < 64; ++i) coherent[i] += scale * sum[i] * sum[i];
}

}  // namespace

JpegSpectrum JpegSpectrumOf(const std::vector<PixelWeights>& patterns) {
  JpegSpectrum out;
  const double n = double(patterns.size());
  for (const PixelWeights& w : patterns) {
    for (const auto& [p, v] : w) out.luma_sum += v * v / n;
    for (int ay = 0; ay < 8; ++ay)
      for (int ax = 0; ax < 8; ++ax)
        AddBlockSpectrum(w, ax, ay, 1 / (64 * n), out.luma, out.luma_coherent);
    // The chroma plane, for both parities of the pattern against the chroma samples.
    for (int py = 0; py < 2; ++py)
      for (int px = 0; px < 2; ++px) {
        PixelWeights wc;
        for (const auto& [p, v] : w) {
          int tx[2], ty[2];
          double gx[2], gy[2];
          UpsampleTaps(p.first + px, tx, gx);
          UpsampleTaps(p.second + py, ty, gy);
          for (int b = 0; b < 2; ++b)
            for (int a = 0; a < 2; ++a) wc[{tx[a], ty[b]}] += v * gx[a] * gy[b];
        }
        for (const auto& [p, v] : wc) out.chroma_sum += v * v / (4 * n);
        for (int ay = 0; ay < 8; ++ay)
          for (int ax = 0; ax < 8; ++ax)
            AddBlockSpectrum(wc, ax, ay, 1 / (256 * n), out.chroma, out.chroma_coherent);
      }
  }
  return out;
}

JpegCodingModel::JpegCodingModel(const ImageF& codes, const ImageF& variance, int quality) {
  const int w = codes.width, h = codes.height;
  luma_w_ = (w + 7) / 8, chroma_w_ = (w + 15) / 16;
  const int luma_h = (h + 7) / 8, chroma_h = (h + 15) / 16;
  const std::array<int, 64> q_luma = QuantTable(quality, false),
                            q_chroma = QuantTable(quality, true);
  const auto& dct = Dct8();
  // A component's plane (at full or half resolution, edges replicated as libjpeg pads them):
  // the clean value and the RGB-correlated noise variance per sample.
  auto clamp_x = [&](int x) { return std::clamp(x, 0, w - 1); };
  auto clamp_y = [&](int y) { return std::clamp(y, 0, h - 1); };
  // Y, Cb or Cr of the clean codes at a pixel, and the variance of the RGB noise in it.
  auto component = [&](int c, int x, int y, double* value, double* var) {
    x = clamp_x(x), y = clamp_y(y);
    *value = 0, *var = 0;
    for (int j = 0; j < 3; ++j) {
      *value += kA[c][j] * codes.at(x, y, j);
      *var += kA[c][j] * kA[c][j] * variance.at(x, y, j);
    }
    if (c > 0) *value += 128;
  };
  // One block: the noise-free coefficients s, the correlated noise's variance per coefficient
  // (the block's mean, white), the independent roundings' variance; then E and beta.
  auto code_block = [&](const double* samples, double corr_var, double own_var,
                        const std::array<int, 64>& q, Block& out) {
    for (int v = 0; v < 8; ++v)
      for (int u = 0; u < 8; ++u) {
        double s = 0;
        for (int y = 0; y < 8; ++y)
          for (int x = 0; x < 8; ++x) s += dct[v][y] * dct[u][x] * (samples[y * 8 + x] - 128);
        double e2, beta, bias;
        const double sigma2 = corr_var + own_var;
        QuantisedMoments(s, std::sqrt(sigma2), q[v * 8 + u], &e2, &beta, &bias);
        out.beta[v * 8 + u] = float(beta);
        out.bias2[v * 8 + u] = float(bias * bias);
        out.d[v * 8 + u] = float(std::max(0.0, e2 - bias * bias - beta * beta * corr_var));
      }
  };
  y_.resize(size_t(luma_w_) * luma_h), rgb_var_.resize(y_.size());
  for (int by = 0; by < luma_h; ++by)
    for (int bx = 0; bx < luma_w_; ++bx) {
      double samples[64], corr = 0;
      std::array<double, 3> rgb{};
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          double var;
          component(0, 8 * bx + x, 8 * by + y, &samples[y * 8 + x], &var);
          corr += var / 64;
          for (int j = 0; j < 3; ++j)
            rgb[j] += variance.at(clamp_x(8 * bx + x), clamp_y(8 * by + y), j) / 64;
        }
      // The encoder rounds Y to an integer: 1/12, independent.
      code_block(samples, corr, 1.0 / 12, q_luma, y_[size_t(by) * luma_w_ + bx]);
      rgb_var_[size_t(by) * luma_w_ + bx] = {float(rgb[0]), float(rgb[1]), float(rgb[2])};
    }
  // 4:2:0 on the noise-free chroma: the 2 x 2 means, upsampled by libjpeg's triangle filter
  // (edge samples replicated), less the chroma; its DCT in each luma block.
  const int cw = (w + 1) / 2, chh = (h + 1) / 2;
  for (int c = 1; c <= 2; ++c) {
    std::vector<double> full(size_t(w) * h), half(size_t(cw) * chh, 0.0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        double value, var;
        component(c, x, y, &value, &var);
        full[size_t(y) * w + x] = value;
      }
    for (int j = 0; j < chh; ++j)
      for (int i = 0; i < cw; ++i)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx)
            half[size_t(j) * cw + i] +=
                full[size_t(clamp_y(2 * j + dy)) * w + clamp_x(2 * i + dx)] / 4;
    std::vector<double> error(size_t(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int tx[2], ty[2];
        double gx[2], gy[2], up = 0;
        UpsampleTaps(x, tx, gx);
        UpsampleTaps(y, ty, gy);
        for (int b = 0; b < 2; ++b)
          for (int a = 0; a < 2; ++a)
            up += gx[a] * gy[b] *
                  half[size_t(std::clamp(ty[b], 0, chh - 1)) * cw + std::clamp(tx[a], 0, cw - 1)];
        error[size_t(y) * w + x] = up - full[size_t(y) * w + x];
      }
    std::vector<std::array<float, 64>>& sub = subsampled_[c - 1];
    sub.resize(y_.size());
    for (int by = 0; by < luma_h; ++by)
      for (int bx = 0; bx < luma_w_; ++bx)
        for (int v = 0; v < 8; ++v)
          for (int u = 0; u < 8; ++u) {
            double e = 0;
            for (int y = 0; y < 8; ++y)
              for (int x = 0; x < 8; ++x)
                e += dct[v][y] * dct[u][x] *
                     error[size_t(clamp_y(8 * by + y)) * w + clamp_x(8 * bx + x)];
            sub[size_t(by) * luma_w_ + bx][v * 8 + u] = float(e * e);
          }
  }
  for (int c = 1; c <= 2; ++c) {
    std::vector<Block>& plane = c == 1 ? cb_ : cr_;
    plane.resize(size_t(chroma_w_) * chroma_h);
    for (int by = 0; by < chroma_h; ++by)
      for (int bx = 0; bx < chroma_w_; ++bx) {
        double samples[64], corr = 0;
        for (int y = 0; y < 8; ++y)
          for (int x = 0; x < 8; ++x) {
            // libjpeg's h2v2 downsampling: the mean of 2 x 2 pixels.
            double sum = 0, var = 0;
            for (int dy = 0; dy < 2; ++dy)
              for (int dx = 0; dx < 2; ++dx) {
                double value, v;
                component(c, 16 * bx + 2 * x + dx, 16 * by + 2 * y + dy, &value, &v);
                sum += value / 4, var += v / 16;
              }
            samples[y * 8 + x] = sum;
            corr += var / 64;
          }
        // The encoder's rounding of Cb, Cr (1/12 per pixel, averaged over 4) and of their mean
        // (in quarters of a code with libjpeg's alternating bias 1, 2: 3/32).
        code_block(samples, corr, 1.0 / 48 + 3.0 / 32, q_chroma,
                   plane[size_t(by) * chroma_w_ + bx]);
      }
  }
}

std::array<double, 3> JpegCodingModel::WhiteEquivalentVariance(int x, int y,
                                                               const JpegSpectrum& k) const {
  const Block& luma = y_[size_t(y / 8) * luma_w_ + x / 8];
  const Block* chroma[2] = {&cb_[size_t(y / 16) * chroma_w_ + x / 16],
                            &cr_[size_t(y / 16) * chroma_w_ + x / 16]};
  const std::array<float, 3>& sigma2 = rgb_var_[size_t(y / 8) * luma_w_ + x / 8];
  std::array<double, 3> out{};
  for (int ch = 0; ch < 3; ++ch) {
    double noise = 0, independent = 0;
    for (int v = 0; v < 8; ++v)
      for (int u = 0; u < 8; ++u) {
        const int i = v * 8 + u;
        // beta per component at this spatial frequency: chroma's coefficient (2u, 2v), none
        // above the chroma plane's Nyquist frequency.
        double beta[3] = {luma.beta[i], 0, 0};
        if (u < 4 && v < 4)
          for (int c = 1; c <= 2; ++c) beta[c] = chroma[c - 1]->beta[(2 * v) * 8 + 2 * u];
        for (int j = 0; j < 3; ++j) {
          double gain = 0;
          for (int c = 0; c < 3; ++c) gain += kM[ch][c] * beta[c] * kA[c][j];
          noise += k.luma[i] * sigma2[j] * gain * gain;
        }
        independent += k.luma[i] * luma.d[i] + k.luma_coherent[i] * luma.bias2[i];
        for (int c = 1; c <= 2; ++c)
          independent +=
              kM[ch][c] * kM[ch][c] *
              (k.chroma[i] * chroma[c - 1]->d[i] + k.chroma_coherent[i] * chroma[c - 1]->bias2[i] +
               k.luma_coherent[i] * subsampled_[c - 1][size_t(y / 8) * luma_w_ + x / 8][i]);
      }
    // The decoder rounds Y, Cb, Cr after its inverse DCT (chroma: in the chroma plane) and the
    // chroma again after upsampling: 1/12 each.
    independent += k.luma_sum / 12;
    for (int c = 1; c <= 2; ++c)
      independent += kM[ch][c] * kM[ch][c] * (k.chroma_sum + k.luma_sum) / 12;
    out[ch] = (noise + independent) / k.luma_sum;
  }
  return out;
}

NoiseFloor PredictNoiseFloor(const std::string& slab_dir, const std::string& clean,
                             const std::string& screen_json, const std::string& truth_dir,
                             const SensorNoiseModel& sensor, const ChainNoiseModel& chain) {
  const Dataset ds = Dataset::Load(clean);
  const ScreenCalibration cal = ScreenCalibration::Load(screen_json);
  const SlabInfo truth_info = SlabInfo::Load(truth_dir);
  const SlabInfo info = SlabInfo::Load(slab_dir);
  const double a = 5.0 / 6, b = 1.0 / 12;
  const double gain_1d = a / std::pow(a * a - 4 * b * b, 1.5);
  const double deconv_gain = gain_1d * gain_1d;
  const double scale = *ds.radiometric_scale, peak = ds.filter.peak;
  const double texel_area = info.layout.TexelW() * info.layout.TexelH();
  ImageF gain, dark;
  if (!chain.gain_exr.empty()) gain = ReadExr(chain.gain_exr, {"Y"});
  if (!chain.dark_exr.empty()) dark = ReadExr(chain.dark_exr, {"black", "current", "hot"});
  const ImageF* gain_map = chain.gain_exr.empty() ? nullptr : &gain;
  const ImageF* dark_map = chain.dark_exr.empty() ? nullptr : &dark;
  auto read_position = [&](int i, int j) {
    std::map<bool, SlidePhotos> slides;
    for (const PhotoEntry& e : ds.PhotosOf(i, j)) {
      SlidePhotos& slide = slides[e.positive];
      slide.exposure.push_back(e.exposure);
      slide.image.push_back(ReadExr(clean + "/" + e.file, {"R", "G", "B"}));
      if (sensor.jpeg_quality > 0) {
        // The photo's expected codes and their noise in codes (one code: code_step).
        const ImageF& im = slide.image.back();
        ImageF codes(im.width, im.height, 3), variance(im.width, im.height, 3);
        for (size_t p = 0; p < im.data.size(); ++p) {
          const double sv = im.data[p], step = sensor.code_step(sv);
          codes.data[p] = float(std::clamp(sensor.code_of(sv), 0.0, 255.0));
          variance.data[p] = float(sensor.Variance(sv) / (step * step));
        }
        slide.jpeg.emplace_back(codes, variance, sensor.jpeg_quality);
      }
    }
    return slides;
  };
  NoiseFloor out;
  double scale_var = 0;
  if (chain.reference_radius_px > 0)
    scale_var = ScaleRelativeVariance(cal, read_position(chain.reference_i, chain.reference_j),
                                      gain_map, dark_map, sensor, chain);
  out.scale_relative = std::sqrt(scale_var);
  double var_sum = 0, ref2 = 0;
  for (const auto& [i, j] : info.present) {
    const SlabPosition truth = ReadSlabPosition(truth_dir, truth_info, i, j);
    const SlabPosition slab = ReadSlabPosition(slab_dir, info, i, j);
    const std::map<bool, SlidePhotos> slides = read_position(i, j);
    const int w = slides.begin()->second.image[0].width;
    const int h = slides.begin()->second.image[0].height;
    float max_ref = 0;
    for (float v : truth.irradiance.data) max_ref = std::max(max_ref, std::abs(v));
    const Eigen::Vector2d c = ds.grid.Centre(i, j);
    double position_var = 0, position_ref2 = 0;
    for (int row = 0; row < info.layout.res_y; ++row)
      for (int col = 0; col < info.layout.res_x; ++col) {
        const size_t k = size_t(row) * info.layout.res_x + col;
        float mag = 0;
        for (int ch = 0; ch < 3; ++ch)
          mag = std::max(mag, std::abs(truth.irradiance.data[k * 3 + ch]));
        if (mag < 0.01 * max_ref || slab.mask.data[k] < 0.5f) continue;
        const Eigen::Vector2d lab = info.layout.TexelCentre(col, row) - c;
        const Eigen::Vector2d px = cal.ImageFromScreen(lab);
        // Pixel footprint on the screen (mm^2) from the calibration's Jacobian.
        const Eigen::Vector2d dx = cal.ScreenFromImage(px + Eigen::Vector2d(0.5, 0)) -
                                   cal.ScreenFromImage(px - Eigen::Vector2d(0.5, 0));
        const Eigen::Vector2d dy = cal.ScreenFromImage(px + Eigen::Vector2d(0, 0.5)) -
                                   cal.ScreenFromImage(px - Eigen::Vector2d(0, 0.5));
        const double pixel_area = std::abs(dx.x() * dy.y() - dx.y() * dy.x());
        const double side = std::sqrt(texel_area / pixel_area);
        int x = std::clamp(int(std::lround(px.x())), 0, w - 1);
        int y = std::clamp(int(std::lround(px.y())), 0, h - 1);
        // A hot pixel reads as the mean of its nearest pixels that are not hot (lib/photo's
        // defect correction): the noise there is theirs, taken here as that of the nearest one.
        if (dark_map && dark.at(x, y, 2) > 0.5f) {
          int best = -1, bx = x, by = y;
          for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
              const int xx = x + dx, yy = y + dy, d2 = dx * dx + dy * dy;
              if (xx < 0 || yy < 0 || xx >= w || yy >= h || dark.at(xx, yy, 2) > 0.5f) continue;
              if (best < 0 || d2 < best) best = d2, bx = xx, by = yy;
            }
          x = bx, y = by;
        }
        const double g = gain_map ? gain.at(x, y, 0) : 1.0;
        // The flat's relative variance at this pixel: the mean of its frames.
        double flat_var = 0;
        if (chain.flat_frames > 0) {
          const double t = chain.flat_exposure;
          const double d = dark_map ? dark.at(x, y, 0) + dark.at(x, y, 1) * t : 0.0;
          const double u = chain.flat_level * g * t;
          flat_var = sensor.Variance(u + d) / (u * u) / chain.flat_frames;
        }
        for (int ch = 0; ch < 3; ++ch) {
          double var = 0;
          const JpegSpectrum* spectrum =
              sensor.jpeg_quality > 0 ? &TexelJpegSpectrum(side) : nullptr;
          for (const auto& [positive, slide] : slides)
            var += MergedVariance(slide, x, y, ch, sensor, spectrum);
          const double t = truth.irradiance.data[k * 3 + ch];
          const double averaged = TexelVarianceFactor(side, ch, sensor.bayer_rggb);
          const double v = (peak * peak * scale * scale * var / (g * g) + t * t * flat_var) *
                               averaged * deconv_gain +
                           t * t * scale_var;
          position_var += v;
          position_ref2 += t * t;
        }
      }
    out.positions.push_back({i, j, std::sqrt(position_var / position_ref2)});
    var_sum += position_var;
    ref2 += position_ref2;
  }
  out.overall = std::sqrt(var_sum / ref2);
  return out;
}

}  // namespace lumislab::testing
