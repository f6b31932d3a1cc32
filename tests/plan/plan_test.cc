// lumislab-plan (docs/method.md §4.8): the model's predictions against what lumislab-study
// measured (docs/study/*/study.csv, end-to-end on synthetic scenes), the recommended grid against
// GridCovers, out-of-reach targets, the command line.
#include "plan/plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "../e2e/test_util.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

using namespace lumislab::testing;

const std::string kSource = LUMISLAB_SOURCE_DIR;

// The rows of a study.csv as column -> text.
std::vector<std::map<std::string, std::string>> ReadCsv(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::istringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
    if (header.empty()) {
      header = cells;
      continue;
    }
    std::map<std::string, std::string> row;
    for (size_t k = 0; k < header.size() && k < cells.size(); ++k) row[header[k]] = cells[k];
    rows.push_back(row);
  }
  return rows;
}

PlanSetting SettingOf(const std::map<std::string, std::string>& row) {
  PlanSetting s;
  s.h_mm = std::stod(row.at("h_mm"));
  s.nu = std::stoi(row.at("nu"));
  s.nv = std::stoi(row.at("nv"));
  s.k_max = std::stoi(row.at("k_max"));
  s.resolution = std::stoi(row.at("slab_res"));
  s.samples = std::stoi(row.at("samples"));
  return s;
}

// The stated factor: every prediction within x3 of the measured error on the pixels the grid
// covers, at d, 2d and 4d, for every point of both studies (the model's constants were fitted on
// three numbers of the default scene; the rest are checks).
constexpr double kFactor = 3;

void CheckStudy(const std::string& scene_file, const std::string& csv, int* checked,
                double* worst) {
  const PlanInput in = PlanInputFromScene(LoadScene(scene_file));
  const char* dist[] = {"d", "2d", "4d"};
  // The plan models a noise-free capture at reconstruct's default regularisation: the study's
  // noise, brackets and lambda knobs (sensor noise, lambda up to 1) measure what it leaves out.
  const std::set<std::string> modelled = {"spacing", "extent",     "photo",
                                          "k_max",   "resolution", "samples"};
  for (const auto& row : ReadCsv(csv)) {
    if (!modelled.count(row.at("knob"))) continue;
    const PlanSetting s = SettingOf(row);
    for (int k = 0; k < 3; ++k) {
      const double measured = std::stod(row.at(std::string("err_cov_") + dist[k]));
      if (measured < 0) continue;  // the grid covers no pixel there
      const double D = in.distance_mm * (1 << k);
      const double predicted = PredictError(in, s, D).total;
      const double ratio = predicted / measured;
      EXPECT_GT(ratio, 1 / kFactor) << csv << " " << row.at("key") << " at " << dist[k]
                                    << ": predicted " << predicted << ", measured " << measured;
      EXPECT_LT(ratio, kFactor) << csv << " " << row.at("key") << " at " << dist[k]
                                << ": predicted " << predicted << ", measured " << measured;
      *worst = std::max(*worst, std::max(ratio, 1 / ratio));
      ++*checked;
    }
  }
}

TEST(Plan, PredictionsBracketTheStudysMeasurements) {
  int checked = 0;
  double worst = 1;
  CheckStudy("default", kSource + "/docs/study/default-quick/study.csv", &checked, &worst);
  CheckStudy(kSource + "/docs/study/wide-quick/scene.json",
             kSource + "/docs/study/wide-quick/study.csv", &checked, &worst);
  EXPECT_GE(checked, 80);
  std::printf("predictions within x%.2f of %d measurements\n", worst, checked);
}

