// E -> E' against core/geometry.h, the GL sampler's lookup on the CPU, the spot-light formula of
// one position (eq. 14) on a receiver plane, and E' read from slab files on several threads.
#include "lib/lightfield/light_field.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "core/basis.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/slab.h"

namespace lumislab {
namespace {

SlabInfo TestInfo(int nu, int nv, double h, double window, int res) {
  SlabInfo info;
  info.distance_mm = 750;
  info.grid = {nu, nv, h};
  info.layout = {window, window, res, res};
  info.filter = FilterInfo::Of(DualFilter::Truncated(1), h);
  return info;
}

// A smooth, nowhere-constant 3-channel test texture (values 0.2 .. 2.4).
ImageF TestTexture(int w, int h) {
  ImageF t(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        t.at(x, y, c) = float(1.3 + std::sin(0.37 * x + 0.11 * y * (c + 1) + c));
      }
    }
  }
  return t;
}

TEST(LightFieldIntensity, IsIrradianceOverShiftInvariantGeometryInSquareMetres) {
  const SlabInfo info = TestInfo(3, 3, 0.5, 100, 100);
  const ImageF e = TestTexture(100, 100);
  for (const auto& [i, j] : {std::pair{0, 0}, std::pair{2, 1}}) {
    const Eigen::Vector2d c = info.grid.Centre(i, j);
    const ImageF e_prime = IntensityFromIrradiance(info, i, j, e);
    ASSERT_EQ(e_prime.channels, 3);
    double worst = 0;
    for (int row = 0; row < 100; ++row) {
      for (int col = 0; col < 100; ++col) {
        const Eigen::Vector2d st = info.layout.TexelCentre(col, row);
        const double g_m2 = ShiftInvariantGeometry(info.distance_mm, c, st.x(), st.y()) * 1e6;
        for (int ch = 0; ch < 3; ++ch) {
          const double back = e_prime.at(col, row, ch) * g_m2;  // E' g = E
          worst = std::max(worst, std::abs(back / e.at(col, row, ch) - 1));
        }
      }
    }
    EXPECT_LE(worst, 1e-6) << i << "," << j;
  }
  // Straight ahead of c_20 = (0.5, -0.5) (texel 50, 50): g = 1/d^2, so E' = E d^2 (d in m).
  const ImageF e_prime = IntensityFromIrradiance(info, 2, 0, e);
  ASSERT_TRUE(info.layout.TexelCentre(50, 50).isApprox(info.grid.Centre(2, 0)));
  EXPECT_NEAR(e_prime.at(50, 50, 1), e.at(50, 50, 1) * 0.75 * 0.75, 1e-6);
}

TEST(LightFieldSampleLayout, IsExactAtTexelCentresAndZeroOutsideTheWindow) {
  const SlabLayout layout{120, 80, 12, 8};
  const ImageF t = TestTexture(12, 8);
  for (int row = 0; row < 8; ++row) {
    for (int col = 0; col < 12; ++col) {
      const Eigen::Vector2d st = layout.TexelCentre(col, row);
      const Eigen::Vector3d v = SampleLayout(layout, t, st.x(), st.y());
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(v[ch], t.at(col, row, ch), 1e-6);
    }
  }
  // Halfway between texels (3, 2) and (4, 2): their mean (bilinear).
  const Eigen::Vector2d mid = 0.5 * (layout.TexelCentre(3, 2) + layout.TexelCentre(4, 2));
  EXPECT_NEAR(SampleLayout(layout, t, mid.x(), mid.y())[0], 0.5 * (t.at(3, 2, 0) + t.at(4, 2, 0)),
              1e-6);
  // Inside the window but beyond the last texel centre: the edge texel (clamp to edge).
  EXPECT_NEAR(SampleLayout(layout, t, 59.9, 39.9)[2], t.at(11, 0, 2), 1e-6);
  EXPECT_NEAR(SampleLayout(layout, t, -59.9, -39.9)[2], t.at(0, 7, 2), 1e-6);
  // Outside the window: nothing, whatever the edge texels hold.
  for (const auto& [s, tt] : {std::pair{60.01, 0.0}, std::pair{-60.01, 0.0}, std::pair{0.0, 40.01},
                              std::pair{0.0, -40.01}, std::pair{500.0, 500.0}}) {
    EXPECT_EQ(SampleLayout(layout, t, s, tt), Eigen::Vector3d::Zero()) << s << "," << tt;
  }
}

