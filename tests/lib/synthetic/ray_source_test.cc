// A TM-25 ray file as a synthetic source (lib/synthetic/ray_source.h, PlaneLight): rays
// importance-sampled from known emitters converge on their analytic truth slab at the Monte-Carlo
// rate, an extended source's near field differs from a point's, the photos hold the truth, and a
// bad ray file is exit 2 naming it.
#include "lib/synthetic/ray_source.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "acquire_test_util.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "lib/synthetic/render.h"
#include "lib/synthetic/truth.h"
#include "ray_samples.h"

namespace lumislab {
namespace {

using acquire_test::FreshDir;

// A luminaire.json (the scene file's luminaire block) with one "rays" emitter per file.
Luminaire RayLuminaire(const std::string& dir, const std::vector<std::string>& files,
                       const std::vector<Eigen::Vector3d>& rgb, double cell_mm) {
  nlohmann::json emitters = nlohmann::json::array();
  for (size_t k = 0; k < files.size(); ++k)
    emitters.push_back({{"position_mm", {0, 0, 0}},
                        {"rays",
                         {{"file", files[k]},
                          {"rgb", {rgb[k].x(), rgb[k].y(), rgb[k].z()}},
                          {"cell_mm", cell_mm}}}});
  nlohmann::json j = {{"schema_version", 1}, {"luminaire", {{"emitters", emitters}}}};
  WriteTextAtomically(dir + "/luminaire.json", j.dump(2));
  return LoadLuminaire(dir + "/luminaire.json");
}

// Relative L2 of a slab against another over every texel, position and channel.
double RelativeL2(const Luminaire& a, const Luminaire& b, const SlabInfo& info) {
  double num = 0, den = 0;
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i) {
      const SlabPosition pa = TruthPosition(a, info, i, j), pb = TruthPosition(b, info, i, j);
      for (size_t k = 0; k < pa.irradiance.data.size(); ++k) {
        num += std::pow(double(pa.irradiance.data[k]) - pb.irradiance.data[k], 2);
        den += std::pow(double(pb.irradiance.data[k]), 2);
      }
    }
  return std::sqrt(num / den);
}

// The Monte-Carlo error a ray source's truth slab should show against the exact one, relative
// L2: a texel's value is sum_r flux_r Phi~_r K(x - x_r) with K the splat's kernel (tent splat,
// bilinear read), so for rays of equal flux f drawn from the emitter's light its variance is
// f Phi~(u(x))^2 E_unfiltered(x) int K^2, and int K^2 averaged over where x falls in a cell is
// (1/2)^2 / cell^2 (1/2 per axis: 2/3 on a node, 5/12 midway). Phi~^2 E = E_filtered^2 / E.
double PredictedMonteCarloError(const std::vector<Emitter>& emitters,
                                const std::vector<double>& ray_flux, const SlabInfo& info,
                                double cell_mm) {
  const DualFilter f = info.filter.Filter();
  const double kernel2 = 0.25 / (cell_mm * cell_mm * 1e-6);  // int K^2, 1/m^2
  double var = 0, den = 0;
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i)
      for (int row = 0; row < info.layout.res_y; ++row)
        for (int col = 0; col < info.layout.res_x; ++col) {
          const Eigen::Vector2d st = info.layout.TexelCentre(col, row);
          Eigen::Vector3d total = Eigen::Vector3d::Zero();
          for (size_t e = 0; e < emitters.size(); ++e) {
            Luminaire one;
            one.emitters = {emitters[e]};
            const Eigen::Vector3d ef = one.FilteredIrradiance(
                f, info.grid.spacing_mm, info.grid.Centre(i, j), info.distance_mm, st.x(), st.y());
            const Eigen::Vector3d eu = one.PlaneIrradiance(st.x(), st.y(), info.distance_mm);
            total += ef;
            // Per channel the rays carry f times the channel's weight (intensity_w_sr).
            for (int c = 0; c < 3; ++c)
              if (eu[c] > 0)
                var +=
                    ray_flux[e] * emitters[e].intensity_w_sr[c] * ef[c] * ef[c] / eu[c] * kernel2;
          }
          den += total.squaredNorm();
        }
  return std::sqrt(var / den);
}

