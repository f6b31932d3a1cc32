#include "virtual_lab.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "acquire/synth.h"
#include "core/atomic_file.h"
#include "core/error.h"

namespace fs = std::filesystem;

namespace lumislab::virtual_lab {

Optics::Optics(SynthScene scene, LabSetup lab, std::string control_dir)
    : scene_(std::move(scene)),
      lab_(std::move(lab)),
      control_dir_(std::move(control_dir)),
      view_(ScreenView::Of(scene_)),
      scale_(ChooseRadiometricScale(scene_, 2)) {
  store_.camera_folder = true;
  if (scene_.Response()) store_.encoding = PhotoEncoding::kCurve8Jpeg;
}

std::string Optics::Control(const std::string& name) const {
  std::ifstream in(control_dir_ + "/" + name);
  std::string value;
  in >> value;
  return value;
}

bool Optics::BoardOn() const { return Control("board") == "on"; }

std::optional<bool> Optics::SlideInPlace(const std::map<char, double>& stage_mm) const {
  if (lab_.slide_axis) {
    const auto it = stage_mm.find(lab_.slide_axis->axis);
    const double z = it == stage_mm.end() ? 0 : it->second;
    // A slide sits in the beam only where the axis holds it (within a tenth of a millimetre).
    if (std::abs(z - lab_.slide_axis->p_mm) < 0.1) return true;
    if (std::abs(z - lab_.slide_axis->n_mm) < 0.1) return false;
    return std::nullopt;
  }
  const std::string slide = Control("slide");
  if (slide == "p") return true;
  if (slide == "n") return false;
  return std::nullopt;
}

LabPhoto Optics::Shoot(const std::map<char, double>& stage_mm, double shutter_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double exposure = shutter_s / kBaseExposureTimeS;
  ImageF photo(view_.width, view_.height, 3);
  if (BoardOn()) {
    // The board lit by the room: reflectance x exposure (white 0.8 at exposure 1).
    const ImageF board = RenderCalibration(scene_, 2);
    for (size_t p = 0; p < size_t(view_.width) * view_.height; ++p)
      for (int ch = 0; ch < 3; ++ch) photo.data[p * 3 + ch] = float(board.data[p] * exposure);
  } else if (const std::optional<bool> slide = SlideInPlace(stage_mm)) {
    // Where the stage is, in the luminaire frame: the inverse of LabSetup::PositionTargets.
    const auto at = [&](char axis) {
      const auto it = stage_mm.find(axis);
      return it == stage_mm.end() ? 0.0 : it->second;
    };
    const Eigen::Vector2d c((at(lab_.axis_u) - lab_.origin_mm.x()) * lab_.direction.x(),
                            (at(lab_.axis_v) - lab_.origin_mm.y()) * lab_.direction.y());
    if (!rendered_at_ || (*rendered_at_ - c).norm() > 1e-9) {
      RenderAt(scene_, view_, c, 1.0 / scale_, &plus_, &minus_);
      rendered_at_ = c;
    }
    const ImageF& render = *slide ? plus_ : minus_;
    for (size_t k = 0; k < render.data.size(); ++k)
      photo.data[k] = float(render.data[k] * exposure);
    PhotoContext context;
    context.photo_index = photo_index_;
    context.exposure = exposure;
    ApplyEffects(scene_, context, &photo);
  }
  const std::string ext = StoredExtension(scene_, store_);
  const std::string tmp =
      (fs::temp_directory_path() / ("virtual_lab_" + std::to_string(::getpid()) + "." + ext))
          .string();
  StoreSlidePhoto(scene_, store_, tmp, photo, exposure, photo_index_++);
  LabPhoto out;
  out.extension = ext;
  out.bytes = ReadTextFile(tmp);
  fs::remove(tmp);
  return out;
}

std::string SetupJson(const SynthScene& scene, double radiometric_scale,
                      const std::string& lab_json) {
  Dataset ds = DatasetSkeleton(scene);
  ds.radiometric_scale = radiometric_scale;
  nlohmann::json setup = ds.ToJson();
  setup.erase("photos");
  setup.erase("synthetic");
  setup.erase("photo_folder");
  setup["calibration"]["photo"] = "board.tif";  // capture names it after the camera's file
  setup["lab"] = nlohmann::json::parse(lab_json);
  return setup.dump(2);
}

}  // namespace lumislab::virtual_lab
