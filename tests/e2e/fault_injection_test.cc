// Fault injection: each tool is killed with SIGKILL at seeded random points of its work, then the
// same command is run again, and
//   (a) the rerun exits 0,
//   (b) the outputs are byte-identical to those of one uninterrupted run,
//   (c) no temporary file (a name starting with '.', docs/architecture.md §7.5) is left anywhere
//   under
//       the folder the tool writes into.
// The tools: `lumislab-acquire synth` (3x3 grid, 640x480 photos), `lumislab-calibrate screen`,
// `lumislab-reconstruct` (60x60) and `lumislab-preview --watch` following a slab that a feeder
// thread writes position by position while it runs.
//
// Every run happens in the same folder (so that no output can differ by an embedded path), the
// uninterrupted reference run is timed first and the kill delays are spread over the shorter of
// it and the second uninterrupted run below, when that one runs as the kill runs do (stratified:
// one uniformly drawn delay in each of n equal slices of it, from a fixed seed): a tool that runs
// for tens of milliseconds (calibrate) varies by a factor of two between runs, and delays spread
// over its slowest run would mostly fall after a faster run had ended.
// A second uninterrupted run checks that the tool is deterministic at all, so that a difference
// after a kill is not mistaken for one the kill caused (for the preview that run gets the
// positions faster than it polls, several at a time). 36 kill points in all (8 acquire,
// 8 calibrate, 10 reconstruct, 10 preview). Only the processes this test starts are ever
// signalled, by their pid. A failing test keeps its folder (logs/ holds every run's output).
//
// Run alone: ctest -L fault_injection.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/exr_io.h"
#include "test_util.h"

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::SnapshotTree;
using testing::TreeSnapshot;
using testing::WriteBinaryFile;

constexpr uint32_t kSeed = 20240611;
constexpr double kRunTimeoutS = 60;  // any single run; past it the run is killed and fails

// A 3x3 grid with 640x480 half-float EXR photos.
std::string Scene() {
  json scene = {{"schema_version", 1},
                {"setup",
                 {{"distance_mm", 750},
                  {"grid", {{"nu", 3}, {"nv", 3}, {"spacing_mm", 5}}},
                  {"screen_mm", {1200, 1200}}}},
                {"luminaire",
                 {{"emitters",
                   {{{"position_mm", {1.5, -2, -20}},
                     {"intensity_w_sr", {1.0, 0.9, 0.8}},
                     {"lobe_exponent", 8}},
                    {{"position_mm", {-3, 1, -12}},
                     {"intensity_w_sr", {0.5, 0.6, 0.9}},
                     {"lobe_exponent", 3}}}}}},
                {"camera",
                 {{"size_px", {640, 480}},
                  {"focal_px", 560},
                  {"position_mm", {0, -200, 2400}},
                  {"look_at_mm", {0, 0, 750}}}},
                {"effects", json::array()}};
  return scene.dump(2) + "\n";
}

struct Outcome {
  int exit_code = -1;   // 128 + signal when killed
  bool killed = false;  // the kill landed (the process was still running)
  double seconds = 0;   // wall time until it ended
  std::string output;   // stdout and stderr
};

// Runs build/bin/<tool> <args> in `cwd` (output into `log`); when kill_after_s >= 0 sends SIGKILL
// to that process (and only to it) once that many seconds have passed.
Outcome Spawn(const std::string& cwd, const std::string& tool, const std::vector<std::string>& args,
              const std::string& log, double kill_after_s = -1) {
  testing::ToolProcess process(cwd, tool, args, log);
  Outcome outcome;
  if (!process.started()) return outcome;
  const double first_stop = kill_after_s >= 0 ? std::min(kill_after_s, kRunTimeoutS) : kRunTimeoutS;
  if (!process.WaitFor(first_stop)) {
    outcome.killed = process.Signal(SIGKILL);
    process.WaitFor(kRunTimeoutS);
  }
  outcome.seconds = process.Elapsed();
  outcome.exit_code = process.exit_code();
  outcome.killed = outcome.killed && process.signalled();
  outcome.output = ReadBinaryFile(log);
  return outcome;
}

