// Issue 29: every number in the exported files means what the standard says. On a lux truth slab
// of the default scene's luminaire (its 9 x 7 grid, 1.2 m screen at 750 mm) with
// truth/luminaire.json beside it: the coverage refusal and the stated share, the file generation
// type, the symmetric subsets' averaging and asymmetry, [FILEGENINFO] without absolute paths,
// keyword text split between UTF-8 characters, input watts and efficacy in `info`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "../e2e/test_util.h"
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

const char kKeywords[] =
    " --test T-1 --lab 'Test Lab' --manufacturer Maker --issue-date 2026-12-02";

// The default scene's luminaire as a synthetic dataset's truth slab, in lux (K x W/m^2), at 32
// texels (the seen cone depends on the grid and the window, not the resolution).
// With `measured`, the luminaire is one emitter whose lobe is that file of tests/data/ies
// (3.ies: a real luminaire without symmetry), tilted 15 degrees about x and y so that no mirror
// plane of the C range is one of its own.
struct Dataset {
  std::string dir;
  explicit Dataset(const std::string& name, const std::string& measured = "")
      : dir(FreshDir(name)) {
    const SynthScene scene = DefaultScene();
    Luminaire luminaire = scene.luminaire;
    if (!measured.empty()) {
      std::filesystem::copy_file(std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/ies/" + measured,
                                 dir + "/" + measured);
      testing::WriteFile(dir + "/luminaire.json",
                         R"({"schema_version": 1, "luminaire": {"emitters": [
          {"position_mm": [0, 0, -1], "intensity_w_sr": [1, 1, 1],
           "distribution": {"file": ")" +
                             measured + R"(", "rotation_deg": [15, 15, 0]}}]}})");
      luminaire = LoadLuminaire(dir + "/luminaire.json");
    }
    SlabInfo info = TruthSlabInfo(scene, 32);
    info.units = "lux";
    WriteTruthSlab(luminaire, info, dir + "/ds/slab", 2, scene.LuminousEfficacy());
    std::filesystem::create_directories(dir + "/ds/truth");
    WriteTruthLuminaire(luminaire, dir + "/ds/truth/luminaire.json");
  }
  std::string Ds() const { return ShellQuote(dir + "/ds"); }
  std::string Out(const std::string& name) const { return ShellQuote(dir + "/" + name); }
};

// A keyword's text with its [MORE] lines joined by spaces (the writer wraps long text).
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

nlohmann::json InfoJson(const std::string& file) {
  const auto r = RunTool("lumislab-export", "info --json " + ShellQuote(file));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return nlohmann::json::parse(r.output.substr(r.output.find('{')));
}

