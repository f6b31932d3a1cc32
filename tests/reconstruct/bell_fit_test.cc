// The bell fit on its own: exact recovery, masks, constants, and noise that stays bounded.
#include "reconstruct/bell_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace lumislab {
namespace {

constexpr int kW = 64, kH = 48;

std::vector<double> RandomField(int w, int h, int ch, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  std::vector<double> c(size_t(w) * h * ch);
  for (auto& v : c) v = u(rng);
  return c;
}

std::vector<unsigned char> DiskWithHoles(int w, int h) {
  std::vector<unsigned char> seen(size_t(w) * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double r = std::hypot(x - 0.5 * w, y - 0.5 * h);
      const bool hole = (x % 11 == 3 && y % 7 == 2) || (x > 40 && x < 44);
      seen[size_t(y) * w + x] = (r < 0.45 * h && !hole) ? 1 : 0;
    }
  return seen;
}

double MaxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (size_t k = 0; k < a.size(); ++k) m = std::max(m, std::abs(a[k] - b[k]));
  return m;
}

TEST(BellFit, StencilFromTheBasis) {
  const BellStencil s = BellStencil::FromBasis();
  EXPECT_NEAR(s.w0, 5.0 / 6.0, 1e-14);
  EXPECT_NEAR(s.w1, 1.0 / 12.0, 1e-14);
  EXPECT_NEAR(s.w0 + 2 * s.w1, 1.0, 1e-14);  // partition of unity
}

TEST(BellFit, ForwardOperatorMatchesTheStencilInTheInterior) {
  std::vector<unsigned char> seen(size_t(kW) * kH, 1);
  std::vector<double> c(size_t(kW) * kH, 0.0);
  c[size_t(20) * kW + 30] = 1.0;  // one bell
  const std::vector<double> b = ApplyBellBoxOperator(c, seen, kW, kH, 1);
  const double w0 = 5.0 / 6, w1 = 1.0 / 12;
  EXPECT_NEAR(b[size_t(20) * kW + 30], w0 * w0, 1e-14);
  EXPECT_NEAR(b[size_t(20) * kW + 31], w0 * w1, 1e-14);
  EXPECT_NEAR(b[size_t(21) * kW + 31], w1 * w1, 1e-14);
  EXPECT_EQ(b[size_t(22) * kW + 30], 0.0);
  double sum = 0;
  for (double v : b) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-12);  // the box averages of one bell integrate to 1 texel
}

TEST(BellFit, RecoversKnownCoefficients) {
  const std::vector<unsigned char> seen(size_t(kW) * kH, 1);
  const std::vector<double> c = RandomField(kW, kH, 3, 1);
  const std::vector<double> b = ApplyBellBoxOperator(c, seen, kW, kH, 3);
  BellFitOptions o;
  o.lambda = 1e-12;
  o.tolerance = 1e-12;
  BellFitReport report;
  const std::vector<double> fit = FitBell(b, seen, kW, kH, 3, o, &report);
  EXPECT_LE(MaxAbsDiff(fit, c), 1e-6);
  EXPECT_LE(report.iterations, 40);  // well conditioned: a few tens of iterations at most
  EXPECT_LE(report.relative_residual, 1e-12);
}

TEST(BellFit, RecoversKnownCoefficientsWithAMask) {
  const std::vector<unsigned char> seen = DiskWithHoles(kW, kH);
  std::vector<double> c = RandomField(kW, kH, 2, 2);
  for (size_t k = 0; k < seen.size(); ++k)
    if (!seen[k]) c[2 * k] = c[2 * k + 1] = 0;
  const std::vector<double> b = ApplyBellBoxOperator(c, seen, kW, kH, 2);
  BellFitOptions o;
  o.lambda = 1e-12;
  o.tolerance = 1e-12;
  const std::vector<double> fit = FitBell(b, seen, kW, kH, 2, o);
  EXPECT_LE(MaxAbsDiff(fit, c), 1e-6);
  for (size_t k = 0; k < seen.size(); ++k)
    if (!seen[k]) {
      ASSERT_EQ(fit[2 * k], 0.0) << k;  // unseen texels are written as 0
    }
}

