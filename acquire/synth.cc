#include "acquire/synth.h"

#include <atomic>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>
#include <vector>

#include "acquire/render.h"
#include "acquire/truth.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/slab.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

constexpr double kTargetPeakValue = 0.85;
constexpr int kPrePassStride = 7;  // pixels of the pre-pass: every 7th one that sees the screen

void WritePhoto(const SynthScene& scene, const std::string& path, ImageF& photo,
                bool compress_exr) {
  if (scene.Quantized()) {
    cv::Mat bgr, png;
    cv::cvtColor(AsMat(photo), bgr, cv::COLOR_RGB2BGR);
    bgr.convertTo(png, CV_16UC3, 65535.0);  // rounds and clips: code values of the effect
    WriteAtomically(path, [&](const std::string& tmp) {
      if (!cv::imwrite(tmp, png)) throw IoError(path, "could not encode the PNG photo");
    });
  } else {
    ExrOptions options;
    options.compress = compress_exr;
    WriteExr(path, photo, {"R", "G", "B"}, {}, options);
  }
}

void WriteCalibrationPhoto(const SynthScene& scene, const std::string& path) {
  const cv::Mat img = RenderCalibration(scene);
  WriteAtomically(path, [&](const std::string& tmp) {
    if (!cv::imwrite(tmp, img)) throw IoError(path, "could not encode the calibration photo");
  });
}

}  // namespace

void SynthOptions::Check() const {
  if (out_dir.empty()) throw BadInput("--out: expected a dataset folder, got nothing");
  if (!(interval_s < 0 || interval_s <= 3600))
    throw BadInput("--interval: expected seconds in [0, 3600], got " + std::to_string(interval_s));
  if (threads < 0 || threads > 1024)
    throw BadInput("--threads: expected 0 (all cores) .. 1024, got " + std::to_string(threads));
  if (truth_resolution < 1 || truth_resolution > 16384)
    throw BadInput("--truth-resolution: expected 1 .. 16384, got " +
                   std::to_string(truth_resolution));
}

double ChooseRadiometricScale(const SynthScene& scene, int threads) {
  if (scene.camera.radiometric_scale_w_m2 > 0) return scene.camera.radiometric_scale_w_m2;
  const ScreenView view = ScreenView::Of(scene);
  const double max_e = MaxSlideIrradiance(scene, view, kPrePassStride, threads);
  if (!(max_e > 0))
    throw BadInput(scene.source + ": camera: expected a view of the lit screen, got " +
                   (view.pixels.empty() ? "no pixel on the screen" : "only dark pixels"));
  return max_e / kTargetPeakValue;
}

void ApplyEffects(const SynthScene& scene, int photo_index, ImageF* photo) {
  cv::Mat mat = AsMat(*photo);
  for (const auto& effect : scene.effects) effect->Apply(mat, {photo_index});
}

ImageF SynthPhoto(const SynthScene& scene, const ScreenView& view, double scale, int i, int j,
                  bool positive) {
  ImageF plus, minus;
  RenderPosition(scene, view, i, j, scale, &plus, &minus);
  ImageF& photo = positive ? plus : minus;
  ApplyEffects(scene, PhotoIndex(scene, i, j, positive), &photo);
  return std::move(photo);
}

bool DatasetComplete(const std::string& dir) {
  try {
    const Dataset ds = Dataset::Load(dir);
    if (!fs::exists(ds.Path(ds.calibration.photo))) return false;
    for (const auto& p : ds.photos)
      if (!fs::exists(ds.Path(p.file))) return false;
    if (!fs::exists(dir + "/truth/camera.json")) return false;
    return SlabInfo::Load(dir + "/truth").Complete();
  } catch (const Error&) {
    return false;
  }
}

SynthReport RunSynth(const SynthOptions& options) {
  options.Check();
  return RunSynth(LoadScene(options.scene), options);
}

SynthReport RunSynth(const SynthScene& scene, const SynthOptions& options) {
  options.Check();
  SynthReport report;
  const std::string& out = options.out_dir;
  if (!options.force && DatasetComplete(out)) {
    LogInfo("a complete dataset is already in ", out, " (use --force to redo it)");
    report.skipped = true;
    return report;
  }
  const int threads = options.threads > 0 ? options.threads
                                          : int(std::max(1u, std::thread::hardware_concurrency()));
  Dataset dataset = DatasetSkeleton(scene);
  dataset.photos = PhotoList(scene);
  dataset.radiometric_scale = ChooseRadiometricScale(scene, threads);
  report.radiometric_scale = *dataset.radiometric_scale;
  LogInfo("scene ", scene.source, ": ", scene.grid.nu, "x", scene.grid.nv, " positions, ",
          scene.camera.width, "x", scene.camera.height, " px photos (", scene.PhotoExtension(),
          "), radiometric scale ", report.radiometric_scale, " W/m^2 per unit, ",
          scene.effects.size(), " effect(s)");
  MakeDirectories(out + "/photos");
  MakeDirectories(out + "/truth");

  // dataset.json and the calibration photo come first: a live reader can start at once.
  dataset.Save(out);
  WriteCalibrationPhoto(scene, out + "/" + scene.calibration.photo);
  WriteTruthCamera(scene, out + "/truth/camera.json");
  WriteTruthSlab(scene, dataset, out + "/truth", options.truth_resolution, threads);

  const ScreenView view = ScreenView::Of(scene);
  const double scale = *dataset.radiometric_scale;
  auto capture = [&](int q) {
    const int i = q % scene.grid.nu, j = q / scene.grid.nu;
    ImageF plus, minus;
    RenderPosition(scene, view, i, j, scale, &plus, &minus);
    for (bool positive : {true, false}) {
      ImageF& photo = positive ? plus : minus;
      const int index = PhotoIndex(scene, i, j, positive);
      ApplyEffects(scene, index, &photo);
      const std::string file = dataset.photos[index].file;
      WritePhoto(scene, out + "/" + file, photo, options.compress_exr);
    }
  };

  Progress progress("acquire", scene.grid.count());
  if (options.interval_s >= 0) {
    for (int q = 0; q < scene.grid.count(); ++q) {
      if (q > 0) std::this_thread::sleep_for(std::chrono::duration<double>(options.interval_s));
      capture(q);
      progress.Advance();
    }
  } else {
    std::atomic<int> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&] {
      for (int q = next++; q < scene.grid.count(); q = next++) {
        try {
          capture(q);
          progress.Advance();
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
          next = scene.grid.count();
        }
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
    if (error) std::rethrow_exception(error);
  }
  progress.Finish();
  report.photos_written = int(dataset.photos.size());
  return report;
}

}  // namespace lumislab
