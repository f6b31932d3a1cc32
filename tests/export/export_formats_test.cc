// lumislab-export ies | ldt | tm25 | info through the executable, on a truth slab of known
// emitters: the written candela (W/sr) against the emitters' intensity, the files read back by
// lib/photometry, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "../e2e/test_util.h"
#include "core/geometry.h"
#include "lib/lightfield/far_field.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/ies.h"
#include "lib/photometry/tm25.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::ShellQuote;

// The default scene's emitters 1 and 1.5 mm behind S (the slab's parallax error is then 0.1 %,
// docs/method.md §4.5) on its 9 x 7 grid at 48 texels: a complete truth slab in a folder, in
// lux as a lux meter reads it (K x W/m^2, K = the scene's luminous efficacy), with
// truth/luminaire.json beside it (a synthetic dataset: the analytic luminaire states coverage).
// ctest runs each test in its own process, in parallel: the folder is the running test's own (one
// shared name had two processes clearing and refilling it at once).
struct Fixture {
  std::string dir = FreshDir(std::string("export_formats_") +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
  Luminaire luminaire = DefaultScene().luminaire;
  SlabInfo info = LuxSlabInfo(9, 7, 5, 48);
  double k = DefaultScene().LuminousEfficacy();  // lm/W
  Fixture() {
    luminaire.emitters[0].position_mm.z() = -1;
    luminaire.emitters[1].position_mm.z() = -1.5;
    WriteTruthSlab(luminaire, info, dir + "/ds/slab", 2, k);
    std::filesystem::create_directories(dir + "/ds/truth");
    WriteTruthLuminaire(luminaire, dir + "/ds/truth/luminaire.json");
  }
  static SlabInfo LuxSlabInfo(int nu, int nv, double h, int resolution) {
    SlabInfo info = DefaultSlabInfo(nu, nv, h, resolution);
    info.units = "lux";
    return info;
  }
  // cd: K x the emitters' W/sr (Rec. 709 luminance).
  double Truth(double c_deg, double gamma_deg) const {
    const Eigen::Vector3d w = TypeCDirection(c_deg, gamma_deg);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Emitter& e : luminaire.emitters) sum += e.Intensity(w);
    return k * Rec709Weights().dot(sum);
  }
};
const Fixture& Data() {
  static const Fixture fixture;
  return fixture;
}

const char kKeywords[] =
    " --test T-1 --lab 'Test Lab' --manufacturer Maker --issue-date 2026-12-02";
// The screen sees gamma <= 37.7 degrees (47 diagonally): a full grid is partial coverage.
const char kPartial[] = " --allow-partial";

// Relative L2 of the file's intensities against the truth over the directions it has light in
// (the screen saw them), and the flux there against the truth's over the same cone.
void ExpectMatchesTruth(const IntensityDistribution& d, double tolerance) {
  const Fixture& f = Data();
  double num = 0, den = 0, gamma_max = 0;
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
    for (size_t ig = 0; ig < d.gamma_deg.size(); ++ig) {
      if (d.At(ic, ig) == 0) continue;
      const double truth = f.Truth(d.c_deg[ic], d.gamma_deg[ig]);
      num += std::pow(d.At(ic, ig) - truth, 2);
      den += truth * truth;
      gamma_max = std::max(gamma_max, d.gamma_deg[ig]);
    }
  ASSERT_GT(den, 0);
  std::printf("%s: relative L2 %.2e over gamma <= %.1f deg\n", d.format.c_str(),
              std::sqrt(num / den), gamma_max);
  EXPECT_LT(std::sqrt(num / den), tolerance);
  EXPECT_GT(gamma_max, 35);  // the 1.2 m screen at 750 mm sees 37.7 degrees, 47 diagonally
  // The truth's flux in the same directions, on the same grid (so the zonal sum's own error
  // cancels).
  IntensityDistribution truth = d;
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
    for (size_t ig = 0; ig < d.gamma_deg.size(); ++ig)
      truth.values[ic * d.gamma_deg.size() + ig] =
          d.At(ic, ig) > 0 ? f.Truth(d.c_deg[ic], d.gamma_deg[ig]) : 0;
  std::printf("%s: flux %.6g lm, truth in the same directions %.6g lm\n", d.format.c_str(),
              d.TotalFlux(), truth.TotalFlux());
  EXPECT_NEAR(d.TotalFlux() / truth.TotalFlux(), 1, 0.01);
}