// The snapshot without temporary names (what (b) compares).
TreeSnapshot Final(const TreeSnapshot& snapshot) {
  TreeSnapshot out = snapshot;
  for (const auto& t : testing::TemporaryPaths(snapshot)) out.erase(t);
  // checks.json is the stages' report, stamped with the time of each run (core/checks.h): its
  // outcomes are what the rerun must reproduce, not its bytes.
  for (auto it = out.begin(); it != out.end();)
    it = fs::path(it->first).filename() == "checks.json" ? out.erase(it) : std::next(it);
  return out;
}

std::string Lines(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& item : items) s += "    " + item + "\n";
  return s;
}

// For differing EXR files: how far apart their R, G, B values are (largest absolute and
// relative difference), so that a report can tell rounding from a wrong image.
std::string ExrDistance(const std::string& a, const std::string& b) {
  try {
    const ImageF x = ReadExr(a, {"R", "G", "B"}), y = ReadExr(b, {"R", "G", "B"});
    if (x.data.size() != y.data.size()) return "different sizes";
    double abs_diff = 0, rel_diff = 0, peak = 0;
    size_t differing = 0;
    for (size_t k = 0; k < x.data.size(); ++k) {
      const double d = std::abs(double(x.data[k]) - double(y.data[k]));
      peak = std::max(peak, std::abs(double(x.data[k])));
      abs_diff = std::max(abs_diff, d);
      if (d > 0) {
        ++differing;
        rel_diff = std::max(rel_diff, d / std::max(std::abs(double(x.data[k])), 1e-30));
      }
    }
    std::ostringstream os;
    os << differing << " of " << x.data.size() << " values differ, largest difference " << abs_diff
       << " (peak value " << peak << "), largest relative difference " << rel_diff;
    return os.str();
  } catch (const std::exception& e) {
    return std::string("cannot compare: ") + e.what();
  }
}

// Delays spread over [0, total): one uniform draw in each of n equal slices.
std::vector<double> KillDelays(int n, double total, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> delays;
  for (int k = 0; k < n; ++k) delays.push_back(total * (k + u(rng)) / n);
  return delays;
}

// One tool under test: how to reset the work folder before a run, the command, and which folder
// holds its outputs (compared byte for byte, and searched for temporary names).
struct Subject {
  std::string name;
  std::string root;  // the test's folder
  std::string cwd;   // where the tool runs (every run: the same folder)
  std::string tool;
  std::vector<std::string> args;
  std::string outputs;               // compared and searched for temporary files, relative to root
  std::function<void()> reset;       // back to the state before the tool's first run
  std::function<void()> before_run;  // starts whatever runs beside the tool (the feeder)
  std::function<void()> after_run;   // waits for it
  // Called with true before the second uninterrupted run, with false after it: a subject whose
  // result could depend on timing runs it differently there (the feeder's pace).
  std::function<void(bool)> vary;
  int kill_points = 8;
  uint32_t seed_offset = 0;  // the delays come from kSeed + seed_offset
};

