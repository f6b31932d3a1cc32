#include "lib/synthetic/scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/geometry.h"
#include "core/json.h"
#include "lib/synthetic/spectral.h"

namespace lumislab {
namespace {

const char* kDefaultSceneJson = R"({
  "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 9, "nv": 7, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "filter": { "k_max": 1 },
  "luminaire": { "emitters": [
    {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8},
    {"position_mm": [-3, 1, -12], "intensity_w_sr": [0.5, 0.6, 0.9], "lobe_exponent": 3} ] },
  "camera": { "size_px": [1600, 1200], "focal_px": 1300, "position_mm": [0, -400, 2400],
              "look_at_mm": [0, 0, 750] },
  "effects": []
}
)";

// A luminaire that emits into the whole sphere, to be captured from several orientations
// (docs/formats.md §19): six broad lobes along +-x, +-y, +-z of unequal strength (so every
// overlap of two orientations has gradients to register on), a side lobe towards +x, a little
// down, and a narrow asymmetric lobe towards C 60, gamma 120 (behind the gamma = 90 plane). Its
// own origin, centre_mm, 8 mm behind S, every emitter within 3.2 mm of it; a screen of 2000 mm
// at 750 mm sees 52 degrees either side of the axis, so the six cube faces overlap. The grid
// must hold the light up to the cone's edge: an emitter z behind S sends it through S within
// z tan(52) of itself, under 18 mm here, and 9 x 9 positions of 5 mm reach 25 mm.
const char* kFullSphereSceneJson = R"({
  "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 9, "nv": 9, "spacing_mm": 5},
             "screen_mm": [2000, 2000] },
  "filter": { "k_max": 1 },
  "luminaire": { "centre_mm": [0, 0, -8], "emitters": [
    {"position_mm": [0, 0, -6], "axis": [0, 0, 1], "intensity_w_sr": [0.60, 0.60, 0.60], "lobe_exponent": 1.5},
    {"position_mm": [0, 0, -10], "axis": [0, 0, -1], "intensity_w_sr": [0.35, 0.35, 0.35], "lobe_exponent": 1.5},
    {"position_mm": [2, 0, -8], "axis": [1, 0, 0], "intensity_w_sr": [0.50, 0.50, 0.50], "lobe_exponent": 2},
    {"position_mm": [-2, 0, -8], "axis": [-1, 0, 0], "intensity_w_sr": [0.30, 0.30, 0.30], "lobe_exponent": 2},
    {"position_mm": [0, 2, -8], "axis": [0, 1, 0], "intensity_w_sr": [0.45, 0.45, 0.45], "lobe_exponent": 2.5},
    {"position_mm": [0, -2, -8], "axis": [0, -1, 0], "intensity_w_sr": [0.25, 0.25, 0.25], "lobe_exponent": 2.5},
    {"position_mm": [3, -1, -8], "axis": [0.94, 0, -0.34], "intensity_w_sr": [1.0, 0.8, 0.6], "lobe_exponent": 12},
    {"position_mm": [1, -2, -9], "axis": [0.433, -0.75, -0.5], "intensity_w_sr": [0.8, 0.9, 1.0], "lobe_exponent": 20} ] },
  "camera": { "size_px": [1600, 1200], "focal_px": 700, "position_mm": [0, -400, 2400],
              "look_at_mm": [0, 0, 750] },
  "effects": []
}
)";

// A point of the lab or luminaire frame, mm: three finite numbers within kMaxCoordinateMm.
Eigen::Vector3d Vec3(const JsonView& v) {
  const std::vector<double> a = v.Numbers(3);
  for (double x : a)
    if (std::abs(x) > kMaxCoordinateMm) v.Fail("three coordinates within 1e6 mm");
  return {a[0], a[1], a[2]};
}

void ParseSetup(const JsonView& root, SynthScene* scene) {
  const JsonView setup = root["setup"];
  scene->distance_mm = ParseDistance(setup["distance_mm"]);
  scene->grid = ParseGrid(setup["grid"]);
  const Eigen::Vector2d screen = ParseLengthPair(setup["screen_mm"]);
  scene->screen_w_mm = screen.x();
  scene->screen_h_mm = screen.y();
  if (root.Has("filter") && root["filter"].Has("k_max"))
    scene->k_max = ParseFilterTruncation(root["filter"]["k_max"]);
}

