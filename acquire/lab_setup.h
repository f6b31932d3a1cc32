// How a lab's hardware carries out a capture: the "lab" block of setup.json (docs/formats.md §3),
// read by `lumislab-acquire capture` and by nothing else (dataset.json does not keep it; the
// capture copies setup.json into <dataset>/capture/). Where the grid's positions are on the
// stage, the stage's travel (soft limits, checked before anything moves), how the slides are
// changed, and the camera's settings and brackets.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "acquire/devices/device.h"
#include "core/dataset.h"

namespace lumislab {

struct LabSetup {
  // The stage axes that move the luminaire along the grid's u and v (luminaire frame), the stage
  // position of the grid's centre, and each axis' sense (+1: stage coordinate grows with u or v).
  char axis_u = 'X', axis_v = 'Y';
  Eigen::Vector2d origin_mm{0, 0};
  Eigen::Vector2d direction{1, 1};
  // Soft limits per stage axis (mm), every axis capture moves; checked before the first move.
  struct Travel {
    char axis;
    double min_mm, max_mm;
  };
  std::vector<Travel> travel;
  StageSettings stage;
  // A stage axis that carries the slides: the positions (mm) at which T+ and T- are in place.
  // Absent: the operator swaps the slides when prompted.
  struct SlideAxis {
    char axis = 'Z';
    double p_mm = 0, n_mm = 0;
  };
  std::optional<SlideAxis> slide_axis;
  // A stage axis that turns the luminaire (docs/formats.md §19, "Capturing orientations in the
  // lab"): `capture --orientations` moves it to each orientation's axis_deg (absolute degrees)
  // and asks the operator only to remount. `about` is the capture-frame direction it turns
  // about, right-handed for growing angles (+x, +y, +z, -x, -y or -z).
  struct RotationAxis {
    char axis = 'A';
    Eigen::Vector3d about{0, 1, 0};
    std::string about_name = "y";  // as the setup spells it
  };
  std::optional<RotationAxis> rotation_axis;
  CameraSettings camera;
  // Photos per slide at each position and the ratio between neighbouring ones (stops); the
  // shortest is chosen by the test shot unless `shutter_s` gives the whole bracket (s).
  int brackets = 3;
  double bracket_stops = 2;
  std::vector<double> shutter_s;
  // The board photo's exposure time (s); 0: chosen by a test shot like the slides'.
  double board_shutter_s = 0;

  // The stage targets of grid position (i, j): the u and v axes.
  AxisTargets PositionTargets(const SamplingGrid& grid, int i, int j) const;
  // The target of the slide axis for a slide.
  AxisTargets SlideTargets(bool positive) const;
  // BadInput naming `file` and the axis when a target of the grid or the slide axis lies outside
  // `travel` (or an axis moved has no travel given).
  void CheckTravel(const SamplingGrid& grid, const std::string& file) const;
};

// The "lab" block of a setup file (errors name the file and field: setup.json:
// lab.stage.travel_mm.X).
LabSetup ParseLabSetup(const JsonView& lab);
// The lab block of the setup file at `path`; a setup without one is BadInput naming the file
// (capture needs to know where the grid is on the stage).
LabSetup LoadLabSetup(const std::string& path);

}  // namespace lumislab
