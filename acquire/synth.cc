#include "acquire/synth.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>
#include <vector>

#include "acquire/photo_store.h"
#include "acquire/synth_calibration.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/slab.h"
#include "core/stop_signal.h"
#include "lib/photo/photo_write.h"
#include "lib/synthetic/render.h"
#include "lib/synthetic/truth.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

constexpr double kTargetPeakValue = 0.85;
constexpr int kPrePassStride = 7;  // pixels of the pre-pass: every 7th one that sees the screen

PhotoEncoding SlidePhotoEncoding(const SynthScene& scene, const SynthOptions& options) {
  if (scene.Response()) return PhotoEncoding::kCurve8Jpeg;    // the camera's 8-bit output
  if (scene.Quantized()) return PhotoEncoding::kLinear16Png;  // the codes of the effect
  if (options.photo_format == "float")
    return options.compress_float ? PhotoEncoding::kFloatExrPiz : PhotoEncoding::kFloatExr;
  return PhotoEncoding::kHalfExr;
}

// The calibration photo as a camera's 8-bit output: linear reflectance through the sRGB curve
// (lib/photo's decoder linearises it back).
void WriteCalibrationPhoto(const SynthScene& scene, const std::string& path, int threads) {
  WritePhoto(path, RenderCalibration(scene, threads), PhotoEncoding::kSrgb8Png);
}

}  // namespace

