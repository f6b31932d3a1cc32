#include "lib/synthetic/calibration_captures.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "lib/synthetic/render.h"
#include "lib/synthetic/scene.h"

namespace lumislab {
namespace {

std::vector<double> Stops(const JsonView& list, size_t min_count, size_t max_count) {
  if (list.Size() < min_count || list.Size() > max_count)
    list.Fail(std::to_string(min_count) + " to " + std::to_string(max_count) + " stops");
  std::vector<double> stops;
  for (size_t k = 0; k < list.Size(); ++k) {
    const double stop = list[k].NumberIn(-8, 8);  // as the brackets effect's
    for (double other : stops)
      if (BracketsEffect::Tag(other) == BracketsEffect::Tag(stop))
        list[k].Fail("a stop not listed before");
    stops.push_back(stop);
  }
  return stops;
}

void CheckMembers(const JsonView& block, const std::vector<std::string>& allowed) {
  for (const std::string& key : block.Keys())
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError(block.file(), block.path() + "." + key, "one of " + list, "unknown member");
    }
}

bool Applies(const std::string& type, CaptureKind kind) {
  if (kind == CaptureKind::kDark)
    return type != "vignetting" && type != "screen_gain" && type != "ambient";
  if (kind == CaptureKind::kFlat) return type != "ambient";
  if (kind == CaptureKind::kCameraView || kind == CaptureKind::kColourChart)
    return type != "screen_gain" && type != "ambient";
  return true;
}

}  // namespace

CalibrationCaptures ParseCalibrationCaptures(const JsonView& block, const SynthScene& scene) {
  CheckMembers(block, {"dark_frames", "dark_stops", "flat_frames", "flat_level", "response_stops",
                       "reference", "colour_chart"});
  CalibrationCaptures c;
  if (block.Has("dark_frames")) c.dark_frames = block["dark_frames"].IntIn(0, 64);
  if (block.Has("dark_stops")) c.dark_stops = Stops(block["dark_stops"], 1, 9);
  if (block.Has("flat_frames")) c.flat_frames = block["flat_frames"].IntIn(0, 64);
  if (block.Has("flat_level")) c.flat_level = block["flat_level"].NumberIn(1e-3, 1);
  if (block.Has("response_stops")) c.response_stops = Stops(block["response_stops"], 2, 16);
  if (block.Has("colour_chart")) c.colour_chart = block["colour_chart"].OneOf({"D50", "D65"});
  if (block.Has("reference")) {
    const JsonView ref = block["reference"];
    CheckMembers(ref, {"position", "point_mm"});
    const JsonView position = ref["position"];
    c.reference_i = position[0].IntIn(0, scene.grid.nu - 1);
    c.reference_j = position[1].IntIn(0, scene.grid.nv - 1);
    if (position.Size() != 2) position.Fail("[i, j], a grid position");
    const std::vector<double> xy = ref["point_mm"].Numbers(2);
    c.point_mm = {xy[0], xy[1]};
    // The point must be on the screen and in the photos (the reading is compared to a pixel).
    const Eigen::Vector2d px =
        PinholeCamera(scene.camera).Project({xy[0], xy[1], scene.distance_mm});
    if (std::abs(xy[0]) > 0.5 * scene.screen_w_mm || std::abs(xy[1]) > 0.5 * scene.screen_h_mm ||
        !(px.x() >= 2 && px.y() >= 2 && px.x() <= scene.camera.width - 3 &&
          px.y() <= scene.camera.height - 3))
      ref["point_mm"].Fail("a lab point on the screen, in view of the camera");
    c.reference = true;
  }
  return c;
}

void ApplyCaptureEffects(const SynthScene& scene, CaptureKind kind, const PhotoContext& context,
                         ImageF* photo) {
  for (const auto& effect : scene.effects)
    if (Applies(effect->Type(), kind)) effect->Apply(*photo, context);
}

