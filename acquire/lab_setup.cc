#include "acquire/lab_setup.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/json.h"
#include "core/log.h"

namespace lumislab {
namespace {

const std::vector<std::string> kAxes = {"X", "Y", "Z", "A", "B", "C"};

char ParseAxis(const JsonView& v) { return v.OneOf(kAxes)[0]; }

std::string Mm(double v) { return Num(v, 6) + " mm"; }

}  // namespace

AxisTargets LabSetup::PositionTargets(const SamplingGrid& grid, int i, int j) const {
  const Eigen::Vector2d p = grid.Centre(i, j);
  return {{axis_u, origin_mm.x() + direction.x() * p.x()},
          {axis_v, origin_mm.y() + direction.y() * p.y()}};
}

AxisTargets LabSetup::SlideTargets(bool positive) const {
  if (!slide_axis) return {};
  return {{slide_axis->axis, positive ? slide_axis->p_mm : slide_axis->n_mm}};
}

void LabSetup::CheckTravel(const SamplingGrid& grid, const std::string& file) const {
  // The grid's extreme positions are its corners; the slide axis has two targets.
  std::vector<AxisTargets> targets = {PositionTargets(grid, 0, 0),
                                      PositionTargets(grid, grid.nu - 1, grid.nv - 1)};
  if (slide_axis) {
    targets.push_back(SlideTargets(true));
    targets.push_back(SlideTargets(false));
  }
  for (const AxisTargets& t : targets) {
    for (const auto& target : t) {
      const char axis = target.first;
      const double mm = target.second;
      const auto it = std::find_if(travel.begin(), travel.end(),
                                   [&](const Travel& tr) { return tr.axis == axis; });
      const std::string field = std::string("lab.stage.travel_mm.") + axis;
      if (it == travel.end())
        throw InputError(file, field, "the travel of every axis the capture moves", "none");
      if (mm < it->min_mm - 1e-9 || mm > it->max_mm + 1e-9)
        throw InputError(file, field,
                         "a travel [" + Mm(it->min_mm) + ", " + Mm(it->max_mm) +
                             "] that holds every target of the grid and the slides",
                         "a target at " + Mm(mm) + " (the grid spans " +
                             Mm((grid.nu - 1) * grid.spacing_mm) + " x " +
                             Mm((grid.nv - 1) * grid.spacing_mm) + " around the origin)");
    }
  }
}

LabSetup ParseLabSetup(const JsonView& lab) {
  LabSetup s;
  const JsonView stage = lab["stage"];
  if (stage.Has("axes")) {
    const JsonView axes = stage["axes"];
    if (axes.Size() != 2) axes.Fail("two stage axes, for u and v");
    s.axis_u = ParseAxis(axes[0]);
    s.axis_v = ParseAxis(axes[1]);
    if (s.axis_u == s.axis_v) axes.Fail("two different axes");
  }
  const std::vector<double> origin = stage["origin_mm"].Numbers(2);
  s.origin_mm = {origin[0], origin[1]};
  for (double o : origin)
    if (std::abs(o) > kMaxCoordinateMm) stage["origin_mm"].Fail("coordinates within 1e6 mm");
  if (stage.Has("direction")) {
    const std::vector<double> d = stage["direction"].Numbers(2);
    for (double v : d)
      if (v != 1 && v != -1) stage["direction"].Fail("[±1, ±1]");
    s.direction = {d[0], d[1]};
  }
  const JsonView travel = stage["travel_mm"];
  for (const std::string& key : travel.Keys()) {
    if (std::find(kAxes.begin(), kAxes.end(), key) == kAxes.end())
      travel[key].Fail("an axis X, Y, Z, A, B or C");
    const std::vector<double> range = travel[key].Numbers(2);
    if (!(range[0] < range[1]) || std::abs(range[0]) > kMaxCoordinateMm ||
        std::abs(range[1]) > kMaxCoordinateMm)
      travel[key].Fail("[min, max] with min < max (mm)");
    s.travel.push_back({key[0], range[0], range[1]});
  }
  s.stage.home = stage.BoolOr("home", false);
  s.stage.feed_mm_min = stage.Has("feed_mm_min") ? stage["feed_mm_min"].NumberIn(1, 1e5) : 1000;
  s.stage.tolerance_mm =
      stage.Has("tolerance_mm") ? stage["tolerance_mm"].NumberIn(1e-4, 10) : 0.01;
  s.stage.reply_timeout_s =
      stage.Has("reply_timeout_s") ? stage["reply_timeout_s"].NumberIn(0.1, 600) : 5;
  s.stage.move_timeout_s =
      stage.Has("move_timeout_s") ? stage["move_timeout_s"].NumberIn(0.1, 3600) : 120;
  s.stage.settle_s = stage.Has("settle_s") ? stage["settle_s"].NumberIn(0, 600) : 0;

  if (lab.Has("slides")) {
    const JsonView slides = lab["slides"];
    LabSetup::SlideAxis axis;
    axis.axis = ParseAxis(slides["axis"]);
    if (axis.axis == s.axis_u || axis.axis == s.axis_v)
      slides["axis"].Fail("an axis other than the grid's two");
    axis.p_mm = slides["p_mm"].NumberIn(-kMaxCoordinateMm, kMaxCoordinateMm);
    axis.n_mm = slides["n_mm"].NumberIn(-kMaxCoordinateMm, kMaxCoordinateMm);
    if (axis.p_mm == axis.n_mm) slides["n_mm"].Fail("a position other than p_mm");
    s.slide_axis = axis;
  }

  if (lab.Has("rotation_axis")) {
    const JsonView rotation = lab["rotation_axis"];
    LabSetup::RotationAxis axis;
    axis.axis = ParseAxis(rotation["stage_axis"]);
    if (axis.axis == s.axis_u || axis.axis == s.axis_v ||
        (s.slide_axis && axis.axis == s.slide_axis->axis))
      rotation["stage_axis"].Fail("an axis other than the grid's two and the slides'");
    axis.about_name = rotation["about"].OneOf({"x", "y", "z", "-x", "-y", "-z"});
    const int k = axis.about_name.back() - 'x';
    axis.about = Eigen::Vector3d::Unit(k) * (axis.about_name[0] == '-' ? -1 : 1);
    s.rotation_axis = axis;
    s.stage.rotary_axis = axis.axis;
    s.stage.tolerance_deg =
        rotation.Has("tolerance_deg") ? rotation["tolerance_deg"].NumberIn(1e-4, 10) : 0.05;
  }

  if (lab.Has("camera")) {
    const JsonView camera = lab["camera"];
    s.camera.aperture = camera.StringOr("aperture", "");
    s.camera.iso = camera.StringOr("iso", "");
    s.camera.image_format = camera.StringOr("image_format", "");
    s.camera.delete_from_card = camera.BoolOr("delete_from_card", false);
    s.camera.capture_timeout_s =
        camera.Has("capture_timeout_s") ? camera["capture_timeout_s"].NumberIn(1, 3600) : 60;
    s.camera.connect_timeout_s =
        camera.Has("connect_timeout_s") ? camera["connect_timeout_s"].NumberIn(1, 600) : 10;
    s.brackets = camera.Has("brackets") ? camera["brackets"].IntIn(1, 9) : 3;
    s.bracket_stops = camera.Has("bracket_stops") ? camera["bracket_stops"].NumberIn(0.3, 8) : 2;
    if (camera.Has("shutter_s")) {
      s.shutter_s = camera["shutter_s"].Numbers();
      for (size_t k = 0; k < s.shutter_s.size(); ++k) {
        if (!(s.shutter_s[k] >= 1e-6 && s.shutter_s[k] <= 3600))
          camera["shutter_s"][k].Fail("an exposure time in [1e-6, 3600] s");
        if (k > 0 && !(s.shutter_s[k] > s.shutter_s[k - 1]))
          camera["shutter_s"][k].Fail("times in increasing order");
      }
      if (camera.Has("brackets") && int(s.shutter_s.size()) != s.brackets)
        camera["shutter_s"].Fail(std::to_string(s.brackets) + " times (lab.camera.brackets)");
      s.brackets = int(s.shutter_s.size());
    }
    s.board_shutter_s =
        camera.Has("board_shutter_s") ? camera["board_shutter_s"].NumberIn(1e-6, 3600) : 0;
  }
  return s;
}

LabSetup LoadLabSetup(const std::string& path) {
  const JsonDocument doc = JsonDocument::Load(path);
  if (!doc.root().Has("lab"))
    throw InputError(path, "lab",
                     "the lab block (where the grid is on the stage, its travel, the camera; "
                     "docs/formats.md §3)",
                     "none");
  return ParseLabSetup(doc.root()["lab"]);
}

}  // namespace lumislab
