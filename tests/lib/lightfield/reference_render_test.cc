// The exact CPU reference (docs/method.md §4.5) against the analytic truth of the built-in
// synthetic luminaire: agreement on the receiver plane at D = d, convergence with the samples per
// basis support, visibility against a blocker with a known shadow, and the preview's eq. 14
// (SpotIrradiance) against it at D = 2d.
#include "lib/lightfield/reference_render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "core/basis.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/stop_signal.h"
#include "lib/lightfield/light_field.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

// The default scene's setup (d = 750 mm, 9 x 7 grid, h = 5 mm, K = 1, 1.2 m window) at a small
// texel count: E_ij varies over hundreds of mm, so bilinear lookups between 10 mm texels stay
// far below the tolerances here.
struct Fixture {
  SynthScene scene = DefaultScene();
  SlabInfo info = DefaultSlabInfo(9, 7, 5, 120);
  std::vector<ImageF> irradiance;
  std::vector<PointSource> sources;
  Fixture() {
    for (int j = 0; j < info.grid.nv; ++j)
      for (int i = 0; i < info.grid.nu; ++i)
        irradiance.push_back(TruthPosition(scene.luminaire, info, i, j).irradiance);
    for (const Emitter& e : scene.luminaire.emitters)
      sources.push_back({e.position_mm, [e](const Eigen::Vector3d& w) { return e.Intensity(w); }});
  }
};

const Fixture& Data() {
  static const Fixture fixture;
  return fixture;
}

ReferenceOptions Options(int samples) {
  ReferenceOptions o;
  o.samples = samples;
  o.threads = 2;
  o.progress = false;
  return o;
}

// Relative L2 of `test` against `truth` (all channels) over the pixels `use` selects.
double RelativeL2(const ImageF& test, const ImageF& truth,
                  const std::function<bool(int, int)>& use) {
  double num = 0, den = 0;
  for (int y = 0; y < truth.height; ++y)
    for (int x = 0; x < truth.width; ++x) {
      if (!use(x, y)) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = double(test.at(x, y, c)) - truth.at(x, y, c);
        num += d * d;
        den += double(truth.at(x, y, c)) * truth.at(x, y, c);
      }
    }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

// Pixels whose light, from every emitter, crosses S where the grid's duals sum to 1.
std::function<bool(int, int)> CoveredByGrid(const ReferenceScene& view, const SlabInfo& info) {
  return [&view, &info](int x, int y) {
    const SurfacePoint p = view.Primary(x, y);
    return p.hit && GridCovers(Data().scene.luminaire, info, p.x);
  };
}

// The rule integrates 1 and x exactly and x^2 ever better as N grows (the second moment of phi is
// 1/8), which is what makes the error of a smooth integrand fall monotonically.
TEST(BellQuadratureTest, StrataAreExactForLinearAndConvergeOnQuadratics) {
  std::vector<double> offsets, weights;
  BellQuadrature(1, &offsets, &weights);
  ASSERT_EQ(offsets.size(), 1u);
  EXPECT_EQ(offsets[0], 0.0);
  EXPECT_EQ(weights[0], 1.0);
  double previous = 1;
  for (int n : {1, 2, 3, 4, 7, 16}) {
    BellQuadrature(n, &offsets, &weights);
    double sum = 0, first = 0, second = 0;
    for (int k = 0; k < n; ++k) {
      sum += weights[k];
      first += weights[k] * offsets[k];
      second += weights[k] * offsets[k] * offsets[k];
      EXPECT_GT(offsets[k], -1.0);
      EXPECT_LT(offsets[k], 1.0);
      EXPECT_NEAR(weights[k], BellIntegral(-1.0 + 2.0 * k / n, -1.0 + 2.0 * (k + 1) / n), 1e-14);
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
    EXPECT_NEAR(first, 0.0, 1e-14);
    // What the rule misses is the variance of phi within each cell, at most (2 / n)^2 / 4.
    const double error = 0.125 - second;
    EXPECT_GT(error, 0) << n;
    EXPECT_LT(error, 0.25 * (2.0 / n) * (2.0 / n)) << n;
    EXPECT_LT(error, previous) << n;
    previous = error;
  }
}

// At D = d the exact model telescopes: every sample of position (i, j) adds w/h^2 E_ij(x), so the
// reference is sum_ij E_ij(x) = the luminaire's irradiance wherever the duals sum to 1.
TEST(ReferenceRenderTest, AgreesWithAnalyticTruthOnThePlaneAtD) {
  const Fixture& f = Data();
  const ReferenceScene view(MakeSceneSetup("plane", f.info), 64, 64);
  const ReferenceImage truth = RenderPointSources(view, f.sources, Options(1));
  const auto covered = CoveredByGrid(view, f.info);
  int pixels = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) pixels += covered(x, y);
  ASSERT_GT(pixels, 64 * 64 / 3);  // the test means something: most of the plane is covered
  for (int n : {1, 2, 4}) {
    const ReferenceImage ref = RenderReference(view, f.info, f.irradiance, Options(n));
    ASSERT_TRUE(ref.complete);
    const double error = RelativeL2(ref.irradiance, truth.irradiance, covered);
    std::printf("D = d, N = %d: reference vs analytic, relative L2 over %d covered pixels: %.3g\n",
                n, pixels, error);
    EXPECT_LT(error, 2e-3);
  }
}

