#include "acquire/synth_calibration.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/exr_io.h"
#include "core/json.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/slab.h"  // Rec709Weights
#include "lib/synthetic/calibration_captures.h"
#include "lib/synthetic/camera_views.h"
#include "lib/synthetic/spectral.h"

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
  // Lit by its own lamp, exposed for it (the white patch ~0.7 of full scale), not at e0.
  if (!c.colour_chart.empty())
    frames.push_back({CaptureKind::kColourChart, "calibration/colour/chart." + ext, 1.0});
  return frames;
}

// The ColorChecker photo at the camera's size (lib/synthetic/spectral.h), before effects: the
// effects add the camera's noise.
ImageF ColourChartRender(const SynthScene& scene) {
  ColourChartPhotoSpec spec;
  spec.width = scene.camera.width;
  spec.height = scene.camera.height;
  spec.illuminant = scene.captures->colour_chart;
  spec.noise = 0;
  return RenderColourChartPhoto(spec);
}

nlohmann::json Rgb(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// What the truth meter reads at the reference point with slide T+ / T- in (ambient light
// included): a lux meter 683 integral of V E_lambda, a radiometer the Rec. 709 mix of the RGB
// irradiance. With a spectrum on every emitter (cct_k) the lux reading is exact: an emitter's
// camera RGB is its radiant irradiance (380 - 780 nm) times its RGB per watt (BlackbodyRgbPerWatt),
// so each emitter, rendered alone, gives its W/m^2, times its LuminousEfficacy; the ambient light
// is an equal-energy spectrum (camera RGB = its W/m^2 in every channel, DefaultLuminousEfficacy).
// Without, lux = K x the Rec. 709 mix (SynthScene::LuminousEfficacy, the synthetic convention).
struct Readings {
  double plus = 0, minus = 0;
  Eigen::Vector3d rgb_plus = Eigen::Vector3d::Zero(), rgb_minus = Eigen::Vector3d::Zero();
};
Readings MeterReadings(const SynthScene& scene, double radiometric_scale, bool lux) {
  Readings r;
  ReferenceIrradiance(scene, radiometric_scale, &r.rgb_plus, &r.rgb_minus);
  bool spectral = !scene.luminaire.emitters.empty() && scene.luminaire.ray_sources.empty();
  for (const Emitter& e : scene.luminaire.emitters) spectral = spectral && e.cct_k > 0;
  if (!lux || !spectral) {
    const double k = lux ? scene.LuminousEfficacy() : 1.0;  // lux = K x W/m^2
    r.plus = k * Rec709Weights().dot(r.rgb_plus);
    r.minus = k * Rec709Weights().dot(r.rgb_minus);
    return r;
  }
  SynthScene alone = scene;
  alone.luminaire.emitters.clear();
  Eigen::Vector3d ambient_p, ambient_n;  // the same on both: the ambient light alone
  ReferenceIrradiance(alone, radiometric_scale, &ambient_p, &ambient_n);
  r.plus = DefaultLuminousEfficacy() * ambient_p.x();
  r.minus = DefaultLuminousEfficacy() * ambient_n.x();
  for (const Emitter& e : scene.luminaire.emitters) {
    alone.luminaire.emitters = {e};
    Eigen::Vector3d p, n;
    ReferenceIrradiance(alone, radiometric_scale, &p, &n);
    const double rgb_per_watt = e.intensity_w_sr.sum() / e.radiant_w_sr;
    r.plus += e.LuminousEfficacy() * (p - ambient_p).sum() / rgb_per_watt;
    r.minus += e.LuminousEfficacy() * (n - ambient_n).sum() / rgb_per_watt;
  }
  return r;
}

void WriteTruth(const SynthScene& scene, const Dataset& dataset, const std::string& dir) {
  WriteExr(dir + "/truth/flat.exr", TruthFlatGain(scene), {"Y"}, {}, {false, ExrCompression::kPiz});
  WriteExr(dir + "/truth/dark.exr", TruthDarkMap(scene), {"black", "current", "hot"}, {},
           {false, ExrCompression::kPiz});
}

}  // namespace