TEST(Plan, WholeViewErrorOfACoveringGridIsPredicted) {
  // The planner never calls a grid covering where the study measured a coverage loss at d, and
  // the default study's extent x1.5 (13 x 10 at 5 mm), the one point that covers the whole view
  // at d (at its pixel centres), has its whole-view error at d, 2d, 4d predicted. The planner
  // asks for the rays to the screen's very corner, so at h = 5 mm it wants 10 x 11 (the v edge
  // needs 17.53 mm, 13 x 10 reaches 17.5).
  const PlanInput in = PlanInputFromScene(LoadScene("default"));
  int full = 0;
  for (const auto& row : ReadCsv(kSource + "/docs/study/default-quick/study.csv")) {
    const PlanSetting s = SettingOf(row);
    const double covered = std::stod(row.at("covered_d"));
    if (SettingCovers(in, s)) {
      EXPECT_GT(covered, 0.999) << row.at("key");
    }
    if (covered < 0.999) {
      EXPECT_FALSE(SettingCovers(in, s)) << row.at("key");
      continue;
    }
    ++full;
    const char* dist[] = {"err_d", "err_2d", "err_4d"};
    for (int k = 0; k < 3; ++k) {
      const double measured = std::stod(row.at(dist[k]));
      const double predicted = PredictError(in, s, in.distance_mm * (1 << k)).total;
      EXPECT_GT(predicted / measured, 1 / kFactor) << dist[k];
      EXPECT_LT(predicted / measured, kFactor) << dist[k];
    }
  }
  EXPECT_EQ(full, 1);
  const Coverage c = RequiredCoverage(in);
  EXPECT_EQ(RequiredPositions(c.u_mm, 5, 1), 10);
  EXPECT_EQ(RequiredPositions(c.v_mm, 5, 1), 11);
}