// A rotation_deg member: three angles within 36000 degrees (R = Rz Ry Rx).
Eigen::Vector3d RotationDeg(const JsonView& v) {
  const std::vector<double> r = v.Numbers(3);
  for (double x : r)
    if (std::abs(x) > 36000) v.Fail("three angles within 36000 degrees");
  return {r[0], r[1], r[2]};
}

// {"file": "x.ray", "rotation_deg": [rx, ry, rz], "rgb": [r, g, b], "cell_mm": c}: a TM-25 ray
// file relative to the JSON file's folder, its origin at the emitter's position_mm, its axes
// turned by R; rgb the W per channel per unit of a ray's flux; cell_mm the splat lattice on the
// screen (default: the scene's larger screen side / kRayCellsPerScreen).
RaySource ParseRaySource(const JsonView& e, const Eigen::Vector3d& position_mm,
                         double default_cell_mm) {
  const JsonView r = e["rays"];
  for (const std::string& key : r.Keys())
    if (key != "file" && key != "rotation_deg" && key != "rgb" && key != "cell_mm")
      r[key].Fail("file, rotation_deg, rgb or cell_mm");
  std::filesystem::path file = r["file"].String();
  if (file.is_relative()) file = std::filesystem::path(r.file()).parent_path() / file;
  const Eigen::Vector3d rotation =
      r.Has("rotation_deg") ? RotationDeg(r["rotation_deg"]) : Eigen::Vector3d::Zero();
  Eigen::Vector3d rgb = Eigen::Vector3d::Ones();
  if (r.Has("rgb")) {
    const JsonView v = r["rgb"];
    for (size_t c = 0; c < 3; ++c) rgb[c] = v[c].NumberIn(0, 1e9);
    if (v.Size() != 3) v.Fail("[R, G, B] in W per unit of ray flux");
  }
  const double cell = r.Has("cell_mm") ? r["cell_mm"].NumberIn(1e-3, 1e5) : default_cell_mm;
  // At most kMaxRayCellsPerScreen cells along the screen (a map per position is that squared).
  const double screen = default_cell_mm * kRayCellsPerScreen;
  if (screen > 0 && cell < screen / kMaxRayCellsPerScreen)
    r["cell_mm"].Fail("at least the larger screen side / " +
                      std::to_string(int(kMaxRayCellsPerScreen)) + " (" +
                      std::to_string(screen / kMaxRayCellsPerScreen) + " mm)");
  try {
    return RaySource::Load(file.string(), position_mm, rotation, rgb, cell);
  } catch (const Error& error) {
    // The reader names the ray file and its field; the scene file and its field lead.
    if (error.exit_code() != int(ExitCode::kBadInput)) throw;
    throw BadInput(r.file() + ": " + r["file"].path() + ": " + error.what());
  }
}

