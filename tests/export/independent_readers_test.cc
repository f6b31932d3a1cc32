// Issue 29's evidence "an independent reader accepts every file lumislab writes": every IES,
// EULUMDAT and TM-25 file lumislab writes (lumislab-export from a slab in lux, and the writers on
// each symmetry) read by a reader lumislab did not write, and what it read compared with
// lumislab's own reader. IES: three.js's IESLoader (npm `three`, tests/export/readers/
// package.json) under node. EULUMDAT and TM-25: no reader exists in the npm registry or Debian's
// archive, so tests/export/readers/ldt_read.py and tm25_read.py read them from the formats'
// public layouts (cited there), sharing no code with lib/photometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../e2e/test_util.h"
#include "core/geometry.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/ies.h"
#include "lib/photometry/tm25.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunShell;
using testing::RunTool;
using testing::ShellQuote;

const std::string kReaders = std::string(LUMISLAB_SOURCE_DIR) + "/tests/export/readers";

// A small truth slab of the default scene in lux (a lux meter's scale: candela and lumen), the
// export's keywords, and a grid the 1.2 m screen sees whole (gamma up to 30 degrees), so that the
// files claim no direction the capture did not see.
struct Slab {
  std::string dir;
  explicit Slab(const std::string& name) : dir(FreshDir("independent_readers_" + name)) {
    SlabInfo info = DefaultSlabInfo(3, 3, 5, 16);
    info.units = "lux";
    WriteTruthSlab(DefaultScene().luminaire, info, dir + "/slab", 2);
  }
  // lumislab-export <format> to dir/out.<ext>; the file's path.
  std::string Export(const std::string& format, const std::string& ext,
                     const std::string& extra) const {
    const std::string out = dir + "/out." + ext;
    const auto r = RunTool("lumislab-export", format + " --slab " + ShellQuote(dir) + " --out " +
                                                  ShellQuote(out) + " " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return out;
  }
};
const char kGrid[] =
    "--c-step 15 --gamma-angles 0,5,10,15,20,25,30 --test T-1 --lab 'Test Lab' "
    "--manufacturer Maker --issue-date 2026-12-04";

// A distribution on each symmetry's C range, gamma 0-180 in 10 degrees, asymmetric within it.
std::vector<std::pair<std::string, IntensityDistribution>> EverySymmetry() {
  const std::vector<std::pair<std::string, std::vector<double>>> ranges = {
      {"axial", {0}},
      {"quadrant", {0, 30, 60, 90}},
      {"c0c180", {0, 45, 90, 135, 180}},
      {"c90c270", {90, 135, 180, 225, 270}},
      {"none", {0, 60, 120, 180, 240, 300, 360}}};
  std::vector<std::pair<std::string, IntensityDistribution>> out;
  for (const auto& [name, c] : ranges) {
    IntensityDistribution d;
    d.c_deg = c;
    for (int g = 0; g <= 180; g += 10) d.gamma_deg.push_back(g);
    for (double cv : c)
      for (double g : d.gamma_deg) {
        const double k = kPi / 180, lobe = 1 + 0.3 * std::pow(std::sin(cv * k / 2), 2);
        d.values.push_back(g < 90 ? 100 * std::cos(g * k) * lobe : 2.0);  // C 360 = C 0
      }
    d.keywords = {
        {"TEST", "T-2"}, {"TESTLAB", "Lab"}, {"ISSUEDATE", "2026-12-04"}, {"MANUFAC", "Maker"}};
    d.opening = {20, 30, 0};
    out.push_back({name, d});
  }
  return out;
}

// Runs `command` (stderr kept) and parses one JSON object per line of its output.
std::vector<nlohmann::json> RunJsonLines(const std::string& command) {
  const auto r = RunShell(command + " 2>&1");
  EXPECT_EQ(r.exit_code, 0) << command << "\n" << r.output;
  std::vector<nlohmann::json> out;
  std::istringstream in(r.output);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] == '{') out.push_back(nlohmann::json::parse(line));
  return out;
}

std::string Joined(const std::vector<std::string>& files) {
  std::string s;
  for (const std::string& f : files) s += " " + ShellQuote(f);
  return s;
}

bool HavePython() { return RunShell("python3 -c 'import json, struct' 2>&1").exit_code == 0; }

// A folder with three installed from tests/export/readers/package.json: build/npm (scripts/
// setup.sh installs it; this test installs it into its own build folder when it is missing). Empty,
// with `why` set, when npm cannot install it.
std::string ThreeFolder(std::string* why) {
  const std::string dir = std::string(LUMISLAB_BIN_DIR) + "/../npm";
  const std::string loader = "/node_modules/three/examples/jsm/loaders/IESLoader.js";
  // This build's folder, else build/'s (the sanitizer build shares what setup.sh installed).
  for (const std::string& d : {dir, std::string(LUMISLAB_SOURCE_DIR) + "/build/npm"})
    if (std::filesystem::exists(d + loader)) return d;
  if (RunShell("node --version && npm --version").exit_code != 0) {
    *why = "node or npm is not installed (scripts/setup.sh installs Debian's nodejs and npm)";
    return "";
  }
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kReaders + "/package.json", dir + "/package.json",
                             std::filesystem::copy_options::overwrite_existing);
  const auto r =
      RunShell("cd " + ShellQuote(dir) + " && timeout 180 npm install --no-audit --no-fund 2>&1");
  if (r.exit_code != 0 || !std::filesystem::exists(dir + loader)) {
    *why = "npm could not install three (tests/export/readers/package.json) into " + dir +
           ": the npm registry is not reachable from here? npm said: " +
           r.output.substr(r.output.size() > 600 ? r.output.size() - 600 : 0);
    return "";
  }
  return dir;
}

