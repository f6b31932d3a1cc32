#include "calibrate/radiometric/response_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace lumislab {
namespace {

constexpr int kCodes = 256;

// g(z) = (1 - f) g[k] + f g[k + 1]: the knot below z and the fraction f.
void Knots(double z, int* k, double* f) {
  *k = std::min(int(z), kCodes - 2);
  *f = z - *k;
}

// The noise weight of an observation at knot k: a code error dz moves g by g'(z) dz.
double NoiseWeight(const Eigen::VectorXd* slope, int k) {
  if (!slope) return 1;
  const double s = (*slope)[k];
  return 1 / (s * s);
}

// |g'| per code segment (the last code: its segment's), floored at a tenth of its median so
// that a flat stretch of a poor fit cannot take all the weight.
Eigen::VectorXd Slopes(const Eigen::VectorXd& g) {
  Eigen::VectorXd slope(kCodes);
  for (int c = 0; c + 1 < kCodes; ++c) slope[c] = std::abs(g[c + 1] - g[c]);
  slope[kCodes - 1] = slope[kCodes - 2];
  std::vector<double> sorted(slope.data(), slope.data() + kCodes);
  std::nth_element(sorted.begin(), sorted.begin() + kCodes / 2, sorted.end());
  const double floor = std::max(0.1 * sorted[kCodes / 2], 1e-9);
  for (int c = 0; c < kCodes; ++c) slope[c] = std::max(slope[c], floor);
  return slope;
}

// One weighted least-squares solve: the normal equations of
//   sum_i sum_j w_ij (g(z_ij) - a_i - l_j)^2 + s sum_k (g[k-1] - 2 g[k] + g[k+1])^2
// with each a_i (ln E_i) eliminated: a_i = sum_j w_ij (g(z_ij) - l_j) / sum_j w_ij, so sample i
// adds B^T (D - w w^T / W) (B g - l) with D = diag(w), W = sum w, B the interpolation rows.
Eigen::VectorXd Solve(const std::vector<float>& codes, int frames,
                      const std::vector<double>& log_exposure, double smoothness,
                      const Eigen::VectorXd* slope, size_t* used) {
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(kCodes, kCodes);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(kCodes);
  const size_t samples = codes.size() / size_t(frames);
  std::vector<int> k(frames);
  std::vector<double> f(frames), w(frames), l(frames);
  double total_weight = 0;
  size_t n_used = 0;
  for (size_t i = 0; i < samples; ++i) {
    int m = 0;
    double sum_w = 0;
    for (int j = 0; j < frames; ++j) {
      const float z = codes[i * frames + j];
      if (z < 0) continue;
      Knots(z, &k[m], &f[m]);
      const double weight = NoiseWeight(slope, k[m]);
      w[m] = weight, l[m] = log_exposure[j], sum_w += weight, ++m;
    }
    if (m < 2) continue;
    ++n_used;
    total_weight += sum_w;
    // M = D - w w^T / W, applied through the two knots of each observation.
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < m; ++b) {
        const double mab = (a == b ? w[a] : 0) - w[a] * w[b] / sum_w;
        const double ca[2] = {1 - f[a], f[a]}, cb[2] = {1 - f[b], f[b]};
        for (int p = 0; p < 2; ++p) {
          for (int q = 0; q < 2; ++q) normal(k[a] + p, k[b] + q) += ca[p] * mab * cb[q];
          rhs[k[a] + p] += ca[p] * mab * l[b];
        }
      }
  }
  if (used) *used = n_used;
  // The smoothness term, relative to one code's share of the data weight: the second
  // derivative of g with respect to u = ln(z + 1), whose squared second differences at
  // non-uniform spacing are scaled to (1, -2, 1) at code 128. A camera curve is close to a
  // power law, a straight line in (u, g): the term then bends the curve least where it is
  // steepest (the dark codes, where a penalty in z pulled g 15 % off at code 32) and smooths
  // JPEG's quantisation wiggles where the data are dense.
  const double s = smoothness * total_weight / kCodes;
  const double h_ref = std::log(129.0 / 128.0);
  for (int c = 1; c + 1 < kCodes; ++c) {
    const int idx[3] = {c - 1, c, c + 1};
    const double h1 = std::log(double(c + 1) / c), h2 = std::log(double(c + 2) / (c + 1));
    const double coef[3] = {h_ref / h1, -h_ref / h1 - h_ref / h2, h_ref / h2};
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) normal(idx[p], idx[q]) += s * coef[p] * coef[q];
  }
  // The gauge (the data fix g only up to a constant): g[255] = 0; the penalty is met exactly
  // because no other term changes under a constant shift.
  normal(kCodes - 1, kCodes - 1) += total_weight + 1;
  return normal.ldlt().solve(rhs);
}

}  // namespace

std::array<double, 256> FitLogInverseResponse(const std::vector<float>& codes, int frames,
                                              const std::vector<double>& log_exposure,
                                              double smoothness, size_t* used) {
  LUMISLAB_CHECK(
      frames >= 2 && int(log_exposure.size()) == frames && codes.size() % size_t(frames) == 0,
      "FitLogInverseResponse: codes of `frames` frames");
  Eigen::VectorXd g = Solve(codes, frames, log_exposure, smoothness, nullptr, used);
  // Two more passes with the noise weights of the previous pass's slope.
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::VectorXd slope = Slopes(g);
    g = Solve(codes, frames, log_exposure, smoothness, &slope, used);
  }
  std::array<double, 256> out;
  for (int c = 0; c < kCodes; ++c) out[c] = g[c] - g[kCodes - 1];
  return out;
}

ResidualBins ResidualsByCode(const std::vector<float>& codes, int frames,
                             const std::vector<double>& log_exposure,
                             const std::array<double, 256>& g, int bin_width) {
  const Eigen::VectorXd g_vec = Eigen::Map<const Eigen::VectorXd>(g.data(), kCodes);
  const Eigen::VectorXd slope = Slopes(g_vec);
  const int bins = (kCodes + bin_width - 1) / bin_width;
  ResidualBins out{std::vector<double>(bins, 0.0), std::vector<size_t>(bins, 0)};
  std::vector<double> weight_sum(bins, 0.0);
  const size_t samples = codes.size() / size_t(frames);
  std::vector<double> value(frames), weight(frames);
  for (size_t i = 0; i < samples; ++i) {
    double sum = 0, sum_w = 0;
    int m = 0;
    for (int j = 0; j < frames; ++j) {
      const float z = codes[i * frames + j];
      weight[j] = 0;
      if (z < 0) continue;
      int k;
      double f;
      Knots(z, &k, &f);
      value[j] = (1 - f) * g[k] + f * g[k + 1] - log_exposure[j];
      weight[j] = NoiseWeight(&slope, k);
      sum += weight[j] * value[j], sum_w += weight[j], ++m;
    }
    if (m < 2) continue;
    const double log_e = sum / sum_w;
    for (int j = 0; j < frames; ++j) {
      if (weight[j] == 0) continue;
      const int b = std::min(int(codes[i * frames + j]) / bin_width, bins - 1);
      out.mean[b] += weight[j] * (value[j] - log_e), weight_sum[b] += weight[j], ++out.count[b];
    }
  }
  for (int b = 0; b < bins; ++b)
    if (weight_sum[b] > 0) out.mean[b] /= weight_sum[b];
  return out;
}

}  // namespace lumislab