// The "luminaire" block of a scene file (also the whole of truth/luminaire.json). A ray source
// without cell_mm gets `default_cell_mm` (0 where no screen is known: LoadLuminaire).
Luminaire ParseLuminaire(const JsonView& root, double default_cell_mm) {
  Luminaire luminaire;
  if (root["luminaire"].Has("centre_mm"))
    luminaire.centre_mm = Vec3(root["luminaire"]["centre_mm"]);
  const JsonView emitters = root["luminaire"]["emitters"];
  if (emitters.Size() == 0) emitters.Fail("a non-empty array of emitters");
  for (size_t k = 0; k < emitters.Size(); ++k) {
    const JsonView e = emitters[k];
    const int kinds = int(e.Has("lobe_exponent")) + int(e.Has("distribution")) + int(e.Has("rays"));
    if (kinds != 1)
      e.Fail(
          "exactly one of lobe_exponent, distribution (a measured IES / EULUMDAT file) or "
          "rays (a TM-25 ray file)");
    if (e.Has("rays") && e.Has("cct_k"))
      e["cct_k"].Fail("no cct_k with rays (rays.rgb weighs the channels)");
    if (e.Has("rays")) {
      // The file's origin anywhere: its rays are checked one by one (RaySource::Load).
      if (e.Has("intensity_w_sr"))
        e["intensity_w_sr"].Fail(
            "no intensity_w_sr with rays (the rays carry their flux; "
            "rays.rgb weighs the channels)");
      luminaire.ray_sources.push_back(ParseRaySource(e, Vec3(e["position_mm"]), default_cell_mm));
      continue;
    }
    Emitter emitter;
    emitter.position_mm = Vec3(e["position_mm"]);
    if (!(emitter.position_mm.z() < 0))
      e["position_mm"].Fail("a point behind the filter plane S (z < 0 mm)");
    const JsonView intensity = e["intensity_w_sr"];
    if (e.Has("cct_k")) {
      // A blackbody-like emitter: its radiant intensity and temperature; the camera's RGB of
      // that spectrum (docs/testing.md, "Colour").
      emitter.cct_k = e["cct_k"].NumberIn(1000, 25000);
      emitter.radiant_w_sr = intensity.NumberIn(0, 1e9);
      emitter.intensity_w_sr = emitter.radiant_w_sr * BlackbodyRgbPerWatt(emitter.cct_k);
    } else {
      for (size_t c = 0; c < 3; ++c) emitter.intensity_w_sr[c] = intensity[c].NumberIn(0, 1e9);
      if (intensity.Size() != 3) intensity.Fail("[R, G, B] in W/sr (or one number with cct_k)");
    }
    if (e.Has("axis")) {
      const Eigen::Vector3d axis = Vec3(e["axis"]);
      if (!(axis.norm() > 1e-9)) e["axis"].Fail("a non-zero direction");
      emitter.axis = axis.normalized();
    }
    if (e.Has("lobe_exponent")) {
      emitter.lobe_exponent = e["lobe_exponent"].NumberIn(0, 1e6);
    } else {
      // {"file": "x.ies" | "x.ldt", "rotation_deg": [rx, ry, rz]}: the file relative to the
      // JSON file's folder; R = Rz Ry Rx turns its gamma = 0 axis into the luminaire frame.
      const JsonView d = e["distribution"];
      for (const std::string& key : d.Keys())
        if (key != "file" && key != "rotation_deg") d[key].Fail("file or rotation_deg");
      std::filesystem::path file = d["file"].String();
      if (file.is_relative()) file = std::filesystem::path(d.file()).parent_path() / file;
      const Eigen::Vector3d rotation =
          d.Has("rotation_deg") ? RotationDeg(d["rotation_deg"]) : Eigen::Vector3d::Zero();
      emitter.measured =
          std::make_shared<const MeasuredLobe>(MeasuredLobe::Load(file.string(), rotation));
    }
    luminaire.emitters.push_back(emitter);
  }
  return luminaire;
}

void ParseCamera(const JsonView& root, SynthScene* scene) {
  const JsonView cam = root["camera"];
  CameraSpec& c = scene->camera;
  c.width = cam["size_px"][0].IntIn(16, 20000);
  c.height = cam["size_px"][1].IntIn(16, 20000);
  if (cam["size_px"].Size() != 2) cam["size_px"].Fail("[width, height] in pixels");
  c.focal_px = cam["focal_px"].NumberIn(1, 1e7);
  c.position_mm = Vec3(cam["position_mm"]);
  c.look_at_mm = Vec3(cam["look_at_mm"]);
  if ((c.look_at_mm - c.position_mm).norm() < 1e-6)
    cam["look_at_mm"].Fail("a point different from camera.position_mm");
  if (std::abs(c.position_mm.z() - scene->distance_mm) < 1e-6)
    cam["position_mm"].Fail(
        "a point off the screen plane z = " + std::to_string(scene->distance_mm) + " mm");
  c.exposure = cam.Has("exposure") ? cam["exposure"].NumberIn(1e-6, 1e6) : 1.0;
  c.radiometric_scale_w_m2 =
      cam.Has("radiometric_scale_w_m2") ? cam["radiometric_scale_w_m2"].NumberIn(1e-12, 1e12) : 0.0;
}