// Every point of the plane z = D inside the region whose rays GridCovers accepts with an
// unbounded grid (the screen's cone) is covered by the recommended grid; one row fewer fails.
void CheckCovers(const std::string& scene_file, const PlanInput& in, const PlanSetting& s) {
  SynthScene scene = LoadScene(scene_file);
  scene.k_max = s.k_max;
  scene.grid = {s.nu, s.nv, s.h_mm};
  const SlabInfo info = TruthSlabInfo(scene, 32);
  SlabInfo huge = info;
  huge.grid = {999, 999, s.h_mm};
  SlabInfo fewer_u = info, fewer_v = info;
  fewer_u.grid.nu -= 2;
  fewer_v.grid.nv -= 2;
  int inside = 0, lost_u = 0, lost_v = 0;
  for (const double D : {in.distance_mm, in.D()}) {
    const double half_w =
        (D == in.distance_mm ? in.screen_w_mm : in.screen_w_mm * D / in.distance_mm) / 2;
    const double half_h =
        (D == in.distance_mm ? in.screen_h_mm : in.screen_h_mm * D / in.distance_mm) / 2;
    const int n = 80;
    for (int a = 0; a <= n; ++a) {
      for (int b = 0; b <= n; ++b) {
        const Eigen::Vector3d x(-half_w + 2 * half_w * a / n, -half_h + 2 * half_h * b / n, D);
        if (!GridCovers(scene.luminaire, huge, x)) continue;
        ++inside;
        EXPECT_TRUE(GridCovers(scene.luminaire, info, x))
            << scene_file << " " << x.transpose() << " with " << s.nu << "x" << s.nv;
        lost_u += !GridCovers(scene.luminaire, fewer_u, x);
        lost_v += !GridCovers(scene.luminaire, fewer_v, x);
      }
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_GT(lost_u, 0) << "the recommended grid is wider than it needs to be";
  EXPECT_GT(lost_v, 0) << "the recommended grid is taller than it needs to be";
}

TEST(Plan, RecommendedGridCoversPerGridCovers) {
  for (const std::string& scene :
       {std::string("default"), kSource + "/docs/study/wide-quick/scene.json"}) {
    for (const double target : {0.005, 0.012}) {
      PlanInput in = PlanInputFromScene(LoadScene(scene));
      in.receiver_mm = 2 * in.distance_mm;
      in.target = target;
      const Plan p = MakePlan(in);
      EXPECT_TRUE(p.covers);
      CheckCovers(scene, in, p.setting);
      // The region the screen holds at D: every point inside is covered by the recommended
      // grid; a little beyond its edges some are not, whatever the grid.
      SynthScene sc = LoadScene(scene);
      sc.grid = {p.setting.nu, p.setting.nv, p.setting.h_mm};
      const SlabInfo info = TruthSlabInfo(sc, 32);
      SlabInfo huge = info;
      huge.grid = {999, 999, p.setting.h_mm};
      const double hw = p.roi_max.u_mm / 2, hh = p.roi_max.v_mm / 2, D = in.D();
      EXPECT_GT(hw, 0.9 * in.screen_w_mm);  // at 2d most of the screen x 2
      for (int a = 0; a <= 40; ++a) {
        for (int b = 0; b <= 40; ++b) {
          const Eigen::Vector3d x(-hw + 2 * hw * a / 40, -hh + 2 * hh * b / 40, D);
          EXPECT_TRUE(GridCovers(sc.luminaire, info, x)) << x.transpose();
        }
      }
      // (The region is symmetric, the light need not be: one side or the other loses.)
      auto held = [&](double px, double py) {
        return GridCovers(sc.luminaire, huge, Eigen::Vector3d(px, py, D));
      };
      EXPECT_FALSE(held(hw + 3, 0) && held(-hw - 3, 0));
      EXPECT_FALSE(held(0, hh + 3) && held(0, -hh - 3));
    }
  }
}

TEST(Plan, RecommendationMeetsTheTargetAtLeastCost) {
  PlanInput in = PlanInputFromScene(LoadScene("default"));
  in.target = 0.002;  // at d: the slab term decides
  const Plan p = MakePlan(in);
  EXPECT_TRUE(p.reachable);
  EXPECT_TRUE(p.warnings.empty());
  EXPECT_LE(p.at_D.total, in.target);
  EXPECT_DOUBLE_EQ(p.lab_s, p.setting.positions() * (2 + 2 * 0.5));
  // No covering setting with fewer positions meets the target at any slab resolution up to the
  // maximum (the search's claim, checked by brute force over h).
  for (double h = 0.5; h <= in.h_max_mm; h += 0.5) {
    PlanSetting s = p.setting;
    s.h_mm = h;
    const Coverage c = RequiredCoverage(in);
    s.nu = RequiredPositions(c.u_mm, h, s.k_max);
    s.nv = RequiredPositions(c.v_mm, h, s.k_max);
    s.resolution = in.resolution_max;
    if (s.positions() < p.setting.positions()) {
      EXPECT_GT(PredictError(in, s, in.D()).total, in.target) << "h " << h;
    }
  }
  // A looser target never costs more.
  PlanInput loose = in;
  loose.target = 0.01;
  EXPECT_LE(MakePlan(loose).setting.positions(), p.setting.positions());
}

TEST(Plan, ParallaxFloorMakesTargetsAwayFromDOutOfReach) {
  PlanInput in = PlanInputFromScene(LoadScene("default"));
  in.receiver_mm = 4 * in.distance_mm;
  in.target = 0.001;  // below the 4d parallax error (0.94 % measured)
  const Plan p = MakePlan(in);
  EXPECT_FALSE(p.reachable);
  ASSERT_EQ(p.warnings.size(), 1u);
  EXPECT_NE(p.warnings[0].find("parallax"), std::string::npos) << p.warnings[0];
  EXPECT_TRUE(p.covers);  // the setting shown still covers
  // The same target at d is reachable.
  in.receiver_mm = 0;
  EXPECT_TRUE(MakePlan(in).reachable);
  // h does not move the parallax term (docs/method.md §4.5).
  PlanSetting a = p.setting, b = p.setting;
  a.h_mm = 2.5;
  b.h_mm = 10;
  EXPECT_DOUBLE_EQ(PredictError(in, a, 3000).parallax, PredictError(in, b, 3000).parallax);
}

// The recommendation measured end to end: lumislab-study on the default scene with the planner's
// grid for 1 % at 2d (extent x1) and the same h at half the span (x0.5, cheaper): the recommended
// grid covers the view at d, meets the target at 2d and is predicted within the stated factor at
// d, 2d and 4d; the cheaper one does not cover and misses the target.
TEST(Plan, RecommendationMeasuredByTheStudy) {
  PlanInput in = PlanInputFromScene(LoadScene("default"));
  in.receiver_mm = 2 * in.distance_mm;
  in.target = 0.01;
  const Plan p = MakePlan(in);
  ASSERT_TRUE(p.reachable);
  const std::string dir = FreshDir("plan_measured");
  nlohmann::json scene = nlohmann::json::parse(DefaultSceneJson());
  scene["setup"]["grid"] = {
      {"nu", p.setting.nu}, {"nv", p.setting.nv}, {"spacing_mm", p.setting.h_mm}};
  scene["filter"]["k_max"] = p.setting.k_max;
  WriteFile(dir + "/scene.json", scene.dump(2));
  const CommandResult r = RunTool(
      "lumislab-study", "--scene " + ShellQuote(dir + "/scene.json") +
                            " --quick --knobs extent --values 2 --render-size 24 --resolution " +
                            std::to_string(p.setting.resolution) + " --samples " +
                            std::to_string(p.setting.samples) + " --threads 2 --out " +
                            ShellQuote(dir + "/study"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = ReadCsv(dir + "/study/study.csv");
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    const PlanSetting s = SettingOf(row);
    if (row.at("value") == "x1") {
      EXPECT_EQ(s.positions(), p.setting.positions());
      EXPECT_TRUE(SettingCovers(in, s));
      EXPECT_GT(std::stod(row.at("covered_d")), 0.999);
      EXPECT_LE(std::stod(row.at("err_2d")), in.target);
      const char* dist[] = {"err_d", "err_2d", "err_4d"};
      for (int k = 0; k < 3; ++k) {
        const double measured = std::stod(row.at(dist[k]));
        const double predicted = PredictError(in, s, in.distance_mm * (1 << k)).total;
        std::printf("recommended %dx%d at h %g: %s predicted %.3g %%, measured %.3g %%\n", s.nu,
                    s.nv, s.h_mm, dist[k], 100 * predicted, 100 * measured);
        EXPECT_GT(predicted / measured, 1 / kFactor) << dist[k];
        EXPECT_LT(predicted / measured, kFactor) << dist[k];
      }
    } else {
      EXPECT_LT(s.positions(), p.setting.positions());
      EXPECT_FALSE(SettingCovers(in, s));
      EXPECT_LT(std::stod(row.at("covered_d")), 0.999);
      EXPECT_GT(std::stod(row.at("err_2d")), in.target);
    }
  }
}

TEST(PlanCli, TableJsonWarningsAndBadInput) {
  const std::string dir = FreshDir("plan_cli");
  const std::string json = dir + "/plan.json";
  CommandResult r =
      RunTool("lumislab-plan", "--scene default --target 0.5% --json " + ShellQuote(json));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("positions"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("lab time"), std::string::npos) << r.output;
  const nlohmann::json j = nlohmann::json::parse(ReadBinaryFile(json));
  EXPECT_TRUE(j["reachable"].get<bool>());
  EXPECT_TRUE(j["covers"].get<bool>());
  EXPECT_LE(j["error_at_D"]["total"].get<double>(), 0.005);
  EXPECT_EQ(j["setting"]["positions"].get<int>(),
            j["setting"]["nu"].get<int>() * j["setting"]["nv"].get<int>());

  // By size and depth; out of reach at 4d: exit 0, a warning naming the parallax term.
  r = RunTool("lumislab-plan", "--aperture-mm 3,2 --depth-mm 20 --target 0.1% --receiver-mm 3000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("out of reach"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("NOT met"), std::string::npos) << r.output;

  // Evaluate an under-covering grid: a warning.
  r = RunTool("lumislab-plan", "--scene default --h 5 --nu 9 --nv 7 --resolution 48");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("does not cover"), std::string::npos) << r.output;

  // A region of interest the screen cannot hold: a warning.
  r = RunTool("lumislab-plan", "--scene default --receiver-mm 1500 --roi-mm 2500,2000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("beyond what the screen holds"), std::string::npos) << r.output;
  r = RunTool("lumislab-plan", "--scene default --receiver-mm 1500 --roi-mm 1000,1000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;

  // h beyond the calibrated range: a warning, with the measured counter-example.
  r = RunTool("lumislab-plan", "--scene default --h 20");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("outside the model's calibrated range"), std::string::npos) << r.output;

  // Bad input: exit 2 naming the option, no JSON written.
  const std::string bad = dir + "/bad.json";
  struct Case {
    std::string args, name;
  };
  for (const Case& c :
       std::vector<Case>{{"--scene default --target 2", "--target"},
                         {"--scene default --target abc%", "--target"},
                         {"--aperture-mm 3,x --depth-mm 20", "--aperture-mm"},
                         {"--depth-mm 20", "--aperture-mm"},
                         {"--aperture-mm 3", "--depth-mm"},
                         {"--aperture-mm 3 --depth-mm 20 --screen-mm 0", "--screen-mm"},
                         {"--scene default --aperture-mm 3", "--scene"},
                         {"--scene default --nu 5", "--h"},
                         {"--scene /nonexistent/scene.json", "scene.json"},
                         {"--scene default --k-max 9", "--k-max"}}) {
    r = RunTool("lumislab-plan", c.args + " --json " + ShellQuote(bad));
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.name), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_EQ(ReadBinaryFile(bad), "") << c.args;
  }
  r = RunTool("lumislab-plan", "--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.output.find("--receiver-mm"), std::string::npos);
}

}  // namespace
}  // namespace lumislab
