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

// The masked operators on a width x height grid, CH interleaved channels. Only seen texels are
// touched; every neighbour index of a seen texel points to the texel itself when that neighbour
// is unseen or outside (the Neumann mirror), so the loops are branch-free gathers. Unseen
// entries of every vector stay 0.
// Buffers reused across fits on one thread: fresh multi-megabyte vectors per position cost more
// in page faults than the solve itself.
struct Workspace {
  std::vector<int> active, xlo, xhi, ylo, yhi;
  std::vector<double> tmp, tmp2, x, b, rhs, r, z, p, ap, inv_diag;
};
Workspace& ThreadWorkspace() {
  thread_local Workspace ws;
  return ws;
}

template <int CH>
class MaskedGrid {
 public:
  MaskedGrid(const std::vector<unsigned char>& seen, int width, int height)
      : n_(size_t(width) * height),
        s_(BellStencil::FromBasis()),
        ws_(ThreadWorkspace()),
        active_(ws_.active),
        xlo_(ws_.xlo),
        xhi_(ws_.xhi),
        ylo_(ws_.ylo),
        yhi_(ws_.yhi),
        tmp_(ws_.tmp),
        tmp2_(ws_.tmp2) {
    for (auto* v : {&active_, &xlo_, &xhi_, &ylo_, &yhi_}) v->clear();
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const int k = y * width + x;
        if (!seen[k]) continue;
        auto nb = [&](int nx, int ny) {
          const bool ok =
              nx >= 0 && ny >= 0 && nx < width && ny < height && seen[size_t(ny) * width + nx] != 0;
          return ok ? ny * width + nx : k;
        };
        active_.push_back(k);
        xlo_.push_back(nb(x - 1, y));
        xhi_.push_back(nb(x + 1, y));
        ylo_.push_back(nb(x, y - 1));
        yhi_.push_back(nb(x, y + 1));
      }
    tmp_.assign(n_ * CH, 0.0);
    tmp2_.assign(n_ * CH, 0.0);
  }
  size_t Size() const { return n_ * CH; }
  const std::vector<int>& active() const { return active_; }

  // out = 1D box operator with neighbours lo/hi.
  void Apply1D(const double* in, double* out, const std::vector<int>& lo,
               const std::vector<int>& hi) const {
    const double w0 = s_.w0, w1 = s_.w1;
    for (size_t a = 0; a < active_.size(); ++a) {
      const size_t k = size_t(active_[a]) * CH, l = size_t(lo[a]) * CH, h = size_t(hi[a]) * CH;
      for (int c = 0; c < CH; ++c) out[k + c] = w0 * in[k + c] + w1 * (in[l + c] + in[h + c]);
    }
  }
  // B c = Bx (By c); both factors are symmetric, so B^T v = By (Bx v).
  void ApplyB(const std::vector<double>& c, std::vector<double>& out) const {
    Apply1D(c.data(), tmp_.data(), ylo_, yhi_);
    Apply1D(tmp_.data(), out.data(), xlo_, xhi_);
  }
  void ApplyBt(const std::vector<double>& v, std::vector<double>& out) const {
    Apply1D(v.data(), tmp_.data(), xlo_, xhi_);
    Apply1D(tmp_.data(), out.data(), ylo_, yhi_);
  }
  // out = B^T B c + lambda D^T D c. With mirrored neighbours, (D^T D c)_k = 4 c_k - sum of the
  // four neighbour entries (a mirrored neighbour contributes c_k - c_k = 0).
  void ApplyNormal(const std::vector<double>& coef, double lambda, std::vector<double>& out) const {
    ApplyB(coef, tmp2_);
    Apply1D(tmp2_.data(), tmp_.data(), xlo_, xhi_);
    const double w0 = s_.w0, w1 = s_.w1;
    const double* in = tmp_.data();
    const double* cf = coef.data();
    for (size_t a = 0; a < active_.size(); ++a) {
      const size_t k = size_t(active_[a]) * CH;
      const size_t yl = size_t(ylo_[a]) * CH, yh = size_t(yhi_[a]) * CH;
      const size_t xl = size_t(xlo_[a]) * CH, xh = size_t(xhi_[a]) * CH;
      for (int c = 0; c < CH; ++c)
        out[k + c] = w0 * in[k + c] + w1 * (in[yl + c] + in[yh + c]) +
                     lambda * (4 * cf[k + c] - cf[xl + c] - cf[xh + c] - cf[yl + c] - cf[yh + c]);
    }
  }
  // Diagonal of B^T B + lambda D^T D per active texel (the Jacobi preconditioner): the squared
  // norm of column k of B (By spreads e_k vertically, Bx each of those horizontally).
  std::vector<double> Diagonal(double lambda) const {
    std::vector<double> d(active_.size());
    std::vector<int> slot(n_, -1);
    for (size_t a = 0; a < active_.size(); ++a) slot[active_[a]] = int(a);
    const double w0 = s_.w0, w1 = s_.w1;
    auto self = [&](size_t a, const std::vector<int>& lo, const std::vector<int>& hi) {
      const int k = active_[a];
      return w0 + w1 * ((lo[a] == k ? 1 : 0) + (hi[a] == k ? 1 : 0));
    };
    auto col_x = [&](size_t a) {
      const int k = active_[a];
      const double t = self(a, xlo_, xhi_);
      return t * t + w1 * w1 * ((xlo_[a] != k ? 1 : 0) + (xhi_[a] != k ? 1 : 0));
    };
    for (size_t a = 0; a < active_.size(); ++a) {
      const int k = active_[a];
      const double t = self(a, ylo_, yhi_);
      double sum = t * t * col_x(a);
      int neighbours = 0;
      for (int nb : {ylo_[a], yhi_[a]})
        if (nb != k) sum += w1 * w1 * col_x(size_t(slot[nb]));
      for (int nb : {xlo_[a], xhi_[a], ylo_[a], yhi_[a]}) neighbours += nb != k ? 1 : 0;
      d[a] = sum + lambda * neighbours;
    }
    return d;
  }

 private:
  size_t n_;
  BellStencil s_;
  Workspace& ws_;
  std::vector<int>&active_, &xlo_, &xhi_, &ylo_, &yhi_;
  std::vector<double>&tmp_, &tmp2_;
};