// A checkerboard centred on the screen: 14 x 13 squares of 80 mm (smaller on small screens),
// covering ~93 % x 87 % of a 1.2 m screen with a 40 mm white margin. The screen calibration fits
// radial distortion to the board corners and extrapolates it to the screen edges; a board of
// 14 x 11 squares of 60 mm left the default slab 5 % off in its corners (0.3 % with this one).
// Every corner of the board must be in the photo, or the screen calibration finds no board.
void CheckBoardInView(const SynthScene& scene) {
  const CalibrationTarget& t = scene.calibration;
  const PinholeCamera camera(scene.camera);
  for (int a = 0; a <= t.squares_x; a += t.squares_x)
    for (int b = 0; b <= t.squares_y; b += t.squares_y) {
      const Eigen::Vector2d xy = t.origin_mm + t.square_mm * Eigen::Vector2d(a, b);
      const Eigen::Vector3d lab(xy.x(), xy.y(), scene.distance_mm);
      const Eigen::Vector3d in_camera =
          camera.lab_from_camera().transpose() * (lab - scene.camera.position_mm);
      const Eigen::Vector2d px = camera.Project(lab);
      if (!(in_camera.z() > 0) || px.x() < 0 || px.y() < 0 || px.x() > scene.camera.width - 1 ||
          px.y() > scene.camera.height - 1)
        throw InputError(scene.source, "camera",
                         "a view that holds the whole calibration board (corner at " +
                             std::to_string(xy.x()) + ", " + std::to_string(xy.y()) + " mm)",
                         "a corner outside the photo");
    }
}

void ParseCalibration(const JsonView& root, SynthScene* scene) {
  CalibrationTarget& t = scene->calibration;
  t.photo = "photos/calib_0.png";
  t.squares_x = 14;
  t.squares_y = 13;
  t.square_mm = std::min({80.0, (scene->screen_w_mm - 80) / 14, (scene->screen_h_mm - 80) / 13});
  // On a small screen the 40 mm margins leave little or nothing: a screen of 100 mm got squares
  // of 0.7 mm, a board no camera finds (tests/e2e/hard_cases_test.cc, RandomisedSweep). Below
  // half of the small-screen board's square, that board (90 % of the screen) is used.
  const double small = 0.9 * std::min(scene->screen_w_mm / 14, scene->screen_h_mm / 13);
  if (!(t.square_mm > 0.5 * small)) t.square_mm = small;
  if (root.Has("calibration")) {
    const JsonView c = root["calibration"];
    if (c.Has("squares")) {
      t.squares_x = c["squares"][0].IntIn(3, 200);
      t.squares_y = c["squares"][1].IntIn(3, 200);
    }
    if (c.Has("square_mm")) t.square_mm = c["square_mm"].NumberIn(kMinSpacingMm, kMaxScreenMm);
    if (t.squares_x * t.square_mm > scene->screen_w_mm ||
        t.squares_y * t.square_mm > scene->screen_h_mm)
      c.Fail("a checkerboard that fits on the screen");
  }
  t.origin_mm = {-0.5 * t.squares_x * t.square_mm, -0.5 * t.squares_y * t.square_mm};
  // What lumislab-calibrate would refuse after the capture is refused before it.
  t.Check(scene->source, "calibration");
}

// raw (DNG photos) excludes the other effects that choose the photos' format.
bool RawFormatClash(const std::string& a, const std::string& b) {
  const auto format = [](const std::string& t) { return t == "response" || t == "quantization"; };
  return (a == "raw" && format(b)) || (b == "raw" && format(a));
}

