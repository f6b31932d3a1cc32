// lumislab-reconstruct: the batch and --watch drivers around ReconstructPosition.
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <exception>
#include <filesystem>
#include <opencv2/core.hpp>
#include <sstream>
#include <thread>

#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/slab_compare.h"
#include "reconstruct/reconstructor.h"
#include "reconstruct/slab_writer.h"

namespace fs = std::filesystem;

namespace lumislab {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void OnStopSignal(int) { g_stop = true; }

// SIGINT/SIGTERM set g_stop while a run is in progress; the previous handlers come back after.
class StopSignalScope {
 public:
  StopSignalScope()
      : old_int_(std::signal(SIGINT, OnStopSignal)),
        old_term_(std::signal(SIGTERM, OnStopSignal)) {}
  ~StopSignalScope() {
    std::signal(SIGINT, old_int_);
    std::signal(SIGTERM, old_term_);
  }

 private:
  using Handler = void (*)(int);
  Handler old_int_, old_term_;
};

struct RunConfig {
  std::string dataset_dir;
  ReconstructOptions options;
  bool watch = false;
  bool force = false;
  int threads = 0;
  double poll_s = 0.2;
  double idle_timeout_s = 0;  // --watch: give up after this long without new photos (0: never)
};

using Position = std::pair<int, int>;

std::string Name(const Position& p) {
  return std::to_string(p.first) + "," + std::to_string(p.second);
}

// Photos of a position all exist under their final names (temporaries start with '.').
bool PhotosReady(const Dataset& dataset, int i, int j) {
  bool has_p = false, has_n = false;
  for (const auto& e : dataset.PhotosOf(i, j)) {
    if (!fs::exists(dataset.Path(e.file))) return false;
    (e.positive ? has_p : has_n) = true;
  }
  return has_p && has_n;
}

void CheckPhotosExist(const Dataset& dataset, const std::vector<Position>& todo) {
  for (const auto& [i, j] : todo) {
    const auto entries = dataset.PhotosOf(i, j);
    if (entries.empty())
      throw InputError(dataset.Path("dataset.json"), "photos", "photos for every grid position",
                       "none for position " + Name({i, j}));
    for (const auto& e : entries)
      if (!fs::exists(dataset.Path(e.file)))
        throw BadInput(dataset.Path(e.file) + ": photo missing (listed in dataset.json photos)");
  }
}

// Reconstructs and writes `todo` with up to `threads` positions in flight; the first error is
// rethrown after the positions in flight have finished. Stops picking new positions on a signal.
void ProcessPositions(const Dataset& dataset, const ScreenCalibration& calibration,
                      SlabWriter& writer, const std::vector<Position>& todo,
                      const RunConfig& config, Progress* progress) {
  if (todo.empty()) return;
  const int workers = std::max(1, std::min<int>(config.threads, int(todo.size())));
  cv::setNumThreads(std::max(1, config.threads / workers));
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (;;) {
      if (failed || g_stop) return;
      const size_t k = next++;
      if (k >= todo.size()) return;
      const auto [i, j] = todo[k];
      try {
        PositionReport r;
        const SlabPosition pos =
            ReconstructPosition(dataset, calibration, writer.info(), i, j, config.options, &r);
        const auto t0 = std::chrono::steady_clock::now();
        writer.Write(pos);
        r.write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (r.saturated_pixels > 0)
          LogWarning("position ", Name({i, j}), ": ", r.saturated_pixels,
                     " saturated photo pixels; ", r.saturated_texels,
                     " texels left out of the fit (mask 0)");
        LogDebug("position ", Name({i, j}), ": seen ", r.seen_texels,
                 " texels, K=", r.samples_per_texel, ", fit ", r.fit_iterations, " it (residual ",
                 r.fit_residual, "), decode ", r.decode_s, " s, rectify ", r.rectify_s, " s, fit ",
                 r.fit_s, " s, write ", r.write_s, " s");
        if (progress) progress->Advance(1, "pos " + Name({i, j}));
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

std::vector<Position> Missing(const Dataset& dataset, const SlabWriter& writer) {
  std::vector<Position> out;
  for (int j = 0; j < dataset.grid.nv; ++j)
    for (int i = 0; i < dataset.grid.nu; ++i)
      if (!writer.IsPresent(i, j)) out.push_back({i, j});
  return out;
}

std::string CalibrationPath(const std::string& dir) { return dir + "/calib/screen.json"; }

void ReportAgainstTruth(const std::string& dataset_dir, const std::string& slab_dir);

int RunBatch(const RunConfig& config) {
  const Dataset dataset = Dataset::Load(config.dataset_dir);
  const std::string calib_path = CalibrationPath(config.dataset_dir);
  if (!fs::exists(calib_path))
    throw BadInput(calib_path + ": missing; run lumislab-calibrate screen first");
  const ScreenCalibration calibration = ScreenCalibration::Load(calib_path);
  std::vector<Position> todo;
  for (int j = 0; j < dataset.grid.nv; ++j)
    for (int i = 0; i < dataset.grid.nu; ++i) todo.push_back({i, j});
  CheckPhotosExist(dataset, todo);
  SlabWriter writer(dataset, config.options.resolution, config.force);
  todo = Missing(dataset, writer);
  const int skipped = dataset.grid.count() - int(todo.size());
  if (skipped > 0)
    LogInfo(skipped, " position(s) already in ", writer.dir(), " (use --force to redo them)");
  Progress progress("reconstruct", int(todo.size()));
  ProcessPositions(dataset, calibration, writer, todo, config, &progress);
  progress.Finish();
  if (g_stop) {
    LogWarning("interrupted: slab is partial (", writer.PresentCount(), "/", dataset.grid.count(),
               " positions); run again to continue");
    return 1;
  }
  LogInfo("slab: ", writer.dir(), " (", writer.PresentCount(), "/", dataset.grid.count(),
          " positions, ", config.options.resolution, "x", config.options.resolution, ", ",
          writer.info().units, ")");
  ReportAgainstTruth(config.dataset_dir, writer.dir());
  return 0;
}

// Synthetic datasets carry their ground truth: say how far the slab is from it.
void ReportAgainstTruth(const std::string& dataset_dir, const std::string& slab_dir) {
  const std::string truth = dataset_dir + "/truth";
  if (!fs::exists(truth + "/slab.json")) return;
  const SlabInfo truth_info = SlabInfo::Load(truth);
  const SlabInfo slab_info = SlabInfo::Load(slab_dir);
  if (truth_info.layout.res_x != slab_info.layout.res_x) {
    LogInfo("truth: ", truth, " is at resolution ", truth_info.layout.res_x,
            "; not compared (reconstruct with --resolution ", truth_info.layout.res_x, ")");
    return;
  }
  LogInfo("error against truth/: ", CompareSlabs(slab_dir, truth).Summary());
}

// Polls until `path` exists; false when stopped by a signal.
bool WaitFor(const std::string& path, double poll_s) {
  bool said = false;
  while (!fs::exists(path)) {
    if (g_stop) return false;
    if (!said) LogInfo("waiting for ", path);
    said = true;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_s));
  }
  return true;
}

int RunWatch(const RunConfig& config) {
  const std::string dir = config.dataset_dir;
  if (!fs::is_directory(dir))
    throw BadInput(dir + "/dataset.json: missing (the dataset folder does not exist)");
  if (!WaitFor(dir + "/dataset.json", config.poll_s)) return 1;
  Dataset dataset = Dataset::Load(dir);
  auto dataset_time = fs::last_write_time(dir + "/dataset.json");
  if (!WaitFor(CalibrationPath(dir), config.poll_s)) return 1;
  const ScreenCalibration calibration = ScreenCalibration::Load(CalibrationPath(dir));
  SlabWriter writer(dataset, config.options.resolution, config.force);
  Progress progress("reconstruct --watch", dataset.grid.count());
  progress.Advance(writer.PresentCount());
  auto last_new = std::chrono::steady_clock::now();
  while (!writer.Complete() && !g_stop) {
    const auto t = fs::last_write_time(dir + "/dataset.json");
    if (t != dataset_time) {  // the acquisition may list photos as it goes
      dataset = Dataset::Load(dir);
      dataset_time = t;
    }
    std::vector<Position> ready;
    for (const auto& p : Missing(dataset, writer))
      if (PhotosReady(dataset, p.first, p.second)) ready.push_back(p);
    if (!ready.empty()) {
      ProcessPositions(dataset, calibration, writer, ready, config, &progress);
      last_new = std::chrono::steady_clock::now();
      continue;
    }
    if (config.idle_timeout_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - last_new).count() >
            config.idle_timeout_s)
      throw Failure("--watch: no new photos for " + std::to_string(config.idle_timeout_s) +
                    " s; slab is partial (" + std::to_string(writer.PresentCount()) + "/" +
                    std::to_string(dataset.grid.count()) + " positions)");
    std::this_thread::sleep_for(std::chrono::duration<double>(config.poll_s));
  }
  progress.Finish();
  if (!writer.Complete()) {
    LogWarning("interrupted: slab is partial (", writer.PresentCount(), "/", dataset.grid.count(),
               " positions); run again to continue");
    return 1;
  }
  LogInfo("slab: ", writer.dir(), " (complete, ", dataset.grid.count(), " positions)");
  ReportAgainstTruth(config.dataset_dir, writer.dir());
  return 0;
}

}  // namespace

