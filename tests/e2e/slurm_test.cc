// The batch workflow (pipelines/Snakefile) through the Slurm profile (pipelines/slurm/) on a real
// one-node Slurm cluster (pipelines/slurm/local-cluster.sh, docs/architecture.md §6), on ten tiny
// synthetic datasets, one broken: every job submitted with the CPUs, memory and time limit that
// the cost model declares for it (pipelines/stage_resources.py), as Slurm's job completion
// records hold them; the broken dataset reported; a rerun submits only what is missing; a
// reconstruct cancelled by scancel is seen to fail and a rerun resumes it; every output byte for
// byte the local run's (pipelines/batch-convert.sh). Prints the jobs, their states and resources.
// Skipped, saying why, where Slurm, munge or Snakemake are not installed or we are not root.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "test_util.h"

namespace lumislab {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::ShellQuote;

// A scene of nu x nv positions photographed at 400 x 300 pixels (a 3 x 3 dataset in about a
// second, reconstructed at slab resolution 48 in a fraction of one).
std::string Scene(int n) {
  return R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": )" +
         std::to_string(n) + R"(, "nv": )" + std::to_string(n) + R"(, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8} ] },
  "camera": {"size_px": [400, 300], "focal_px": 330, "position_mm": [0, -100, 2400],
             "look_at_mm": [0, 0, 750]},
  "effects": [] })";
}

std::string Pipelines() { return std::string(LUMISLAB_SOURCE_DIR) + "/pipelines"; }
const char kStageArgs[] = " --lab 'Slurm Lab' --manufacturer Maker --resolution 48";

// One Slurm job as the completion records (JobCompType=jobcomp/filetxt) hold it.
struct Job {
  std::string id, name, state, dataset;  // dataset: from Snakemake's output
  int cpus = 0, mem_mb = 0, time_min = 0;
};

std::string Field(const std::string& line, const std::string& key) {
  const size_t at = line.find(" " + key + "=");
  if (at == std::string::npos) return "";
  const size_t from = at + key.size() + 2;
  return line.substr(from, line.find(' ', from) - from);
}

std::vector<Job> ReadJobs(const std::string& jobcomp) {
  std::vector<Job> jobs;
  std::istringstream in(testing::ReadBinaryFile(jobcomp));
  for (std::string line; std::getline(in, line);) {
    line = " " + line;
    Job job;
    job.id = Field(line, "JobId");
    job.name = Field(line, "Name");
    job.state = Field(line, "JobState");
    job.time_min = std::atoi(Field(line, "TimeLimit").c_str());
    const std::string tres = Field(line, "Tres");  // cpu=1,mem=350M,node=1,billing=1
    std::smatch m;
    if (std::regex_search(tres, m, std::regex("cpu=(\\d+)"))) job.cpus = std::stoi(m[1]);
    if (std::regex_search(tres, m, std::regex("mem=(\\d+)M"))) job.mem_mb = std::stoi(m[1]);
    if (std::regex_search(tres, m, std::regex("mem=(\\d+)G"))) job.mem_mb = 1024 * std::stoi(m[1]);
    jobs.push_back(job);
  }
  return jobs;
}

// Slurm job id -> "<rule> <dataset name>", from Snakemake's output ("rule reconstruct:",
// "wildcards: ds=data/lamp_00" or "name=lamp_00", "Submitted job 3 with external jobid '12'.").
std::map<std::string, std::string> SubmittedJobs(const std::string& output) {
  std::map<std::string, std::string> jobs;
  std::istringstream in(output);
  std::string rule, dataset;
  const std::regex submitted("Submitted job \\d+ with external jobid '(\\d+)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (line.rfind("rule ", 0) == 0) rule = line.substr(5, line.find(':') - 5);
    const size_t w = line.find("wildcards: ");
    if (w != std::string::npos)
      dataset = fs::path(line.substr(line.find('=', w) + 1)).filename().string();
    if (std::regex_search(line, m, submitted)) jobs[m[1]] = rule + " " + dataset;
  }
  return jobs;
}