void WriteReferenceReading(const SynthScene& scene, const Dataset& dataset, const std::string& dir,
                           const std::string& meter) {
  const bool lux = meter == "lux";
  SynthScene read = scene;
  if (!read.captures || !read.captures->reference) {
    if (!lux) return;  // a radiometer reading only where the scene asks for one
    // A lux meter at the screen's centre, read at the grid position where the slides' signal
    // there (T+ minus T-) is largest: calibrate scale divides by it, and a position whose
    // slide p holds no light (an emitter under the negative lobe) gives no scale.
    CalibrationCaptures c = read.captures ? *read.captures : CalibrationCaptures{};
    c.reference = true;
    c.point_mm = {0, 0};
    double best = -1;
    for (int j = 0; j < scene.grid.nv; ++j)
      for (int i = 0; i < scene.grid.nu; ++i) {
        CalibrationCaptures at = c;
        at.reference_i = i;
        at.reference_j = j;
        read.captures = at;
        const Readings r = MeterReadings(read, *dataset.radiometric_scale, lux);
        const double signal = r.plus - r.minus;
        if (signal > best) best = signal, c = at;
      }
    read.captures = c;
  }
  const CalibrationCaptures& c = *read.captures;
  const Readings r = MeterReadings(read, *dataset.radiometric_scale, lux);
  const double k = lux ? scene.LuminousEfficacy() : 1.0;  // truth lm = K x W
  nlohmann::json j;
  j["schema_version"] = 1;
  j["position"] = {c.reference_i, c.reference_j};
  j["point_mm"] = {c.point_mm.x(), c.point_mm.y()};
  j["unit"] = lux ? "lux" : "W/m2";
  j["reading_p"] = r.plus;
  j["reading_n"] = r.minus;
  j["irradiance_p_w_m2"] = Rgb(r.rgb_plus);
  j["irradiance_n_w_m2"] = Rgb(r.rgb_minus);
  if (lux) j["luminous_efficacy_lm_w"] = k;
  j["note"] = std::string(lux ? "lux meter readings (683 x the integral of V E_lambda for "
                                "emitters with a spectrum, cct_k; otherwise K x the Rec. 709 "
                                "mix of the RGB irradiance, K = luminous_efficacy_lm_w)"
                              : "radiometer readings (Rec. 709 mix of the RGB irradiance)") +
              " at point_mm (lab, screen) with slide p and n in at position [i, j], ambient "
              "light included";
  WriteJsonAtomically(dir + "/truth/reference.json", j);
}

