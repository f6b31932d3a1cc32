// The luminaire folder (docs/formats.md §19): luminaire.json, registration.json, the cones of
// the orientations and their coverage.
#include "core/luminaire_set.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/slab.h"

namespace lumislab {
namespace {

constexpr double kDeg = 180.0 / kPi;

Eigen::Vector3d Vector3(const JsonView& v, double limit) {
  const std::vector<double> a = v.Numbers(3);
  for (const double x : a)
    if (!(std::abs(x) <= limit)) v.Fail("three numbers within " + std::to_string(int(limit)));
  return {a[0], a[1], a[2]};
}

// A 3 x 3 rotation matrix (rows), orthonormal with determinant +1 within 1e-6.
Eigen::Matrix3d RotationMatrix(const JsonView& v) {
  if (v.Size() != 3) v.Fail("a 3 x 3 rotation matrix (three rows of three numbers)");
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    const std::vector<double> row = v[size_t(i)].Numbers(3);
    for (int j = 0; j < 3; ++j) r(i, j) = row[size_t(j)];
  }
  if (!((r * r.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
        std::abs(r.determinant() - 1) < 1e-6))
    v.Fail("a rotation matrix (orthonormal, determinant +1)");
  return r;
}

// Registration's refined poses over the nominal ones (registration.json, schema 1).
void ApplyRegistration(const std::string& path, LuminaireSet* set) {
  CheckInputFile(path, "registration file");
  const JsonDocument doc = JsonDocument::Load(path);
  doc.CheckSchemaVersion(kRegistrationSchemaVersion);
  const JsonView list = doc.root()["orientations"];
  std::set<std::string> done;
  for (size_t k = 0; k < list.Size(); ++k) {
    const JsonView e = list[k];
    const std::string name = e["name"].String();
    auto it = std::find_if(set->orientations.begin(), set->orientations.end(),
                           [&](const Orientation& o) { return o.name == name; });
    if (it == set->orientations.end())
      e["name"].Fail("the name of an orientation of luminaire.json");
    if (!done.insert(name).second) e["name"].Fail("each orientation once");
    it->rotation = RotationMatrix(e["rotation_matrix"]);
    it->registered = true;
    if (e.Has("correction_deg")) {
      it->correction_deg = Vector3(e["correction_deg"], 180);
      // The correction it states must be its rotation over luminaire.json's nominal pose: a
      // registration made for other nominal poses (luminaire.json edited since) is stale.
      const Eigen::AngleAxisd stated(it->correction_deg.norm() / kDeg,
                                     it->correction_deg.norm() > 0
                                         ? Eigen::Vector3d(it->correction_deg.normalized())
                                         : Eigen::Vector3d::UnitX());
      const Eigen::Matrix3d implied = it->rotation * it->NominalRotation().transpose();
      const double mismatch_deg =
          Eigen::AngleAxisd(stated.toRotationMatrix().transpose() * implied).angle() * kDeg;
      if (!(mismatch_deg < 0.01))
        e["correction_deg"].Fail(
            "the rotation over luminaire.json's nominal pose of " + name + " (it differs by " +
            std::to_string(mismatch_deg) +
            " deg: registration.json was made for other nominal poses; register again with "
            "lumislab-calibrate orientations --force)");
    }
    if (e.Has("sigma_deg")) {
      const JsonView s = e["sigma_deg"];
      if (s.Size() != 3) s.Fail("three numbers >= 0 or null (unconstrained)");
      for (int i = 0; i < 3; ++i) {
        const JsonView c = s[size_t(i)];
        it->sigma_deg[i] =
            c.IsNull() ? std::numeric_limits<double>::infinity() : c.NumberIn(0, 360);
      }
    }
  }
  if (done.size() != set->orientations.size())
    list.Fail("every orientation of luminaire.json (" + std::to_string(set->orientations.size()) +
              "), got " + std::to_string(done.size()));
}

}  // namespace

double OrientationCone::MarginDeg(const Eigen::Vector3d& w) const {
  if (!(w.z() > 0)) return -90;
  const double ax = std::atan2(std::abs(w.x()), w.z()), ay = std::atan2(std::abs(w.y()), w.z());
  const double lx = std::atan2(half_w_mm, distance_mm), ly = std::atan2(half_h_mm, distance_mm);
  return std::min(lx - ax, ly - ay) * kDeg;
}

namespace {

// d and the screen's half-sizes less the positions' support on S (grid half-extent plus h).
OrientationCone ConeOf(double distance_mm, const SamplingGrid& g, double screen_w_mm,
                       double screen_h_mm) {
  OrientationCone cone;
  cone.distance_mm = distance_mm;
  cone.half_w_mm = 0.5 * screen_w_mm - (0.5 * (g.nu - 1) + 1) * g.spacing_mm;
  cone.half_h_mm = 0.5 * screen_h_mm - (0.5 * (g.nv - 1) + 1) * g.spacing_mm;
  return cone;
}

}  // namespace

OrientationCone ConeOfDataset(const Dataset& dataset) {
  return ConeOf(dataset.distance_mm, dataset.grid, dataset.screen_w_mm, dataset.screen_h_mm);
}

OrientationCone ConeOfSlab(const SlabInfo& info) {
  return ConeOf(info.distance_mm, info.grid, info.layout.window_w_mm, info.layout.window_h_mm);
}

std::vector<Eigen::Vector3d> FibonacciDirections(int n, bool hemisphere) {
  const double golden = kPi * (3 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> out(static_cast<size_t>(std::max(0, n)));
  for (int i = 0; i < n; ++i) {
    const double z = hemisphere ? 1 - (i + 0.5) / n : 1 - 2 * (i + 0.5) / n;
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    out[size_t(i)] = Eigen::Vector3d(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return out;
}

double ConeTaper(const OrientationCone& cone, const Eigen::Vector3d& w, double taper_deg) {
  const double m = cone.MarginDeg(w);
  if (!(m > 0)) return 0;
  if (m >= taper_deg) return 1;
  const double t = m / taper_deg;
  return t * t * (3 - 2 * t);
}

Eigen::Matrix3d Orientation::NominalRotation() const { return RotationZyxDegrees(rotation_deg); }

std::string LuminaireSet::DatasetFolder(size_t k) const {
  return folder + "/" + orientations.at(k).dataset;
}

std::string LuminaireJsonPath(const std::string& folder) { return folder + "/luminaire.json"; }
std::string RegistrationJsonPath(const std::string& folder) {
  return folder + "/registration.json";
}

bool IsLuminaireFolder(const std::string& folder) {
  std::error_code ec;
  return std::filesystem::is_regular_file(LuminaireJsonPath(folder), ec);
}

LuminaireSet LoadLuminaireSet(const std::string& folder) {
  LuminaireSet set = LoadLuminaireSetFile(LuminaireJsonPath(folder), folder);
  if (std::filesystem::exists(RegistrationJsonPath(folder)))
    ApplyRegistration(RegistrationJsonPath(folder), &set);
  return set;
}

LuminaireSet LoadLuminaireSetFile(const std::string& path, const std::string& folder) {
  CheckInputFile(path, "luminaire file");
  const JsonDocument doc = JsonDocument::Load(path);
  doc.CheckSchemaVersion(kLuminaireSetSchemaVersion);
  const JsonView root = doc.root();
  LuminaireSet set;
  set.folder = folder;
  set.coverage = root["coverage"].OneOf({"sphere", "hemisphere"});
  const JsonView list = root["orientations"];
  if (list.Size() < 1 || list.Size() > 1000) list.Fail("1 to 1000 orientations");
  std::set<std::string> names, datasets;
  for (size_t k = 0; k < list.Size(); ++k) {
    const JsonView e = list[k];
    Orientation o;
    o.name = e["name"].String();
    if (o.name.empty() || o.name.size() > 64 || !names.insert(o.name).second)
      e["name"].Fail("a unique name of 1 to 64 characters");
    o.dataset = e["dataset"].String();
    // A plain relative path of named components ("o00", "a/o00"; a trailing '/' dropped), none
    // of them the folder's own entries, and one folder per orientation: by name, and on disk
    // where the folders exist (a symbolic link to another orientation's folder is the same one).
    while (o.dataset.size() > 1 && o.dataset.back() == '/') o.dataset.pop_back();
    const std::filesystem::path rel(o.dataset);
    const std::string first = rel.empty() ? "" : rel.begin()->string();
    const bool plain = !o.dataset.empty() && !rel.is_absolute() &&
                       std::none_of(rel.begin(), rel.end(),
                                    [](const std::filesystem::path& p) {
                                      return p.empty() || p == ".." || p == ".";
                                    }) &&
                       first != "truth" && first != "capture" && first != "exports" &&
                       first != "luminaire.json" && first != "registration.json";
    std::error_code ec;
    const std::filesystem::path on_disk =
        std::filesystem::weakly_canonical(std::filesystem::path(folder) / rel, ec);
    if (!plain || !datasets.insert(rel.lexically_normal().string()).second ||
        (!ec && !datasets.insert("disk:" + on_disk.string()).second))
      e["dataset"].Fail(
          "a folder inside the luminaire folder, one per orientation, not truth, capture or "
          "exports");
    o.rotation_deg = Vector3(e["rotation_deg"], 36000);
    o.centre_mm = Vector3(e["centre_mm"], 1e6);
    if (e.Has("mount")) o.mount = e["mount"].IntIn(0, 1000);
    if (e.Has("axis_deg")) o.axis_deg = e["axis_deg"].NumberIn(-36000, 36000);
    o.rotation = o.NominalRotation();
    set.orientations.push_back(std::move(o));
  }
  return set;
}

void WriteLuminaireSet(const LuminaireSet& set) {
  WriteLuminaireSetFile(set, LuminaireJsonPath(set.folder));
}

void WriteLuminaireSetFile(const LuminaireSet& set, const std::string& file) {
  nlohmann::json list = nlohmann::json::array();
  for (const Orientation& o : set.orientations) {
    nlohmann::json e = {
        {"name", o.name},
        {"dataset", o.dataset},
        {"rotation_deg", {o.rotation_deg.x(), o.rotation_deg.y(), o.rotation_deg.z()}},
        {"centre_mm", {o.centre_mm.x(), o.centre_mm.y(), o.centre_mm.z()}}};
    if (o.mount) e["mount"] = *o.mount;
    if (o.axis_deg) e["axis_deg"] = *o.axis_deg;
    list.push_back(std::move(e));
  }
  WriteJsonAtomically(file, {{"schema_version", kLuminaireSetSchemaVersion},
                             {"coverage", set.coverage},
                             {"orientations", list}});
}

CoverageReport AnalyseCoverage(const std::vector<Eigen::Matrix3d>& poses,
                               const std::vector<OrientationCone>& cones, bool hemisphere,
                               int samples, const std::vector<std::string>& names) {
  LUMISLAB_CHECK(poses.size() == cones.size() && !poses.empty() && samples > 0,
                 "one cone per pose, at least one");
  const size_t n = poses.size();
  const double total_sr = hemisphere ? 2 * kPi : 4 * kPi;
  const std::vector<Eigen::Vector3d> lattice = FibonacciDirections(samples, hemisphere);
  std::vector<int> pair_count(n * n, 0);
  int covered = 0;
  std::vector<size_t> seen_by;
  for (const Eigen::Vector3d& w : lattice) {
    seen_by.clear();
    for (size_t k = 0; k < n; ++k)
      if (cones[k].MarginDeg(poses[k] * w) > 0) seen_by.push_back(k);
    if (!seen_by.empty()) ++covered;
    for (size_t a = 0; a < seen_by.size(); ++a)
      for (size_t b = a + 1; b < seen_by.size(); ++b) ++pair_count[seen_by[a] * n + seen_by[b]];
  }
  CoverageReport out;
  out.covered_fraction = double(covered) / samples;
  out.unseen_sr = (1 - out.covered_fraction) * total_sr;
  const double sr_per_sample = total_sr / samples;
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b)
      if (pair_count[a * n + b] > 0)
        out.pairs.push_back({int(a), int(b), pair_count[a * n + b] * sr_per_sample});
  // Orientations connected to the first through pairs that can be registered.
  std::vector<bool> reached(n, false);
  reached[0] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (const PairOverlap& p : out.pairs)
      if (p.overlap_sr >= kMinOverlapSr && reached[size_t(p.a)] != reached[size_t(p.b)]) {
        reached[size_t(p.a)] = reached[size_t(p.b)] = true;
        grew = true;
      }
  }
  const auto name = [&](size_t k) {
    return k < names.size() ? names[k] : "orientation " + std::to_string(k);
  };
  std::ostringstream why;
  why.precision(3);
  for (size_t k = 0; k < n; ++k) {
    if (reached[k]) continue;
    const PairOverlap* best = nullptr;
    for (const PairOverlap& p : out.pairs)
      if ((size_t(p.a) == k || size_t(p.b) == k) && (!best || p.overlap_sr > best->overlap_sr))
        best = &p;
    if (why.tellp() > 0) why << "; ";
    why << name(k) << " does not connect to " << name(0) << " through overlaps of at least "
        << kMinOverlapSr << " sr (";
    if (best)
      why << "its largest overlap is " << best->overlap_sr << " sr, with "
          << name(size_t(best->a) == k ? size_t(best->b) : size_t(best->a));
    else
      why << "it overlaps no other orientation";
    why << ")";
  }
  out.overlap_problem = why.str();
  return out;
}

}  // namespace lumislab
