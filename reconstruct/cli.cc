// lumislab-reconstruct: the command line, and the batch and --watch drivers around
// ReconstructPosition.
#include "reconstruct/cli.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <opencv2/core.hpp>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "core/checks.h"
#include "core/command_line.h"
#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/slab_compare.h"
#include "core/slab_light.h"
#include "core/stop_signal.h"
#include "reconstruct/capture_checks.h"
#include "reconstruct/reconstructor.h"
#include "reconstruct/slab_writer.h"

namespace fs = std::filesystem;

namespace lumislab {

namespace {

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
    if (!fs::exists(dataset.PhotoPath(e.file))) return false;
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
      if (!fs::exists(dataset.PhotoPath(e.file)))
        throw BadInput(dataset.PhotoPath(e.file) +
                       ": photo missing (listed in dataset.json photos)");
  }
}

// What the merge of a bracket found: the dynamic range, the pixels no exposure measured well,
// and how far the exposure ratios in the pixels are from the recorded ones (info above 1 %, a
// warning above 5 %: EXIF shutter times are nominal, 1/30 s may be 1/32 s), with the advice to
// use the estimate only where the deviation is the same at every brightness.
void ReportBrackets(const Position& position, const PositionReport& r, const RunConfig& config) {
  LogInfo("position ", Name(position), ": ", r.exposures, " exposures per slide merged, dynamic ",
          "range ", r.dynamic_range_stops, " stops (", r.brightest, " / ", r.faintest, "), ",
          r.saturated_pixels, " pixels clipped in every exposure (masked), ", r.near_black_pixels,
          " near-black in every exposure (of the photo pixels the slab reads)");
  const bool used = config.options.merge.bracket_ratios == BracketRatios::kEstimated;
  for (const BracketRatio& b : r.bracket_ratios) {
    std::ostringstream text;
    text << "position " << Name(position) << " slide " << (b.positive ? "p" : "n") << ": exposures "
         << b.recorded_short << " -> " << b.recorded_long << ": ratio ";
    if (b.samples == 0) {
      text << "not estimated (fewer than " << kMinRatioSamples
           << " values well exposed in both); the recorded " << b.Recorded() << " is used";
      LogInfo(text.str());
      continue;
    }
    text << b.estimated << " in the pixels, " << b.Recorded() << " recorded ("
         << 100 * b.Deviation() << " %, " << b.samples << " values); ";
    const double deviation = std::abs(b.Deviation());
    if (!b.DeviationIsTheExposures()) {
      // No advice: an estimate that changes with the brightness measures the noise, a dark
      // offset or the response curve, which --bracket-ratios estimated would not correct.
      text << "the ratio changes with the brightness (" << b.estimated_dim << " in the dimmer, "
           << b.estimated_bright << " in the brighter half of those values): not the "
           << "exposures' own; " << (used ? "the estimate is used" : "the recorded one is used");
      if (deviation > 0.01)
        LogInfo(text.str());
      else
        LogDebug(text.str());
      continue;
    }
    text << (used ? "the estimate is used"
                  : "the recorded one is used (--bracket-ratios estimated uses the estimate)");
    if (deviation > kRatioAdviceAbove)
      LogWarning(text.str());
    else if (deviation > 0.01)
      LogInfo(text.str());
    else
      LogDebug(text.str());
  }
}

// Reconstructs one position and writes it into the slab.
void ProcessPosition(const Dataset& dataset, const ScreenCalibration& calibration,
                     SlabWriter& writer, const Position& position, const RunConfig& config,
                     CaptureChecks& checks) {
  const auto [i, j] = position;
  PositionReport r;
  const SlabPosition pos =
      ReconstructPosition(dataset, calibration, writer.info(), i, j, config.options, &r);
  if (r.exposures > 1) ReportBrackets(position, r, config);
  checks.AddPosition(pos, writer.info().layout, r);  // a bracket in the wrong order: exit 2
  const auto t0 = std::chrono::steady_clock::now();
  writer.Write(pos);
  r.write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Hot pixels of calib/dark.json read as their neighbours' mean (said once at the start): what
  // is saturated here, the light saturated.
  if (r.saturated_pixels > 0)
    LogWarning("position ", Name(position), ": ", r.saturated_pixels, " saturated photo pixels; ",
               r.saturated_texels, " texels left out of the fit (mask 0)");
  // Outside what the slab can say: no light at all (a slab of zeros is not a measurement of
  // this luminaire), or light that varies within a texel (the bell basis needs light smooth
  // over a few texels, kUnresolvedLight).
  if (r.no_light)
    LogWarning("position ", Name(position), ": no light measured (",
               r.brightest_codes >= 0
                   ? "the brightest photo pixel is " + std::to_string(r.brightest_codes) +
                         " codes above black, below the near-black floor"
                   : std::string("every seen texel is 0"),
               "): its slab image holds no signal; raise the exposure");
  else if (r.bell_correction > kUnresolvedLight)
    LogWarning("position ", Name(position), ": the light varies within a texel (the fit moves ",
               "the texel averages by ", 100 * r.bell_correction,
               " %): the slab keeps its flux, not its shape; use a higher --resolution");
  LogDebug("position ", Name(position), ": seen ", r.seen_texels,
           " texels, K=", r.samples_per_texel, ", fit ", r.fit_iterations, " it (residual ",
           r.fit_residual, "), decode ", r.decode_s, " s, rectify ", r.rectify_s, " s, fit ",
           r.fit_s, " s, write ", r.write_s, " s");
}