class Slurm : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    skip_ = Missing();
    if (!skip_.empty()) return;
    root_ = testing::FreshDir("slurm_" + std::to_string(getpid()));
    cluster_ = root_ + "/cluster";
    // The cluster is stopped however this process ends (a crash, ctest's timeout): a watcher
    // process of its own session waits for this one's end of a pipe to close, then stops it.
    int fds[2];
    // Close-on-exec: the daemons that the tests start must not hold the pipe open.
    ASSERT_EQ(pipe2(fds, O_CLOEXEC), 0);
    watcher_ = fork();
    if (watcher_ == 0) {
      setsid();
      close(fds[1]);
      char c;
      while (read(fds[0], &c, 1) > 0) {
      }
      const std::string stop =
          Pipelines() + "/slurm/local-cluster.sh stop " + ShellQuote(cluster_) + " >/dev/null 2>&1";
      execl("/bin/sh", "sh", "-c", stop.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[0]);
    watch_fd_ = fds[1];
    // Jobs that mostly wait for Snakemake to start: eight at a time on this machine's cores.
    const CommandResult start =
        Run(root_, "LUMISLAB_CLUSTER_CPUS=8 " + Pipelines() + "/slurm/local-cluster.sh start " +
                       ShellQuote(cluster_));
    std::cout << start.output;
    ASSERT_EQ(start.exit_code, 0) << start.output;
  }
  static void TearDownTestSuite() {
    if (watcher_ > 0) {
      close(watch_fd_);  // the watcher stops the cluster
      int status = 0;
      waitpid(watcher_, &status, 0);
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
          << "local-cluster.sh stop left processes running";
    }
    if (!root_.empty() && !::testing::Test::HasFailure()) fs::remove_all(root_);
  }

  // Why the test does not run here, or "" (then the cluster is started).
  static std::string Missing() {
    if (testing::kSanitized)
      return "the sanitized build (the tools run many times over: the Release build's)";
    if (getuid() != 0) return "not root (slurmd runs jobs as their users)";
    for (const char* tool : {"slurmctld", "slurmd", "sbatch", "munged", "snakemake"})
      if (std::system(
              ("PATH=$PATH:/usr/sbin command -v " + std::string(tool) + " >/dev/null").c_str()) !=
          0)
        return std::string(tool) +
               " is not installed (Debian: apt install slurm-wlm munge snakemake, "
               "scripts/setup.sh)";
    return "";
  }

  // `command` through sh in `cwd` with the cluster's configuration and the build's binaries.
  static CommandResult Run(const std::string& cwd, const std::string& command) {
    return testing::RunShell("cd " + ShellQuote(cwd) +
                             " && SLURM_CONF=" + ShellQuote(cluster_ + "/slurm.conf") +
                             " LUMISLAB_BIN=" + ShellQuote(LUMISLAB_BIN_DIR) +
                             " PATH=$PATH:/usr/sbin " + command + " 2>&1");
  }
  // The workflow through the Slurm profile. CI=true: Snakemake checks its jobs every second
  // (else every 10 s).
  static CommandResult Snakemake(const std::string& datasets) {
    return Run(root_, "CI=true snakemake -s " + ShellQuote(Pipelines() + "/Snakefile") +
                          " --profile " + ShellQuote(Pipelines() + "/slurm") +
                          " --config 'datasets=[" + datasets +
                          "]' out=out 'lab=Slurm Lab' manufacturer=Maker threads=1 resolution=48");
  }
  static std::vector<Job> Jobs() { return ReadJobs(cluster_ + "/log/jobcomp.txt"); }

  static std::string skip_, root_, cluster_;
  static pid_t watcher_;
  static int watch_fd_;
};
std::string Slurm::skip_, Slurm::root_, Slurm::cluster_;
pid_t Slurm::watcher_ = -1;
int Slurm::watch_fd_ = -1;