void WriteCalibrationCaptures(const SynthScene& scene, const Dataset& dataset,
                              const std::string& dir, const PhotoStore& store, int threads) {
  if (!scene.captures) return;
  std::vector<std::string> subs = {"/calibration/dark", "/calibration/flat",
                                   "/calibration/response"};
  if (!scene.captures->colour_chart.empty()) subs.push_back("/calibration/colour");
  for (const std::string& sub : subs) {
    MakeDirectories(dir + sub);
    RemoveOrphanedTemporaries(dir + sub);
  }
  WriteTruth(scene, dataset, dir);
  const std::vector<Frame> frames = FrameList(scene, StoredExtension(scene, store));
  ParallelFor(int(frames.size()), threads, [&](int k) {
    const Frame& f = frames[k];
    ImageF photo = f.kind == CaptureKind::kFlat       ? FlatFrameRender(scene, f.exposure)
                   : f.kind == CaptureKind::kResponse ? ResponseSceneRender(scene, f.exposure)
                   : f.kind == CaptureKind::kColourChart
                       ? ColourChartRender(scene)
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
    if (f.kind == CaptureKind::kColourChart) {
      manifest["colour"] = {{"file", f.file},
                            {"chart", "ColorChecker Classic 24"},
                            {"illuminant", scene.captures->colour_chart}};
      continue;
    }
    const char* key = f.kind == CaptureKind::kDark   ? "dark"
                      : f.kind == CaptureKind::kFlat ? "flat"
                                                     : "response";
    manifest[key].push_back({{"file", f.file}, {"exposure", f.exposure}});
  }
  WriteJsonAtomically(dir + "/calibration/captures.json", manifest);
  LogInfo("calibration captures: ", frames.size(),
          " frame(s) in calibration/ (listed in calibration/captures.json)");
}

std::string CameraViewFile(const SynthScene& scene, const PhotoStore& store, int k) {
  return Numbered("calibration/camera/view", k, StoredExtension(scene, store));
}

void WriteCameraViews(const SynthScene& scene, const Dataset& dataset, const std::string& dir,
                      const PhotoStore& store, int count, int threads) {
  if (count <= 0) return;
  MakeDirectories(dir + "/calibration/camera");
  RemoveOrphanedTemporaries(dir + "/calibration/camera");
  const std::vector<BoardPose> poses = CameraViewPoses(scene, count);
  // Noise streams after the slide photos' and the calibration captures'.
  const int first_index =
      int(dataset.photos.size()) +
      (scene.captures ? int(FrameList(scene, StoredExtension(scene, store)).size()) : 0);
  nlohmann::json views = nlohmann::json::array();
  for (int k = 0; k < count; ++k) {
    const ImageF board = RenderCameraView(scene, poses[k], threads);
    ImageF photo(board.width, board.height, 3);
    for (size_t p = 0; p < board.data.size(); ++p)
      for (int c = 0; c < 3; ++c) photo.data[p * 3 + c] = board.data[p];
    PhotoContext context;
    context.photo_index = first_index + k;
    context.exposure = scene.camera.exposure;
    ApplyCaptureEffects(scene, CaptureKind::kCameraView, context, &photo);
    const std::string file = CameraViewFile(scene, store, k);
    StoreSlidePhoto(scene, store, dir + "/" + file, photo, context.exposure, context.photo_index);
    const Eigen::AngleAxisd r(poses[k].rotation);
    const Eigen::Vector3d rvec = r.angle() * r.axis();
    const Eigen::Vector3d& t = poses[k].translation_mm;
    views.push_back({{"photo", file},
                     {"tilt_deg", poses[k].TiltDeg()},
                     {"rotation", {rvec.x(), rvec.y(), rvec.z()}},
                     {"translation_mm", {t.x(), t.y(), t.z()}}});
  }
  nlohmann::json j;
  j["schema_version"] = 1;
  j["board"] = {{"type", "chessboard"},
                {"inner_corners", {kViewBoardInnerCols, kViewBoardInnerRows}},
                {"square_mm", kViewBoardSquareMm}};
  j["views"] = views;
  // Inner corner (c, r) lies (c + 1) squares from the board's corner, the board centred on the
  // frame's origin (ViewBoardTarget).
  j["note"] =
      "camera_from_board poses (angle-axis rad, mm) of the board views; board corner (c, r) is "
      "at ((c + 1 - " +
      Num((kViewBoardInnerCols + 1) / 2.0, 6) + ") s, (r + 1 - " +
      Num((kViewBoardInnerRows + 1) / 2.0, 6) + ") s, 0) mm in the board frame, s = square_mm";
  WriteJsonAtomically(dir + "/truth/camera_views.json", j);
  LogInfo("calibration views: ", count, " photo(s) of a ", kViewBoardInnerCols, "x",
          kViewBoardInnerRows, " board of ", kViewBoardSquareMm,
          " mm squares in calibration/camera/ (lumislab-calibrate camera --photos "
          "<out>/calibration/camera --board ",
          kViewBoardInnerCols, "x", kViewBoardInnerRows, " --square-mm ", kViewBoardSquareMm, ")");
}

bool CameraViewsComplete(const SynthScene& scene, const PhotoStore& store, const std::string& dir,
                         int count) {
  if (count <= 0) return true;
  if (!std::filesystem::exists(dir + "/truth/camera_views.json")) return false;
  for (int k = 0; k < count; ++k)
    if (!std::filesystem::exists(dir + "/" + CameraViewFile(scene, store, k))) return false;
  return true;
}

}  // namespace lumislab