TEST(BellFit, ConstantFieldReproducedExactly) {
  for (bool masked : {false, true}) {
    const std::vector<unsigned char> seen =
        masked ? DiskWithHoles(kW, kH) : std::vector<unsigned char>(size_t(kW) * kH, 1);
    std::vector<double> b(seen.size(), 0.0);
    for (size_t k = 0; k < seen.size(); ++k)
      if (seen[k]) b[k] = 3.7;
    const std::vector<double> fit = FitBell(b, seen, kW, kH, 1, BellFitOptions());
    for (size_t k = 0; k < seen.size(); ++k)
      if (seen[k]) {
        ASSERT_NEAR(fit[k], 3.7, 1e-8) << "texel " << k << " masked " << masked;
      }
  }
}

TEST(BellFit, LinearRampExactInTheInterior) {
  // The box average of a linear function is its centre value: the fit returns the data.
  const int w = 40, h = 30;
  const std::vector<unsigned char> seen(size_t(w) * h, 1);
  std::vector<double> b(seen.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) b[size_t(y) * w + x] = 0.3 * x - 0.2 * y + 5;
  const std::vector<double> fit = FitBell(b, seen, w, h, 1, BellFitOptions());
  for (int y = 8; y < h - 8; ++y)
    for (int x = 8; x < w - 8; ++x)
      ASSERT_NEAR(fit[size_t(y) * w + x], b[size_t(y) * w + x], 1e-4) << x << "," << y;
}

// White noise of sigma on the data comes out amplified by the inverse stencil: in 2D the
// standard deviation grows by a / (a^2 - 4 b^2)^1.5 (a = 5/6, b = 1/12), about 1.531, and never
// by more than 1 / (2/3)^2 = 2.25 (smallest eigenvalue of B). No blow-up.
TEST(BellFit, NoiseStaysBounded) {
  const int w = 120, h = 120;
  const std::vector<unsigned char> seen(size_t(w) * h, 1);
  std::vector<double> c(seen.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      c[size_t(y) * w + x] = std::exp(-((x - 60) * (x - 60) + (y - 50) * (y - 50)) / 800.0);
  std::vector<double> b = ApplyBellBoxOperator(c, seen, w, h, 1);
  std::mt19937 rng(5);
  const double sigma = 0.01;
  std::normal_distribution<double> noise(0.0, sigma);
  for (double& v : b) v += noise(rng);
  BellFitReport report;
  const std::vector<double> fit = FitBell(b, seen, w, h, 1, BellFitOptions(), &report);
  double err2 = 0;
  for (size_t k = 0; k < c.size(); ++k) err2 += (fit[k] - c[k]) * (fit[k] - c[k]);
  const double rms = std::sqrt(err2 / c.size());
  const double a = 5.0 / 6, bb = 1.0 / 12;
  const double predicted = sigma * a / std::pow(a * a - 4 * bb * bb, 1.5);
  EXPECT_NEAR(rms, predicted, 0.1 * predicted);
  EXPECT_LE(rms, 2.25 * sigma);
  EXPECT_LE(report.iterations, 40);
}

TEST(BellFit, StrongerRegularisationSmoothsNoise) {
  const int w = 60, h = 60;
  const std::vector<unsigned char> seen(size_t(w) * h, 1);
  std::vector<double> b(seen.size(), 1.0);
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (double& v : b) v += noise(rng);
  auto rms_error = [&](double lambda) {
    BellFitOptions o;
    o.lambda = lambda;
    const std::vector<double> fit = FitBell(b, seen, w, h, 1, o);
    double e = 0;
    for (double v : fit) e += (v - 1.0) * (v - 1.0);
    return std::sqrt(e / fit.size());
  };
  EXPECT_LT(rms_error(0.1), 0.7 * rms_error(1e-4));
}

TEST(BellFit, DegenerateInputsGiveZerosNotNaN) {
  const std::vector<unsigned char> none(size_t(kW) * kH, 0), all(size_t(kW) * kH, 1);
  const std::vector<double> zeros(size_t(kW) * kH, 0.0);
  for (const auto* seen : {&none, &all}) {
    BellFitReport report;
    const std::vector<double> fit = FitBell(zeros, *seen, kW, kH, 1, BellFitOptions(), &report);
    for (double v : fit) ASSERT_EQ(v, 0.0);
    EXPECT_EQ(report.iterations, 0);
  }
  // A single seen texel: its own value comes back (Neumann boundary on all sides).
  std::vector<unsigned char> one(size_t(kW) * kH, 0);
  one[100] = 1;
  std::vector<double> b(one.size(), 0.0);
  b[100] = 2.5;
  const std::vector<double> fit = FitBell(b, one, kW, kH, 1, BellFitOptions());
  EXPECT_NEAR(fit[100], 2.5, 1e-9);
}

}  // namespace
}  // namespace lumislab