// Away from d the exact model no longer telescopes; the integral over each support converges as
// N grows (midpoint rule on a smooth integrand). Against the analytic truth a model error stays:
// an emitter at depth z behind S is seen from (u, v) through (s, t) on M, and as (u, v) moves
// the point where that ray's emitter crosses S moves by a = z / (d + z) (1 - d / D) times as
// much. The truth weighs it by 1 + a per axis, the bell reconstruction by 1 + a (1 + P'(w)),
// P(w) = sum_m c_m p(w - m), p(y) = sum_k k phi(y - k) - y (the bell reproduces constants but not
// linear functions; |p'| <= 1), so |error| <= 2 a sum_m |c_m| to first order in a
// (docs/method.md §4.5).
TEST(ReferenceRenderTest, ConvergesWithSamplesAt2d) {
  const Fixture& f = Data();
  SceneRequest request;
  request.name = "plane";
  request.receiver_plane_mm = 2 * f.info.distance_mm;
  request.extent_mm = 2300;  // pixels not commensurate with the texels (see below)
  const ReferenceScene view(MakeSceneSetup(request, f.info), 24, 24);
  const auto all = [](int, int) { return true; };
  const ReferenceImage best = RenderReference(view, f.info, f.irradiance, Options(16));
  const ReferenceImage truth = RenderPointSources(view, f.sources, Options(1));
  const auto covered = CoveredByGrid(view, f.info);
  double parallax = 0;  // the largest a of the emitters
  for (const Emitter& e : f.scene.luminaire.emitters) {
    const double z = -e.position_mm.z(), d = f.info.distance_mm;
    parallax = std::max(parallax, z / (d + z) * (1 - d / request.receiver_plane_mm));
  }
  double coefficients = 0;
  for (size_t m = 0; m < f.info.filter.dual_coefficients.size(); ++m)
    coefficients += (m == 0 ? 1 : 2) * std::abs(f.info.filter.dual_coefficients[m]);
  const double bound = 2 * parallax * coefficients;
  double previous = 1e9;
  for (int n : {1, 2, 4, 8}) {
    const ReferenceImage ref = RenderReference(view, f.info, f.irradiance, Options(n));
    const double self = RelativeL2(ref.irradiance, best.irradiance, all);
    const double analytic = RelativeL2(ref.irradiance, truth.irradiance, covered);
    std::printf("D = 2d, N = %d: vs N = 16 %.3g, vs analytic (covered) %.3g (bound %.3g)\n", n,
                self, analytic, bound);
    EXPECT_LT(self, previous);
    EXPECT_LT(analytic, bound);
    previous = self;
  }
}

