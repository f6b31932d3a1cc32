#include "reconstruct/bell_fit.h"

#include <algorithm>
#include <cmath>

#include "core/basis.h"
#include "core/error.h"

namespace lumislab {

BellStencil BellStencil::FromBasis() {
  BellStencil s;
  s.w0 = BellIntegral(-0.5, 0.5);
  s.w1 = BellIntegral(0.5, 1.5);
  return s;
}

namespace {

// The masked operators on a width x height grid with interleaved channels.
class MaskedGrid {
 public:
  MaskedGrid(const std::vector<unsigned char>& seen, int width, int height, int channels)
      : seen_(seen), w_(width), h_(height), ch_(channels), s_(BellStencil::FromBasis()) {}

  bool Seen(int x, int y) const {
    return x >= 0 && y >= 0 && x < w_ && y < h_ && seen_[size_t(y) * w_ + x] != 0;
  }
  size_t Size() const { return size_t(w_) * h_ * ch_; }

  // out = the 1D box operator along x (dx = 1) or y (dy = 1); unseen neighbours mirror the texel.
  void Apply1D(const std::vector<double>& in, std::vector<double>& out, int dx, int dy) const {
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        const size_t k = (size_t(y) * w_ + x) * ch_;
        if (!Seen(x, y)) {
          for (int c = 0; c < ch_; ++c) out[k + c] = 0;
          continue;
        }
        const bool lo = Seen(x - dx, y - dy), hi = Seen(x + dx, y + dy);
        const size_t klo = lo ? k - (size_t(dy) * w_ + dx) * ch_ : k;
        const size_t khi = hi ? k + (size_t(dy) * w_ + dx) * ch_ : k;
        for (int c = 0; c < ch_; ++c)
          out[k + c] = s_.w0 * in[k + c] + s_.w1 * (in[klo + c] + in[khi + c]);
      }
  }
  // B c = Bx (By c); both factors are symmetric, so B^T v = By (Bx v).
  void ApplyB(const std::vector<double>& c, std::vector<double>& out) const {
    tmp_.resize(Size());
    Apply1D(c, tmp_, 0, 1);
    Apply1D(tmp_, out, 1, 0);
  }
  void ApplyBt(const std::vector<double>& v, std::vector<double>& out) const {
    tmp_.resize(Size());
    Apply1D(v, tmp_, 1, 0);
    Apply1D(tmp_, out, 0, 1);
  }
  // out = B^T B c + lambda D^T D c.
  void ApplyNormal(const std::vector<double>& coef, double lambda, std::vector<double>& out) const {
    tmp2_.resize(Size());
    ApplyB(coef, tmp2_);
    ApplyBt(tmp2_, out);
    if (lambda == 0) return;
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        if (!Seen(x, y)) continue;
        const size_t k = (size_t(y) * w_ + x) * ch_;
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int n = 0; n < 4; ++n) {
          if (!Seen(nx[n], ny[n])) continue;
          const size_t kn = (size_t(ny[n]) * w_ + nx[n]) * ch_;
          for (int c = 0; c < ch_; ++c) out[k + c] += lambda * (coef[k + c] - coef[kn + c]);
        }
      }
  }
  // Diagonal of B^T B + lambda D^T D per texel (the Jacobi preconditioner).
  std::vector<double> Diagonal(double lambda) const {
    std::vector<double> d(size_t(w_) * h_, 1.0);
    auto self = [&](int x, int y, int dx, int dy) {
      return s_.w0 + s_.w1 * ((Seen(x - dx, y - dy) ? 0 : 1) + (Seen(x + dx, y + dy) ? 0 : 1));
    };
    // Squared norm of the x-operator's column at (x, y).
    auto col_x = [&](int x, int y) {
      const double a = self(x, y, 1, 0);
      return a * a + s_.w1 * s_.w1 * ((Seen(x - 1, y) ? 1 : 0) + (Seen(x + 1, y) ? 1 : 0));
    };
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        if (!Seen(x, y)) continue;
        const double t = self(x, y, 0, 1);
        double sum = t * t * col_x(x, y);
        int neighbours = 0;
        for (int dy : {-1, 1})
          if (Seen(x, y + dy)) sum += s_.w1 * s_.w1 * col_x(x, y + dy);
        for (int n = 0; n < 4; ++n)
          neighbours += Seen(x + (n == 0) - (n == 1), y + (n == 2) - (n == 3)) ? 1 : 0;
        d[size_t(y) * w_ + x] = sum + lambda * neighbours;
      }
    return d;
  }
  int channels() const { return ch_; }

 private:
  const std::vector<unsigned char>& seen_;
  int w_, h_, ch_;
  BellStencil s_;
  mutable std::vector<double> tmp_, tmp2_;
};

}  // namespace