// (a) Rays importance-sampled from the default scene's two cos^n emitters (n = 8 at 20 mm, n = 3
// at 12 mm behind S), written as TM-25 and read back as ray sources: their truth slab against the
// emitters' analytic one falls as 1 / sqrt(rays) and within the predicted Monte-Carlo error.
TEST(RaySource, TruthConvergesToThePointEmittersTruth) {
  const std::string dir = FreshDir("ray_source_convergence");
  const SynthScene scene = DefaultScene();
  const std::vector<Emitter>& emitters = scene.luminaire.emitters;
  SlabInfo info = DefaultSlabInfo(5, 5, 5, 24);
  const double cell = 12;
  std::printf("rays per emitter | rel. L2 vs analytic | predicted MC | ratio | time (s)\n");
  double previous = 0;
  // The sanitized build (several times slower) checks the first two steps.
#ifdef LUMISLAB_SANITIZED
  const std::vector<int> counts = {25000, 100000};
#else
  const std::vector<int> counts = {25000, 100000, 400000};
#endif
  for (const int n : counts) {
    std::vector<std::string> files;
    std::vector<Eigen::Vector3d> rgb;
    std::vector<double> ray_flux;
    for (size_t e = 0; e < emitters.size(); ++e) {
      const Eigen::Vector3d& p = emitters[e].position_mm;
      const Tm25RaySet set =
          ray_samples::PointEmitterRays(p.x(), p.y(), p.z(), emitters[e].lobe_exponent, n, 17 + e);
      files.push_back("e" + std::to_string(e) + "_" + std::to_string(n) + ".ray");
      WriteTm25(set, dir + "/" + files.back());
      rgb.push_back(emitters[e].intensity_w_sr);  // the rays carry 1 W/sr on the axis
      ray_flux.push_back(set.rays[0].flux);
    }
    const auto start = std::chrono::steady_clock::now();
    const Luminaire rays = RayLuminaire(dir, files, rgb, cell);
    const double err = RelativeL2(rays, scene.luminaire, info);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double predicted = PredictedMonteCarloError(emitters, ray_flux, info, cell);
    std::printf("%16d | %19.4f | %12.4f | %5.2f | %.2f\n", n, err, predicted, err / predicted,
                seconds);
    // The kernel's blur adds a bias that does not fall with the rays (below 0.5 % at 12 mm
    // cells for these footprints, >= 190 mm on M), so the error is the MC error within +-40 %.
    EXPECT_GT(err, 0.6 * predicted);
    EXPECT_LT(err, 1.4 * predicted + 0.005);
    if (previous > 0) {
      EXPECT_LT(err, 0.6 * previous);  // 4x the rays: half the error
    }
    previous = err;
  }
}

// A Lambertian disc of radius a at depth z (radiance L) as point emitters on a square lattice of
// pitch `pitch_mm` (cos lobes, I0 = L x the disc's area / count): the disc's exact light to within
// the lattice's quadrature.
Luminaire DiscOfPointEmitters(double x0, double y0, double z, double a, double radiance,
                              double pitch_mm) {
  Luminaire disc;
  for (double x = -a + 0.5 * pitch_mm; x < a; x += pitch_mm)
    for (double y = -a + 0.5 * pitch_mm; y < a; y += pitch_mm)
      if (x * x + y * y <= a * a) disc.emitters.push_back({{x0 + x, y0 + y, z}, {1, 1, 1}, 1});
  const double i0 = radiance * kPi * a * a * 1e-6 / double(disc.emitters.size());
  for (Emitter& e : disc.emitters) e.intensity_w_sr = Eigen::Vector3d::Constant(i0);
  return disc;
}

// (b) An extended source: a Lambertian disc 15 mm across, 5 mm behind S (radiance 2e4 W/m^2/sr,
// 11 W), as 400 000 rays. Its truth slab against the disc integrated as ~700 point emitters
// (cos lobes on a 0.5 mm lattice) agrees within the predicted Monte-Carlo error, and differs from
// a point source of the same flux at its centre by far more: the slab holds the near field, which
// the filter on S resolves. (The filtered values of an extended source cancel over the disc, so
// their relative Monte-Carlo error is larger than a point's for the same rays: the prediction
// sums Phi~^2 E over the disc's points.)
TEST(RaySource, ExtendedSourceHasItsNearField) {
  const std::string dir = FreshDir("ray_source_disc");
  const double a = 7.5, z = -5, radiance = 2e4;
#ifdef LUMISLAB_SANITIZED
  GTEST_SKIP() << "accuracy run: the Release build's";
#endif
  const int n = 400000;
  Tm25RaySet set;
  ray_samples::AddLambertianDisc(0, 0, z, a, radiance, n, 5, &set);
  WriteTm25(set, dir + "/disc.ray");
  const double cell = 20;
  const Luminaire rays = RayLuminaire(dir, {"disc.ray"}, {Eigen::Vector3d::Ones()}, cell);
  EXPECT_NEAR(rays.ray_sources[0].flux, kPi * radiance * kPi * a * a * 1e-6, 1e-4);
  const Luminaire disc = DiscOfPointEmitters(0, 0, z, a, radiance, 0.5);
  Luminaire point;
  point.emitters.push_back(
      {{0, 0, z}, Eigen::Vector3d::Constant(radiance * kPi * a * a * 1e-6), 1});
  const SlabInfo info = DefaultSlabInfo(5, 5, 5, 24);
  const double err = RelativeL2(rays, disc, info);
  // Every ray carries f W per channel; the disc's points have I0 each, so f / I0 per unit I0.
  const std::vector<double> per_point(disc.emitters.size(),
                                      set.rays[0].flux / disc.emitters[0].intensity_w_sr[0]);
  const double predicted = PredictedMonteCarloError(disc.emitters, per_point, info, cell);
  const double near_field = RelativeL2(point, disc, info);
  std::printf("disc (%zu emitters): rays vs disc %.4f (predicted MC %.4f); point vs disc %.3f\n",
              disc.emitters.size(), err, predicted, near_field);
  EXPECT_GT(err, 0.6 * predicted);
  EXPECT_LT(err, 1.4 * predicted + 0.01);
  EXPECT_GT(near_field, 10 * err);
}