// A square blocker of side 2b halfway to the plane, turned by 17 degrees (so that its edges
// cross the strata at every offset along the penumbra): the plane's umbra is known in closed
// form, and both images are exactly 0 there; far from the penumbra the blocker changes nothing;
// in the penumbra the reference converges with N.
TEST(ReferenceRenderTest, BlockerCastsTheExpectedShadow) {
  const Fixture& f = Data();
  const double d = f.info.distance_mm, b = 97.3;
  const int pixels = 40;
  // The central 530 mm of the plane: the penumbra spans several pixels.
  SceneRequest request;
  request.name = "plane";
  request.extent_mm = 530;
  SceneSetup setup = MakeSceneSetup(request, f.info);
  const Eigen::Rotation2Dd turn(17 * kPi / 180);
  auto corner = [&](double x, double y) -> Eigen::Vector3f {
    const Eigen::Vector2d p = turn * Eigen::Vector2d(x, y);
    return {float(p.x()), float(p.y()), float(d / 2)};
  };
  setup.mesh.AddQuad(corner(-b, -b), corner(b, -b), corner(b, b), corner(-b, b), {1, 1, 1});
  const ReferenceScene view(setup, pixels, pixels);
  const ReferenceScene open(MakeSceneSetup(request, f.info), pixels, pixels);
  const ReferenceImage truth = RenderPointSources(view, f.sources, Options(1));
  const ReferenceImage unblocked = RenderReference(open, f.info, f.irradiance, Options(2));
  // Samples lie within 4h + h = 25 mm of the axis, emitters' rays cross S within 16 mm: from
  // (X, Y, d) the segment to them passes z = d/2 at ((X, Y) + (u, v))/2, inside the blocker when
  // (X, Y) is more than 25 mm inside the square of side 4b, outside it when more than 25 mm out.
  const auto distance = [&](int x, int y) {  // "radius" of the pixel's point in the square's frame
    const Eigen::Vector2d p = turn.inverse() * view.Primary(x, y).x.head<2>();
    return p.cwiseAbs().maxCoeff();
  };
  const auto umbra = [&](int x, int y) { return distance(x, y) < 2 * b - 30; };
  const auto outside = [&](int x, int y) { return distance(x, y) > 2 * b + 30; };
  const auto all = [](int, int) { return true; };
  const ReferenceImage best = RenderReference(view, f.info, f.irradiance, Options(16));
  double previous = 1e9;
  for (int n : {1, 2, 4, 8}) {
    const ReferenceImage ref = RenderReference(view, f.info, f.irradiance, Options(n));
    int umbra_pixels = 0;
    for (int y = 0; y < pixels; ++y)
      for (int x = 0; x < pixels; ++x) {
        if (!umbra(x, y)) continue;
        ++umbra_pixels;
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(truth.irradiance.at(x, y, c), 0.f);
          EXPECT_EQ(ref.irradiance.at(x, y, c), 0.f);
        }
      }
    EXPECT_GT(umbra_pixels, 200);
    EXPECT_LT(RelativeL2(ref.irradiance, unblocked.irradiance, outside), 1e-6);
    const double self = RelativeL2(ref.irradiance, best.irradiance, all);
    std::printf("blocker, N = %d: vs N = 16 (penumbra included) %.3g\n", n, self);
    EXPECT_LT(self, previous);
    previous = self;
  }
}

// The preview's eq. 14 (one spot light per position, geometry frozen at c_ij) against the exact
// model: the same at D = d up to the texture lookups, and off by the shift-invariant error of
// docs/method.md §3.4 at D = 2d, which is bounded by E_r at the largest angle of the view.
TEST(ReferenceRenderTest, PreviewEq14AgainstExactModel) {
  const Fixture& f = Data();
  std::vector<ImageF> intensity;
  for (int j = 0; j < f.info.grid.nv; ++j)
    for (int i = 0; i < f.info.grid.nu; ++i)
      intensity.push_back(
          IntensityFromIrradiance(f.info, i, j, f.irradiance[size_t(j) * f.info.grid.nu + i]));
  for (double distance : {f.info.distance_mm, 2 * f.info.distance_mm}) {
    SceneRequest request;
    request.name = "plane";
    request.receiver_plane_mm = distance;
    const ReferenceScene view(MakeSceneSetup(request, f.info), 24, 24);
    const ReferenceImage exact = RenderReference(view, f.info, f.irradiance, Options(12));
    const ReferenceImage one = RenderReference(view, f.info, f.irradiance, Options(1));
    ImageF eq14(24, 24, 3);
    double max_angle = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        const SurfacePoint p = view.Primary(x, y);
        max_angle = std::max(max_angle, std::atan(p.x.head<2>().norm() / p.x.z()));
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int j = 0; j < f.info.grid.nv; ++j)
          for (int i = 0; i < f.info.grid.nu; ++i)
            sum +=
                SpotIrradiance(f.info, i, j, intensity[size_t(j) * f.info.grid.nu + i], p.x, p.n);
        for (int c = 0; c < 3; ++c) eq14.at(x, y, c) = float(sum[c]);
      }
    const auto all = [](int, int) { return true; };
    const double error = RelativeL2(eq14, exact.irradiance, all);
    const double vs_one = RelativeL2(eq14, one.irradiance, all);
    const double bound = ShiftInvariantError(max_angle, 2 * f.info.grid.spacing_mm / distance);
    std::printf("D = %g: eq. 14 vs exact (N = 12) %.3g, vs reference N = 1 %.3g, E_r bound %.3g\n",
                distance, error, vs_one, bound);
    EXPECT_LT(vs_one, 1e-3);  // N = 1 is eq. 14 (E bilinear instead of E')
    EXPECT_LT(error, bound);
  }
}

