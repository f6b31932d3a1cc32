// The slab's far-field intensity (docs/design.md §4.9) against the analytic one of a synthetic
// luminaire: the sum of its emitters' intensities in that direction (point sources seen from
// infinitely far), in the directions the slab window saw from every position. The exact model
// keeps its parallax error there (§4.5): a = z_e / (d + z_e) for D -> infinity, |error| <= 2 a
// Σ|c_m|; N does not reduce it.
#include "lib/lightfield/far_field.h"

#include <gtest/gtest.h>

#include <cmath>

#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

struct Comparison {
  double worst = 0, bound = 0;
  int directions = 0;
};

Comparison CompareWithEmitters(const Luminaire& luminaire) {
  const SlabInfo info = DefaultSlabInfo(9, 7, 5, 120);
  std::vector<ImageF> irradiance;
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i)
      irradiance.push_back(TruthPosition(luminaire, info, i, j).irradiance);
  Comparison out;
  double parallax = 0, coefficients = 0;
  for (const Emitter& e : luminaire.emitters) {
    const double z = -e.position_mm.z(), d = info.distance_mm;
    parallax = std::max(parallax, z / (d + z));
  }
  for (size_t m = 0; m < info.filter.dual_coefficients.size(); ++m)
    coefficients += (m == 0 ? 1 : 2) * std::abs(info.filter.dual_coefficients[m]);
  out.bound = 2 * parallax * coefficients;
  for (const double c : {0.0, 90.0, 180.0, 270.0, 45.0})
    for (double gamma = 0; gamma <= 40; gamma += 5) {
      const Eigen::Vector3d w = DirectionFromCGamma(c, gamma);
      if (!SlabSeesDirection(info, w)) continue;
      Eigen::Vector3d truth = Eigen::Vector3d::Zero();
      for (const Emitter& e : luminaire.emitters) truth += e.Intensity(w);
      for (const int samples : {1, 4}) {
        const Eigen::Vector3d slab = SlabFarFieldIntensity(info, irradiance, w, samples);
        out.worst = std::max(out.worst, (slab - truth).norm() / truth.norm());
        ++out.directions;
      }
    }
  return out;
}

TEST(FarField, MatchesTheEmittersWithinTheParallaxBound) {
  // The built-in luminaire (emitters 12 and 20 mm behind S), and one emitter 1 mm behind S
  // whose parallax is 20 times smaller.
  Luminaire close;
  close.emitters.push_back({{2, -1.5, -1}, {1, 1, 1}, 3});
  for (const Luminaire& luminaire : {DefaultScene().luminaire, close}) {
    const Comparison r = CompareWithEmitters(luminaire);
    std::printf("far field vs emitters: worst relative error %.2e (bound %.2e) over %d\n", r.worst,
                r.bound, r.directions);
    EXPECT_GE(r.directions, 60);  // the window (1.2 m at 750 mm) sees up to about 37 degrees
    EXPECT_LT(r.worst, r.bound);
  }
}

TEST(FarField, DirectionsAndWhatTheWindowSaw) {
  const SlabInfo info = DefaultSlabInfo(9, 7, 5, 16);
  EXPECT_TRUE(SlabSeesDirection(info, DirectionFromCGamma(0, 35)));
  EXPECT_FALSE(SlabSeesDirection(info, DirectionFromCGamma(0, 40)));
  EXPECT_FALSE(SlabSeesDirection(info, {0, 0, -1}));
  const std::vector<ImageF> irradiance(info.grid.count(), ImageF(16, 16, 3, 1.f));
  EXPECT_EQ(SlabFarFieldIntensity(info, irradiance, {0, 0, -1}), Eigen::Vector3d::Zero());
  // A constant E = 1 W/m^2 from every position: I(0) = d^2 (m^2) x positions.
  EXPECT_NEAR(SlabFarFieldIntensity(info, irradiance, {0, 0, 1}).x(), 0.75 * 0.75 * 63, 1e-9);
  const Eigen::Vector3d w = DirectionFromCGamma(30, 20);
  EXPECT_NEAR(w.norm(), 1, 1e-12);
  EXPECT_NEAR(w.z(), std::cos(20 * M_PI / 180), 1e-12);
  EXPECT_NEAR(w.y() / w.x(), std::tan(30 * M_PI / 180), 1e-12);
}

}  // namespace
}  // namespace lumislab