// The photos hold the truth: through the photo's splat (the screen, shifted by the stage) and the
// truth's (the slab window) the ray source gives peak (E+ - E-) = E_ij at every point, as the
// point emitters' SlideIrradiance and FilteredIrradiance do.
TEST(RaySource, PhotosHoldTheTruth) {
  const std::string dir = FreshDir("ray_source_photos");
  Tm25RaySet set;
  ray_samples::AddLambertianDisc(1, -2, -4, 5, 1e4, 50000, 9, &set);
  WriteTm25(set, dir + "/disc.ray");
  std::string text = acquire_test::SmallSceneJson();
  const std::string from = R"({"position_mm": [-3, 1, -12])";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), text.find('}', text.find(from)) - text.find(from) + 1,
               R"({"position_mm": [0, 0, -1], "rays": {"file": "disc.ray",
                   "rotation_deg": [0, 0, 90]}})");
  WriteTextAtomically(dir + "/scene.json", text);
  const SynthScene scene = LoadScene(dir + "/scene.json");
  ASSERT_EQ(scene.luminaire.ray_sources.size(), 1u);
  ASSERT_EQ(scene.luminaire.emitters.size(), 1u);
  EXPECT_EQ(scene.luminaire.ray_sources[0].cell_mm,
            std::max(scene.screen_w_mm, scene.screen_h_mm) / kRayCellsPerScreen);
  // Rotated by 90 degrees about z and moved 1 mm back: the disc's centre (1, -2, -4) is at
  // (2, 1, -5).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const SourceRay& r : *scene.luminaire.ray_sources[0].rays) mean += r.origin_mm;
  mean /= double(scene.luminaire.ray_sources[0].rays->size());
  EXPECT_NEAR(mean.x(), 2, 0.05);
  EXPECT_NEAR(mean.y(), 1, 0.05);
  EXPECT_NEAR(mean.z(), -5, 1e-5);
  const SlabInfo info = TruthSlabInfo(scene, 20);
  const DualFilter f = scene.Filter();
  const ScreenView view = ScreenView::Of(scene);
  double worst = 0, largest = 0;
  for (int q = 0; q < scene.grid.count(); ++q) {
    const Eigen::Vector2d c = scene.grid.Centre(q % scene.grid.nu, q / scene.grid.nu);
    const PlaneLight photo = ScreenLight(scene, f, c);
    const Eigen::Vector2d half(0.5 * info.layout.window_w_mm, 0.5 * info.layout.window_h_mm);
    const PlaneLight truth = PlaneLight::ThroughSlides(scene.luminaire, f, scene.grid.spacing_mm, c,
                                                       scene.distance_mm, -half, half);
    for (size_t k = 0; k < view.pixels.size(); k += 37) {
      const Eigen::Vector2d st = view.lab_mm[k] + c;
      if (std::abs(st.x()) > half.x() || std::abs(st.y()) > half.y()) continue;
      Eigen::Vector3d plus, minus;
      photo.Slides(st.x(), st.y(), &plus, &minus);
      const Eigen::Vector3d e = truth.Filtered(st.x(), st.y());
      worst = std::max(worst, (f.Peak2D() * (plus - minus) - e).cwiseAbs().maxCoeff());
      largest = std::max(largest, e.cwiseAbs().maxCoeff());
    }
  }
  EXPECT_GT(largest, 0);
  EXPECT_LT(worst, 1e-12 * largest);
}

