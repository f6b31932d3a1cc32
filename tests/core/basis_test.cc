#include "core/basis.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lumislab {
namespace {

// Numerical integral of f over [a, b] (Simpson, fine enough for piecewise quadratics).
template <typename F>
double Integrate(F f, double a, double b) {
  // Simpson panels aligned with the knots (multiples of 1/2) are exact for piecewise quadratics.
  const int n = int(std::lround(4000 * (b - a)));
  const double h = (b - a) / n;
  double sum = f(a) + f(b);
  for (int k = 1; k < n; ++k) sum += f(a + k * h) * (k % 2 ? 4 : 2);
  return sum * h / 3;
}

TEST(BellTest, InterpolatesAndPartitionsUnity) {
  EXPECT_DOUBLE_EQ(Bell(0), 1.0);
  EXPECT_DOUBLE_EQ(Bell(1), 0.0);
  EXPECT_DOUBLE_EQ(Bell(-1), 0.0);
  EXPECT_DOUBLE_EQ(Bell(2.5), 0.0);
  for (double x = -0.5; x <= 0.5; x += 0.01) {
    double sum = 0;
    for (int k = -3; k <= 3; ++k) sum += Bell(x - k);
    EXPECT_NEAR(sum, 1.0, 1e-14) << x;
  }
}

TEST(BellTest, IsC1) {
  // Value and derivative are continuous at the knots +-1/2 and +-1.
  for (double knot : {-1.0, -0.5, 0.5, 1.0}) {
    EXPECT_NEAR(Bell(knot - 1e-9), Bell(knot + 1e-9), 1e-8);
    EXPECT_NEAR(BellDerivative(knot - 1e-9), BellDerivative(knot + 1e-9), 1e-8);
  }
  // The derivative matches finite differences everywhere.
  for (double x = -1.2; x <= 1.2; x += 0.037) {
    const double fd = (Bell(x + 1e-6) - Bell(x - 1e-6)) / 2e-6;
    EXPECT_NEAR(BellDerivative(x), fd, 1e-6) << x;
  }
}

TEST(BellTest, IntegralAndGramMatchQuadrature) {
  EXPECT_NEAR(BellIntegral(-1, 1), 1.0, 1e-15);
  EXPECT_NEAR(BellIntegral(-0.5, 0.5), 5.0 / 6.0, 1e-15);
  EXPECT_NEAR(BellIntegral(0.3, 0.9), Integrate(Bell, 0.3, 0.9), 1e-12);
  EXPECT_NEAR(BellGram(0), Integrate([](double x) { return Bell(x) * Bell(x); }, -1, 1), 1e-12);
  EXPECT_NEAR(BellGram(1), Integrate([](double x) { return Bell(x) * Bell(x - 1); }, -1, 2), 1e-12);
  EXPECT_DOUBLE_EQ(BellGram(0), 23.0 / 30.0);
  EXPECT_DOUBLE_EQ(BellGram(1), 7.0 / 60.0);
  EXPECT_EQ(BellGram(2), 0.0);
}

TEST(DualTest, ExactDualConstants) {
  EXPECT_NEAR(ExactDual::Ratio(), -0.1559, 5e-5);
  EXPECT_NEAR(ExactDual::Amplitude(), 1.3693, 5e-5);
  // Biorthogonal: sum_m c_m G(k - m) = delta_k0 (the infinite dual, summed far enough).
  for (int k = 0; k <= 3; ++k) {
    double sum = 0;
    for (int m = -40; m <= 40; ++m) sum += ExactDual::Coefficient(m) * BellGram(k - m);
    EXPECT_NEAR(sum, k == 0 ? 1.0 : 0.0, 1e-14) << k;
  }
}

TEST(DualTest, TruncatedFilterReproducesConstants) {
  for (int k_max : {1, 2, 3}) {
    const DualFilter f = DualFilter::Truncated(k_max);
    EXPECT_NEAR(f.Integral(), 1.0, 1e-14);
    EXPECT_NEAR(Integrate([&](double x) { return f.Eval(x); }, -k_max - 1, k_max + 1), 1.0, 1e-10);
    EXPECT_EQ(f.Eval(k_max + 1.0), 0.0);
    EXPECT_DOUBLE_EQ(f.SupportHalfWidth(), k_max + 1.0);
  }
  // The printed filter spans +-2h.
  EXPECT_EQ(DualFilter::Truncated(1).coefficients().size(), 2u);
}

TEST(DualTest, CrossTalkIsComputedAndShrinksWithWidth) {
  const DualFilter f = DualFilter::Truncated(1);
  // Cross-talk from the coefficients equals the quadrature of phi~ phi(x - k).
  for (int k = 0; k <= 3; ++k) {
    const double q = Integrate([&](double x) { return f.Eval(x) * Bell(x - k); }, -3, 4);
    EXPECT_NEAR(f.CrossTalk(k), q, 1e-10) << k;
  }
  // Biorthogonal to the centre; the response to the neighbours is small but not zero, and it
  // decreases for wider truncations (the accuracy knob).
  EXPECT_NEAR(f.CrossTalk(0), 1.0, 1e-14);
  EXPECT_NEAR(f.CrossTalk(1), 0.020940, 1e-6);  // (1-G0)/(2(G1-G0)) G0 + ... for K = 1
  EXPECT_NEAR(f.CrossTalk(2), -0.020940, 1e-6);
  EXPECT_GT(std::abs(f.CrossTalk(1)), 1e-4);
  EXPECT_LT(std::abs(f.CrossTalk(1)), 0.03);
  EXPECT_LT(std::abs(f.CrossTalk(2)), 0.03);
  const DualFilter wide = DualFilter::Truncated(3);
  EXPECT_LT(std::abs(wide.CrossTalk(1)), std::abs(f.CrossTalk(1)));
  // Sum over all k of the cross-talk is 1 (partition of unity).
  double sum = 0;
  for (int k = -3; k <= 3; ++k) sum += f.CrossTalk(k);
  EXPECT_NEAR(sum, 1.0, 1e-14);
}

TEST(DualTest, PeakIsTheMaximumMagnitude) {
  const DualFilter f = DualFilter::Truncated(1);
  double brute = 0;
  for (double x = -2; x <= 2; x += 1e-5) brute = std::max(brute, std::abs(f.Eval(x)));
  EXPECT_NEAR(f.Peak1D(), brute, 1e-9);
  EXPECT_NEAR(f.Peak2D(), brute * brute, 1e-9);
  EXPECT_GT(f.Peak1D(), 1.0);
  // Negative lobes exist (that is why two slides are printed).
  double min = 0;
  for (double x = -2; x <= 2; x += 1e-3) min = std::min(min, f.Eval(x));
  EXPECT_LT(min, -0.05);
}

// sum|c_m| and the parallax bound 2 z/(d + z) |1 - d/D| sum|c_m| built on it (docs/method.md §4.5).
TEST(DualTest, SumOfMagnitudesAndTheParallaxBound) {
  const DualFilter f = DualFilter::FromCoefficients({1.5, -0.25});
  EXPECT_DOUBLE_EQ(f.SumAbs(), 2.0);  // c_0 once, c_1 for +1 and -1
  const DualFilter k1 = DualFilter::Truncated(1);
  EXPECT_NEAR(k1.SumAbs(), 67.0 / 39.0, 1e-12);
  // z = 20 mm behind S, d = 750: at D = 0.05 d, a = 20/770 * 19 and 2 a S = 1.70 (> 1).
  EXPECT_NEAR(ParallaxFirstOrderBound(20, 750, 37.5, k1), 2 * 20.0 / 770 * 19 * 67 / 39, 1e-12);
  EXPECT_DOUBLE_EQ(ParallaxFirstOrderBound(20, 750, 750, k1), 0.0);  // D = d: no parallax
  EXPECT_DOUBLE_EQ(ParallaxFirstOrderBound(0, 750, 37.5, k1), 0.0);  // light on S
}

TEST(DualTest, FromCoefficientsRoundTrips) {
  const DualFilter f = DualFilter::Truncated(2);
  const DualFilter g = DualFilter::FromCoefficients(f.coefficients());
  for (double x = -3; x <= 3; x += 0.1) EXPECT_DOUBLE_EQ(f.Eval(x), g.Eval(x));
  EXPECT_THROW(DualFilter::FromCoefficients({}), std::exception);
}

}  // namespace
}  // namespace lumislab
