// pipelines/batch-convert.sh and pipelines/Snakefile on three tiny synthetic datasets, one of
// them broken (a photo cut short): two converted, the broken one reported with its reason, exit
// code 1; a rerun rewrites nothing; Snakemake plans the same jobs and runs them.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "core/slab_compare.h"
#include "test_util.h"

namespace lumislab {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::ShellQuote;

// A 2 x 2 grid photographed at 400 x 300 pixels: a dataset in about half a second.
const char* kTinyScene = R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 2, "nv": 2, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8} ] },
  "camera": {"size_px": [400, 300], "focal_px": 330, "position_mm": [0, -100, 2400],
             "look_at_mm": [0, 0, 750]},
  "effects": [] })";

// Runs `command` through sh in `cwd` with the build's binaries; stdout and stderr together.
CommandResult RunIn(const std::string& cwd, const std::string& command) {
  const std::string cmd = "cd " + ShellQuote(cwd) +
                          " && LUMISLAB_BIN=" + ShellQuote(LUMISLAB_BIN_DIR) + " " + command +
                          " 2>&1";
  return testing::RunShell(cmd);
}

std::string Pipelines() { return std::string(LUMISLAB_SOURCE_DIR) + "/pipelines"; }
// The IES/EULUMDAT files name the lab and the maker: the batch refuses to make them up.
const char kLab[] = " --lab 'Batch Lab' --manufacturer Maker";
std::string BatchConvert() { return ShellQuote(Pipelines() + "/batch-convert.sh"); }
std::string Snakemake() {
  return "snakemake -s " + ShellQuote(Pipelines() + "/Snakefile") +
         " --config 'datasets=[data]' out=out 'lab=Batch Lab' manufacturer=Maker --cores 2";
}
bool HaveSnakemake() { return std::system("command -v snakemake >/dev/null 2>&1") == 0; }

// The summary CSV: rows by dataset, fields by the header's names.
using Row = std::map<std::string, std::string>;
std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t k = 0; k < line.size(); ++k) {
    const char c = line[k];
    if (quoted && c == '"' && k + 1 < line.size() && line[k + 1] == '"') {
      fields.back() += '"';
      ++k;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}
std::map<std::string, Row> ReadSummary(const std::string& path) {
  std::istringstream in(testing::ReadBinaryFile(path));
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = SplitCsvLine(line);
  std::map<std::string, Row> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = SplitCsvLine(line);
    EXPECT_EQ(fields.size(), header.size()) << line;
    Row row;
    for (size_t k = 0; k < header.size() && k < fields.size(); ++k) row[header[k]] = fields[k];
    rows[row["dataset"]] = row;
  }
  return rows;
}

// The jobs a dry run plans, as "<stage> <dataset name>": batch-convert.sh prints them so;
// Snakemake prints "rule <stage>:" and then "wildcards: ds=<folder>" or "name=<name>".
std::set<std::string> Lines(const std::string& text) {
  std::set<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.insert(line);
  return lines;
}
std::set<std::string> SnakemakeJobs(const std::string& dry_run) {
  std::set<std::string> jobs;
  std::istringstream in(dry_run);
  std::string rule;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("rule ", 0) == 0) rule = line.substr(5, line.find(':') - 5);
    const size_t w = line.find("wildcards: ");
    if (w == std::string::npos || rule.empty()) continue;
    std::string value = line.substr(line.find('=', w) + 1);
    jobs.insert(rule + " " + fs::path(value).filename().string());
    rule.clear();
  }
  return jobs;
}

class Batch : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One folder per process: ctest runs each test in its own process, side by side.
    root_ = testing::FreshDir("batch_" + std::to_string(getpid()));
    testing::WriteFile(root_ + "/scene.json", kTinyScene);
    // A lux meter's reading in each (truth/reference.json): the calibrate stage scales the slab
    // with it, so that the IES and EULUMDAT files hold candela.
    for (const char* name : {"lamp_a", "lamp_b", "broken"}) {
      const auto r =
          testing::RunTool("lumislab-acquire", "synth --meter lux --scene " + root_ +
                                                   "/scene.json --out " + root_ + "/data/" + name);
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    // A photo cut short, as a failed copy leaves it: reconstruct refuses it (exit 2). Not one of
    // position (1, 0), where the lux meter read (calibrate scale reads those photos).
    fs::resize_file(root_ + "/data/broken/photos/pos_0_1_p.exr", 1000);
  }
  static void TearDownTestSuite() {
    if (!::testing::Test::HasFailure()) fs::remove_all(root_);
  }
  static std::string root_;
};
std::string Batch::root_;

