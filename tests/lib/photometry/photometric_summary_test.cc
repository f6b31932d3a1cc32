// The photometric summary (lib/photometry/photometric_summary.h) against analytic
// distributions: I = I0 cos^n(gamma) has beam angle 2 acos(0.5^(1/n)), field angle
// 2 acos(0.1^(1/n)) and flux 2 pi I0 (cos^(n+1) a - cos^(n+1) b) / (n + 1) in the zone [a, b].
#include "lib/photometry/photometric_summary.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/geometry.h"

namespace lumislab {
namespace {

constexpr double kDeg = kPi / 180;

// A full type C grid (C 0..360 by c_step, gamma 0..180 by 0.5 degrees) of I(C, gamma).
template <typename F>
IntensityDistribution Grid(double c_step, F intensity) {
  IntensityDistribution d;
  for (double c = 0; c <= 360 + 1e-9; c += c_step) d.c_deg.push_back(c);
  for (int k = 0; k <= 360; ++k) d.gamma_deg.push_back(0.5 * k);
  for (double c : d.c_deg)
    for (double g : d.gamma_deg) d.values.push_back(intensity(c, g));
  d.Check("test grid");
  return d;
}

double CosN(double gamma_deg, double n) {
  return gamma_deg < 90 ? 1000 * std::pow(std::cos(gamma_deg * kDeg), n) : 0.0;
}

double ZoneTruth(double lo, double hi, double n) {
  return 2 * kPi * 1000 *
         (std::pow(std::cos(lo * kDeg), n + 1) - std::pow(std::cos(hi * kDeg), n + 1)) / (n + 1);
}

TEST(PhotometricSummary, CosineLobesBeamFieldAndZones) {
  for (double n : {1.0, 4.0, 20.0}) {
    const IntensityDistribution d = Grid(15, [&](double, double g) { return CosN(g, n); });
    const PhotometricSummary s = SummarisePhotometry(d);
    const double beam = 2 * std::acos(std::pow(0.5, 1 / n)) / kDeg;
    const double field = 2 * std::acos(std::pow(0.1, 1 / n)) / kDeg;
    ASSERT_EQ(s.spreads.size(), 4u) << "C0, C90, C45, C135 are all stored planes";
    for (const BeamSpread& b : s.spreads) {
      EXPECT_NEAR(b.beam_deg, beam, 0.1) << "n " << n << " C " << b.c_deg;
      EXPECT_NEAR(b.field_deg, field, 0.1) << "n " << n << " C " << b.c_deg;
    }
    EXPECT_DOUBLE_EQ(s.peak, 1000);
    EXPECT_EQ(s.peak_gamma_deg, 0);
    EXPECT_NEAR(s.total_flux / ZoneTruth(0, 90, n), 1, 1e-3);
    ASSERT_EQ(s.zones.size(), 18u);
    double percent = 0;
    for (const ZonalFlux& z : s.zones) {
      // Zones holding 1 % of the flux or more (a zone far down the flank of n = 20 holds 0.4 %,
      // where the zonal sum's cell clipped at the zone's edge is 0.2 % of it).
      const double truth =
          z.gamma_lo_deg < 90 ? ZoneTruth(z.gamma_lo_deg, std::min(z.gamma_hi_deg, 90.0), n) : 0;
      if (truth > 0.01 * s.total_flux) {
        EXPECT_NEAR(z.flux / truth, 1, 1e-3) << "n " << n << " zone " << z.gamma_lo_deg;
      } else {
        EXPECT_NEAR(z.flux, truth, 1e-4 * s.total_flux) << "n " << n << " zone " << z.gamma_lo_deg;
      }
      percent += z.percent;
    }
    EXPECT_NEAR(percent, 100, 1e-9);
  }
}

// Lambertian (n = 1): the share within half-angle a is sin^2 a, so N1..N3 are 43.75, 75, 93.75.
TEST(PhotometricSummary, CieFluxCodeOfALambertianLuminaire) {
  const PhotometricSummary s =
      SummarisePhotometry(Grid(30, [](double, double g) { return CosN(g, 1); }));
  EXPECT_NEAR(s.cie_flux_code[0], 43.75, 0.05);
  EXPECT_NEAR(s.cie_flux_code[1], 75, 0.05);
  EXPECT_NEAR(s.cie_flux_code[2], 93.75, 0.05);
  EXPECT_NEAR(s.cie_flux_code[3], 100, 1e-9);
  EXPECT_EQ(s.cie_flux_code[4], 100);
  EXPECT_EQ(CieFluxCodeText(s.cie_flux_code), "44 75 94 100 100");
}

// A lobe tilted 20 degrees towards C = 90: the peak comes out there, and across the C90-C270 pair
// the profile is cos^n(theta - 20) along the signed angle, so the beam angle is unchanged.
TEST(PhotometricSummary, TiltedLobeKeepsItsPeakDirectionAndBeam) {
  const double n = 8;
  auto dir = [](double c, double g) {
    return Eigen::Vector3d(std::sin(g * kDeg) * std::cos(c * kDeg),
                           std::sin(g * kDeg) * std::sin(c * kDeg), std::cos(g * kDeg));
  };
  const Eigen::Vector3d axis = dir(90, 20);
  const IntensityDistribution d = Grid(5, [&](double c, double g) {
    const double cosine = dir(c, g).dot(axis);
    return cosine > 0 ? 500 * std::pow(cosine, n) : 0.0;
  });
  const PhotometricSummary s = SummarisePhotometry(d);
  EXPECT_EQ(s.peak_c_deg, 90);
  EXPECT_EQ(s.peak_gamma_deg, 20);
  ASSERT_GE(s.spreads.size(), 2u);
  EXPECT_EQ(s.spreads[1].c_deg, 90);
  EXPECT_NEAR(s.spreads[1].beam_deg, 2 * std::acos(std::pow(0.5, 1 / n)) / kDeg, 0.1);
  EXPECT_NEAR(s.spreads[1].field_deg, 2 * std::acos(std::pow(0.1, 1 / n)) / kDeg, 0.1);
}

// Directions not seen are unknown, not dark: a wide lobe seen to 30 degrees has no beam angle,
// only a lower bound of 60, and its measured cone is 30 degrees.
TEST(PhotometricSummary, UnseenDirectionsGiveALowerBound) {
  const IntensityDistribution d = Grid(90, [](double, double g) { return CosN(g, 1); });
  std::vector<uint8_t> seen;
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
    for (double g : d.gamma_deg) seen.push_back(g <= 30);
  const PhotometricSummary s = SummarisePhotometry(d, seen);
  EXPECT_EQ(SeenConeDeg(d, seen), 30);
  EXPECT_EQ(SeenConeDeg(d, {}), 180);
  ASSERT_EQ(s.spreads.size(), 2u);
  EXPECT_TRUE(std::isnan(s.spreads[0].beam_deg));
  EXPECT_DOUBLE_EQ(s.spreads[0].beam_at_least_deg, 60);
}

TEST(PhotometricSummary, AxialSymmetryAndEfficacy) {
  IntensityDistribution d;
  d.c_deg = {0};
  for (int k = 0; k <= 180; ++k) d.gamma_deg.push_back(k);
  for (double g : d.gamma_deg) d.values.push_back(CosN(g, 4));
  d.input_watts = 20;
  const PhotometricSummary s = SummarisePhotometry(d);
  ASSERT_EQ(s.spreads.size(), 4u);
  EXPECT_NEAR(s.spreads[0].beam_deg, 2 * std::acos(std::pow(0.5, 0.25)) / kDeg, 0.1);
  EXPECT_NEAR(s.efficacy, s.total_flux / 20, 1e-9);
  EXPECT_NEAR(s.PerKlm(1000), 1e6 / s.total_flux, 1e-9);
  d.photometric = false;
  EXPECT_EQ(SummarisePhotometry(d).efficacy, 0) << "W/sr: no lm/W";
}

TEST(PhotometricSummary, NemaBeamTypes) {
  EXPECT_EQ(NemaBeamType(9.9), 0);
  EXPECT_EQ(NemaBeamType(std::nan("")), 0);
  EXPECT_EQ(NemaBeamType(10), 1);
  EXPECT_EQ(NemaBeamType(18), 1);
  EXPECT_EQ(NemaBeamType(18.1), 2);
  EXPECT_EQ(NemaBeamType(46), 3);
  EXPECT_EQ(NemaBeamType(69), 4);
  EXPECT_EQ(NemaBeamType(100), 5);
  EXPECT_EQ(NemaBeamType(129), 6);
  EXPECT_EQ(NemaBeamType(131), 7);
}

}  // namespace
}  // namespace lumislab
