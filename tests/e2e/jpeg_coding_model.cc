#include "jpeg_coding_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace lumislab::testing {

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

}  // namespace lumislab::testing