// Reconstructs and writes `todo` with up to `threads` positions in flight; the first error is
// rethrown after the positions in flight have finished. Stops picking new positions on a signal.
void ProcessPositions(const Dataset& dataset, const ScreenCalibration& calibration,
                      SlabWriter& writer, const std::vector<Position>& todo,
                      const RunConfig& config, CaptureChecks& checks, Progress* progress) {
  if (todo.empty()) return;
  const int workers = std::max(1, std::min<int>(config.threads, int(todo.size())));
  cv::setNumThreads(std::max(1, config.threads / workers));
  ParallelFor(int(todo.size()), workers, [&](int k) {
    if (StopRequested()) return;
    ProcessPosition(dataset, calibration, writer, todo[k], config, checks);
    if (progress) progress->Advance(1, "pos " + Name(todo[k]));
  });
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

// The complete slab's total light, recorded in the dataset's checks.json ("slab.total_light"):
// exit 2 after writing a slab of negative light (its slides swapped) rather than exit 0.
void CheckSlab(const std::string& slab_dir, CheckLog& checks) {
  const SlabInfo info = SlabInfo::Load(slab_dir);
  // Position by position: one image in memory (a 15 x 15 slab at 1200 texels is 5 GB whole).
  SlabLightSum sum(info);
  for (const auto& [i, j] : info.present) sum.Add(ReadSlabPosition(slab_dir, info, i, j));
  CheckSlabLight(info, sum.Result(), slab_dir, checks);
  checks.Save();
}

// "radiometry.saturation_level": JPEG's coding error spreads clipped highlights over the codes
// just below 255, so a saturation level of 1 (what an empty setup.json radiometry gives) merges
// them as light. Measured on a synthetic JPEG camera (gamma curve with a shoulder, quality 95,
// three brackets, dark offset 0.005): worst position 4.1 % from truth at 1.0, 1.7 % at 0.95
// (tests/e2e/consistency_slab_test.cc). A lab may mean 1 (a camera whose JPEG never clips):
// a warning, recorded, with the value to set.
constexpr double kJpegSaturationLevel = 0.95;
void CheckSaturationLevel(const Dataset& dataset, const std::vector<DecodedPhoto>& photos,
                          CheckLog& checks) {
  bool jpeg = false;
  for (const DecodedPhoto& p : photos) jpeg = jpeg || p.photo.format == PhotoFormat::kJpeg;
  if (!jpeg) return;
  const nlohmann::json values = {{"saturation_level", dataset.saturation_level},
                                 {"jpeg_saturation_level", kJpegSaturationLevel}};
  if (dataset.saturation_level > kJpegSaturationLevel)
    checks.Warn("radiometry.saturation_level",
                dataset.Path("dataset.json") +
                    ": radiometry.saturation_level: " + Num(dataset.saturation_level, 4) +
                    " for JPEG photos, whose coding spreads clipped highlights below code 255: "
                    "they are merged as light (the slab a few % off); set it to " +
                    Num(kJpegSaturationLevel, 3) + " (setup.json radiometry, then import)",
                values);
  else
    checks.Pass("radiometry.saturation_level",
                "JPEG photos clipped at " + Num(dataset.saturation_level, 4) + " of full scale",
                values);
}

// Reconstructs every position the slab in `dir` lacks; false when stopped by a signal.
bool FillSlab(const Dataset& dataset, const ScreenCalibration& calibration, const std::string& dir,
              const RunConfig& config, CheckLog& log) {
  SlabWriter writer(dataset, config.options.resolution, config.force, dir,
                    config.options.radiometry.get());
  const std::vector<Position> todo = Missing(dataset, writer);
  const int skipped = dataset.grid.count() - int(todo.size());
  if (skipped > 0)
    LogInfo(skipped, " position(s) already in ", writer.dir(), " (use --force to redo them)");
  Progress progress("reconstruct", int(todo.size()));
  CaptureChecks checks(dataset, &log);
  ProcessPositions(dataset, calibration, writer, todo, config, checks, &progress);
  progress.Finish();
  // The photos checked against each other over the whole slab (exit 2 before a staged slab
  // replaces the previous one).
  if (!StopRequested()) checks.Finish(writer.dir(), writer.info());
  if (StopRequested() && dir == dataset.Path("slab"))
    LogWarning("interrupted: slab is partial (", writer.PresentCount(), "/", dataset.grid.count(),
               " positions); run again to continue");
  return !StopRequested();
}

int RunBatch(RunConfig config) {
  const Dataset dataset = Dataset::Load(config.dataset_dir);
  config.options.radiometry =
      std::make_shared<ReconstructRadiometry>(LoadReconstructRadiometry(dataset));
  const std::string calib_path = CalibrationPath(config.dataset_dir);
  if (!fs::exists(calib_path))
    throw BadInput(calib_path + ": missing; run lumislab-calibrate screen first");
  const ScreenCalibration calibration = ScreenCalibration::Load(calib_path);
  std::vector<Position> all;
  for (int j = 0; j < dataset.grid.nv; ++j)
    for (int i = 0; i < dataset.grid.nu; ++i) all.push_back({i, j});
  CheckPhotosExist(dataset, all);
  // The run's consistency record (checks.json's stage "reconstruct", docs/verifies.md).
  CheckLog checks(dataset.dir, "reconstruct");
  // Photos that do not fit the calibration (size, format) are refused before anything is
  // written: decode the first position's photos now.
  CheckSaturationLevel(
      dataset, DecodePosition(dataset, calibration, 0, 0, config.options.radiometry->corrections),
      checks);
  const std::string slab_dir = dataset.Path("slab");
  // --force over an existing slab builds the new one beside it and swaps it in when complete:
  // a failure or a stop leaves the previous slab as it was (and then nothing is resumable).
  const bool staged = config.force && fs::exists(slab_dir);
  if (staged) RemoveOrphanedTemporaries(dataset.dir);
  const std::string dir = staged ? TemporaryPathFor(slab_dir) : slab_dir;
  try {
    if (!FillSlab(dataset, calibration, dir, config, checks)) {
      if (staged) {
        fs::remove_all(dir);
        LogWarning("interrupted: the previous slab is unchanged (--force starts over)");
      }
      return 1;
    }
    if (staged) ReplaceFolder(dir, slab_dir);
  } catch (...) {
    std::error_code ec;
    if (staged) fs::remove_all(dir, ec);
    throw;
  }
  const SlabInfo info = SlabInfo::Load(slab_dir);
  LogInfo("slab: ", slab_dir, " (", info.present.size(), "/", dataset.grid.count(), " positions, ",
          config.options.resolution, "x", config.options.resolution, ", ", info.units, ")");
  ReportAgainstTruth(config.dataset_dir, slab_dir);
  CheckSlab(slab_dir, checks);
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
    if (StopRequested()) return false;
    if (!said) LogInfo("waiting for ", path);
    said = true;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_s));
  }
  return true;
}

