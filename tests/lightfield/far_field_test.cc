// The slab's far-field intensity (lib/lightfield/far_field.h, docs/design.md §4.9) against the
// analytic one of a synthetic luminaire: the sum of its emitters' intensities in that direction
// (point sources seen from infinitely far), in the directions the slab saw. The exact model
// keeps its parallax error there (§4.5): a = z_e / (d + z_e) for D -> infinity,
// |error| <= 2 a Σ|c_m|; N does not reduce it.
#include "lib/lightfield/far_field.h"

#include <gtest/gtest.h>

#include <cmath>

#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

std::vector<SlabPosition> TruthPositions(const Luminaire& luminaire, const SlabInfo& info) {
  std::vector<SlabPosition> positions;
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i)
      positions.push_back(TruthPosition(luminaire, info, i, j));
  return positions;
}

TEST(FarField, MatchesTheEmittersWithinTheParallaxBound) {
  // The built-in luminaire (emitters 12 and 20 mm behind S), and one emitter 1 mm behind S
  // whose parallax is 20 times smaller.
  Luminaire close;
  close.emitters.push_back({{2, -1.5, -1}, {1, 1, 1}, 3});
  const SlabInfo info = DefaultSlabInfo(9, 7, 5, 120);
  const std::vector<double> c_deg = {0, 45, 90, 180, 270}, gamma_deg = {0, 10, 20, 30, 35, 60, 90};
  for (const Luminaire& luminaire : {DefaultScene().luminaire, close}) {
    double parallax = 0, coefficients = 0;
    for (const Emitter& e : luminaire.emitters) {
      const double z = -e.position_mm.z();
      parallax = std::max(parallax, z / (info.distance_mm + z));
    }
    for (size_t m = 0; m < info.filter.dual_coefficients.size(); ++m)
      coefficients += (m == 0 ? 1 : 2) * std::abs(info.filter.dual_coefficients[m]);
    const double bound = 2 * parallax * coefficients;
    const std::vector<SlabPosition> positions = TruthPositions(luminaire, info);
    for (const int samples : {1, 4}) {
      FarFieldOptions options;
      options.samples = samples;
      options.threads = 2;
      const FarField f = ComputeFarField(info, positions, c_deg, gamma_deg, options);
      double worst = 0;
      for (size_t ic = 0; ic < c_deg.size(); ++ic)
        for (size_t ig = 0; ig < gamma_deg.size(); ++ig) {
          const size_t k = ic * gamma_deg.size() + ig;
          // The 1.2 m window at 750 mm sees up to about 37 degrees from every position.
          EXPECT_EQ(f.seen[k], gamma_deg[ig] <= 35) << c_deg[ic] << " " << gamma_deg[ig];
          if (!f.seen[k]) {
            EXPECT_EQ(f.values[k], 0);
            continue;
          }
          double truth = 0;
          for (const Emitter& e : luminaire.emitters)
            truth +=
                e
                    .Intensity(Eigen::Vector3d(
                        std::sin(gamma_deg[ig] * M_PI / 180) * std::cos(c_deg[ic] * M_PI / 180),
                        std::sin(gamma_deg[ig] * M_PI / 180) * std::sin(c_deg[ic] * M_PI / 180),
                        std::cos(gamma_deg[ig] * M_PI / 180)))
                    .dot(LuminanceWeights());
          worst = std::max(worst, std::abs(f.values[k] / truth - 1));
        }
      std::printf("far field vs emitters, N = %d: worst relative error %.2e (bound %.2e)\n",
                  samples, worst, bound);
      EXPECT_LT(worst, bound);
      EXPECT_EQ(f.unseen, 2 * int(c_deg.size()));
      EXPECT_EQ(f.behind, int(c_deg.size()));
    }
  }
}

TEST(FarField, ConstantSlab) {
  // E = 1 W/m^2 everywhere from every position: I(0) = d^2 (m^2) x positions.
  const SlabInfo info = DefaultSlabInfo(9, 7, 5, 16);
  SlabPosition p;
  p.irradiance = ImageF(16, 16, 3, 1.f);
  p.mask = ImageF(16, 16, 1, 1.f);
  std::vector<SlabPosition> positions(info.grid.count(), p);
  const FarField f = ComputeFarField(info, positions, {0}, {0}, FarFieldOptions{});
  EXPECT_NEAR(f.values[0], 0.75 * 0.75 * 63, 1e-9);
  positions[10].mask.at(8, 8, 0) = 0;  // one unseen texel at the centre: direction 0 unseen
  EXPECT_EQ(ComputeFarField(info, positions, {0}, {0}, FarFieldOptions{}).seen[0], 0);
}

}  // namespace
}  // namespace lumislab
