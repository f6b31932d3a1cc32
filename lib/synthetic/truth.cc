#include "lib/synthetic/truth.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/geometry.h"
#include "core/json.h"
#include "core/parallel.h"
#include "lib/synthetic/camera.h"

namespace lumislab {

SlabPosition TruthPosition(const Luminaire& luminaire, const SlabInfo& info, int i, int j) {
  SlabPosition p;
  p.i = i;
  p.j = j;
  p.irradiance = ImageF(info.layout.res_x, info.layout.res_y, 3);
  p.mask = ImageF(info.layout.res_x, info.layout.res_y, 1, 1.f);
  const DualFilter filter = info.filter.Filter();
  const Eigen::Vector2d c = info.grid.Centre(i, j);
  // The texel centres lie in the window; a ray source is splatted over it (the same lattice as
  // the photos', so its truth is what they hold).
  const Eigen::Vector2d half(0.5 * info.layout.window_w_mm, 0.5 * info.layout.window_h_mm);
  const PlaneLight light = PlaneLight::ThroughSlides(luminaire, filter, info.grid.spacing_mm, c,
                                                     info.distance_mm, -half, half);
  for (int row = 0; row < info.layout.res_y; ++row)
    for (int col = 0; col < info.layout.res_x; ++col) {
      const Eigen::Vector2d st = info.layout.TexelCentre(col, row);
      const Eigen::Vector3d e = light.Filtered(st.x(), st.y());
      for (int ch = 0; ch < 3; ++ch) p.irradiance.at(col, row, ch) = float(e[ch]);
    }
  return p;
}

bool GridCovers(const Luminaire& luminaire, const SlabInfo& info, const Eigen::Vector3d& x) {
  const int k = int(info.filter.dual_coefficients.size()) - 1;
  const double h = info.grid.spacing_mm, d = info.distance_mm;
  const double umax = ((info.grid.nu - 1) / 2.0 - k) * h;
  const double vmax = ((info.grid.nv - 1) / 2.0 - k) * h;
  if (!(x.z() > 0)) return false;
  const double spread = std::abs(1 - d / x.z()) * (k + 2) * h;
  const double smax = 0.5 * info.layout.window_w_mm - spread;
  const double tmax = 0.5 * info.layout.window_h_mm - spread;
  for (const Emitter& e : luminaire.emitters) {
    const Eigen::Vector2d uv = IntersectPlaneZ(e.position_mm, x, 0);
    const Eigen::Vector2d st = IntersectPlaneZ(e.position_mm, x, d);
    if (!(std::abs(uv.x()) <= umax && std::abs(uv.y()) <= vmax)) return false;
    if (!(std::abs(st.x()) <= smax && std::abs(st.y()) <= tmax)) return false;
  }
  return true;
}

void WriteTruthSlab(const Luminaire& luminaire, SlabInfo info, const std::string& dir, int threads,
                    double luminous_efficacy) {
  MakeDirectories(dir);
  info.present.clear();
  float scale = info.units == "lux" ? float(luminous_efficacy) : 1.f;
  // A lux truth of emitters with a spectrum is their luminous intensity (683 integral of V
  // I_lambda, Emitter::LuminousIntensity) as grey light: the camera's RGB of such light is not
  // luminance under any fixed weights, and CompareSlabs compares lux slabs in luminance.
  Luminaire grey = luminaire;
  bool spectral = false;
  for (const Emitter& e : luminaire.emitters) spectral = spectral || e.cct_k > 0;
  if (info.units == "lux" && spectral) {
    for (Emitter& e : grey.emitters) {
      // LuminousIntensity(w) / Shape(w), the same for every w: the lobe's I0 in cd.
      const double i0_cd = e.cct_k > 0
                               ? e.LuminousEfficacy() * e.radiant_w_sr
                               : e.LuminousEfficacy() * Rec709Weights().dot(e.intensity_w_sr);
      e.cct_k = 0;
      e.intensity_w_sr = Eigen::Vector3d::Constant(i0_cd);
    }
    scale = 1.f;
    info.channel_weights = Rec709Weights();  // grey: any weights summing to 1 give the same
  }
  const Luminaire& truth = info.units == "lux" && spectral ? grey : luminaire;
  ParallelFor(info.grid.count(), threads, [&](int q) {
    const int i = q % info.grid.nu, j = q / info.grid.nu;
    SlabPosition p = TruthPosition(truth, info, i, j);
    for (float& v : p.irradiance.data) v *= scale;
    WriteSlabPosition(dir, info, p);
  });
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i) info.MarkPresent(i, j);
  info.Save(dir);
}

SlabInfo TruthSlabInfo(const SynthScene& scene, int resolution) {
  SlabInfo info = SlabInfo::FromDataset(DatasetSkeleton(scene), resolution);
  info.units = "W/m^2";  // TruthPosition's values are irradiance in W/m^2, not relative
  return info;
}