TEST_F(Batch, ConvertsReportsTheBrokenDatasetAndResumes) {
  if (testing::kSanitized)
    GTEST_SKIP() << "runs the tools many times over; the Release build's (the tools' own tests "
                    "run sanitized)";
  // Before anything ran: four stages for each of the three datasets.
  const CommandResult plan = RunIn(root_, BatchConvert() + " data --out out --dry-run" + kLab);
  ASSERT_EQ(plan.exit_code, 0) << plan.output;
  EXPECT_EQ(Lines(plan.output).size(), 12u) << plan.output;
  EXPECT_EQ(Lines(plan.output).count("reconstruct broken"), 1u) << plan.output;

  const CommandResult first = RunIn(root_, BatchConvert() + " data --out out --jobs 2" + kLab);
  ASSERT_EQ(first.exit_code, 1) << first.output;
  // The table names the failing stage and the tool's reason (the photo).
  EXPECT_NE(first.output.find("reconstruct (exit 2)"), std::string::npos) << first.output;
  EXPECT_NE(first.output.find("pos_0_1_p.exr"), std::string::npos) << first.output;
  auto rows = ReadSummary(root_ + "/out/summary.csv");
  ASSERT_EQ(rows.size(), 3u);
  for (const char* name : {"lamp_a", "lamp_b"}) {
    const Row& row = rows[name];
    EXPECT_EQ(row.at("status"), "ok") << name;
    EXPECT_EQ(row.at("positions"), "4/4") << name;
    EXPECT_EQ(row.at("ran"), "calibrate reconstruct export preview") << name;
    EXPECT_EQ(row.at("failure"), "") << name;
    for (const char* stage : {"calibrate_s", "reconstruct_s", "export_s", "preview_s"})
      EXPECT_GT(std::stod(row.at(stage)), 0) << name << " " << stage;
    // The error the summary reports is the slab's against truth/ (core/slab_compare.h), and a
    // noise-free capture is reconstructed within 0.5 % (EndToEnd's bound for the default scene).
    const std::string ds = root_ + "/data/" + name;
    const SlabComparison c = CompareSlabs(ds + "/slab", ds + "/truth");
    EXPECT_NEAR(std::stod(row.at("error_overall_pct")), 100 * c.overall_relative_l2, 0.001);
    EXPECT_NEAR(std::stod(row.at("error_max_pct")), 100 * c.max_relative_l2, 0.001);
    EXPECT_LT(c.overall_relative_l2, 0.005) << name;
    for (const std::string& file :
         {"/" + std::string(name) + ".ies", "/" + std::string(name) + ".ldt",
          std::string("/polar.png"), std::string("/irradiance_1500mm.png"),
          std::string("/preview.png")}) {
      EXPECT_TRUE(fs::is_regular_file(root_ + "/out/" + name + file)) << name << file;
      EXPECT_NE(row.at("outputs").find(name + file), std::string::npos) << row.at("outputs");
    }
    // The IES file holds the slab's far field: a lab's reader finds positive flux in it.
    const auto info = testing::RunTool(
        "lumislab-export", "info --json " + root_ + "/out/" + name + "/" + name + ".ies");
    EXPECT_EQ(info.exit_code, 0) << info.output;
    EXPECT_NE(info.output.find("\"flux\""), std::string::npos) << info.output;
    // Candela (the lux meter's scale), the lab as given, the coverage stated (issue 29).
    EXPECT_NE(info.output.find("\"photometric\": true"), std::string::npos) << info.output;
    EXPECT_NE(info.output.find("\"TESTLAB\": \"Batch Lab\""), std::string::npos) << info.output;
    EXPECT_NE(info.output.find("\"coverage\": \"partial: "), std::string::npos) << info.output;
  }
  const Row& broken = rows["broken"];
  EXPECT_EQ(broken.at("status"), "failed");
  EXPECT_EQ(broken.at("ran"), "calibrate reconstruct");
  EXPECT_EQ(broken.at("failure").rfind("reconstruct (exit 2): ", 0), 0u) << broken.at("failure");
  EXPECT_NE(broken.at("failure").find("pos_0_1_p.exr"), std::string::npos);
  EXPECT_FALSE(fs::exists(root_ + "/out/broken/preview.png"));
  EXPECT_TRUE(fs::is_regular_file(root_ + "/out/log/broken/reconstruct.log"));
  EXPECT_TRUE(testing::TemporaryPaths(testing::SnapshotTree(root_ + "/out")).empty());

  // Only the broken dataset's stages from reconstruct on are left, and Snakemake, which decides
  // by the same rules, plans the same jobs.
  const CommandResult left = RunIn(root_, BatchConvert() + " data --out out -n" + kLab);
  EXPECT_EQ(Lines(left.output),
            (std::set<std::string>{"reconstruct broken", "export broken", "preview broken"}))
      << left.output;

  // A rerun does no work for the converted datasets: their folders, outputs and logs are left
  // byte for byte and untouched in time (SnapshotTree hashes every file; the listing below
  // checks modification times).
  const auto before_a = testing::SnapshotTree(root_ + "/data/lamp_a");
  const auto before_out = testing::SnapshotTree(root_ + "/out/lamp_a");
  const auto before_log = testing::SnapshotTree(root_ + "/out/log/lamp_b");
  const auto time_ies = fs::last_write_time(root_ + "/out/lamp_a/lamp_a.ies");
  const auto time_slab = fs::last_write_time(root_ + "/data/lamp_b/slab/slab.json");
  const auto first_rows = rows;
  const CommandResult again = RunIn(root_, BatchConvert() + " data --out out --jobs 2" + kLab);
  EXPECT_EQ(again.exit_code, 1) << again.output;
  EXPECT_TRUE(
      testing::DiffSnapshots(before_a, testing::SnapshotTree(root_ + "/data/lamp_a")).empty());
  EXPECT_TRUE(
      testing::DiffSnapshots(before_out, testing::SnapshotTree(root_ + "/out/lamp_a")).empty());
  EXPECT_TRUE(
      testing::DiffSnapshots(before_log, testing::SnapshotTree(root_ + "/out/log/lamp_b")).empty());
  EXPECT_EQ(fs::last_write_time(root_ + "/out/lamp_a/lamp_a.ies"), time_ies);
  EXPECT_EQ(fs::last_write_time(root_ + "/data/lamp_b/slab/slab.json"), time_slab);
  rows = ReadSummary(root_ + "/out/summary.csv");
  EXPECT_EQ(rows["lamp_a"].at("ran"), "");
  // The summary still describes the converted datasets: the times and error of the earlier run.
  for (const char* field : {"status", "positions", "error_overall_pct", "reconstruct_s", "outputs"})
    EXPECT_EQ(rows["lamp_b"].at(field), first_rows.at("lamp_b").at(field)) << field;
  EXPECT_EQ(rows["broken"].at("ran"), "reconstruct");
  EXPECT_EQ(rows["broken"].at("status"), "failed");

  if (!HaveSnakemake())
    GTEST_SKIP() << "snakemake is not installed (Debian: apt install snakemake): the Snakefile's "
                    "dry run and run are not checked";
  const CommandResult dry = RunIn(root_, Snakemake() + " -n");
  ASSERT_EQ(dry.exit_code, 0) << dry.output;
  EXPECT_EQ(SnakemakeJobs(dry.output), Lines(left.output)) << dry.output;

  // A real run: one lost output is redone (and only it, of the converted datasets); the broken
  // dataset fails again; the summary is written at the end.
  fs::remove(root_ + "/out/lamp_b/preview.png");
  const auto ies_time = fs::last_write_time(root_ + "/out/lamp_b/lamp_b.ies");
  const CommandResult run = RunIn(root_, Snakemake() + " --keep-going");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_TRUE(fs::is_regular_file(root_ + "/out/lamp_b/preview.png")) << run.output;
  EXPECT_EQ(fs::last_write_time(root_ + "/out/lamp_b/lamp_b.ies"), ies_time);
  EXPECT_NE(run.output.find("reconstruct (exit 2)"), std::string::npos) << run.output;
  EXPECT_EQ(Lines(RunIn(root_, BatchConvert() + " data --out out -n" + kLab).output),
            (std::set<std::string>{"reconstruct broken", "export broken", "preview broken"}));
}