// The reference run, a determinism check, then the kill points; every problem is an EXPECT
// failure naming the kill point, and a table of all of them is printed.
void Exercise(const Subject& s) {
  const std::string logs = s.root + "/logs";
  fs::create_directories(logs);
  auto run = [&](const std::string& label, double kill_after_s) {
    if (s.before_run) s.before_run();
    const Outcome o = Spawn(s.cwd, s.tool, s.args, logs + "/" + label + ".log", kill_after_s);
    if (s.after_run && kill_after_s < 0) s.after_run();
    return o;
  };
  const std::string out_dir = s.root + "/" + s.outputs;

  // The reference: one uninterrupted run.
  s.reset();
  const Outcome reference = run("reference", -1);
  ASSERT_EQ(reference.exit_code, 0) << reference.output;
  const TreeSnapshot expected = SnapshotTree(out_dir);
  ASSERT_FALSE(expected.empty());
  EXPECT_TRUE(testing::TemporaryPaths(expected).empty())
      << "temporary files after an uninterrupted run:\n"
      << Lines(testing::TemporaryPaths(expected));
  const std::string kept = s.root + "/reference_outputs";
  fs::copy(out_dir, kept, fs::copy_options::recursive);
  std::printf("%s: uninterrupted run %.3f s, %zu entries under %s\n", s.name.c_str(),
              reference.seconds, expected.size(), s.outputs.c_str());

  // Determinism: a second uninterrupted run gives the same bytes.
  s.reset();
  if (s.vary) s.vary(true);
  const Outcome again = run("reference_again", -1);
  if (s.vary) s.vary(false);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const auto nondeterministic =
      testing::DiffSnapshots(Final(expected), Final(SnapshotTree(out_dir)));
  EXPECT_TRUE(nondeterministic.empty())
      << s.name << ": two uninterrupted runs differ (not caused by a kill):\n"
      << Lines(nondeterministic);

  // The kill points, spread over the shorter uninterrupted run (the file's header says why); the
  // reference's alone where the second run was varied (s.vary), which changes its time.
  const double total = s.vary ? reference.seconds : std::min(reference.seconds, again.seconds);
  // The sanitized build kills at a third of the points (at least 3), still spread over the
  // whole run (stratified): each kill is two more runs of a tool several times slower there.
  const int kill_points =
      testing::kSanitized ? std::max(3, (s.kill_points + 2) / 3) : s.kill_points;
  const std::vector<double> delays = KillDelays(kill_points, total, kSeed + s.seed_offset);
  int landed = 0;
  std::string table;
  for (int k = 0; k < int(delays.size()); ++k) {
    s.reset();
    const std::string label = "kill" + std::to_string(k);
    const Outcome killed = run(label, delays[k]);
    // The state the kill left, for the record.
    const TreeSnapshot left = SnapshotTree(out_dir);
    const size_t temporaries_left = testing::TemporaryPaths(left).size();
    // (a) The same command again at once, to completion (a feeder started with the killed run
    // goes on writing beside it).
    const Outcome rerun = run(label + "_rerun", -1);
    const TreeSnapshot got = SnapshotTree(out_dir);
    const auto differences = testing::DiffSnapshots(Final(expected), Final(got));
    const auto temporaries = testing::TemporaryPaths(got);
    std::string distances;
    for (const auto& d : differences) {
      const std::string path = d.substr(0, d.find(": "));
      if (path.size() > 4 && path.substr(path.size() - 4) == ".exr" &&
          fs::exists(kept + "/" + path))
        distances +=
            "    " + path + ": " + ExrDistance(kept + "/" + path, out_dir + "/" + path) + "\n";
    }
    landed += killed.killed;
    char line[512];
    std::snprintf(line, sizeof(line),
                  "  %-12s kill %d at %.3f s: %s (exit %d), %zu temporaries after the kill; "
                  "rerun exit %d in %.3f s, %zu differences, %zu temporaries\n",
                  s.name.c_str(), k, delays[k], killed.killed ? "killed" : "had already ended",
                  killed.exit_code, temporaries_left, rerun.exit_code, rerun.seconds,
                  differences.size(), temporaries.size());
    table += line;
    EXPECT_EQ(rerun.exit_code, 0) << s.name << " kill point " << k << " (" << delays[k]
                                  << " s): the rerun failed\n"
                                  << rerun.output;
    EXPECT_TRUE(differences.empty()) << s.name << " kill point " << k << " (" << delays[k]
                                     << " s): outputs differ from the uninterrupted run:\n"
                                     << Lines(differences) << distances << "rerun output:\n"
                                     << rerun.output;
    EXPECT_TRUE(temporaries.empty()) << s.name << " kill point " << k << " (" << delays[k]
                                     << " s): temporary files left after the rerun:\n"
                                     << Lines(temporaries);
  }
  std::printf("%s", table.c_str());
  // The delays come from the reference run's time; most must land inside the work.
  EXPECT_GE(landed, kill_points / 2)
      << s.name << ": only " << landed << " of " << kill_points << " kills landed";
}