TEST(IndependentReaders, ThreeJsIesLoaderReadsEveryIesFile) {
  std::string why;
  const std::string three = ThreeFolder(&why);
  if (three.empty()) GTEST_SKIP() << "three.js IESLoader not available: " << why;
  const Slab slab("ies");
  std::vector<std::string> files = {slab.Export("ies", "ies", kGrid)};
  for (const auto& [name, d] : EverySymmetry()) {
    files.push_back(slab.dir + "/" + name + ".ies");
    WriteIes(d, files.back());
  }
  const std::vector<nlohmann::json> read = RunJsonLines(
      "node " + ShellQuote(kReaders + "/ies_three.mjs") + " " + ShellQuote(three) + Joined(files));
  ASSERT_EQ(read.size(), files.size());
  for (size_t f = 0; f < files.size(); ++f) {
    const nlohmann::json& j = read[f];
    const IntensityDistribution ours = ReadIes(files[f]);
    SCOPED_TRACE(files[f]);
    EXPECT_EQ(j["lumens"].get<double>(), -1);  // absolute photometry
    EXPECT_EQ(j["numVerAngles"].get<size_t>(), ours.gamma_deg.size());
    // The loader shifts the C range to start at 0 and closes one that then ends between 180 and
    // 360 with a copy of the first plane.
    const double span = ours.c_deg.back() - ours.c_deg.front();
    const bool closed = span > 180 && span < 360;
    EXPECT_EQ(j["numHorAngles"].get<size_t>(), ours.c_deg.size() + (closed ? 1 : 0));
    for (size_t g = 0; g < ours.gamma_deg.size(); ++g)
      EXPECT_NEAR(j["verAngles"][g].get<double>(), ours.gamma_deg[g], 1e-9);
    for (size_t c = 0; c < ours.c_deg.size(); ++c)  // the loader shifts them to start at 0
      EXPECT_NEAR(j["horAngles"][c].get<double>() + ours.c_deg[0], ours.c_deg[c], 1e-9);
    // Its candela divided by their maximum (it normalises): ours alike.
    const double peak = *std::max_element(ours.values.begin(), ours.values.end());
    double worst = 0;
    for (size_t c = 0; c < ours.c_deg.size(); ++c)
      for (size_t g = 0; g < ours.gamma_deg.size(); ++g)
        worst = std::max(worst, std::abs(j["candela"][c][g].get<double>() - ours.At(c, g) / peak));
    EXPECT_LT(worst, 1e-9);
    EXPECT_TRUE(j["texture"]["finite"].get<bool>());
    EXPECT_GT(j["texture"]["max"].get<double>(), 0.5);
    std::printf("three.js IESLoader: %s: %zu x %zu angles, candela within %.1e of ours\n",
                std::filesystem::path(files[f]).filename().c_str(), ours.c_deg.size(),
                ours.gamma_deg.size(), worst);
  }
}

