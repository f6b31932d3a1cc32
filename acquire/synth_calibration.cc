#include "acquire/synth_calibration.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/exr_io.h"
#include "core/json.h"
#include "core/log.h"
#include "core/parallel.h"
#include "lib/synthetic/calibration_captures.h"

namespace lumislab {
namespace {

struct Frame {
  CaptureKind kind;
  std::string file;  // relative to the dataset folder
  double exposure;
};

std::string Numbered(const std::string& stem, int k, const std::string& ext) {
  return stem + "_" + (k < 10 ? "0" : "") + std::to_string(k) + "." + ext;
}

std::vector<Frame> FrameList(const SynthScene& scene, const std::string& ext) {
  const CalibrationCaptures& c = *scene.captures;
  const double e0 = scene.camera.exposure;
  std::vector<Frame> frames;
  for (double stop : c.dark_stops)
    for (int k = 0; k < c.dark_frames; ++k)
      frames.push_back({CaptureKind::kDark,
                        Numbered("calibration/dark/dark_" + BracketsEffect::Tag(stop), k, ext),
                        e0 * std::exp2(stop)});
  for (int k = 0; k < c.flat_frames; ++k)
    frames.push_back({CaptureKind::kFlat, Numbered("calibration/flat/flat", k, ext), e0});
  for (double stop : c.response_stops)
    frames.push_back({CaptureKind::kResponse,
                      "calibration/response/response_" + BracketsEffect::Tag(stop) + "." + ext,
                      e0 * std::exp2(stop)});
  return frames;
}

nlohmann::json Rgb(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
double Luminance(const Eigen::Vector3d& v) {
  return 0.2126 * v.x() + 0.7152 * v.y() + 0.0722 * v.z();  // Rec. 709, as LinearGray
}

void WriteTruth(const SynthScene& scene, const Dataset& dataset, const std::string& dir) {
  WriteExr(dir + "/truth/flat.exr", TruthFlatGain(scene), {"Y"}, {}, {false, ExrCompression::kPiz});
  WriteExr(dir + "/truth/dark.exr", TruthDarkMap(scene), {"black", "current", "hot"}, {},
           {false, ExrCompression::kPiz});
  const CalibrationCaptures& c = *scene.captures;
  if (!c.reference) return;
  Eigen::Vector3d plus, minus;
  ReferenceIrradiance(scene, *dataset.radiometric_scale, &plus, &minus);
  nlohmann::json j;
  j["schema_version"] = 1;
  j["position"] = {c.reference_i, c.reference_j};
  j["point_mm"] = {c.point_mm.x(), c.point_mm.y()};
  j["unit"] = "W/m2";
  j["reading_p"] = Luminance(plus);
  j["reading_n"] = Luminance(minus);
  j["irradiance_p_w_m2"] = Rgb(plus);
  j["irradiance_n_w_m2"] = Rgb(minus);
  j["note"] =
      "radiometer readings (Rec. 709 luminance of the RGB irradiance) at point_mm (lab, screen) "
      "with slide p and n in at position [i, j], ambient light included";
  WriteJsonAtomically(dir + "/truth/reference.json", j);
}

}  // namespace

void WriteCalibrationCaptures(const SynthScene& scene, const Dataset& dataset,
                              const std::string& dir, const PhotoStore& store, int threads) {
  if (!scene.captures) return;
  for (const char* sub : {"/calibration/dark", "/calibration/flat", "/calibration/response"}) {
    MakeDirectories(dir + sub);
    RemoveOrphanedTemporaries(dir + sub);
  }
  WriteTruth(scene, dataset, dir);
  const std::vector<Frame> frames = FrameList(scene, StoredExtension(scene, store));
  ParallelFor(int(frames.size()), threads, [&](int k) {
    const Frame& f = frames[k];
    ImageF photo = f.kind == CaptureKind::kFlat ? FlatFrameRender(scene, f.exposure)
                   : f.kind == CaptureKind::kResponse
                       ? ResponseSceneRender(scene, f.exposure)
                       : ImageF(scene.camera.width, scene.camera.height, 3);
    PhotoContext context;
    context.photo_index = int(dataset.photos.size()) + k;  // after every slide photo
    context.exposure = f.exposure;
    ApplyCaptureEffects(scene, f.kind, context, &photo);
    StoreSlidePhoto(scene, store, dir + "/" + f.file, photo, f.exposure, context.photo_index);
  });
  nlohmann::json manifest;
  manifest["schema_version"] = 1;
  for (const char* key : {"dark", "flat", "response"}) manifest[key] = nlohmann::json::array();
  for (const Frame& f : frames) {
    const char* key = f.kind == CaptureKind::kDark   ? "dark"
                      : f.kind == CaptureKind::kFlat ? "flat"
                                                     : "response";
    manifest[key].push_back({{"file", f.file}, {"exposure", f.exposure}});
  }
  WriteJsonAtomically(dir + "/calibration/captures.json", manifest);
  LogInfo("calibration captures: ", frames.size(),
          " frame(s) in calibration/ (listed in calibration/captures.json)");
}

}  // namespace lumislab
