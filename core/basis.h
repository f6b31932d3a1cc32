// The 1D bell basis (docs/method.md §2), its exact dual and the truncated printed filter.
// x is in units of the grid spacing h (dimensionless).
#pragma once

#include <vector>

namespace lumislab {

// phi(x) = 1-2x^2 (|x|<=1/2), 2(|x|-1)^2 (1/2<|x|<=1), 0 otherwise.
double Bell(double x);
// d phi / dx.
double BellDerivative(double x);
// Exact integral of phi over [a, b].
double BellIntegral(double a, double b);
// Gram entries: G(0) = 23/30, G(1) = 7/60, 0 beyond.
double BellGram(int k);

// Exact dual phi~ = sum_k c_k phi(x-k) with c_k = a r^|k| (infinite support).
struct ExactDual {
  static double Ratio();             // r ~ -0.1559
  static double Amplitude();         // a ~ 1.3693
  static double Coefficient(int k);  // a r^|k|
};

// The truncation K of every printed filter lumislab makes or reads: one range for the scene file,
// the filter printer, dataset.json and slab.json (at most K + 1 dual coefficients).
constexpr int kMinFilterTruncation = 1;
constexpr int kMaxFilterTruncation = 8;

// A dual truncated to support [-(K+1), K+1]: phi~ = c0 phi(x) + sum_{k=1..K} c_k
// (phi(x-k)+phi(x+k)). The coefficients are those closest to the exact dual's (least squares)
// that keep two conditions exactly: the integral of phi~ is 1 (constants, hence flux, are
// reproduced) and <phi~, phi> = 1 (the filter responds 1 to its own basis function); a plain
// rescale of the exact dual keeps only the first. K = 1 gives c0 = 53/39, c1 = -7/39: the
// printed filter of docs/method.md §2 (support +-2h).
class DualFilter {
 public:
  // K in [kMinFilterTruncation, kMaxFilterTruncation]; BadInput otherwise.
  static DualFilter Truncated(int k_max = 1);
  static DualFilter FromCoefficients(std::vector<double> coefficients);  // as in dataset.json

  double Eval(double x) const;    // phi~(x)
  double Integral() const;        // integral of phi~ (1 by construction)
  double CrossTalk(int k) const;  // integral phi~(x) phi(x-k) dx
  double Peak1D() const;          // max |phi~(x)|
  double Peak2D() const;          // max |phi~(u) phi~(v)| = Peak1D()^2
  double SumAbs() const;          // sum over m of |c_m| (c_0 once, c_k for +-k)
  double SupportHalfWidth() const { return coefficients_.size(); }  // in units of h
  const std::vector<double>& coefficients() const { return coefficients_; }

  // 2D filter value Phi~(u,v) = phi~(u) phi~(v), u, v in units of h relative to the centre.
  double Eval2D(double u, double v) const { return Eval(u) * Eval(v); }

 private:
  explicit DualFilter(std::vector<double> c) : coefficients_(std::move(c)) {}
  std::vector<double> coefficients_;
};

// The first-order bound on the exact model's parallax error for light z mm behind S seen on a
// receiver plane D mm from S with the slab's plane M at d (docs/method.md §4.5): 2 a sum|c_m|
// with a = z / (d + z) |1 - d / D|. At 1 or more the expansion the bound rests on does not
// converge: no error bound holds there (measured: 1.7 at D = 0.05 d, z = 20 mm, docs/testing.md
// §2).
double ParallaxFirstOrderBound(double z_mm, double d_mm, double D_mm, const DualFilter& filter);

}  // namespace lumislab