TEST(ReferenceRenderTest, DeterministicAcrossThreads) {
  const Fixture& f = Data();
  SceneRequest request;
  request.name = "plane";
  request.receiver_plane_mm = 1.5 * f.info.distance_mm;
  const ReferenceScene view(MakeSceneSetup(request, f.info), 16, 16);
  ReferenceOptions one = Options(3), many = Options(3);
  one.threads = 1;
  many.threads = 3;
  EXPECT_EQ(RenderReference(view, f.info, f.irradiance, one).image.data,
            RenderReference(view, f.info, f.irradiance, many).image.data);
}

// A stop signal ends the render between rows: the image says it is incomplete.
TEST(ReferenceRenderTest, StopsWhenAsked) {
  const Fixture& f = Data();
  const ReferenceScene view(MakeSceneSetup("plane", f.info), 16, 16);
  RequestStop();
  const ReferenceImage stopped = RenderReference(view, f.info, f.irradiance, Options(2));
  { const StopSignalScope clear; }  // a scope starts with the flag cleared
  EXPECT_FALSE(stopped.complete);
  EXPECT_TRUE(RenderReference(view, f.info, f.irradiance, Options(1)).complete);
}

// A room: the camera sees surfaces (finite, non-negative radiance where lit) and the reference
// N = 1 without shadows matches eq. 14 of the preview term by term wherever the point is lit.
TEST(ReferenceRenderTest, CryptIsFiniteAndLit) {
  const Fixture& f = Data();
  const ReferenceScene view(MakeSceneSetup("crypt", f.info), 32, 24);
  const ReferenceImage ref = RenderReference(view, f.info, f.irradiance, Options(1));
  int hit = 0, lit = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 32; ++x) {
      hit += view.Primary(x, y).hit;
      lit += ref.image.at(x, y, 0) > 0;
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(ref.image.at(x, y, c)));
    }
  EXPECT_GT(hit, 32 * 24 / 2);
  EXPECT_GT(lit, 20);
}

TEST(TruthLuminaireTest, RoundTripsThroughTheDatasetFolder) {
  const std::string dir = ::testing::TempDir() + "/reference_luminaire";
  std::filesystem::create_directories(dir + "/truth");
  const Luminaire luminaire = DefaultScene().luminaire;
  WriteTruthLuminaire(luminaire, dir + "/truth/luminaire.json");
  const Luminaire back = LoadLuminaire(dir);
  ASSERT_EQ(back.emitters.size(), luminaire.emitters.size());
  for (size_t k = 0; k < back.emitters.size(); ++k) {
    EXPECT_EQ(back.emitters[k].position_mm, luminaire.emitters[k].position_mm);
    EXPECT_EQ(back.emitters[k].intensity_w_sr, luminaire.emitters[k].intensity_w_sr);
    EXPECT_EQ(back.emitters[k].lobe_exponent, luminaire.emitters[k].lobe_exponent);
  }
  EXPECT_EQ(LoadLuminaire("default").emitters.size(), 2u);
  try {
    LoadLuminaire(dir + "/nothing");
    FAIL() << "a missing luminaire file must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("nothing"), std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