// Sets ws.b to the data on the seen texels, ws.rhs = B^T b, and the starting point ws.x: the
// data improved by one Neumann step B^-1 ~ 2I - B (B is within [0.44, 1] of I): c0 = 2b - Bb,
// whose error (I - B)^2 c is tiny for smooth fields. The other vectors are zeroed.
template <int CH>
void WarmStart(const MaskedGrid<CH>& grid, const std::vector<double>& data, Workspace& ws) {
  const std::vector<int>& act = grid.active();
  for (auto* v : {&ws.x, &ws.b, &ws.rhs, &ws.r, &ws.z, &ws.p, &ws.ap}) v->assign(grid.Size(), 0.0);
  for (int k : act)
    for (int c = 0; c < CH; ++c) ws.b[size_t(k) * CH + c] = data[size_t(k) * CH + c];
  grid.ApplyB(ws.b, ws.ap);
  for (int k : act)
    for (int c = 0; c < CH; ++c) {
      const size_t i = size_t(k) * CH + c;
      ws.x[i] = 2 * ws.b[i] - ws.ap[i];
    }
  grid.ApplyBt(ws.b, ws.rhs);
}

template <int CH>
std::vector<double> Solve(const std::vector<double>& data, const std::vector<unsigned char>& seen,
                          int width, int height, const BellFitOptions& options,
                          BellFitReport* report) {
  const MaskedGrid<CH> grid(seen, width, height);
  const std::vector<int>& act = grid.active();
  Workspace& ws = ThreadWorkspace();
  WarmStart(grid, data, ws);
  std::vector<double>&x = ws.x, &rhs = ws.rhs, &r = ws.r, &z = ws.z, &p = ws.p, &ap = ws.ap,
  &inv_diag = ws.inv_diag;
  grid.ApplyNormal(x, options.lambda, ap);
  const std::vector<double> diag = grid.Diagonal(options.lambda);
  inv_diag.resize(diag.size());
  for (size_t a = 0; a < diag.size(); ++a) inv_diag[a] = diag[a] > 0 ? 1.0 / diag[a] : 0.0;
  double rhs_norm[CH] = {}, rz[CH] = {}, rr[CH] = {};
  for (size_t a = 0; a < act.size(); ++a) {
    const size_t k = size_t(act[a]) * CH;
    for (int c = 0; c < CH; ++c) {
      r[k + c] = rhs[k + c] - ap[k + c];
      z[k + c] = inv_diag[a] * r[k + c];
      p[k + c] = z[k + c];
      rhs_norm[c] += rhs[k + c] * rhs[k + c];
      rz[c] += r[k + c] * z[k + c];
      rr[c] += r[k + c] * r[k + c];
    }
  }
  bool done[CH];
  bool all_done = true;
  for (int c = 0; c < CH; ++c) {
    rhs_norm[c] = std::sqrt(rhs_norm[c]);
    done[c] = rhs_norm[c] == 0 || std::sqrt(rr[c]) <= options.tolerance * rhs_norm[c];
    all_done = all_done && done[c];
  }
  int it = 0;
  while (!all_done && it < options.max_iterations) {
    ++it;
    grid.ApplyNormal(p, options.lambda, ap);
    double pap[CH] = {}, alpha[CH] = {};
    for (int k : act)
      for (int c = 0; c < CH; ++c) pap[c] += p[size_t(k) * CH + c] * ap[size_t(k) * CH + c];
    for (int c = 0; c < CH; ++c) alpha[c] = (!done[c] && pap[c] > 0) ? rz[c] / pap[c] : 0.0;
    double rz_new[CH] = {};
    for (int c = 0; c < CH; ++c) rr[c] = 0;
    for (size_t a = 0; a < act.size(); ++a) {
      const size_t k = size_t(act[a]) * CH;
      for (int c = 0; c < CH; ++c) {
        x[k + c] += alpha[c] * p[k + c];
        r[k + c] -= alpha[c] * ap[k + c];
        z[k + c] = inv_diag[a] * r[k + c];
        rz_new[c] += r[k + c] * z[k + c];
        rr[c] += r[k + c] * r[k + c];
      }
    }
    double beta[CH] = {};
    all_done = true;
    for (int c = 0; c < CH; ++c) {
      beta[c] = rz[c] > 0 ? rz_new[c] / rz[c] : 0.0;
      rz[c] = rz_new[c];
      if (!done[c]) done[c] = std::sqrt(rr[c]) <= options.tolerance * rhs_norm[c];
      all_done = all_done && done[c];
    }
    for (int k : act)
      for (int c = 0; c < CH; ++c)
        p[size_t(k) * CH + c] = z[size_t(k) * CH + c] + beta[c] * p[size_t(k) * CH + c];
  }
  double worst = 0;
  for (int c = 0; c < CH; ++c)
    if (rhs_norm[c] > 0) worst = std::max(worst, std::sqrt(rr[c]) / rhs_norm[c]);
  for (double v : x)
    if (!std::isfinite(v)) throw Failure("FitBell: non-finite coefficient (bad input data?)");
  if (report) {
    report->iterations = it;
    report->relative_residual = worst;
  }
  return x;
}

}  // namespace

