#include "core/dataset.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "core/error.h"
#include "core/json.h"

namespace lumislab {

namespace {
// A path that stays inside the dataset folder: relative, without "..".
bool IsRelativeInside(const std::string& path) {
  return !path.empty() && path[0] != '/' && path.find("..") == std::string::npos;
}
}  // namespace

void CalibrationTarget::Check(const std::string& file, const std::string& field) const {
  const std::string got = std::to_string(squares_x) + " x " + std::to_string(squares_y);
  if (squares_x < kMinBoardSquares || squares_y < kMinBoardSquares)
    throw InputError(file, field + ".squares", "at least 3 x 3 squares", got);
  if (squares_x == squares_y)
    throw InputError(file, field + ".squares",
                     "squares_x != squares_y (a square board with one dot looks the same "
                     "mirrored about its diagonal)",
                     got);
  if (!(square_mm > 0 && std::isfinite(square_mm)))
    throw InputError(file, field + ".square_mm", "a length > 0", std::to_string(square_mm));
}

SamplingGrid ParseGrid(const JsonView& grid) {
  SamplingGrid g;
  g.nu = grid["nu"].IntIn(1, kMaxGridSide);
  g.nv = grid["nv"].IntIn(1, kMaxGridSide);
  g.spacing_mm = grid["spacing_mm"].NumberIn(kMinSpacingMm, kMaxSpacingMm);
  return g;
}

nlohmann::json GridJson(const SamplingGrid& grid) {
  return {{"nu", grid.nu}, {"nv", grid.nv}, {"spacing_mm", grid.spacing_mm}};
}

Eigen::Vector2d ParseLengthPair(const JsonView& value) {
  const std::vector<double> v = value.Numbers(2);
  for (double x : v)
    if (!(x >= kMinScreenMm && x <= kMaxScreenMm))
      value.Fail("two lengths in [" + std::to_string(int(kMinScreenMm)) +
                 ", 1e5] mm (width, height)");
  return {v[0], v[1]};
}

double ParseDistance(const JsonView& value) {
  return value.NumberIn(kMinDistanceMm, kMaxDistanceMm);
}

int ParseFilterTruncation(const JsonView& k_max) {
  return k_max.IntIn(kMinFilterTruncation, kMaxFilterTruncation);
}

FilterInfo FilterInfo::Of(const DualFilter& filter, double spacing_mm) {
  FilterInfo info;
  info.spacing_mm = spacing_mm;
  info.dual_coefficients = filter.coefficients();
  info.peak = filter.Peak2D();
  return info;
}

FilterInfo ParseFilterInfo(const JsonView& filter, const SamplingGrid& grid) {
  FilterInfo f;
  f.basis = filter["basis"].OneOf({"bell"});
  f.spacing_mm = filter["spacing_mm"].NumberIn(kMinSpacingMm, kMaxSpacingMm);
  if (std::abs(f.spacing_mm - grid.spacing_mm) > 1e-9 * grid.spacing_mm)
    filter["spacing_mm"].Fail("the grid spacing (" + std::to_string(grid.spacing_mm) + " mm)");
  f.dual_coefficients = filter["dual_coefficients"].Numbers();
  if (f.dual_coefficients.size() > size_t(kMaxFilterTruncation) + 1)
    filter["dual_coefficients"].Fail(
        "at most " + std::to_string(kMaxFilterTruncation + 1) +
        " coefficients (truncation K <= " + std::to_string(kMaxFilterTruncation) + ")");
  f.peak = filter["peak"].Positive();
  // The slides were printed as Phi~ / peak: a peak that is not that of the coefficients would
  // scale every E_ij by the ratio.
  const double expected = f.Filter().Peak2D();
  if (std::abs(f.peak - expected) > 1e-6 * expected)
    filter["peak"].Fail("max |Phi~| of dual_coefficients (" + std::to_string(expected) + ")");
  return f;
}

nlohmann::json FilterInfoJson(const FilterInfo& filter) {
  return {{"basis", filter.basis},
          {"spacing_mm", filter.spacing_mm},
          {"dual_coefficients", filter.dual_coefficients},
          {"peak", filter.peak}};
}

std::string PhotoFileName(int i, int j, bool positive, const std::string& ext,
                          const std::string& exposure_tag) {
  std::string name =
      "pos_" + std::to_string(i) + "_" + std::to_string(j) + "_" + (positive ? "p" : "n");
  if (!exposure_tag.empty()) name += "_" + exposure_tag;
  return name + "." + ext;
}

std::string Dataset::PhotoPath(const std::string& file) const {
  if (photo_folder.empty()) return Path(file);
  if (photo_folder[0] == '/') return photo_folder + "/" + file;
  return Path(photo_folder + "/" + file);
}

std::vector<PhotoEntry> Dataset::PhotosOf(int i, int j) const {
  std::vector<PhotoEntry> out;
  for (const auto& p : photos)
    if (p.i == i && p.j == j) out.push_back(p);
  return out;
}

Dataset Dataset::Load(const std::string& dir) {
  return Parse(JsonDocument::Load(dir + "/dataset.json"), dir);
}

Dataset Dataset::Parse(const JsonDocument& doc, const std::string& dir, bool with_photos) {
  const std::string& file = doc.file();
  doc.CheckSchemaVersion(kDatasetSchemaVersion);
  const JsonView root = doc.root();
  Dataset ds;
  ds.dir = dir;
  ds.synthetic = root.BoolOr("synthetic", false);

  const JsonView setup = root["setup"];
  ds.distance_mm = ParseDistance(setup["distance_mm"]);
  ds.grid = ParseGrid(setup["grid"]);
  const Eigen::Vector2d screen = ParseLengthPair(setup["screen_mm"]);
  ds.screen_w_mm = screen.x();
  ds.screen_h_mm = screen.y();
  ds.filter = ParseFilterInfo(root["filter"], ds.grid);

  const JsonView radiometry = root["radiometry"];
  if (radiometry.Has("scale_w_m2"))
    ds.radiometric_scale = radiometry["scale_w_m2"].NumberIn(1e-12, 1e12);
  ds.saturation_level =
      radiometry.Has("saturation_level") ? radiometry["saturation_level"].NumberIn(1e-6, 1e6) : 1.0;
  ds.photo_transfer = radiometry.Has("transfer")
                          ? radiometry["transfer"].OneOf({"auto", "linear", "srgb"})
                          : "auto";
  ds.black_level = radiometry.Has("black_level") ? radiometry["black_level"].NumberIn(0, 0.5) : 0;
  ds.white_level = radiometry.Has("white_level") ? radiometry["white_level"].NumberIn(0.5, 1e6) : 1;
  if (!(ds.white_level > ds.black_level)) radiometry["white_level"].Fail("a level > black_level");

  if (root.Has("photo_folder")) {
    ds.photo_folder = root["photo_folder"].String();
    if (ds.photo_folder.empty() || ds.photo_folder.size() > 4096 ||
        ds.photo_folder.find('\0') != std::string::npos)
      root["photo_folder"].Fail("a folder path (absolute or relative to the dataset folder)");
  }
  const JsonView calib = root["calibration"];
  ds.calibration.photo = calib["photo"].String();
  if (!IsRelativeInside(ds.calibration.photo))
    calib["photo"].Fail("a path relative to the photo folder, without \"..\"");
  const JsonView target = calib["target"];
  target["type"].OneOf({"checkerboard"});
  ds.calibration.squares_x = target["squares"][0].IntIn(kMinBoardSquares, kMaxBoardSquares);
  ds.calibration.squares_y = target["squares"][1].IntIn(kMinBoardSquares, kMaxBoardSquares);
  ds.calibration.square_mm = target["square_mm"].NumberIn(kMinSpacingMm, kMaxScreenMm);
  const std::vector<double> origin = target["origin_mm"].Numbers(2);
  for (double v : origin)
    if (std::abs(v) > kMaxCoordinateMm) target["origin_mm"].Fail("coordinates within 1e6 mm");
  ds.calibration.origin_mm = {origin[0], origin[1]};
  ds.calibration.Check(file, "calibration.target");

  if (!with_photos) return ds;
  const JsonView photos = root["photos"];
  std::set<std::tuple<int, int, bool>> slides;
  for (size_t k = 0; k < photos.Size(); ++k) {
    const JsonView p = photos[k];
    PhotoEntry e;
    e.i = p["i"].IntIn(0, ds.grid.nu - 1);
    e.j = p["j"].IntIn(0, ds.grid.nv - 1);
    e.positive = p["slide"].OneOf({"p", "n"}) == "p";
    e.file = p["file"].String();
    if (!IsRelativeInside(e.file))
      p["file"].Fail("a path relative to the photo folder, without \"..\"");
    e.exposure =
        p.Has("exposure") ? p["exposure"].NumberIn(kMinPhotoExposure, kMaxPhotoExposure) : 1.0;
    slides.insert({e.i, e.j, e.positive});
    // The same photo twice, or two photos of one slide at one exposure, would be merged as if
    // they were different measurements.
    for (const PhotoEntry& other : ds.photos)
      if (other.file == e.file || (other.i == e.i && other.j == e.j &&
                                   other.positive == e.positive && other.exposure == e.exposure))
        p.Fail("a photo not listed before (" + other.file + " has the same " +
               (other.file == e.file ? "file" : "position, slide and exposure") + ")");
    ds.photos.push_back(e);
  }
  // A partial dataset names the positions it lacks; every other position has both slides.
  std::set<std::pair<int, int>> missing;
  if (root.Has("missing_positions")) {
    const JsonView list = root["missing_positions"];
    for (size_t k = 0; k < list.Size(); ++k) {
      const JsonView p = list[k];
      if (p.Size() != 2) p.Fail("a position [i, j]");
      const std::pair<int, int> ij = {p[size_t(0)].IntIn(0, ds.grid.nu - 1),
                                      p[size_t(1)].IntIn(0, ds.grid.nv - 1)};
      if (!missing.insert(ij).second) p.Fail("a position not listed before");
      if (slides.count({ij.first, ij.second, true}) || slides.count({ij.first, ij.second, false}))
        p.Fail("a position without photos (photos lists some for it)");
      ds.missing_positions.push_back(ij);
    }
  }
  for (int j = 0; j < ds.grid.nv; ++j)
    for (int i = 0; i < ds.grid.nu; ++i)
      for (bool positive : {true, false})
        if (!slides.count({i, j, positive}) && !missing.count({i, j}))
          throw InputError(
              file, "photos",
              std::string("a photo through slide ") + (positive ? "p" : "n") +
                  " for every grid position not in missing_positions",
              "none for position (" + std::to_string(i) + ", " + std::to_string(j) + ")");
  return ds;
}

void Dataset::Save(const std::string& out_dir) const {
  WriteJsonAtomically(out_dir + "/dataset.json", ToJson());
}

nlohmann::json Dataset::ToJson() const {
  nlohmann::json j;
  j["schema_version"] = photo_folder.empty() ? 2 : kDatasetSchemaVersion;
  if (!photo_folder.empty()) j["photo_folder"] = photo_folder;
  j["synthetic"] = synthetic;
  j["setup"] = {{"distance_mm", distance_mm},
                {"grid", GridJson(grid)},
                {"screen_mm", {screen_w_mm, screen_h_mm}}};
  j["filter"] = FilterInfoJson(filter);
  j["radiometry"] = {{"saturation_level", saturation_level},
                     {"transfer", photo_transfer},
                     {"black_level", black_level},
                     {"white_level", white_level}};
  if (radiometric_scale) j["radiometry"]["scale_w_m2"] = *radiometric_scale;
  j["calibration"] = {{"photo", calibration.photo},
                      {"target",
                       {{"type", "checkerboard"},
                        {"squares", {calibration.squares_x, calibration.squares_y}},
                        {"square_mm", calibration.square_mm},
                        {"origin_mm", {calibration.origin_mm.x(), calibration.origin_mm.y()}}}}};
  nlohmann::json list = nlohmann::json::array();
  for (const auto& p : photos)
    list.push_back({{"i", p.i},
                    {"j", p.j},
                    {"slide", p.positive ? "p" : "n"},
                    {"file", p.file},
                    {"exposure", p.exposure}});
  j["photos"] = list;
  if (!missing_positions.empty()) {
    nlohmann::json missing = nlohmann::json::array();
    for (const auto& [i, jj] : missing_positions) missing.push_back({i, jj});
    j["missing_positions"] = missing;
  }
  return j;
}

}  // namespace lumislab