SlabInfo DefaultSlabInfo(int nu, int nv, double spacing_mm, int resolution) {
  SynthScene scene = DefaultScene();
  scene.grid = {nu, nv, spacing_mm};
  return TruthSlabInfo(scene, resolution);
}

namespace {
nlohmann::json RowMajor(const Eigen::Matrix3d& m) {
  nlohmann::json a = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.push_back(m(r, c));
  return a;
}
nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

void WriteTruthCamera(const SynthScene& scene, const std::string& path) {
  const PinholeCamera camera(scene.camera);
  const Eigen::Matrix3d k = camera.K();
  nlohmann::json j;
  j["schema_version"] = 1;
  j["size_px"] = {scene.camera.width, scene.camera.height};
  j["focal_px"] = scene.camera.focal_px;
  j["principal_point_px"] = {k(0, 2), k(1, 2)};
  j["K"] = RowMajor(k);
  // The lens effect's distortion in calib/camera.json's terms (all 0 without a lens).
  const CameraModel& m = camera.model();
  j["distortion"] = {{"model", "opencv5"}, {"k1", m.k1}, {"k2", m.k2},
                     {"p1", m.p1},         {"p2", m.p2}, {"k3", m.k3}};
  j["position_mm"] = Vec(scene.camera.position_mm);
  j["look_at_mm"] = Vec(scene.camera.look_at_mm);
  // Columns are the camera axes (x right, y down, z forward) in the lab frame.
  j["lab_from_camera"] = RowMajor(camera.lab_from_camera());
  j["screen_plane_z_mm"] = scene.distance_mm;
  // With a lens: ideal pinhole pixels (K times the undistorted ray), not the photo's pixels.
  j["screen_from_image"] = RowMajor(camera.ScreenFromImage(scene.distance_mm));
  j["image_from_screen"] = RowMajor(camera.ImageFromScreen(scene.distance_mm));
  j["exposure"] = scene.camera.exposure;
  WriteJsonAtomically(path, j);
}

void WriteTruthLuminaire(const Luminaire& luminaire, const std::string& path) {
  nlohmann::json emitters = nlohmann::json::array();
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  for (size_t k = 0; k < luminaire.emitters.size(); ++k) {
    const Emitter& e = luminaire.emitters[k];
    nlohmann::json j = {{"position_mm", Vec(e.position_mm)},
                        {"intensity_w_sr", Vec(e.intensity_w_sr)}};
    if (e.cct_k > 0) {  // as the scene gave it: the camera's RGB follows from the spectrum
      j["intensity_w_sr"] = e.radiant_w_sr;
      j["cct_k"] = e.cct_k;
    }
    if (e.axis != Eigen::Vector3d::UnitZ()) j["axis"] = Vec(e.axis);
    if (e.measured) {
      // A copy of the measured file beside luminaire.json, so the dataset stands on its own.
      const std::string name = "emitter_" + std::to_string(k) +
                               std::filesystem::path(e.measured->file).extension().string();
      WriteTextAtomically((folder / name).string(), ReadTextFile(e.measured->file));
      j["distribution"] = {{"file", name}, {"rotation_deg", Vec(e.measured->rotation_deg)}};
    } else {
      j["lobe_exponent"] = e.lobe_exponent;
    }
    emitters.push_back(j);
  }
  // Ray sources after the point emitters, their files copied the same way (numbered on).
  for (size_t r = 0; r < luminaire.ray_sources.size(); ++r) {
    const RaySource& source = luminaire.ray_sources[r];
    std::string ext = std::filesystem::path(source.file).extension().string();
    if (ext.empty()) ext = ".ray";
    const std::string name = "emitter_" + std::to_string(luminaire.emitters.size() + r) + ext;
    WriteTextAtomically((folder / name).string(), ReadTextFile(source.file));
    emitters.push_back({{"position_mm", Vec(source.position_mm)},
                        {"rays",
                         {{"file", name},
                          {"rotation_deg", Vec(source.rotation_deg)},
                          {"rgb", Vec(source.rgb)},
                          {"cell_mm", source.cell_mm}}}});
  }
  nlohmann::json j;
  j["schema_version"] = 1;
  j["luminaire"] = {{"emitters", emitters}};
  if (luminaire.centre_mm != Eigen::Vector3d::Zero())
    j["luminaire"]["centre_mm"] = Vec(luminaire.centre_mm);
  WriteJsonAtomically(path, j);
}

void WriteTruthResponse(const ResponseEffect& response, const std::string& path) {
  nlohmann::json j;
  j["schema_version"] = 1;
  j["curve"] = response.curve();
  if (response.curve() == "gamma") {
    j["gamma"] = response.gamma();
    j["shoulder"] = response.shoulder();
  }
  j["jpeg_quality"] = response.quality();
  nlohmann::json table = nlohmann::json::array();
  for (int k = 0; k < 256; ++k) table.push_back(response.Inverse(k / 255.0));
  j["linear_of_code"] = table;
  WriteJsonAtomically(path, j);
}

}  // namespace lumislab