std::vector<double> ApplyBellBoxOperator(const std::vector<double>& coefficients,
                                         const std::vector<unsigned char>& seen, int width,
                                         int height, int channels) {
  LUMISLAB_CHECK(channels >= 1 && channels <= 4, "ApplyBellBoxOperator: 1..4 channels");
  LUMISLAB_CHECK(coefficients.size() == size_t(width) * height * channels &&
                     seen.size() == size_t(width) * height,
                 "ApplyBellBoxOperator: size mismatch");
  std::vector<double> out(coefficients.size(), 0.0);
  auto run = [&](auto grid) { grid.ApplyB(coefficients, out); };
  switch (channels) {
    case 1:
      run(MaskedGrid<1>(seen, width, height));
      break;
    case 2:
      run(MaskedGrid<2>(seen, width, height));
      break;
    case 3:
      run(MaskedGrid<3>(seen, width, height));
      break;
    default:
      run(MaskedGrid<4>(seen, width, height));
      break;
  }
  return out;
}

std::vector<double> FitBell(const std::vector<double>& data, const std::vector<unsigned char>& seen,
                            int width, int height, int channels, const BellFitOptions& options,
                            BellFitReport* report) {
  LUMISLAB_CHECK(channels >= 1 && channels <= 4, "FitBell: 1..4 channels");
  LUMISLAB_CHECK(
      data.size() == size_t(width) * height * channels && seen.size() == size_t(width) * height,
      "FitBell: data/mask size does not match the grid");
  LUMISLAB_CHECK(options.lambda >= 0 && std::isfinite(options.lambda), "FitBell: lambda >= 0");
  switch (channels) {
    case 1:
      return Solve<1>(data, seen, width, height, options, report);
    case 2:
      return Solve<2>(data, seen, width, height, options, report);
    case 3:
      return Solve<3>(data, seen, width, height, options, report);
    default:
      return Solve<4>(data, seen, width, height, options, report);
  }
}

}  // namespace lumislab