int RunReconstruct(int argc, char** argv) {
  RunConfig config;
  bool verbose = false;
  CLI::App app{
      "lumislab-reconstruct: photos of each grid position -> fitted E_ij in "
      "<dataset>/slab (DESIGN §3)"};
  app.add_option("--dataset", config.dataset_dir, "dataset folder (with dataset.json)")->required();
  app.add_option("--resolution", config.options.resolution, "slab texels per side")
      ->capture_default_str();
  app.add_flag("--watch", config.watch,
               "follow a live acquisition: process each position as its photos arrive, stop "
               "when the grid is complete");
  app.add_flag("--force", config.force, "redo positions whose slab EXR already exists");
  app.add_option("--threads", config.threads, "worker threads (default: all cores)");
  app.add_option("--lambda", config.options.lambda,
                 "regularisation of the fit (first differences, relative)")
      ->capture_default_str();
  app.add_option("--samples-per-texel", config.options.samples_per_texel,
                 "K x K samples per texel (0: automatic, as dense as the photo pixels)")
      ->capture_default_str();
  app.add_option("--poll", config.poll_s, "--watch: polling interval in seconds")
      ->capture_default_str();
  app.add_option("--idle-timeout", config.idle_timeout_s,
                 "--watch: fail after this many seconds without new photos (0: wait forever)")
      ->capture_default_str();
  app.add_flag("--verbose", verbose, "log per-position details");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::kBadInput);
  }
  SetLogTool("reconstruct");
  if (verbose) SetLogLevel(LogLevel::kDebug);
  config.options.Check();
  if (config.threads <= 0) config.threads = std::max(1u, std::thread::hardware_concurrency());
  if (!(config.poll_s > 0 && config.poll_s <= 60))
    throw BadInput("--poll: expected seconds in (0, 60], got " + std::to_string(config.poll_s));
  while (!config.dataset_dir.empty() && config.dataset_dir.size() > 1 &&
         config.dataset_dir.back() == '/')
    config.dataset_dir.pop_back();
  std::ostringstream params;
  params << "dataset=" << config.dataset_dir << " resolution=" << config.options.resolution
         << " lambda=" << config.options.lambda << " samples_per_texel="
         << (config.options.samples_per_texel ? std::to_string(config.options.samples_per_texel)
                                              : std::string("auto"))
         << " watch=" << (config.watch ? "yes" : "no") << " force=" << (config.force ? "yes" : "no")
         << " threads=" << config.threads;
  LogInfo("parameters: ", params.str());
  g_stop = false;
  const StopSignalScope signals;
  return config.watch ? RunWatch(config) : RunBatch(config);
}

}  // namespace lumislab