TEST(LightFieldSpotIrradiance, ConstantIntensityOnAPlaneIsCosCosOverDeltaSquared) {
  const SlabInfo info = TestInfo(5, 3, 5, 1200, 60);
  const Eigen::Vector3d k(0.75, 1.5, 2.5);  // E' (W/sr) everywhere, exact in float
  ImageF intensity(60, 60, 3);
  for (int p = 0; p < 60 * 60; ++p) {
    for (int ch = 0; ch < 3; ++ch) intensity.data[3 * p + ch] = float(k[ch]);
  }
  const double plane_z = 2000;
  const Eigen::Vector3d n(0, 0, -1);
  for (const auto& [i, j] : {std::pair{0, 0}, std::pair{4, 2}, std::pair{2, 1}}) {
    const Eigen::Vector2d c = info.grid.Centre(i, j);
    for (const auto& [x, y] :
         {std::pair{0.0, 0.0}, std::pair{900.0, -400.0}, std::pair{-1500.0, 1100.0}}) {
      const Eigen::Vector3d rel(x - c.x(), y - c.y(), plane_z);
      const double delta = rel.norm(), cos_theta = plane_z / delta;
      const double expected = cos_theta * cos_theta / std::pow(delta / 1000, 2);  // m^-2
      const Eigen::Vector3d e = SpotIrradiance(info, i, j, intensity, {x, y, plane_z}, n);
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(e[ch], expected * k[ch], 1e-9 * expected * k[ch]);
    }
    // Through the window only (|s| <= 600 at d = 750 -> |x| <= 1600 at 2000 mm).
    EXPECT_EQ(SpotIrradiance(info, i, j, intensity, {2000, 0, plane_z}, n),
              Eigen::Vector3d::Zero());
    // Towards +z only, and not onto a surface facing away.
    EXPECT_EQ(SpotIrradiance(info, i, j, intensity, {0, 0, -plane_z}, {0, 0, 1}),
              Eigen::Vector3d::Zero());
    EXPECT_EQ(SpotIrradiance(info, i, j, intensity, {0, 0, plane_z}, {0, 0, 1}),
              Eigen::Vector3d::Zero());
  }
}

TEST(LightFieldReadIntensities, DeriveEPrimeOfSlabFilesOnSeveralThreads) {
  const SlabInfo info = TestInfo(3, 2, 5, 1200, 24);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("lumislab_lightfield_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::vector<std::pair<int, int>> positions;
  std::vector<ImageF> expected;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 3; ++i) {
      SlabPosition p{i, j, TestTexture(24, 24), ImageF(24, 24, 1, 1.f)};
      for (float& v : p.irradiance.data) v *= float(1 + i + 3 * j);
      WriteSlabPosition(dir.string(), info, p);
      positions.emplace_back(i, j);
      expected.push_back(IntensityFromIrradiance(info, i, j, p.irradiance));
    }
  }
  std::reverse(positions.begin(), positions.end());
  std::reverse(expected.begin(), expected.end());
  const std::vector<ImageF> got = ReadIntensities(dir.string(), info, positions, 4);
  ASSERT_EQ(got.size(), expected.size());
  for (size_t k = 0; k < got.size(); ++k) EXPECT_EQ(got[k].data, expected[k].data) << k;
  EXPECT_EQ(ReadIntensity(dir.string(), info, 1, 1).data, expected[1].data);
  // A missing position fails the whole call (the error of the worker thread reaches the caller).
  std::filesystem::remove(SlabPositionPath(dir.string(), 2, 0));
  EXPECT_THROW(ReadIntensities(dir.string(), info, positions, 4), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