// A dataset folder named x'$(touch PWNED)' and config values with an apostrophe, "$(...)" and
// backquotes: the Snakefile passes each to the tools as it is written (every rule converts the
// dataset, the IES file holds the values), and nothing in them is run.
TEST_F(Batch, SnakefileQuotesFolderNamesAndConfigValues) {
  if (!HaveSnakemake())
    GTEST_SKIP() << "snakemake is not installed (Debian: apt install snakemake)";
  const std::string name = "x'$(touch PWNED)'";
  const auto synth = testing::RunTool(
      "lumislab-acquire", "synth --meter lux --scene " + ShellQuote(root_ + "/scene.json") +
                              " --out " + ShellQuote(root_ + "/odd/" + name));
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string lab = "O'Brien's lab", manufacturer = "ACME $(touch PWNED) `touch PWNED`";
  const CommandResult run =
      RunIn(root_, "snakemake -s " + ShellQuote(Pipelines() + "/Snakefile") +
                       " --config 'datasets=[odd]' out=odd_out " + ShellQuote("lab=" + lab) + " " +
                       ShellQuote("manufacturer=" + manufacturer) + " --cores 2");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const std::string ies = testing::ReadBinaryFile(root_ + "/odd_out/" + name + "/" + name + ".ies");
  EXPECT_NE(ies.find("[TESTLAB] " + lab), std::string::npos) << run.output;
  EXPECT_NE(ies.find("[MANUFAC] " + manufacturer), std::string::npos) << run.output;
  for (const char* file : {"polar.png", "preview.png"})
    EXPECT_TRUE(fs::is_regular_file(root_ + "/odd_out/" + name + "/" + file)) << file;
  EXPECT_EQ(ReadSummary(root_ + "/odd_out/summary.csv")[name]["status"], "ok");
  std::vector<std::string> ran;
  for (const auto& entry : fs::recursive_directory_iterator(root_))
    if (entry.path().filename() == "PWNED") ran.push_back(entry.path().string());
  EXPECT_TRUE(ran.empty()) << ran.front();
}