// The test's folder with the scene file; `stage` of the valid dataset made in root/work/ds
// beforehand: 0 none, 1 acquired, 2 calibrated, 3 reconstructed (60x60).
std::string Prepare(const std::string& name, int stage) {
  const std::string root = testing::FreshDir("fault_" + name);
  testing::WriteFile(root + "/scene.json", Scene());
  fs::create_directories(root + "/work");
  auto step = [&](const std::string& tool, const std::vector<std::string>& args) {
    const Outcome o = Spawn(root + "/work", tool, args, root + "/prepare.log");
    EXPECT_EQ(o.exit_code, 0) << tool << "\n" << o.output;
  };
  if (stage >= 1)
    step("lumislab-acquire",
         {"synth", "--scene", "../scene.json", "--out", "ds", "--truth-resolution", "60"});
  if (stage >= 2) step("lumislab-calibrate", {"screen", "--dataset", "ds"});
  if (stage >= 3) step("lumislab-reconstruct", {"--dataset", "ds", "--resolution", "60"});
  return root;
}

TEST(FaultInjection, AcquireSynth) {
  Subject s;
  s.name = "acquire";
  s.root = Prepare("acquire", 0);
  s.cwd = s.root + "/work";
  s.tool = "lumislab-acquire";
  s.args = {"synth", "--scene", "../scene.json", "--out", "ds", "--truth-resolution", "60"};
  // The whole work folder: acquire stages the dataset beside ds/ before it swaps it in.
  s.outputs = "work";
  s.reset = [&] {
    fs::remove_all(s.cwd);
    fs::create_directories(s.cwd);
  };
  Exercise(s);
  if (!::testing::Test::HasFailure()) fs::remove_all(s.root);
}

TEST(FaultInjection, CalibrateScreen) {
  Subject s;
  s.name = "calibrate";
  s.seed_offset = 1;
  s.root = Prepare("calibrate", 1);
  ASSERT_FALSE(::testing::Test::HasFailure()) << "making the valid inputs failed";
  s.cwd = s.root + "/work";
  s.tool = "lumislab-calibrate";
  s.args = {"screen", "--dataset", "ds"};
  // All of ds/: calib/screen.json must be the reference's, and nothing else may change.
  s.outputs = "work/ds";
  s.reset = [&] { fs::remove_all(s.cwd + "/ds/calib"); };
  s.kill_points = 8;
  Exercise(s);
  if (!::testing::Test::HasFailure()) fs::remove_all(s.root);
}

TEST(FaultInjection, Reconstruct) {
  Subject s;
  s.name = "reconstruct";
  s.seed_offset = 2;
  s.kill_points = 10;
  s.root = Prepare("reconstruct", 2);
  ASSERT_FALSE(::testing::Test::HasFailure()) << "making the valid inputs failed";
  s.cwd = s.root + "/work";
  s.tool = "lumislab-reconstruct";
  s.args = {"--dataset", "ds", "--resolution", "60"};
  s.outputs = "work/ds";
  s.reset = [&] { fs::remove_all(s.cwd + "/ds/slab"); };
  Exercise(s);
  if (!::testing::Test::HasFailure()) fs::remove_all(s.root);
}

// Writes the positions of a complete slab into a live slab folder one by one, the way
// reconstruct does: slab.json (with the positions present so far) first, then each EXR under a
// temporary name renamed into place followed by slab.json again, one position every `interval`.
class Feeder {
 public:
  Feeder(std::string source, std::string live, double interval_s)
      : source_(std::move(source)), live_(std::move(live)), interval_s_(interval_s) {}
  ~Feeder() { Join(); }
  void Start() {
    Join();
    thread_ = std::thread([this] { Run(); });
  }
  void Join() {
    if (thread_.joinable()) thread_.join();
  }
  void SetInterval(double interval_s) { interval_s_ = interval_s; }