// Item 1: the demo's IES held 1.228 of the 1.581 W the luminaire emits (the screen sees gamma
// <= 37.5 degrees, 47 diagonally) with zeros elsewhere. By default each of ies, ldt and tm25
// refuses, naming the seen cone, the unseen directions and the analytic luminaire's share of
// the flux there (22 %); --allow-partial writes the file with the coverage stated, and info
// prints it.
TEST(PhotometricTruth, PartialCoverageIsRefusedOrStated) {
  const Dataset data("truth_coverage");
  const std::string refusals[] = {
      "ies --slab " + data.Ds() + " --out " + data.Out("x.ies") + kKeywords,
      "ldt --slab " + data.Ds() + " --out " + data.Out("x.ldt"),
      "tm25 --slab " + data.Ds() + " --out " + data.Out("x.ray") + " --rays 1000"};
  for (const std::string& args : refusals) {
    const auto r = RunTool("lumislab-export", args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find("gamma 0-37.5 deg seen in every C plane"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("the analytic luminaire puts 22."), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--allow-partial"), std::string::npos) << r.output;
  }
  for (const char* f : {"x.ies", "x.ldt", "x.ray"})
    EXPECT_FALSE(std::filesystem::exists(data.dir + "/" + f)) << f;
  // Written with --allow-partial: the file's flux is the seen part, the keyword says the rest.
  auto r = RunTool("lumislab-export", refusals[0] + " --allow-partial");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const IntensityDistribution d = ReadIes(data.dir + "/x.ies");
  const std::string coverage = OneLine(d.Keyword("_COVERAGE"));
  EXPECT_EQ(coverage.rfind("partial: gamma 0-37.5 deg seen in every C plane", 0), 0u) << coverage;
  EXPECT_NE(coverage.find("the analytic luminaire puts 22."), std::string::npos) << coverage;
  // The stated uncertainty, as the report states it (export/report_uncertainty.h), with the
  // synthetic light's depth from truth/luminaire.json (a parallax term for flux and peak).
  const std::string uncertainty = OneLine(d.Keyword("_UNCERTAINTY"));
  EXPECT_EQ(uncertainty.rfind("flux +-", 0), 0u) << uncertainty;
  EXPECT_NE(uncertainty.find("(expanded, k=2; terms: model: parallax"), std::string::npos)
      << uncertainty;
  // The stated share is the file's: 1 - file flux / truth flux (lm = K x W).
  const double k = DefaultScene().LuminousEfficacy();
  const size_t at = r.output.find("the analytic luminaire emits ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const double truth_lm = std::stod(r.output.substr(at + 29));
  std::printf("IES: %.4g lm of the luminaire's %.4g lm (%.4g W x K %.4g)\n", d.TotalFlux(),
              truth_lm, truth_lm / k, k);
  EXPECT_NEAR(truth_lm / k, 1.581, 0.01);
  EXPECT_NEAR(d.TotalFlux() / truth_lm, 1.228 / 1.581, 0.01);
  nlohmann::json j = InfoJson(data.dir + "/x.ies");
  EXPECT_EQ(j["coverage"], coverage);
  r = RunTool("lumislab-export", "info " + data.Out("x.ies"));
  EXPECT_NE(r.output.find("coverage: partial: gamma 0-37.5"), std::string::npos) << r.output;
  // EULUMDAT: in the measurement report field (line 8); TM-25: additional_info, the cone.
  r = RunTool("lumislab-export", refusals[1] + " --allow-partial --test R-2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  j = InfoJson(data.dir + "/x.ldt");
  EXPECT_EQ(j["coverage"].get<std::string>().rfind(
                "partial g<=37.5: unseen 54.2% dirs, 22.6% flux (truth)", 0),
            0u)
      << j;
  EXPECT_EQ(j["keywords"]["TEST"].get<std::string>().rfind("R-2; partial g<=", 0), 0u) << j;
  // (TM-25's texts are UTF-32: a name beyond ASCII round-trips; it was cut to 7 bits.)
  r = RunTool("lumislab-export", refusals[2] + " --allow-partial --name 'Leuchte \u00e9\u00e8'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadTm25(data.dir + "/x.ray").name, "Leuchte \u00e9\u00e8");
  j = InfoJson(data.dir + "/x.ray");
  EXPECT_NE(j["coverage"].get<std::string>().find(
                "partial: rays only in the cone the screen saw: gamma 0-37.5 deg"),
            std::string::npos)
      << j;
  EXPECT_EQ(ReadTm25(data.dir + "/x.ray").creation_method, 0);  // synthetic: simulated
  // A grid within the seen cone is complete: written without --allow-partial.
  r = RunTool("lumislab-export", "ies --slab " + data.Ds() + " --out " + data.Out("cone.ies") +
                                     kKeywords + " --gamma-angles 0,10,20,30,35");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadIes(data.dir + "/cone.ies").Keyword("_COVERAGE"),
            "complete: every grid direction seen");
}

// Item 3: LM-63-2019's file generation type (line 11): a synthetic dataset is a computer
// simulation (1.00010); a capture's far field is an interpolated angle set at an unaccredited lab
// (1.01000) unless --accredited (1.11000), --lumen-scaled adds 1.xx1xx. info names it.
TEST(PhotometricTruth, FileGenerationType) {
  EXPECT_EQ(FileGenerationType{}.Code(), "1.00000");
  FileGenerationType t;
  t.interpolated = true;
  EXPECT_EQ(t.Code(), "1.01000");
  EXPECT_EQ(FileGenerationTypeName("1.01000"),
            "test at an unaccredited lab, interpolated angle set");
  t.accredited = t.lumen_scaled = true;
  EXPECT_EQ(t.Code(), "1.11100");
  EXPECT_EQ(FileGenerationTypeName("1.11100"),
            "test at an accredited lab, interpolated angle set, lumen scaled");
  t.simulation = true;
  EXPECT_EQ(t.Code(), "1.00010");
  EXPECT_EQ(FileGenerationTypeName("1.00010"), "computer simulation");
  EXPECT_EQ(FileGenerationTypeName("1.00001"), "undefined");
  EXPECT_EQ(FileGenerationTypeName("1.2"), "not in LM-63-2019's table");
  // Through the tool: the synthetic dataset is a simulation; without truth/ the same slab is a
  // capture's: interpolated, accredited with the flag.
  const Dataset data("truth_generation_type");
  auto r =
      RunTool("lumislab-export", "ies --slab " + data.Ds() + " --out " + data.Out("s.ies") +
                                     kKeywords + " --allow-partial --c-step 30 --gamma-step 10");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadIes(data.dir + "/s.ies").file_generation_type, "1.00010");
  EXPECT_EQ(InfoJson(data.dir + "/s.ies")["file_generation_type"]["meaning"],
            "computer simulation");
  std::filesystem::remove_all(data.dir + "/ds/truth");
  r = RunTool("lumislab-export", "ies --slab " + data.Ds() + " --out " + data.Out("c.ies") +
                                     kKeywords +
                                     " --allow-partial --accredited --c-step 30 --gamma-step 10");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadIes(data.dir + "/c.ies").file_generation_type, "1.11000");
  // Without truth/ the share is a stated model's.
  EXPECT_NE(
      OneLine(ReadIes(data.dir + "/c.ies").Keyword("_COVERAGE")).find("a model, not a measurement"),
      std::string::npos);
  r = RunTool("lumislab-export", "info " + data.Out("c.ies"));
  EXPECT_NE(r.output.find("file generation type: 1.11000 (test at an accredited lab, "
                          "interpolated angle set)"),
            std::string::npos)
      << r.output;
}

// Item 5: a symmetric subset of an asymmetric luminaire carried the subset's light only (the
// quadrant file integrated to 179 lm, the full one to 112). Now each plane is the mean of its
// mirror images, so the subset's flux is the full range's; the asymmetry (flux-weighted mean
// |I - mean| / mean over the images) is logged, written ([_ASYMMETRY]) and refused above
// --max-asymmetry (5 % by default). The luminaire: one emitter shaped as 3.ies, tilted.
TEST(PhotometricTruth, SymmetricSubsetsAverageTheMirrorImages) {
  const Dataset data("truth_symmetry", "3.ies");
  const std::string grid = " --allow-partial --gamma-step 5";
  auto r = RunTool("lumislab-export", "ies --slab " + data.Ds() + " --out " + data.Out("full.ies") +
                                          kKeywords + grid + " --c-step 15");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double full = ReadIes(data.dir + "/full.ies").TotalFlux();
  for (const char* c :
       {"0,15,30,45,60,75,90", "0,30,60,90,120,150,180", "90,120,150,180,210,240,270"}) {
    const std::string out = data.dir + "/sub.ies";
    std::filesystem::remove(out);
    // Refused by default: the luminaire is far from symmetric.
    r = RunTool("lumislab-export", "ies --slab " + data.Ds() + " --out " + ShellQuote(out) +
                                       kKeywords + grid + " --c-angles " + c);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--c-angles: expected a luminaire symmetric within 5 %"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("--max-asymmetry"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
    r = RunTool("lumislab-export", "ies --slab " + data.Ds() + " --out " + ShellQuote(out) +
                                       kKeywords + grid + " --max-asymmetry 100 --c-angles " + c);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const IntensityDistribution d = ReadIes(out);
    const std::string text = OneLine(d.Keyword("_ASYMMETRY"));
    std::printf("C %s: %.5g lm, full range %.5g lm; %s\n", c, d.TotalFlux(), full, text.c_str());
    EXPECT_NEAR(d.TotalFlux() / full, 1, 0.01) << c;
    ASSERT_NE(text.find("asymmetry "), std::string::npos) << text;
    EXPECT_GT(std::stod(text.substr(text.find("asymmetry ") + 10)), 5) << text;
    EXPECT_NE(r.output.find("mirror images; asymmetry "), std::string::npos) << r.output;
  }
  // The default scene's luminaire (Lambertian-like lobes) is symmetric within 1 %: written.
  const Dataset symmetric("truth_symmetric");
  r = RunTool("lumislab-export", "ies --slab " + symmetric.Ds() + " --out " +
                                     symmetric.Out("q.ies") + kKeywords + grid +
                                     " --c-angles 0,30,60,90");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

// Item 7: [FILEGENINFO] names the dataset, not an absolute path; a keyword over 240 bytes goes on
// in [MORE] lines cut between UTF-8 characters; --input-watts is line 12 (EULUMDAT's lamp
// wattage) and info gives the efficacy; info lists only keywords that are in the file.
TEST(PhotometricTruth, KeywordsInputWattsAndInfo) {
  const Dataset data("truth_keywords");
  // 239 ASCII bytes then a 2-byte character: a cut at 240 bytes would split it.
  const std::string luminaire = std::string(239, 'a') + "\u00e9tag\u00e8re";
  const auto w =
      RunTool("lumislab-export", "ies --slab " + data.Ds() + " --out " + data.Out("k.ies") +
                                     kKeywords + " --allow-partial --c-step 30 --gamma-step 10" +
                                     " --input-watts 12.5 --luminaire " + ShellQuote(luminaire));
  ASSERT_EQ(w.exit_code, 0) << w.output;
  const std::string text = testing::ReadBinaryFile(data.dir + "/k.ies");
  EXPECT_EQ(text.find(data.dir), std::string::npos) << "an absolute path in the file";
  EXPECT_NE(text.find("[FILEGENINFO] lumislab-export ies from the light slab of ds ("),
            std::string::npos);
  EXPECT_NE(text.find("[MORE] \u00e9tag\u00e8re\r\n"), std::string::npos) << text.substr(0, 800);
  const IntensityDistribution d = ReadIes(data.dir + "/k.ies");
  EXPECT_EQ(d.Keyword("LUMINAIRE"), std::string(239, 'a') + "\n\u00e9tag\u00e8re");
  EXPECT_EQ(d.input_watts, 12.5);
  const nlohmann::json j = InfoJson(data.dir + "/k.ies");
  EXPECT_NEAR(j["efficacy"].get<double>(), d.TotalFlux() / 12.5, 1e-9 * d.TotalFlux());
  EXPECT_FALSE(j["keywords"].contains("_LAMPS")) << j["keywords"];  // not a keyword of the file
  EXPECT_EQ(j["lamps"], "1 x absolute photometry");
  for (const auto& [key, value] : j["keywords"].items())
    EXPECT_NE(text.find("[" + key + "]"), std::string::npos) << key << " listed, not in the file";
  const auto r = RunTool("lumislab-export", "info " + data.Out("k.ies"));
  EXPECT_NE(r.output.find("input power: 12.5 W, efficacy "), std::string::npos) << r.output;
  // EULUMDAT: the lamp wattage.
  const auto l =
      RunTool("lumislab-export", "ldt --slab " + data.Ds() + " --out " + data.Out("k.ldt") +
                                     " --allow-partial --c-step 30 --gamma-step 10 "
                                     "--input-watts 12.5");
  ASSERT_EQ(l.exit_code, 0) << l.output;
  EXPECT_EQ(ReadEulumdat(data.dir + "/k.ldt").input_watts, 12.5);
}

// The red team's traps (issue 29): --force over the run's own inputs, a grid whose cells reach
// beyond the seen cone or that is too coarse for the light, a grid of which nothing was seen, an
// EULUMDAT report number that would cut the coverage statement, an impossible efficacy, and the
// uncertainty of a capture without the light's depth or the meter's uncertainty.
TEST(PhotometricTruth, TrapsTheRedTeamFound) {
  const Dataset data("truth_traps");
  testing::WriteFile(data.dir + "/ds/dataset.json", "{}");  // a dataset: its folders are inputs
  const std::string ies = "ies --slab " + data.Ds() + kKeywords;
  for (const std::string& out :
       {"ds/slab/slab.json", "ds/slab/new.ies", "ds/dataset.json", "ds/truth/luminaire.json"}) {
    const auto r = RunTool("lumislab-export", ies +
                                                  " --force --gamma-angles 0,5,10,15,20,25,30 "
                                                  "--out " +
                                                  data.Out(out));
    EXPECT_EQ(r.exit_code, 2) << out << "\n" << r.output;
    EXPECT_NE(r.output.find("which lumislab reads"), std::string::npos) << r.output;
  }
  EXPECT_EQ(SlabInfo::Load(data.dir + "/ds/slab").units, "lux");  // still the slab's own
  // Cells: gamma 0 and 180 has one cell over 0-90 (692 % of the light); 90 and 180 saw nothing.
  auto r = RunTool("lumislab-export", ies + " --gamma-angles 0,180 --out " + data.Out("c.ies"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("the grid is too coarse for this light"), std::string::npos) << r.output;
  r = RunTool("lumislab-export",
              ies + " --gamma-angles 90,180 --allow-partial --out " + data.Out("c.ies"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("saw none of the grid's"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(data.dir + "/c.ies"));
  // EULUMDAT: a report number too long for the coverage statement beside it.
  r = RunTool("lumislab-export",
              "ldt --slab " + data.Ds() + " --lab L --manufacturer M --allow-partial --out " +
                  data.Out("l.ldt") + " --test 'Report 2026/123 for customer ACME, batch 7'");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--test: expected at most"), std::string::npos) << r.output;
  // 1e-3 W for a luminaire of ~200 lm: 2e5 lm/W.
  r = RunTool("lumislab-export", ies +
                                     " --gamma-angles 0,5,10,15,20,25,30 --input-watts 0.001 "
                                     "--out " +
                                     data.Out("w.ies"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--input-watts: expected"), std::string::npos) << r.output;
  // An elliptical opening: IES has one, EULUMDAT not (it wrote a circle); refused for both.
  for (const char* format : {"ies", "ldt"}) {
    r = RunTool("lumislab-export", std::string(format) + " --slab " + data.Ds() + kKeywords +
                                       " --gamma-angles 0,5,10,15,20,25,30 --opening-mm "
                                       "-40,-30,0 --out " +
                                       data.Out(std::string("o.") + format));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--opening-mm: expected an opening IES and EULUMDAT both hold"),
              std::string::npos)
        << r.output;
  }
  // A capture (no truth/): the terms it cannot know are named in the keyword and warned.
  std::filesystem::remove_all(data.dir + "/ds/truth");
  r = RunTool("lumislab-export",
              ies + " --gamma-angles 0,5,10,15,20,25,30 --out " + data.Out("u.ies"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the stated uncertainty leaves out"), std::string::npos) << r.output;
  const std::string keyword = OneLine(ReadIes(data.dir + "/u.ies").Keyword("_UNCERTAINTY"));
  EXPECT_NE(keyword.find("not included: the parallax terms"), std::string::npos) << keyword;
  r = RunTool("lumislab-export", ies +
                                     " --gamma-angles 0,5,10,15,20,25,30 --light-depth-mm 20 "
                                     "--meter-uncertainty 2 --force --out " +
                                     data.Out("u.ies"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(OneLine(ReadIes(data.dir + "/u.ies").Keyword("_UNCERTAINTY")).find("not included"),
            std::string::npos);
}

}  // namespace
}  // namespace lumislab