// issue 28: a dataset named summary.csv would take the summary's place: refused (exit 2) naming
// it, nothing written. --jobs above the core count uses the cores, with a notice, so that no tool
// gets more threads than it accepts; a dataset named in Latin-1 converts like any other.
TEST_F(Batch, RefusesTheSummarysNameAndClampsJobs) {
  if (testing::kSanitized)
    GTEST_SKIP() << "runs the tools many times over; the Release build's (the tools' own tests "
                    "run sanitized)";
  const std::string dir = root_ + "/names";
  fs::create_directories(dir + "/in");
  fs::copy(root_ + "/data/lamp_a", dir + "/in/summary.csv", fs::copy_options::recursive);
  const CommandResult clash = RunIn(dir, BatchConvert() + " in --out out");
  EXPECT_EQ(clash.exit_code, 2) << clash.output;
  EXPECT_NE(clash.output.find("in/summary.csv: a dataset cannot be named summary.csv"),
            std::string::npos)
      << clash.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));

  const std::string latin1 = "lamp_caf\xe9";
  fs::create_directories(dir + "/l1");
  fs::copy(root_ + "/data/lamp_a", dir + "/l1/" + latin1, fs::copy_options::recursive);
  const CommandResult run = RunIn(dir, BatchConvert() + " l1 --out out1 --jobs 9999" + kLab);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("--jobs 9999 is more than the"), std::string::npos) << run.output;
  auto rows = ReadSummary(dir + "/out1/summary.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[latin1]["status"], "ok");
  EXPECT_TRUE(fs::exists(dir + "/out1/" + latin1 + "/" + latin1 + ".ies"));
  // Issue 29: without a lab and a maker the export stage fails, naming them (it wrote
  // "[TESTLAB] unspecified" and reported ok).
  const CommandResult nolab = RunIn(dir, BatchConvert() + " l1 --out out2");
  EXPECT_EQ(nolab.exit_code, 1) << nolab.output;
  rows = ReadSummary(dir + "/out2/summary.csv");
  EXPECT_EQ(rows[latin1]["status"], "failed");
  EXPECT_NE(rows[latin1]["failure"].find("give --lab and --manufacturer"), std::string::npos)
      << rows[latin1]["failure"];
  EXPECT_FALSE(fs::exists(dir + "/out2/" + latin1 + "/" + latin1 + ".ies"));
}

}  // namespace
}  // namespace lumislab