TEST(ExportFormats, IesAndLdtHoldTheSlabsFarField) {
  const Fixture& f = Data();
  const std::string ies = f.dir + "/out.ies", ldt = f.dir + "/out.ldt";
  auto r = RunTool("lumislab-export", "ies --slab " + ShellQuote(f.dir + "/ds") + " --out " +
                                          ShellQuote(ies) + kKeywords + kPartial + " --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("grid directions not seen"), std::string::npos);
  const IntensityDistribution d = ReadIes(ies);
  EXPECT_EQ(d.format, "IES LM-63-2019");
  EXPECT_TRUE(d.photometric);  // a lux slab: cd
  EXPECT_EQ(d.Keyword("_UNITS"), "");
  EXPECT_EQ(d.Keyword("TESTLAB"), "Test Lab");
  EXPECT_EQ(d.c_deg.size(), 73u);
  EXPECT_EQ(d.gamma_deg.size(), 37u);
  EXPECT_NEAR(std::abs(d.opening.length_mm), 50, 1e-6);  // (nu + 1) h
  ExpectMatchesTruth(d, 0.005);
  r = RunTool("lumislab-export", "ldt --slab " + ShellQuote(f.dir + "/ds/slab") + " --out " +
                                     ShellQuote(ldt) + kKeywords + kPartial +
                                     " --c-step 15 --gamma-step 5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const IntensityDistribution l = ReadEulumdat(ldt);
  EXPECT_EQ(l.c_deg.size(), 24u);
  EXPECT_EQ(l.Keyword("MANUFAC"), "Maker");
  ExpectMatchesTruth(l, 0.005);
  // info reads both and reports the flux.
  r = RunTool("lumislab-export", "info --json " + ShellQuote(ldt));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(j["format"], "EULUMDAT");
  EXPECT_NEAR(j["flux"].get<double>(), l.TotalFlux(), 1e-6 * l.TotalFlux());
  // An existing output is exit 2 naming it unless --force (issue 29: it was skipped, exit 0).
  const std::string before = testing::ReadBinaryFile(ies);
  r = RunTool("lumislab-export", "ies --slab " + ShellQuote(f.dir + "/ds") + " --out " +
                                     ShellQuote(ies) + kKeywords + kPartial);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("out.ies: exists (--force rewrites it)"), std::string::npos) << r.output;
  EXPECT_EQ(testing::ReadBinaryFile(ies), before);
}

TEST(ExportFormats, Tm25RaysCarryTheSlabsFlux) {
  const Fixture& f = Data();
  const std::string ray = f.dir + "/out.ray";
  auto r = RunTool("lumislab-export", "tm25 --slab " + ShellQuote(f.dir + "/ds") + " --out " +
                                          ShellQuote(ray) +
                                          " --rays 20000 --seed 3 --name lamp --allow-partial");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Tm25RaySet set = ReadTm25(ray);
  ASSERT_EQ(set.rays.size(), 20000u);
  EXPECT_TRUE(set.photometric);  // a lux slab: lm
  EXPECT_EQ(set.name, "lamp");
  EXPECT_NEAR(set.FluxSum(), set.luminous_flux_lm, 1e-4 * set.luminous_flux_lm);
  // The slab's flux: every position's E over the window.
  const std::vector<SlabPosition> positions =
      ReadSlabPositions(f.dir + "/ds/slab", SlabInfo::Load(f.dir + "/ds/slab"), 2);
  double flux = 0;
  for (const SlabPosition& p : positions)
    for (size_t t = 0; t < p.mask.data.size(); ++t)
      flux += Rec709Weights().dot(Eigen::Vector3d(p.irradiance.data[3 * t],
                                                  p.irradiance.data[3 * t + 1],
                                                  p.irradiance.data[3 * t + 2])) *
              f.info.layout.TexelW() * f.info.layout.TexelH() * 1e-6;
  EXPECT_NEAR(set.FluxSum() / flux, 1, 1e-5);
  r = RunTool("lumislab-export", "info --json " + ShellQuote(ray));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(j["format"], "TM-25");
  EXPECT_EQ(j["rays"], 20000);
  EXPECT_NEAR(j["flux"].get<double>(), set.FluxSum(), 1e-6 * set.FluxSum());
}

TEST(ExportFormats, BadInputIsExitTwoAndWritesNothing) {
  const Fixture& f = Data();
  const std::string ds = ShellQuote(f.dir + "/ds");
  const std::string out = f.dir + "/bad.ies";
  struct Case {
    std::string args;
    std::string expected;
  };
  const std::string nolab = "ies --slab " + ds + " --out " + ShellQuote(out) +
                            " --test T --manufacturer M --allow-partial";
  const Case cases[] = {
      {nolab, "bad.ies: [TESTLAB]: expected a value"},
      {"ies --slab " + ds + " --out " + ShellQuote(out) + kKeywords + " --c-step 7",
       "--c-step: expected a step in (0, 360] that divides 360, got 7"},
      {"ies --slab " + ds + " --out " + ShellQuote(out) + kKeywords + " --c-angles 0,90,45",
       "--c-angles/--gamma-angles: horizontal angle 3: expected more than the one before"},
      {"ies --slab " + ShellQuote(f.dir) + " --out " + ShellQuote(out) + kKeywords,
       "no slab.json there"},
      {"tm25 --slab " + ds + " --out " + ShellQuote(f.dir + "/bad.ray") + " --rays 0", "--rays"},
      {"info " + ShellQuote(f.dir + "/missing.ies"), "missing.ies: file not found"},
  };
  for (const Case& c : cases) {
    const auto r = RunTool("lumislab-export", c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(f.dir + "/bad.ray"));
  EXPECT_EQ(testing::CountTemporaryFiles(f.dir), 0);
  // A metadata file fills the keywords; an unknown member is named.
  testing::WriteFile(f.dir + "/meta.json",
                     R"({"schema_version": 1, "test": "R-7", "testlab": "Lab", "manufac": "M",
                         "lumcat": "X-1", "keywords": {"_LAB_NOTE": "note"}})");
  auto r = RunTool("lumislab-export", "ies --slab " + ds + " --out " + ShellQuote(out) +
                                          " --allow-partial --metadata " +
                                          ShellQuote(f.dir + "/meta.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadIes(out).Keyword("LUMCAT"), "X-1");
  EXPECT_EQ(ReadIes(out).Keyword("_LAB_NOTE"), "note");
  // What lumislab states itself cannot be given (a forged [_COVERAGE] would sit beside the real
  // one, and info would read either), nor a keyword that has its own member.
  for (const char* reserved : {"_COVERAGE", "_UNCERTAINTY", "FILEGENINFO", "LUMCAT"}) {
    testing::WriteFile(f.dir + "/forged.json",
                       std::string(R"({"schema_version": 1, "keywords": {")") + reserved +
                           R"(": "complete: trust me"}})");
    const auto forged = RunTool("lumislab-export", "ies --slab " + ds + " --out " +
                                                       ShellQuote(f.dir + "/forged.ies") +
                                                       " --allow-partial --test T --lab L "
                                                       "--manufacturer M --metadata " +
                                                       ShellQuote(f.dir + "/forged.json"));
    EXPECT_EQ(forged.exit_code, 2) << reserved << "\n" << forged.output;
    EXPECT_NE(forged.output.find(std::string("keywords.") + reserved), std::string::npos)
        << forged.output;
    EXPECT_FALSE(std::filesystem::exists(f.dir + "/forged.ies"));
  }
  testing::WriteFile(f.dir + "/meta2.json", R"({"schema_version": 1, "tset": "R-7"})");
  r = RunTool("lumislab-export", "ies --force --slab " + ds + " --out " + ShellQuote(out) +
                                     " --metadata " + ShellQuote(f.dir + "/meta2.json"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("meta2.json: tset: expected a known member"), std::string::npos)
      << r.output;
}

// IES and EULUMDAT hold candela: a slab in W/m^2 (or relative units) is refused, naming the
// units and how to calibrate; TM-25 writes its rays radiometric (W) instead.
TEST(ExportFormats, RadiometricSlabsAreRefusedForIesAndLdt) {
  const std::string dir = FreshDir("export_radiometric");
  WriteTruthSlab(Data().luminaire, DefaultSlabInfo(3, 3, 5, 16), dir + "/slab", 2);
  for (const char* format : {"ies", "ldt"}) {
    const std::string out = dir + "/x." + format;
    const auto r =
        RunTool("lumislab-export", std::string(format) + " --slab " + ShellQuote(dir) + " --out " +
                                       ShellQuote(out) + kKeywords + kPartial);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("slab.json: units: expected lux"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("lumislab-calibrate scale"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("got W/m^2"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  const auto r =
      RunTool("lumislab-export", "tm25 --slab " + ShellQuote(dir) + " --out " +
                                     ShellQuote(dir + "/x.ray") + " --rays 100 --allow-partial");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Tm25RaySet rays = ReadTm25(dir + "/x.ray");
  EXPECT_FALSE(rays.photometric);
  EXPECT_NEAR(rays.radiant_flux_w, rays.FluxSum(), 1e-4 * rays.FluxSum());
  EXPECT_TRUE(std::isnan(rays.luminous_flux_lm));
}

// The exported intensity of a luminaire whose one emitter is a measured IES file (1.ies, a real
// 9218 lm luminaire, as the scene's "distribution"), against that file: relative L2 over the
// directions the screen saw, and the flux in those directions. Returns the relative L2.
double CompareWithMeasured(const std::string& exported, const std::string& measured_file,
                           double flux_tolerance) {
  const IntensityDistribution out = ReadIes(exported);
  const IntensityDistribution in = ReadIes(measured_file);
  double peak = 0;
  for (double v : in.values) peak = std::max(peak, v);
  // The emitter's I0 = (1, 1, 1) W/sr is the file's peak: the file's cd times K / peak (the
  // exported file is in cd: K lm/W x W/sr).
  peak /= DefaultScene().LuminousEfficacy();
  IntensityDistribution truth = out;
  double num = 0, den = 0;
  for (size_t ic = 0; ic < out.c_deg.size(); ++ic)
    for (size_t ig = 0; ig < out.gamma_deg.size(); ++ig) {
      const size_t k = ic * out.gamma_deg.size() + ig;
      const double t =
          out.values[k] > 0 ? in.Intensity(out.c_deg[ic], out.gamma_deg[ig]) / peak : 0;
      truth.values[k] = t;
      num += std::pow(out.values[k] - t, 2);
      den += t * t;
    }
  const double l2 = std::sqrt(num / den);
  std::printf(
      "measured emitter %s: relative L2 %.2e, flux %.6g lm vs %.6g lm in the seen directions\n",
      measured_file.c_str(), l2, out.TotalFlux(), truth.TotalFlux());
  EXPECT_NEAR(out.TotalFlux() / truth.TotalFlux(), 1, flux_tolerance);
  return l2;
}

const char kMeasuredEmitter[] =
    R"({"position_mm": [0.5, -0.5, -1], "intensity_w_sr": [1, 1, 1], "distribution": {"file": "1.ies"}})";

// The truth slab of the measured emitter (no capture): the far field alone.
TEST(ExportFormats, MeasuredEmitterRoundTripsThroughTheTruthSlab) {
  const std::string dir = FreshDir("export_measured_truth");
  std::filesystem::copy_file(std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/ies/1.ies",
                             dir + "/1.ies");
  testing::WriteFile(dir + "/luminaire.json", std::string(R"({"schema_version": 1,
      "luminaire": {"emitters": [)") + kMeasuredEmitter +
                                                  "]}}");
  const Luminaire luminaire = LoadLuminaire(dir + "/luminaire.json");
  ASSERT_TRUE(luminaire.emitters[0].measured);
  WriteTruthSlab(luminaire, Fixture::LuxSlabInfo(5, 5, 5, 48), dir + "/slab", 2,
                 DefaultScene().LuminousEfficacy());
  const auto r =
      RunTool("lumislab-export", "ies --slab " + ShellQuote(dir + "/slab") + " --out " +
                                     ShellQuote(dir + "/out.ies") + kKeywords + kPartial);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_LT(CompareWithMeasured(dir + "/out.ies", dir + "/1.ies", 0.01), 0.02);
  // truth/luminaire.json keeps a copy of the file beside it and reads back.
  std::filesystem::create_directories(dir + "/truth");
  WriteTruthLuminaire(luminaire, dir + "/truth/luminaire.json");
  const Luminaire back = LoadLuminaire(dir + "/truth/luminaire.json");
  ASSERT_TRUE(back.emitters[0].measured);
  EXPECT_EQ(back.emitters[0].measured->file, dir + "/truth/emitter_0.ies");
  const Eigen::Vector3d w = Eigen::Vector3d(0.3, -0.2, 1).normalized();
  EXPECT_EQ(back.emitters[0].Intensity(w), luminaire.emitters[0].Intensity(w));
}

// The issue's round trip: each of the four real IES files (tests/data/ies) as the measured
// emitter through a synthetic capture (photos, screen calibration, reconstruction) to the slab
// and out as IES: candela within 2 % (relative L2) and flux within 1 % of the file's over the
// directions the screen saw.
class MeasuredEmitterCapture : public ::testing::TestWithParam<const char*> {};

TEST_P(MeasuredEmitterCapture, RoundTripsThroughACapture) {
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run: the Release build's";
  const std::string file = GetParam();
  const std::string dir = FreshDir("export_measured_capture_" + file.substr(0, 1));
  std::filesystem::copy_file(std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/ies/" + file,
                             dir + "/" + file);
  std::string emitter = kMeasuredEmitter;
  emitter.replace(emitter.find("1.ies"), 5, file);
  testing::WriteFile(dir + "/scene.json", std::string(R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 5, "nv": 5, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [)") + emitter +
                                              R"(] },
  "camera": {"size_px": [400, 300], "focal_px": 325, "position_mm": [0, -400, 2400],
             "look_at_mm": [0, 0, 750]} })");
  const std::string ds = ShellQuote(dir + "/ds");
  auto r = RunTool("lumislab-acquire", "synth --scene " + ShellQuote(dir + "/scene.json") +
                                           " --out " + ds + " --truth-resolution 16 --meter lux");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-calibrate", "screen --dataset " + ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The synthetic lux meter's reading makes the slab photometric (lux, so cd in the file).
  r = RunTool("lumislab-calibrate", "scale --dataset " + ds + " --reference " +
                                        ShellQuote(dir + "/ds/truth/reference.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-reconstruct", "--dataset " + ds + " --resolution 64");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-export",
              "ies --slab " + ds + " --out " + ShellQuote(dir + "/out.ies") + kKeywords + kPartial);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_LT(CompareWithMeasured(dir + "/out.ies", dir + "/" + file, 0.01), 0.02);
  EXPECT_TRUE(std::filesystem::exists(dir + "/ds/truth/emitter_0.ies"));
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(RealIesFiles, MeasuredEmitterCapture,
                         ::testing::Values("1.ies", "3.ies", "5.ies", "7.ies"),
                         [](const ::testing::TestParamInfo<const char*>& file) {
                           return "file" + std::string(file.param).substr(0, 1);
                         });

}  // namespace
}  // namespace lumislab