// The effects, built with the scene's camera and screen. brackets, response and dark are
// listed at most once (each sets something of the whole dataset: its photos, their format, its
// black level), and response (8-bit JPEG) excludes quantization (16-bit PNG).
void ParseEffects(const JsonView& effects, SynthScene* scene) {
  // The lens is part of the camera: it is handed to the camera before any effect is built, so
  // that the effects that depend on the camera's geometry (vignetting, screen gain, ambient) see
  // it wherever it is listed.
  for (size_t k = 0; k < effects.Size(); ++k)
    if (effects[k].raw().is_object() && effects[k].Has("type") &&
        effects[k]["type"].raw() == "lens") {
      if (scene->camera.lens) effects[k]["type"].Fail("a type listed once (lens is listed before)");
      EffectSetting setting;
      setting.camera = scene->camera;
      scene->camera.lens = static_cast<const LensEffect&>(*MakeEffect(effects[k], setting)).lens();
    }
  EffectSetting setting;
  setting.camera = scene->camera;
  setting.distance_mm = scene->distance_mm;
  setting.screen_w_mm = scene->screen_w_mm;
  setting.screen_h_mm = scene->screen_h_mm;
  for (size_t k = 0; k < effects.Size(); ++k) {
    auto effect = MakeEffect(effects[k], setting);
    const std::string type = effect->Type();
    for (const auto& other : scene->effects) {
      if (other->Type() == type &&
          (type == "brackets" || type == "response" || type == "dark" || type == "raw"))
        effects[k]["type"].Fail("a type listed once (" + type + " is listed before)");
      if (RawFormatClash(type, other->Type()))
        effects[k]["type"].Fail("not both raw (DNG) and " + (type == "raw" ? other->Type() : type) +
                                " (a photo has one format)");
      const bool formats = (type == "response" && other->Type() == "quantization") ||
                           (type == "quantization" && other->Type() == "response");
      if (formats)
        effects[k]["type"].Fail("not both response (8-bit JPEG) and quantization (16-bit PNG)");
    }
    scene->effects.push_back(std::move(effect));
  }
}

template <typename T>
const T* FindEffect(const SynthScene& scene) {
  for (const auto& e : scene.effects)
    if (const T* found = dynamic_cast<const T*>(e.get())) return found;
  return nullptr;
}

}  // namespace

bool SynthScene::Quantized() const {
  return std::any_of(effects.begin(), effects.end(), [](const auto& e) { return e->Quantizes(); });
}

const BracketsEffect* SynthScene::Brackets() const { return FindEffect<BracketsEffect>(*this); }
const ResponseEffect* SynthScene::Response() const { return FindEffect<ResponseEffect>(*this); }
const DarkEffect* SynthScene::Dark() const { return FindEffect<DarkEffect>(*this); }
const RawEffect* SynthScene::Raw() const { return FindEffect<RawEffect>(*this); }

std::string SynthScene::PhotoExtension() const {
  if (Raw()) return "dng";
  return Response() ? "jpg" : Quantized() ? "png" : "exr";
}

std::vector<double> SynthScene::Stops() const {
  return Brackets() ? Brackets()->stops() : std::vector<double>{0.0};
}

Eigen::Vector2d SynthScene::StageOffsetMm(int i, int j) const {
  Eigen::Vector2d offset(0, 0);
  for (const auto& e : effects) offset += e->StageOffsetMm(i, j);
  return offset;
}

SynthScene ParseScene(const std::string& json_text, const std::string& name) {
  return ParseScene(JsonDocument::Parse(json_text, name), name);
}

SynthScene ParseScene(const JsonDocument& doc, const std::string& name) {
  doc.CheckSchemaVersion(kSceneSchemaVersion);
  const JsonView root = doc.root();
  SynthScene scene;
  scene.source = name;
  ParseSetup(root, &scene);
  scene.luminaire =
      ParseLuminaire(root, std::max(scene.screen_w_mm, scene.screen_h_mm) / kRayCellsPerScreen);
  ParseCamera(root, &scene);
  ParseCalibration(root, &scene);
  if (root.Has("effects")) ParseEffects(root["effects"], &scene);
  CheckBoardInView(scene);  // through the lens, when one is listed
  if (root.Has("calibration_captures"))
    scene.captures = ParseCalibrationCaptures(root["calibration_captures"], scene);
  return scene;
}

double DefaultLuminousEfficacy() { return LuminousEfficacy(Spectrum::Ones()); }

