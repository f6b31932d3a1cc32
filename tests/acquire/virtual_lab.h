// The virtual lab that `acquire capture` is tested in: a synthetic scene's luminaire carried by
// an emulated GRBL stage (grbl_emulator.h), photographed by an emulated PTP/IP camera
// (ptpip_camera_emulator.h) that libgphoto2 itself talks to. Each photo is rendered with
// lib/synthetic for the luminaire where the stage actually is, through the slide actually in
// place (the slide axis' position, or what the operator did), at the exposure actually set, and
// stored as the synthetic camera stores it (acquire/photo_store.h: 16-bit TIFF, JPEG or DNG,
// with EXIF). What the operator does (the slides, the board) the lab is told through files in
// its control folder, which tests/acquire/lab_operator.sh writes when `capture --operator`
// calls it.
#pragma once

#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "acquire/lab_setup.h"
#include "acquire/photo_store.h"
#include "core/image.h"
#include "lib/synthetic/render.h"
#include "lib/synthetic/scene.h"

namespace lumislab::virtual_lab {

struct LabPhoto {
  std::string extension;  // jpg, tif, dng (the camera's file)
  std::string bytes;
};

class Optics {
 public:
  // `control_dir`: where the operator's actions are (files "slide": p, n or none; "board": on or
  // off).
  Optics(SynthScene scene, LabSetup lab, std::string control_dir);
  double radiometric_scale() const { return scale_; }
  const SynthScene& scene() const { return scene_; }
  // The photo of the screen with the stage at `stage_mm` (its axes' positions), exposure time
  // `shutter_s` at the synthetic camera's f-number and ISO (photo_store.h): relative exposure
  // shutter_s / kBaseExposureTimeS. The board when it is on the screen, else the luminaire
  // through the slide in place (none: the luminaire's light unfiltered is not what a lab
  // records; the screen is then dark except for the board).
  LabPhoto Shoot(const std::map<char, double>& stage_mm, double shutter_s);
  int photos_taken() const { return photo_index_; }

 private:
  std::optional<bool> SlideInPlace(const std::map<char, double>& stage_mm) const;
  bool BoardOn() const;
  std::string Control(const std::string& name) const;

  SynthScene scene_;
  LabSetup lab_;
  std::string control_dir_;
  ScreenView view_;
  double scale_ = 0;
  PhotoStore store_;
  // The last render: a bracket's photos share the stage position and differ by exposure only.
  std::optional<Eigen::Vector2d> rendered_at_;
  ImageF plus_, minus_;
  int photo_index_ = 0;
  std::mutex mutex_;
};

// setup.json for a capture of `scene` in the virtual lab: the scene's setup as `acquire synth
// --camera-folder` writes it (what a lab knows), its radiometric scale (what the lab's scale
// calibration gives), and `lab_json` as the lab block.
std::string SetupJson(const SynthScene& scene, double radiometric_scale,
                      const std::string& lab_json);

}  // namespace lumislab::virtual_lab