void SynthOptions::Check() const {
  if (out_dir.empty()) throw BadInput("--out: expected a dataset folder, got nothing");
  if (!(interval_s < 0 || interval_s <= 3600))
    throw BadInput("--interval: expected seconds in [0, 3600], got " + std::to_string(interval_s));
  ResolveThreads(threads);  // BadInput naming --threads when out of range
  if (photo_format != "half" && photo_format != "float")
    throw BadInput("--photo-format: expected half or float, got " + photo_format);
  if (calibration_views < 0 || calibration_views > kMaxCalibrationViews)
    throw BadInput("--calibration-views: expected 0 .. " + std::to_string(kMaxCalibrationViews) +
                   ", got " + std::to_string(calibration_views));
  if (truth_resolution < 1 || truth_resolution > kMaxSlabResolution)
    throw BadInput("--truth-resolution: expected 1 .. " + std::to_string(kMaxSlabResolution) +
                   ", got " + std::to_string(truth_resolution));
  if (meter != "radiometer" && meter != "lux")
    throw BadInput("--meter: expected radiometer or lux, got " + meter);
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

void ApplyEffects(const SynthScene& scene, const PhotoContext& context, ImageF* photo) {
  for (const auto& effect : scene.effects) effect->Apply(*photo, context);
}

ImageF ExposedPhoto(const SynthScene& scene, const ImageF& render, int stop_index) {
  ImageF photo = render;
  if (!scene.Brackets()) return photo;
  // The render is linear in the exposure: scaling it is the photo at camera.exposure x 2^stop
  // (exact for whole stops).
  const float factor = float(std::exp2(scene.Brackets()->stops()[stop_index]));
  for (float& v : photo.data) v *= factor;
  return photo;
}

namespace {

PhotoContext ContextOf(const SynthScene& scene, int i, int j, bool positive, int stop_index) {
  PhotoContext context;
  context.photo_index = PhotoIndex(scene, i, j, positive, stop_index);
  context.exposure = scene.camera.exposure * std::exp2(scene.Stops()[stop_index]);
  return context;
}

}  // namespace

ImageF SynthPhoto(const SynthScene& scene, const ScreenView& view, double scale, int i, int j,
                  bool positive, int stop_index) {
  ImageF plus, minus;
  RenderPosition(scene, view, i, j, scale, &plus, &minus);
  ImageF photo = ExposedPhoto(scene, positive ? plus : minus, stop_index);
  ApplyEffects(scene, ContextOf(scene, i, j, positive, stop_index), &photo);
  return photo;
}

namespace {

// The automatic scale (ChooseRadiometricScale) sees every 7th pixel: light narrower than that
// (a beam of lobe exponent in the thousands) can peak above full scale and clip, which the
// scale was meant to avoid. Said once, with the scale that would keep it at 0.85.
void WarnIfPrePassMissedThePeak(const SynthScene& scene, const ImageF& plus, const ImageF& minus,
                                double scale, int i, int j) {
  if (scene.camera.radiometric_scale_w_m2 > 0) return;
  float peak = 0;
  for (const ImageF* image : {&plus, &minus})
    for (const float v : image->data) peak = std::max(peak, v);
  const double at_unit_exposure = peak / scene.camera.exposure;
  if (!(at_unit_exposure > 1)) return;
  static std::atomic<bool> said{false};
  if (said.exchange(true)) return;
  LogWarning(scene.source, ": light narrower than the scale's pre-pass (every ", kPrePassStride,
             "th pixel) peaks at ", at_unit_exposure, " x full scale at exposure 1 (position ", i,
             ",", j, "): its photos clip; set camera.radiometric_scale_w_m2 >= ",
             scale * at_unit_exposure / kTargetPeakValue);
}

// Renders, applies the effects to and writes the photos of every position: in order with a
// pause for a live acquisition, else on `threads` threads. A stop signal ends it after the
// positions in hand (each written whole). Returns the number of photos written.
int CapturePositions(const SynthScene& scene, const Dataset& dataset, const std::string& dir,
                     const SynthOptions& options, const PhotoStore& store, int threads) {
  const ScreenView view = ScreenView::Of(scene);
  const double scale = *dataset.radiometric_scale;
  const int count = scene.grid.count();
  const int stops = int(scene.Stops().size());
  Progress progress("acquire", count);
  std::atomic<int> written{0};
  auto capture = [&](int q) {
    const int i = q % scene.grid.nu, j = q / scene.grid.nu;
    if (options.interval_s >= 0 && q > 0 && !PauseUnlessStopped(options.interval_s)) return;
    if (StopRequested()) return;
    ImageF plus, minus;
    RenderPosition(scene, view, i, j, scale, &plus, &minus);
    WarnIfPrePassMissedThePeak(scene, plus, minus, scale, i, j);
    for (bool positive : {true, false})
      for (int stop = 0; stop < stops; ++stop) {
        // Without brackets the render itself is the photo (no copy); with them each stop
        // starts from its own scaled copy.
        ImageF& render = positive ? plus : minus;
        ImageF exposed = scene.Brackets() ? ExposedPhoto(scene, render, stop) : ImageF();
        ImageF& photo = scene.Brackets() ? exposed : render;
        const PhotoContext context = ContextOf(scene, i, j, positive, stop);
        ApplyEffects(scene, context, &photo);
        const PhotoEntry& entry = dataset.photos[size_t(context.photo_index)];
        StoreSlidePhoto(scene, store, dir + "/" + entry.file, photo, entry.exposure,
                        context.photo_index);
        ++written;
      }
    progress.Advance();
  };
  ParallelFor(count, options.interval_s >= 0 ? 1 : threads, capture);
  progress.Finish();
  return written;
}

}  // namespace

bool DatasetComplete(const std::string& dir) {
  try {
    const Dataset ds = Dataset::Load(dir);
    if (!fs::exists(ds.PhotoPath(ds.calibration.photo))) return false;
    for (const auto& p : ds.photos)
      if (!fs::exists(ds.PhotoPath(p.file))) return false;
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

namespace {

// Writes the whole dataset into `dir`: dataset.json and the calibration photo first (a live
// reader can start at once), the truth, then the photos. Returns the number of photos written.
int WriteDataset(const SynthScene& scene, const Dataset& dataset, const std::string& dir,
                 const SynthOptions& options, const PhotoStore& store, int threads) {
  const std::string photos = dir + "/" + (options.camera_folder ? kCameraFolder : "photos");
  MakeDirectories(photos);
  MakeDirectories(dir + "/truth");
  int orphans = 0;
  for (const std::string& d : {dir, photos, dir + "/truth"})
    orphans += RemoveOrphanedTemporaries(d);
  if (orphans > 0) LogInfo(dir, ": removed ", orphans, " temporary file(s) of an interrupted run");
  if (options.camera_folder)
    WriteSetupFile(dataset, dir + "/setup.json");  // what a lab knows; no dataset.json
  else
    dataset.Save(dir);
  WriteCalibrationPhoto(scene, dir + "/" + dataset.calibration.photo, threads);
  WriteTruthCamera(scene, dir + "/truth/camera.json");
  WriteTruthLuminaire(scene.luminaire, dir + "/truth/luminaire.json");
  if (scene.Response()) WriteTruthResponse(*scene.Response(), dir + "/truth/response.json");
  SlabInfo truth = SlabInfo::FromDataset(dataset, options.truth_resolution);
  if (options.meter == "lux") truth.units = "lux";  // K x W/m^2, as the meter reads
  WriteTruthSlab(scene.luminaire, truth, dir + "/truth", threads, scene.LuminousEfficacy());
  WriteCalibrationCaptures(scene, dataset, dir, store, threads);  // scene.captures only
  WriteReferenceReading(scene, dataset, dir, options.meter);
  WriteCameraViews(scene, dataset, dir, store, options.calibration_views, threads);
  return CapturePositions(scene, dataset, dir, options, store, threads);
}

}  // namespace

SynthReport RunSynth(const SynthScene& scene, const SynthOptions& options) {
  options.Check();
  SynthReport report;
  const std::string& out = options.out_dir;
  PhotoStore store;
  store.encoding = SlidePhotoEncoding(scene, options);
  store.jpeg_quality = scene.Response() ? scene.Response()->quality() : 95;
  store.camera_folder = options.camera_folder;
  if (!options.force &&
      (options.camera_folder ? CameraFolderComplete(scene, out) : DatasetComplete(out)) &&
      CameraViewsComplete(scene, store, out, options.calibration_views)) {
    LogInfo("a complete dataset is already in ", out, " (use --force to redo it)");
    report.skipped = true;
    return report;
  }
  const int threads = ResolveThreads(options.threads);
  Dataset dataset = DatasetSkeleton(scene);
  dataset.photos = options.camera_folder ? CameraFolderPhotoList(scene) : PhotoList(scene);
  if (options.camera_folder)
    dataset.calibration.photo = std::string(kCameraFolder) + "/" + kCameraBoardPhoto;
  dataset.radiometric_scale = ChooseRadiometricScale(scene, threads);
  report.radiometric_scale = *dataset.radiometric_scale;
  LogInfo("scene ", scene.source, ": ", scene.grid.nu, "x", scene.grid.nv, " positions, ",
          scene.camera.width, "x", scene.camera.height, " px photos (", StoreName(scene, store),
          options.camera_folder ? ", a camera folder" : "", "), radiometric scale ",
          report.radiometric_scale, " W/m^2 per unit, ", scene.effects.size(), " effect(s)");
  if (options.interval_s >= 0) {  // live: readers follow the files where they will stay
    report.photos_written = WriteDataset(scene, dataset, out, options, store, threads);
    return report;
  }
  // Offline: into a staging folder beside `out`, swapped in when complete, so that a failure, a
  // stop signal or a --force over a good dataset leaves the previous folder as it was.
  if (!WriteFolderStaged(out, [&](const std::string& staging) {
        report.photos_written = WriteDataset(scene, dataset, staging, options, store, threads);
        return !StopRequested();
      }))
    report.photos_written = 0;
  return report;
}

}  // namespace lumislab