// The outputs of a dataset that must equal the local run's: its calibration and slab, its
// exports and preview (the logs and times differ).
testing::TreeSnapshot Outputs(const std::string& root, const std::string& name) {
  testing::TreeSnapshot all;
  for (const std::string& dir :
       {root + "/data/" + name + "/calib", root + "/data/" + name + "/slab", root + "/out/" + name})
    for (const auto& [path, what] : testing::SnapshotTree(dir))
      all[dir.substr(root.size()) + "/" + path] = what;
  return all;
}

TEST_F(Slurm, ProfileSubmitsDeclaredResourcesReportsFailuresAndResumes) {
  if (!skip_.empty()) GTEST_SKIP() << "Slurm test skipped: " << skip_;
  const auto t0 = std::chrono::steady_clock::now();
  // The log's time of each phase.
  auto phase = [&](const char* what) {
    std::printf("slurm test: %-52s at %5.1f s\n", what,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    std::fflush(stdout);
  };

  // Ten 3 x 3 datasets (one rendering, copied) of which one has a photo cut short, and a 7 x 7
  // one whose reconstruct lasts long enough to be cancelled; the same again for the local run.
  testing::WriteFile(root_ + "/scene3.json", Scene(3));
  testing::WriteFile(root_ + "/scene7.json", Scene(7));
  for (const auto& [scene, out] : {std::pair{"scene3", "lamp_00"}, {"scene7", "lamp_slow"}}) {
    const auto r = testing::RunTool(
        "lumislab-acquire", "synth --meter lux --truth-resolution 48 --scene " + root_ + "/" +
                                scene + ".json --out " + root_ + "/src/" + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  std::vector<std::string> names;
  for (int k = 0; k < 9; ++k) names.push_back("lamp_0" + std::to_string(k));
  names.push_back("broken");
  for (const std::string& top : {root_, root_ + "/local"}) {
    fs::create_directories(top + "/data");
    fs::create_directories(top + "/late");
    for (const std::string& name : names)
      fs::copy(root_ + "/src/lamp_00", top + "/data/" + name, fs::copy_options::recursive);
    fs::copy(root_ + "/src/lamp_slow", top + "/late/lamp_slow", fs::copy_options::recursive);
    fs::resize_file(top + "/data/broken/photos/pos_0_1_p.exr", 1000);
  }
  const CommandResult local =
      Run(root_ + "/local", ShellQuote(Pipelines() + "/batch-convert.sh") +
                                " data late --out out --jobs 2" + kStageArgs);
  ASSERT_EQ(local.exit_code, 1) << local.output;  // the broken dataset
  phase("datasets rendered, local run done");

  // The whole batch through Slurm: it fails (the broken dataset), the rest converts.
  const CommandResult first = Snakemake("data");
  phase("first run through Slurm done");
  std::cout << first.output.substr(
      first.output.find("dataset ") == std::string::npos ? 0 : first.output.rfind("dataset "));
  EXPECT_NE(first.exit_code, 0) << first.output;
  EXPECT_NE(first.output.find("reconstruct (exit 2)"), std::string::npos) << first.output;
  std::map<std::string, std::string> submitted = SubmittedJobs(first.output);
  std::vector<Job> jobs = Jobs();
  // Nine datasets of four stages, and the broken one's calibrate and reconstruct.
  EXPECT_EQ(jobs.size(), 38u);
  EXPECT_EQ(submitted.size(), jobs.size()) << first.output;

  // Every job as Slurm recorded it: one CPU (threads=1), the memory and time limit that the
  // cost model gives for its stage and dataset; all completed but the broken reconstruct.
  // What the cost model gives each stage of each dataset (pipelines/stage_resources.py, one
  // Python process): "<stage> <name>" -> "mem_mb=<MB> runtime=<minutes>".
  std::string script =
      "import sys; sys.path.insert(0, sys.argv[1]); import stage_resources as s\n"
      "for a in sys.argv[2:]:\n"
      "    st, ds = a.split(':', 1); r = s.resources(st, ds, 1, 48)\n"
      "    print(st, ds.split('/')[-1], 'mem_mb=%d runtime=%d' % (r['mem_mb'], "
      "r['runtime']))\n";
  std::string args;
  for (const char* stage : {"calibrate", "reconstruct", "export", "preview"}) {
    for (const std::string& name : names)
      args += " " + ShellQuote(std::string(stage) + ":" + root_ + "/data/" + name);
    args += " " + ShellQuote(std::string(stage) + ":" + root_ + "/late/lamp_slow");
  }
  std::map<std::string, std::string> expected;
  {
    const CommandResult model = testing::RunShell("python3 -c " + ShellQuote(script) + " " +
                                                  ShellQuote(Pipelines()) + args);
    ASSERT_EQ(model.exit_code, 0) << model.output;
    std::istringstream in(model.output);
    for (std::string stage, name, resources; in >> stage >> name >> resources;) {
      std::string runtime;
      in >> runtime;
      expected[stage + " " + name] = resources + " " + runtime + "\n";
    }
  }
  ASSERT_EQ(expected.size(), 44u);
  std::printf("%-6s %-22s %-10s %-10s %4s %7s %5s\n", "job", "name", "dataset", "state", "cpus",
              "mem MB", "min");
  auto check = [&](Job& job) {
    job.dataset = submitted.count(job.id) ? submitted[job.id] : "?";
    std::printf("%-6s %-22s %-10s %-10s %4d %7d %5d\n", job.id.c_str(), job.name.c_str(),
                job.dataset.substr(job.dataset.find(' ') + 1).c_str(), job.state.c_str(), job.cpus,
                job.mem_mb, job.time_min);
    const std::string stage = job.dataset.substr(0, job.dataset.find(' '));
    EXPECT_EQ(job.name, "lumislab-" + stage) << job.id;
    EXPECT_EQ(job.cpus, 1) << job.dataset;
    EXPECT_EQ(expected.count(job.dataset), 1u) << job.dataset;
    EXPECT_EQ(
        "mem_mb=" + std::to_string(job.mem_mb) + " runtime=" + std::to_string(job.time_min) + "\n",
        expected[job.dataset])
        << job.dataset;
  };
  for (Job& job : jobs) {
    check(job);
    EXPECT_EQ(job.state, job.dataset == "reconstruct broken" ? "FAILED" : "COMPLETED")
        << job.dataset;
  }
  // The resources follow the stage's cost: a preview asks more memory than a calibrate.
  auto mem = [](const std::string& resources) { return std::atoi(resources.c_str() + 7); };
  EXPECT_GT(mem(expected["preview lamp_00"]), mem(expected["calibrate lamp_00"]));

  // A rerun submits only what is missing: a lost preview, a lost polar plot (its export), and
  // the broken dataset's reconstruct, which fails again.
  fs::remove(root_ + "/out/lamp_03/preview.png");
  fs::remove(root_ + "/out/lamp_04/polar.png");
  const CommandResult again = Snakemake("data");
  phase("rerun done");
  EXPECT_NE(again.exit_code, 0) << again.output;
  submitted = SubmittedJobs(again.output);
  std::set<std::string> ran;
  for (const auto& [id, what] : submitted) ran.insert(what);
  EXPECT_EQ(ran, (std::set<std::string>{"preview lamp_03", "export lamp_04", "reconstruct broken"}))
      << again.output;
  jobs = Jobs();
  EXPECT_EQ(jobs.size(), 41u);
  for (size_t k = 38; k < jobs.size(); ++k) check(jobs[k]);

  // A reconstruct cancelled while it runs: Snakemake sees it fail (pipelines/slurm/status.sh),
  // and the rerun resumes it, keeping the positions already written.
  CommandResult cancelled;
  std::thread run([&] { cancelled = Snakemake("late"); });
  const std::string slab = root_ + "/late/lamp_slow/slab";
  auto positions = [&] {
    std::map<std::string, fs::file_time_type> found;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(slab, ec))
      if (e.path().extension() == ".exr")
        found[e.path().filename()] = fs::last_write_time(e.path(), ec);
    return found;
  };
  const bool started = testing::WaitUntil([&] { return positions().size() >= 3; }, 60);
  const CommandResult scancel = Run(root_, "scancel --name=lumislab-reconstruct");
  run.join();
  ASSERT_TRUE(started) << cancelled.output;
  EXPECT_EQ(scancel.exit_code, 0) << scancel.output;
  EXPECT_NE(cancelled.exit_code, 0) << cancelled.output;
  const std::map<std::string, fs::file_time_type> kept = positions();
  EXPECT_LT(kept.size(), 49u) << "the reconstruct ended before it was cancelled";
  jobs = Jobs();
  submitted = SubmittedJobs(cancelled.output);
  bool seen_cancelled = false;
  for (size_t k = 41; k < jobs.size(); ++k) {
    check(jobs[k]);
    seen_cancelled |= jobs[k].state == "CANCELLED" && jobs[k].dataset == "reconstruct lamp_slow";
  }
  EXPECT_TRUE(seen_cancelled);
  const size_t before_resume = jobs.size();
  phase("cancelled run done");
  const CommandResult resumed = Snakemake("late");
  phase("resumed run done");
  EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
  submitted = SubmittedJobs(resumed.output);
  jobs = Jobs();
  for (size_t k = before_resume; k < jobs.size(); ++k) {
    check(jobs[k]);
    EXPECT_EQ(jobs[k].state, "COMPLETED") << jobs[k].dataset;
  }
  const auto now = positions();
  for (const auto& [file, time] : kept)
    EXPECT_EQ(now.count(file) ? now.at(file) : fs::file_time_type{}, time) << file << " was redone";
  EXPECT_EQ(now.size(), 49u);

  // Every output byte for byte the local run's (the broken dataset has none: Snakemake removes a
  // failed job's slab.json, the shell driver leaves it, and neither hands anything out).
  for (const std::string& name : names) {
    if (name == "broken") continue;
    const auto diff = testing::DiffSnapshots(Outputs(root_ + "/local", name), Outputs(root_, name));
    EXPECT_TRUE(diff.empty()) << name << ": " << diff.front();
  }
  EXPECT_FALSE(fs::exists(root_ + "/out/broken/preview.png"));
  EXPECT_EQ(testing::ReadBinaryFile(root_ + "/data/broken/calib/screen.json"),
            testing::ReadBinaryFile(root_ + "/local/data/broken/calib/screen.json"));
  auto late = [](const std::string& root) {
    testing::TreeSnapshot all = testing::SnapshotTree(root + "/late/lamp_slow/slab");
    for (const auto& [path, what] : testing::SnapshotTree(root + "/out/lamp_slow"))
      all["out/" + path] = what;
    return all;
  };
  const auto diff = testing::DiffSnapshots(late(root_ + "/local"), late(root_));
  EXPECT_TRUE(diff.empty()) << diff.front();
  phase("outputs compared");

  // The memory asked is a limit (OverMemoryKill): a job that uses 300 MB having asked 50 is
  // killed, so a model that asks too little shows as failed jobs (status.sh says so), not as a
  // swapping node.
  const std::string over_script =
      "id=$(sbatch --parsable --mem=50 --time=1 --output=over-%j.out --wrap "
      "'python3 -c \"import time; b = bytearray(300 << 20); time.sleep(20)\"') && "
      "status=" +
      ShellQuote(Pipelines() + "/slurm/status.sh") +
      " && "
      "while [ \"$($status $id)\" = running ]; do sleep 0.2; done && echo $id $($status $id)";
  const CommandResult over = Run(root_, "sh -c " + ShellQuote(over_script));
  EXPECT_NE(over.output.find(" failed"), std::string::npos) << over.output;
  const std::string over_id = over.output.substr(0, over.output.find(' '));
  EXPECT_NE(testing::ReadBinaryFile(root_ + "/over-" + over_id + ".out").find("exceeded"),
            std::string::npos)
      << over.output;
  phase("a job above its memory killed");
}

}  // namespace
}  // namespace lumislab
