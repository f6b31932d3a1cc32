// calibrate/radiometric/response_fit.h against curves known exactly: observations made from a
// curve are fitted back to it, whatever the scatter of the samples' irradiances and without
// rounding.
#include "calibrate/radiometric/response_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace lumislab {
namespace {

// A gamma-and-shoulder curve like the synthetic camera's (lib/synthetic/effects.cc): linear
// value x in [0, 1] -> code in [0, 255], and back.
double Code(double x) { return 255 * std::pow(x * 1.5 / (1 + 0.5 * x), 1 / 2.2); }
double Linear(double code) {
  const double z = std::pow(code / 255, 2.2);
  return z / (1.5 - 0.5 * z);
}

// Samples of random irradiance seen in frames one stop apart; codes outside [3, 252] unusable,
// plus Gaussian code noise of `noise` codes.
std::vector<float> Observe(const std::vector<double>& log_exposure, int samples, double noise) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> log_e(std::log(0.003), std::log(2.0));
  std::normal_distribution<double> gauss(0, noise);
  std::vector<float> codes;
  for (int i = 0; i < samples; ++i) {
    const double e = std::exp(log_e(rng));
    for (double l : log_exposure) {
      const double x = e * std::exp(l);
      const double z = x < 1 ? Code(x) + (noise > 0 ? gauss(rng) : 0) : 255;
      codes.push_back(z >= 3 && z <= 252 ? float(z) : -1.f);
    }
  }
  return codes;
}

double WorstRelativeError(const std::array<double, 256>& g, int from) {
  double worst = 0;
  for (int k = from; k < 256; ++k)
    worst = std::max(worst, std::abs(std::exp(g[k]) / Linear(k) - 1));
  return worst;
}

TEST(ResponseFit, RecoversAnExactCurve) {
  const std::vector<double> log_exposure = {std::log(0.25), std::log(0.5), 0, std::log(2),
                                            std::log(4)};
  size_t used = 0;
  const auto g = FitLogInverseResponse(Observe(log_exposure, 20000, 0), 5, log_exposure, 30, &used);
  EXPECT_GT(used, 15000u);
  EXPECT_EQ(g[255], 0);
  // Exact data: what is left is the piecewise-linear g and the smoothness term's pull, largest
  // in the shoulder's extrapolation from code 252 to 255, which shifts every code alike.
  EXPECT_LT(WorstRelativeError(g, 32), 0.005);
  // Ratios between codes (what the exposure series determines) are closer still.
  for (int k = 32; k < 250; ++k)
    EXPECT_NEAR(g[k + 1] - g[k], std::log(Linear(k + 1) / Linear(k)), 2e-3) << "code " << k;
}

TEST(ResponseFit, AveragesCodeNoise) {
  const std::vector<double> log_exposure = {std::log(0.25), std::log(0.5), 0, std::log(2),
                                            std::log(4)};
  // One code of noise per observation (a JPEG's error in a 3 x 3 mean is less).
  const auto g = FitLogInverseResponse(Observe(log_exposure, 30000, 1.0), 5, log_exposure, 30);
  // The shape (values relative to code 128's) within 1 %; the normalisation at code 255, an
  // extrapolation from codes the clip at 252 selects by their noise, within 2.5 % (a common
  // factor: the scale calibration takes it out).
  for (int k = 32; k < 250; ++k)
    EXPECT_NEAR(g[k] - g[128], std::log(Linear(k) / Linear(128)), 0.01) << "code " << k;
  EXPECT_LT(WorstRelativeError(g, 32), 0.025);
  const auto residuals = ResidualsByCode(Observe(log_exposure, 3000, 1.0), 5, log_exposure, g, 16);
  for (size_t b = 2; b < residuals.mean.size(); ++b) {
    if (residuals.count[b] < 100) continue;
    EXPECT_LT(std::abs(residuals.mean[b]), 0.01) << "bin " << b;
  }
}

}  // namespace
}  // namespace lumislab