 private:
  void WriteInfo(const json& present) {
    json info = json::parse(ReadBinaryFile(source_ + "/slab.json"));
    info["present"] = present;
    info["complete"] = false;
    const std::string tmp = live_ + "/.slab.json.feed";
    WriteBinaryFile(tmp, info.dump(2) + "\n");
    fs::rename(tmp, live_ + "/slab.json");
  }
  void Run() {
    const json info = json::parse(ReadBinaryFile(source_ + "/slab.json"));
    const int nu = info["grid"]["nu"], nv = info["grid"]["nv"];
    fs::create_directories(live_);
    json present = json::array();
    WriteInfo(present);
    for (int j = 0; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        std::this_thread::sleep_for(std::chrono::duration<double>(interval_s_));
        const std::string name = "pos_" + std::to_string(i) + "_" + std::to_string(j) + ".exr";
        if (!fs::exists(live_ + "/" + name)) {
          fs::copy_file(source_ + "/" + name, live_ + "/." + name + ".feed",
                        fs::copy_options::overwrite_existing);
          fs::rename(live_ + "/." + name + ".feed", live_ + "/" + name);
        }
        present.push_back({i, j});
        WriteInfo(present);
      }
    }
    // The last slab.json says complete, as reconstruct's does.
    json last = json::parse(ReadBinaryFile(source_ + "/slab.json"));
    const std::string tmp = live_ + "/.slab.json.feed";
    WriteBinaryFile(tmp, last.dump(2) + "\n");
    fs::rename(tmp, live_ + "/slab.json");
  }
  std::string source_, live_;
  double interval_s_;
  std::thread thread_;
};

TEST(FaultInjection, PreviewWatch) {
  Subject s;
  s.name = "preview";
  s.seed_offset = 3;
  s.root = Prepare("preview", 3);
  ASSERT_FALSE(::testing::Test::HasFailure()) << "making the valid inputs failed";
  const std::string source = s.root + "/source";
  fs::rename(s.root + "/work/ds/slab", source);
  fs::remove_all(s.root + "/work");
  s.cwd = s.root + "/live";
  s.tool = "lumislab-preview";
  // The default --size (400x400): writing x.exr takes long enough for kills to land in it.
  s.args = {"--slab",    "slab",    "--scene", "plane", "--out",
            "out/x.exr", "--watch", "--poll",  "0.05"};
  s.kill_points = 10;
  // The render's folder; the slab folder is the feeder's (checked for temporaries below).
  s.outputs = "live/out";
  Feeder feeder(source, s.cwd + "/slab", 0.06);
  s.reset = [&] {
    feeder.Join();
    fs::remove_all(s.cwd);
    fs::create_directories(s.cwd + "/out");
  };
  // The feeder starts with each run that begins on an empty live folder (the reference runs and
  // the killed runs) and goes on through the rerun that follows a kill.
  s.before_run = [&] {
    if (!fs::exists(s.cwd + "/slab")) feeder.Start();
  };
  s.after_run = [&] { feeder.Join(); };
  // The second uninterrupted run: positions arrive faster than the preview polls, several at a
  // time (the reference gets them one per poll).
  s.vary = [&](bool second) { feeder.SetInterval(second ? 0.015 : 0.06); };
  Exercise(s);
  // The render of the complete slab without --watch, for the record: --watch adds positions in
  // batches as they arrive and may sum them in another order.
  const Outcome still =
      Spawn(s.cwd, s.tool, {"--slab", "slab", "--scene", "plane", "--out", "still.exr"},
            s.root + "/logs/still.log");
  ASSERT_EQ(still.exit_code, 0) << still.output;
  const bool same = ReadBinaryFile(s.cwd + "/still.exr") == ReadBinaryFile(s.cwd + "/out/x.exr");
  std::printf("preview: the --watch render %s the render of the complete slab without --watch\n",
              same ? "is byte-identical to" : "DIFFERS from");
  EXPECT_TRUE(testing::TemporaryPaths(SnapshotTree(s.cwd + "/slab")).empty());
  feeder.Join();
  if (!::testing::Test::HasFailure()) fs::remove_all(s.root);
}

}  // namespace
}  // namespace lumislab