// Bad ray files and fields: exit 2 naming the file and the field.
TEST(RaySource, BadInputNamesTheFileAndField) {
  const std::string dir = FreshDir("ray_source_bad");
  auto error_of = [&](const std::string& emitter) -> std::string {
    std::string text = acquire_test::SmallSceneJson();
    const std::string from = R"({"position_mm": [-3, 1, -12])";
    text.replace(text.find(from), text.find('}', text.find(from)) - text.find(from) + 1, emitter);
    WriteTextAtomically(dir + "/scene.json", text);
    try {
      LoadScene(dir + "/scene.json");
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2) << e.what();
      return e.what();
    }
    ADD_FAILURE() << "no error for " << emitter;
    return "";
  };
  auto expect = [&](const std::string& emitter, const std::string& part) {
    const std::string message = error_of(emitter);
    EXPECT_NE(message.find(part), std::string::npos) << message;
  };
  const std::string scene = dir + "/scene.json: luminaire.emitters[1].rays.file: ";
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "none.ray"}})",
         scene + dir + "/none.ray: ");
  WriteTextAtomically(dir + "/broken.ray", "TM25 but nothing else");
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "broken.ray"}})",
         scene + dir + "/broken.ray: ");
  // A file cut short names the section it lacks.
  Tm25RaySet few;
  ray_samples::AddLambertianDisc(0, 0, -2, 3, 1e3, 10, 1, &few);
  WriteTm25(few, dir + "/cut.ray");
  std::string bytes = acquire_test::FileBytes(dir + "/cut.ray");
  WriteTextAtomically(dir + "/cut.ray", bytes.substr(0, bytes.size() - 6));
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "cut.ray"}})",
         scene + dir + "/cut.ray: number of rays (4.7.1.6): the header says 10 rays");
  // Rays only away from S, or all in front of it.
  Tm25RaySet set;
  ray_samples::AddLambertianDisc(0, 0, -2, 3, 1e3, 100, 1, &set);
  for (Tm25Ray& r : set.rays) r.kz = -r.kz;
  WriteTm25(set, dir + "/away.ray");
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "away.ray"}})",
         "away.ray: rays: expected rays that cross the filter plane S from behind");
  expect(R"({"position_mm": [0, 0, 5], "rays": {"file": "away.ray", "rotation_deg": [180, 0, 0]}})",
         "got none of 100");
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "away.ray", "colour": 1}})",
         "luminaire.emitters[1].rays.colour: expected file, rotation_deg, rgb or cell_mm");
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "away.ray", "cell_mm": 0}})",
         "luminaire.emitters[1].rays.cell_mm");
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "away.ray", "cell_mm": 0.1}})",
         "luminaire.emitters[1].rays.cell_mm: expected at least the larger screen side / 4096");
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": "away.ray", "rgb": [1, -1, 1]}})",
         "luminaire.emitters[1].rays.rgb[1]");
  expect(R"({"position_mm": [0, 0, 0], "rays": {"file": 3}})", "luminaire.emitters[1].rays.file");
  expect(R"({"position_mm": [0, 0, 0], "intensity_w_sr": [1, 1, 1], "rays": {"file": "a.ray"}})",
         "luminaire.emitters[1].intensity_w_sr: expected no intensity_w_sr with rays");
  expect(R"({"position_mm": [0, 0, 0], "lobe_exponent": 1, "rays": {"file": "a.ray"}})",
         "luminaire.emitters[1]: expected exactly one of lobe_exponent, distribution");
}

// truth/luminaire.json copies the ray file beside it and reads back the same source; what knows
// point emitters only says so.
TEST(RaySource, TruthLuminaireCopiesTheFile) {
  const std::string dir = FreshDir("ray_source_truth_luminaire");
  Tm25RaySet set;
  ray_samples::AddLambertianDisc(0, 0, -3, 4, 1e4, 2000, 3, &set);
  WriteTm25(set, dir + "/disc.ray");
  Luminaire luminaire = RayLuminaire(dir, {"disc.ray"}, {Eigen::Vector3d(1, 0.5, 0.25)}, 8);
  luminaire.emitters.push_back({{0, 0, -10}, {1, 1, 1}, 2});
  std::filesystem::create_directories(dir + "/truth");
  WriteTruthLuminaire(luminaire, dir + "/truth/luminaire.json");
  EXPECT_EQ(acquire_test::FileBytes(dir + "/truth/emitter_1.ray"),
            acquire_test::FileBytes(dir + "/disc.ray"));
  const Luminaire back = LoadLuminaire(dir);
  ASSERT_EQ(back.ray_sources.size(), 1u);
  ASSERT_EQ(back.emitters.size(), 1u);
  EXPECT_EQ(back.ray_sources[0].rgb, luminaire.ray_sources[0].rgb);
  EXPECT_EQ(back.ray_sources[0].cell_mm, 8);
  EXPECT_EQ(back.ray_sources[0].rays->size(), 2000u);
  const SlabInfo info = DefaultSlabInfo(3, 3, 5, 8);
  EXPECT_EQ(TruthPosition(back, info, 1, 1).irradiance.data,
            TruthPosition(luminaire, info, 1, 1).irradiance.data);
  try {
    RequirePointEmitters(back, "x", "--analytic");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("emitter_1.ray"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lumislab