std::vector<double> ApplyBellBoxOperator(const std::vector<double>& coefficients,
                                         const std::vector<unsigned char>& seen, int width,
                                         int height, int channels) {
  const MaskedGrid grid(seen, width, height, channels);
  LUMISLAB_CHECK(coefficients.size() == grid.Size(), "ApplyBellBoxOperator: size mismatch");
  std::vector<double> out(grid.Size());
  grid.ApplyB(coefficients, out);
  return out;
}

std::vector<double> FitBell(const std::vector<double>& data, const std::vector<unsigned char>& seen,
                            int width, int height, int channels, const BellFitOptions& options,
                            BellFitReport* report) {
  const MaskedGrid grid(seen, width, height, channels);
  LUMISLAB_CHECK(data.size() == grid.Size() && seen.size() == size_t(width) * height,
                 "FitBell: data/mask size does not match the grid");
  LUMISLAB_CHECK(options.lambda >= 0 && std::isfinite(options.lambda), "FitBell: lambda >= 0");
  const size_t n = grid.Size();
  const int ch = channels;
  // Warm start c = b (the box average is within a few percent of the centre value).
  std::vector<double> x(n, 0.0);
  for (size_t k = 0; k < n; ++k)
    if (seen[k / ch]) x[k] = data[k];
  std::vector<double> rhs(n), r(n), z(n), p(n), ap(n);
  grid.ApplyBt(x, rhs);  // B^T b (x == b on seen texels here)
  grid.ApplyNormal(x, options.lambda, ap);
  for (size_t k = 0; k < n; ++k) r[k] = rhs[k] - ap[k];
  const std::vector<double> diag = grid.Diagonal(options.lambda);
  std::vector<double> inv_diag(diag.size());
  for (size_t t = 0; t < diag.size(); ++t) inv_diag[t] = diag[t] > 0 ? 1.0 / diag[t] : 0.0;

  auto dot = [&](const std::vector<double>& a, const std::vector<double>& b, int c) {
    double s = 0;
    for (size_t k = size_t(c); k < n; k += ch) s += a[k] * b[k];
    return s;
  };
  std::vector<double> rhs_norm(ch), rz(ch);
  for (size_t k = 0; k < n; ++k) z[k] = inv_diag[k / ch] * r[k];
  p = z;
  for (int c = 0; c < ch; ++c) {
    rhs_norm[c] = std::sqrt(dot(rhs, rhs, c));
    rz[c] = dot(r, z, c);
  }
  auto converged = [&](int c) {
    const double rn = std::sqrt(dot(r, r, c));
    return rhs_norm[c] == 0 || rn <= options.tolerance * rhs_norm[c];
  };
  int it = 0;
  std::vector<bool> done(ch);
  bool all_done = true;
  for (int c = 0; c < ch; ++c) all_done = (done[c] = converged(c)) && all_done;
  while (!all_done && it < options.max_iterations) {
    ++it;
    grid.ApplyNormal(p, options.lambda, ap);
    std::vector<double> alpha(ch, 0.0);
    for (int c = 0; c < ch; ++c) {
      const double pap = dot(p, ap, c);
      if (!done[c] && pap > 0) alpha[c] = rz[c] / pap;
    }
    for (size_t k = 0; k < n; ++k) {
      x[k] += alpha[k % ch] * p[k];
      r[k] -= alpha[k % ch] * ap[k];
      z[k] = inv_diag[k / ch] * r[k];
    }
    std::vector<double> beta(ch, 0.0);
    all_done = true;
    for (int c = 0; c < ch; ++c) {
      const double rz_new = dot(r, z, c);
      beta[c] = rz[c] > 0 ? rz_new / rz[c] : 0.0;
      rz[c] = rz_new;
      if (!done[c]) done[c] = converged(c);
      all_done = all_done && done[c];
    }
    for (size_t k = 0; k < n; ++k) p[k] = z[k] + beta[k % ch] * p[k];
  }
  double worst = 0;
  for (int c = 0; c < ch; ++c)
    if (rhs_norm[c] > 0) worst = std::max(worst, std::sqrt(dot(r, r, c)) / rhs_norm[c]);
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(x[k])) throw Failure("FitBell: non-finite coefficient (bad input data?)");
  if (report) {
    report->iterations = it;
    report->relative_residual = worst;
  }
  return x;
}

}  // namespace lumislab