ImageF FlatFrameRender(const SynthScene& scene, double exposure) {
  const ScreenView view = ScreenView::Of(scene);
  ImageF photo(view.width, view.height, 3);
  const float v = float(scene.captures->flat_level * exposure);
  for (int p : view.pixels)
    for (int c = 0; c < 3; ++c) photo.data[size_t(p) * 3 + c] = v;
  return photo;
}

ImageF ResponseSceneRender(const SynthScene& scene, double exposure) {
  const ScreenView view = ScreenView::Of(scene);
  ImageF photo(view.width, view.height, 3);
  // The luminaire at the centre grid position without a slide: the screen's unfiltered
  // irradiance, luminaire frame (lab + c).
  const Eigen::Vector2d c = scene.grid.Centre(scene.grid.nu / 2, scene.grid.nv / 2);
  const Eigen::Vector2d half(0.5 * scene.screen_w_mm, 0.5 * scene.screen_h_mm);
  const PlaneLight light = PlaneLight::Open(scene.luminaire, scene.distance_mm, c - half, c + half);
  double peak = 0;
  for (size_t k = 0; k < view.pixels.size(); ++k) {
    const Eigen::Vector2d st = view.lab_mm[k] + c;
    const Eigen::Vector3d e = light.Irradiance(st.x(), st.y());
    for (int ch = 0; ch < 3; ++ch) photo.data[size_t(view.pixels[k]) * 3 + ch] = float(e[ch]);
    peak = std::max(peak, e.maxCoeff());
  }
  const float gain = peak > 0 ? float(0.5 * exposure / peak) : 0.f;
  for (float& v : photo.data) v *= gain;
  return photo;
}

ImageF TruthFlatGain(const SynthScene& scene) {
  ImageF gain(scene.camera.width, scene.camera.height, 1, 1.f);
  for (const auto& effect : scene.effects)
    if (effect->Type() == "vignetting" || effect->Type() == "screen_gain") effect->Apply(gain, {});
  return gain;
}

ImageF TruthDarkMap(const SynthScene& scene) {
  const int w = scene.camera.width, h = scene.camera.height;
  ImageF map(w, h, 3);
  const DarkEffect* dark = scene.Dark();
  if (!dark) return map;
  // The dark signal is black + current x exposure: its values at exposure 0 and 1.
  ImageF at0(w, h, 1), at1(w, h, 1);
  PhotoContext context;
  context.exposure = 0;
  dark->Apply(at0, context);
  context.exposure = 1;
  dark->Apply(at1, context);
  for (int p = 0; p < w * h; ++p) {
    map.data[size_t(p) * 3] = at0.data[p];
    map.data[size_t(p) * 3 + 1] = at1.data[p] - at0.data[p];
    map.data[size_t(p) * 3 + 2] = dark->Hot(p) ? 1.f : 0.f;
  }
  return map;
}

void ReferenceIrradiance(const SynthScene& scene, double radiometric_scale, Eigen::Vector3d* plus,
                         Eigen::Vector3d* minus) {
  const CalibrationCaptures& ref = *scene.captures;
  const DualFilter filter = scene.Filter();
  // Where the stage put the luminaire (as RenderPosition): the reading is of the real light.
  const Eigen::Vector2d c = scene.grid.Centre(ref.reference_i, ref.reference_j) +
                            scene.StageOffsetMm(ref.reference_i, ref.reference_j);
  const Eigen::Vector2d st = ref.point_mm + c;
  ScreenLight(scene, filter, c).Slides(st.x(), st.y(), plus, minus);
  // Ambient light is on the screen whichever slide is in: level x scale W/m^2 (at exposure 1 the
  // effect adds `level` to the normalised value).
  double ambient = 0;
  for (const auto& effect : scene.effects)
    if (const auto* a = dynamic_cast<const AmbientEffect*>(effect.get())) ambient += a->level();
  *plus += Eigen::Vector3d::Constant(ambient * radiometric_scale);
  *minus += Eigen::Vector3d::Constant(ambient * radiometric_scale);
}

}  // namespace lumislab