int RunWatch(RunConfig config) {
  const std::string dir = config.dataset_dir;
  if (!fs::is_directory(dir))
    throw BadInput(dir + "/dataset.json: missing (the dataset folder does not exist)");
  if (!WaitFor(dir + "/dataset.json", config.poll_s)) return 1;
  Dataset dataset = Dataset::Load(dir);
  auto dataset_time = fs::last_write_time(dir + "/dataset.json");
  if (!WaitFor(CalibrationPath(dir), config.poll_s)) return 1;
  const ScreenCalibration calibration = ScreenCalibration::Load(CalibrationPath(dir));
  config.options.radiometry =
      std::make_shared<ReconstructRadiometry>(LoadReconstructRadiometry(dataset));
  SlabWriter writer(dataset, config.options.resolution, config.force, "",
                    config.options.radiometry.get());
  Progress progress("reconstruct --watch", dataset.grid.count());
  CheckLog log(dataset.dir, "reconstruct");  // checks.json's stage (docs/verifies.md)
  CaptureChecks checks(dataset, &log);
  progress.Advance(writer.PresentCount());
  auto last_new = std::chrono::steady_clock::now();
  while (!writer.Complete() && !StopRequested()) {
    const auto t = fs::last_write_time(dir + "/dataset.json");
    // dataset.json is rewritten when an acquisition restarts (--force): follow it. (It always
    // lists every photo, Dataset::Load insists on that; a live acquisition adds the files.)
    if (t != dataset_time) {
      dataset = Dataset::Load(dir);
      dataset_time = t;
    }
    std::vector<Position> ready;
    for (const auto& p : Missing(dataset, writer))
      if (PhotosReady(dataset, p.first, p.second)) ready.push_back(p);
    if (!ready.empty()) {
      ProcessPositions(dataset, calibration, writer, ready, config, checks, &progress);
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
  checks.Finish(writer.dir(), writer.info());
  LogInfo("slab: ", writer.dir(), " (complete, ", dataset.grid.count(), " positions)");
  ReportAgainstTruth(config.dataset_dir, writer.dir());
  CheckSlab(writer.dir(), log);
  return 0;
}

std::string Parameters(const RunConfig& config) {
  std::ostringstream params;
  params << "dataset=" << config.dataset_dir << " resolution=" << config.options.resolution
         << " lambda=" << config.options.lambda << " samples_per_texel="
         << (config.options.samples_per_texel ? std::to_string(config.options.samples_per_texel)
                                              : std::string("auto"))
         << " bracket_ratios="
         << (config.options.merge.bracket_ratios == BracketRatios::kEstimated ? "estimated"
                                                                              : "recorded")
         << " full_well=" << config.options.merge.noise.full_well_e
         << " read_noise=" << config.options.merge.noise.read_noise_e
         << " watch=" << (config.watch ? "yes" : "no") << " force=" << (config.force ? "yes" : "no")
         << " threads=" << config.threads;
  return params.str();
}

}  // namespace

int RunReconstruct(int argc, char** argv) {
  RunConfig config;
  CLI::App app{
      "lumislab-reconstruct: photos of each grid position -> fitted E_ij in "
      "<dataset>/slab (docs/method.md §3)"};
  CommonOptions common;
  AddCommonOptions(&app, &common);
  app.add_option("--dataset", config.dataset_dir, "dataset folder (with dataset.json)")->required();
  app.add_option("--resolution", config.options.resolution, "slab texels per side")
      ->capture_default_str();
  app.add_flag("--watch", config.watch,
               "follow a live acquisition: process each position as its photos arrive, stop "
               "when the grid is complete");
  app.add_flag("--force", config.force, "redo positions whose slab EXR already exists");
  app.add_option("--lambda", config.options.lambda,
                 "regularisation of the fit (first differences, relative)")
      ->capture_default_str();
  app.add_option("--samples-per-texel", config.options.samples_per_texel,
                 "K x K samples per texel (0: automatic, as dense as the photo pixels)")
      ->capture_default_str();
  std::string bracket_ratios = "recorded";
  app.add_option("--bracket-ratios", bracket_ratios,
                 "exposure brackets: 'recorded' divides by the exposures in dataset.json (EXIF "
                 "or manifest), 'estimated' by the ratios between consecutive exposures measured "
                 "in the pixels well exposed in both (the middle exposure keeps its recorded "
                 "value); both report the difference")
      ->check(CLI::IsMember({"recorded", "estimated"}))
      ->capture_default_str();
  app.add_option("--full-well", config.options.merge.noise.full_well_e,
                 "brackets' noise model: electrons at the white level (shot noise)")
      ->capture_default_str();
  app.add_option("--read-noise", config.options.merge.noise.read_noise_e,
                 "brackets' noise model: read noise in electrons rms")
      ->capture_default_str();
  app.add_option("--poll", config.poll_s, "--watch: polling interval in seconds")
      ->capture_default_str();
  app.add_option("--idle-timeout", config.idle_timeout_s,
                 "--watch: fail after this many seconds without new photos (0: wait forever)")
      ->capture_default_str();
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  config.threads = StartTool("reconstruct", common);
  config.options.merge.bracket_ratios =
      bracket_ratios == "estimated" ? BracketRatios::kEstimated : BracketRatios::kRecorded;
  config.options.Check();
  if (!(config.poll_s > 0 && config.poll_s <= 60))
    throw BadInput("--poll: expected seconds in (0, 60], got " + std::to_string(config.poll_s));
  if (!(config.idle_timeout_s >= 0 && config.idle_timeout_s <= 1e6))
    throw BadInput("--idle-timeout: expected seconds in [0, 1e6], got " +
                   std::to_string(config.idle_timeout_s));
  config.dataset_dir = TrimTrailingSlashes(config.dataset_dir);
  LogInfo("parameters: ", Parameters(config));
  const StopSignalScope signals;
  return config.watch ? RunWatch(config) : RunBatch(config);
}

}  // namespace lumislab