double SynthScene::LuminousEfficacy() const {
  if (luminaire.emitters.empty() || !luminaire.ray_sources.empty())
    return DefaultLuminousEfficacy();
  double lumens = 0, watts = 0;
  for (const Emitter& e : luminaire.emitters) {
    if (!(e.cct_k > 0)) return DefaultLuminousEfficacy();
    // Radiant flux (W) = I0 x the lobe's solid angle: a midpoint sum over the sphere (the lobe
    // looks along its axis; the default +z lobe has nothing behind S).
    constexpr int kSteps = 90;
    double solid_angle = 0;
    for (int a = 0; a < 2 * kSteps; ++a)
      for (int b = 0; b < 2 * kSteps; ++b) {
        const double theta = (a + 0.5) * 0.5 * kPi / kSteps, phi = (b + 0.5) * kPi / kSteps;
        const Eigen::Vector3d w(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                std::cos(theta));
        solid_angle += e.Shape(w) * std::sin(theta) * (0.5 * kPi / kSteps) * (kPi / kSteps);
      }
    const double flux = e.radiant_w_sr * solid_angle;
    lumens += flux * e.LuminousEfficacy();
    watts += flux;
  }
  return watts > 0 ? lumens / watts : DefaultLuminousEfficacy();
}

SynthScene LoadScene(const std::string& path_or_default) {
  if (path_or_default == "default") return DefaultScene();
  if (path_or_default == "full-sphere") {
    SynthScene scene = ParseScene(kFullSphereSceneJson, "full-sphere scene");
    scene.source = "full-sphere";
    return scene;
  }
  return ParseScene(JsonDocument::Load(path_or_default), path_or_default);
}

SynthScene DefaultScene() {
  SynthScene scene = ParseScene(kDefaultSceneJson, "default scene");
  scene.source = "default";
  return scene;
}

std::string DefaultSceneJson() { return kDefaultSceneJson; }

std::string FullSphereSceneJson() { return kFullSphereSceneJson; }

Luminaire LoadLuminaire(const std::string& source) {
  if (source == "default" || source == "full-sphere") return LoadScene(source).luminaire;
  const std::string path =
      std::filesystem::is_directory(source)
          ? (std::filesystem::path(source) / "truth" / "luminaire.json").string()
          : source;
  const JsonDocument doc = JsonDocument::Load(path);
  doc.CheckSchemaVersion(kSceneSchemaVersion);
  return ParseLuminaire(doc.root(), 0);
}

Dataset DatasetSkeleton(const SynthScene& scene) {
  Dataset ds;
  ds.distance_mm = scene.distance_mm;
  ds.grid = scene.grid;
  ds.screen_w_mm = scene.screen_w_mm;
  ds.screen_h_mm = scene.screen_h_mm;
  ds.filter = FilterInfo::Of(scene.Filter(), scene.grid.spacing_mm);
  ds.saturation_level = 1.0;
  if (const DarkEffect* dark = scene.Dark()) {
    // The dark step adds the black level to the render's values without scaling them: value 1
    // of the render is code 1 + black, so white_level = 1 + black decodes the render exactly.
    ds.black_level = dark->black_level();
    ds.white_level = 1 + dark->black_level();
  }
  // An sRGB response is what the decoder's "srgb" transfer inverts; the other curves are
  // recorded in truth/response.json only.
  if (scene.Response() && scene.Response()->curve() == "srgb") ds.photo_transfer = "srgb";
  ds.calibration = scene.calibration;
  ds.synthetic = true;
  return ds;
}

std::vector<PhotoEntry> PhotoList(const SynthScene& scene) {
  std::vector<PhotoEntry> list;
  const std::string ext = scene.PhotoExtension();
  const bool bracketed = scene.Brackets() != nullptr;
  const std::vector<double> stops = scene.Stops();
  for (int j = 0; j < scene.grid.nv; ++j)
    for (int i = 0; i < scene.grid.nu; ++i)
      for (bool positive : {true, false})
        for (double stop : stops) {
          const std::string tag = bracketed ? BracketsEffect::Tag(stop) : "";
          list.push_back({i, j, positive, "photos/" + PhotoFileName(i, j, positive, ext, tag),
                          scene.camera.exposure * std::exp2(stop)});
        }
  return list;
}

int PhotoIndex(const SynthScene& scene, int i, int j, bool positive, int stop_index) {
  const int stops = scene.Brackets() ? int(scene.Brackets()->stops().size()) : 1;
  return (2 * scene.grid.Index(i, j) + (positive ? 0 : 1)) * stops + stop_index;
}

}  // namespace lumislab
