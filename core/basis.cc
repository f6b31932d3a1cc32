#include "core/basis.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace lumislab {

double Bell(double x) {
  const double a = std::abs(x);
  if (a <= 0.5) return 1.0 - 2.0 * a * a;
  if (a <= 1.0) return 2.0 * (a - 1.0) * (a - 1.0);
  return 0.0;
}

double BellDerivative(double x) {
  const double a = std::abs(x);
  const double sign = x < 0 ? -1.0 : 1.0;
  if (a <= 0.5) return -4.0 * x;
  if (a <= 1.0) return sign * 4.0 * (a - 1.0);
  return 0.0;
}

namespace {
// Antiderivative of phi on [0, inf), F(0) = 0; phi is even.
double BellPrimitivePositive(double a) {
  if (a <= 0.5) return a - 2.0 * a * a * a / 3.0;
  const double f_half = 0.5 - 2.0 / 24.0;  // 5/12
  if (a <= 1.0) {
    const double b = a - 1.0;  // integral of 2(x-1)^2 from 1/2 to a = 2/3 (b^3 + 1/8)
    return f_half + 2.0 / 3.0 * (b * b * b + 0.125);
  }
  return 0.5;
}
double BellPrimitive(double x) {
  return x < 0 ? -BellPrimitivePositive(-x) : BellPrimitivePositive(x);
}
}  // namespace

double BellIntegral(double a, double b) { return BellPrimitive(b) - BellPrimitive(a); }

double BellGram(int k) {
  k = std::abs(k);
  if (k == 0) return 23.0 / 30.0;
  if (k == 1) return 7.0 / 60.0;
  return 0.0;
}

// The dual's recurrence G1 c_{k-1} + G0 c_k + G1 c_{k+1} = 0 (k >= 1) gives c_k = a r^k with
// G1 r^2 + G0 r + G1 = 0 (|r| < 1); the k = 0 row fixes a = 1 / (G0 + 2 G1 r).
double ExactDual::Ratio() {
  const double g0 = BellGram(0), g1 = BellGram(1);
  return (-g0 + std::sqrt(g0 * g0 - 4.0 * g1 * g1)) / (2.0 * g1);
}
double ExactDual::Amplitude() { return 1.0 / (BellGram(0) + 2.0 * BellGram(1) * Ratio()); }
double ExactDual::Coefficient(int k) { return Amplitude() * std::pow(Ratio(), std::abs(k)); }

DualFilter DualFilter::Truncated(int k_max) {
  if (k_max < kMinFilterTruncation || k_max > kMaxFilterTruncation)
    throw BadInput("dual filter: k_max: expected an integer in [" +
                   std::to_string(kMinFilterTruncation) + ", " +
                   std::to_string(kMaxFilterTruncation) + "], got " + std::to_string(k_max));
  // Closest to the exact dual (least squares, each coefficient weighted by how often it occurs)
  // subject to the two conditions a truncation must keep: the integral is 1 (constants are
  // reproduced, so the flux is right) and <phi~, phi> = 1 (biorthogonal to its own centre).
  // Each condition is a row a . c = 1; c = c* + M^-1 A^T lambda.
  const int n = k_max + 1;
  std::vector<double> c(n), mult(n), a_int(n), a_bio(n, 0.0);
  for (int k = 0; k < n; ++k) {
    c[k] = ExactDual::Coefficient(k);
    mult[k] = k == 0 ? 1.0 : 2.0;
    a_int[k] = mult[k];
  }
  a_bio[0] = BellGram(0);
  a_bio[1] = 2.0 * BellGram(1);
  double s11 = 0, s12 = 0, s22 = 0, r1 = 1, r2 = 1;
  for (int k = 0; k < n; ++k) {
    s11 += a_int[k] * a_int[k] / mult[k];
    s12 += a_int[k] * a_bio[k] / mult[k];
    s22 += a_bio[k] * a_bio[k] / mult[k];
    r1 -= a_int[k] * c[k];
    r2 -= a_bio[k] * c[k];
  }
  const double det = s11 * s22 - s12 * s12;
  const double l1 = (r1 * s22 - r2 * s12) / det, l2 = (s11 * r2 - s12 * r1) / det;
  for (int k = 0; k < n; ++k) c[k] += (a_int[k] * l1 + a_bio[k] * l2) / mult[k];
  return DualFilter(std::move(c));
}

DualFilter DualFilter::FromCoefficients(std::vector<double> coefficients) {
  if (coefficients.empty()) throw BadInput("dual filter: no coefficients");
  return DualFilter(std::move(coefficients));
}

double DualFilter::Eval(double x) const {
  const int k_max = int(coefficients_.size()) - 1;
  if (std::abs(x) >= k_max + 1) return 0.0;
  double sum = coefficients_[0] * Bell(x);
  for (int k = 1; k <= k_max; ++k) sum += coefficients_[k] * (Bell(x - k) + Bell(x + k));
  return sum;
}

double DualFilter::Integral() const {
  double sum = coefficients_[0];
  for (size_t k = 1; k < coefficients_.size(); ++k) sum += 2.0 * coefficients_[k];
  return sum;
}

double DualFilter::CrossTalk(int k) const {
  const int k_max = int(coefficients_.size()) - 1;
  double sum = 0;
  for (int m = -k_max; m <= k_max; ++m) sum += coefficients_[std::abs(m)] * BellGram(k - m);
  return sum;
}

double DualFilter::Peak1D() const {
  // phi~ is quadratic on every half-integer interval: take ends and the vertex of each piece.
  const int k_max = int(coefficients_.size()) - 1;
  double peak = 0;
  for (int m = -2 * (k_max + 1); m < 2 * (k_max + 1); ++m) {
    const double x0 = 0.5 * m, x1 = x0 + 0.5, xm = x0 + 0.25;
    const double f0 = Eval(x0 + 1e-12), f1 = Eval(x1 - 1e-12), fm = Eval(xm);
    peak = std::max({peak, std::abs(f0), std::abs(f1), std::abs(fm)});
    // Quadratic through the three points: f(x) = fm + b (x - xm) + a (x - xm)^2.
    const double h = 0.25;
    const double a = (f0 + f1 - 2 * fm) / (2 * h * h);
    const double b = (f1 - f0) / (2 * h);
    if (a != 0) {
      const double xv = xm - b / (2 * a);
      if (xv > x0 && xv < x1) peak = std::max(peak, std::abs(Eval(xv)));
    }
  }
  return peak;
}

double DualFilter::Peak2D() const {
  const double p = Peak1D();
  return p * p;
}

double DualFilter::SumAbs() const {
  double sum = std::abs(coefficients_[0]);
  for (size_t k = 1; k < coefficients_.size(); ++k) sum += 2 * std::abs(coefficients_[k]);
  return sum;
}

double ParallaxFirstOrderBound(double z_mm, double d_mm, double D_mm, const DualFilter& filter) {
  return 2 * z_mm / (d_mm + z_mm) * std::abs(1 - d_mm / D_mm) * filter.SumAbs();
}

}  // namespace lumislab