TEST(IndependentReaders, LayoutReaderReadsEveryEulumdatFile) {
  if (!HavePython()) GTEST_SKIP() << "python3 is not installed (scripts/setup.sh installs it)";
  const Slab slab("ldt");
  std::vector<std::string> files = {slab.Export("ldt", "ldt", kGrid)};
  for (const auto& [name, d] : EverySymmetry()) {
    files.push_back(slab.dir + "/" + name + ".ldt");
    WriteEulumdat(d, files.back());
  }
  EulumdatWriteOptions lamps;  // relative photometry with two lamp sets
  const IntensityDistribution quadrant = EverySymmetry()[1].second;
  lamps.lamp_sets = {{2, "T16 54W", 2 * quadrant.TotalFlux(), "4000 K", "1B", 120},
                     {2, "T16 80W", 3 * quadrant.TotalFlux(), "", "", 180}};
  files.push_back(slab.dir + "/lamps.ldt");
  WriteEulumdat(quadrant, files.back(), lamps);
  const std::vector<nlohmann::json> read =
      RunJsonLines("python3 " + ShellQuote(kReaders + "/ldt_read.py") + Joined(files));
  ASSERT_EQ(read.size(), files.size());
  for (size_t f = 0; f < files.size(); ++f) {
    const nlohmann::json& j = read[f];
    const IntensityDistribution ours = ReadEulumdat(files[f]);
    SCOPED_TRACE(files[f]);
    EXPECT_EQ(j["crlf_lines"].get<int>(), j["lines"].get<int>());  // every line CR LF
    EXPECT_EQ(j["ityp"].get<int>(), ours.Symmetry() == CSymmetry::kAxial ? 1 : 3);
    EXPECT_EQ(j["ng"].get<size_t>(), ours.gamma_deg.size());
    EXPECT_EQ(j["stored_planes"].get<size_t>(), ours.c_deg.size());
    for (size_t g = 0; g < ours.gamma_deg.size(); ++g)
      EXPECT_NEAR(j["gamma"][g].get<double>(), ours.gamma_deg[g], 1e-9);
    const double lamp_flux = j["lamp_sets"][0]["flux"].get<double>();
    double worst = 0;
    for (size_t c = 0; c < ours.c_deg.size(); ++c)
      for (size_t g = 0; g < ours.gamma_deg.size(); ++g)
        worst = std::max(worst, std::abs(j["intensities"][c][g].get<double>() * lamp_flux / 1000 -
                                         ours.At(c, g)) /
                                    ours.At(0, 0));
    EXPECT_LT(worst, 1e-9);
    const std::array<double, 10> ratios = LdtDirectRatios(ours);
    for (size_t k = 0; k < ratios.size(); ++k)
      EXPECT_NEAR(j["direct_ratios"][k].get<double>(), ratios[k], 1e-4);
    std::printf(
        "EULUMDAT layout reader: %s: Ityp %d, Isym %d, %zu planes x %zu angles, "
        "intensities within %.1e of ours, DR(k=1) %.3f\n",
        std::filesystem::path(files[f]).filename().c_str(), j["ityp"].get<int>(),
        j["isym"].get<int>(), ours.c_deg.size(), ours.gamma_deg.size(), worst, ratios[2]);
  }
  EXPECT_EQ(read.back()["lamp_sets"].size(), 2u);
  EXPECT_EQ(read.back()["lamp_sets"][1]["type"], "T16 80W");
  EXPECT_EQ(read.back()["lorl"].get<double>(), 50);
  EXPECT_EQ(read[0]["lamp_sets"][0]["count"].get<int>(), -1);  // the export: absolute
}

TEST(IndependentReaders, LayoutReaderReadsEveryTm25File) {
  if (!HavePython()) GTEST_SKIP() << "python3 is not installed (scripts/setup.sh installs it)";
  const Slab slab("tm25");
  std::vector<std::string> files = {slab.Export("tm25", "ray", "--rays 500 --allow-partial")};
  Tm25RaySet radiometric;  // the writer's other flux column
  radiometric.photometric = false;
  radiometric.luminous_flux_lm = std::nan("");
  radiometric.name = "test source";
  for (int k = 0; k < 20; ++k) {
    const float a = 0.1f * k;
    radiometric.rays.push_back({a, -a, 0, std::sin(a) * 0.5f, 0, 0, 0.01f * (k + 1)});
    Tm25Ray& r = radiometric.rays.back();
    r.kz = std::sqrt(1 - r.kx * r.kx);
  }
  radiometric.radiant_flux_w = radiometric.FluxSum();
  files.push_back(slab.dir + "/radiometric.ray");
  WriteTm25(radiometric, files.back());
  const std::vector<nlohmann::json> read =
      RunJsonLines("python3 " + ShellQuote(kReaders + "/tm25_read.py") + Joined(files));
  ASSERT_EQ(read.size(), files.size());
  for (size_t f = 0; f < files.size(); ++f) {
    const nlohmann::json& j = read[f];
    const Tm25RaySet ours = ReadTm25(files[f]);
    SCOPED_TRACE(files[f]);
    EXPECT_EQ(j["rays"].get<size_t>(), ours.rays.size());
    EXPECT_EQ(j["flags"]["luminous_flux"].get<int>(), ours.photometric ? 1 : 0);
    EXPECT_EQ(j["flags"]["radiant_flux"].get<int>(), ours.photometric ? 0 : 1);
    const double sum = j["flux_sum"][ours.photometric ? "luminous" : "radiant"].get<double>();
    EXPECT_NEAR(sum, ours.FluxSum(), 1e-5 * ours.FluxSum());
    const char* total = ours.photometric ? "luminous_flux" : "radiant_flux";
    EXPECT_NEAR(j[total].get<double>(), ours.FluxSum(), 1e-4 * ours.FluxSum());
    for (size_t r = 0; r < j["first_rays"].size(); ++r) {
      EXPECT_EQ(j["first_rays"][r][0].get<double>(), ours.rays[r].x);
      EXPECT_EQ(j["first_rays"][r][5].get<double>(), ours.rays[r].kz);
      EXPECT_EQ(j["first_rays"][r][6].get<double>(), ours.rays[r].flux);
    }
    EXPECT_EQ(j["name"].get<std::string>(), ours.name);
    EXPECT_EQ(j["additional_info"].get<std::string>(), ours.additional_info);
    std::printf("TM-25 layout reader: %s: %zu rays, flux %.6g %s (ours %.6g)\n",
                std::filesystem::path(files[f]).filename().c_str(), ours.rays.size(), sum,
                ours.photometric ? "lm" : "W", ours.FluxSum());
  }
}

}  // namespace
}  // namespace lumislab
