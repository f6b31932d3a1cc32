#include "acquire/synth_orientations.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <random>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/synthetic/truth.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// A uniform number in [0, 1) from the generator's 53 high bits: the same sequence on every
// platform (std::uniform_real_distribution's is the library's choice).
double Uniform(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1.0p-53; }

// The mounting error of one orientation: angle uniform in [A/2, A] about a direction uniform
// on the sphere.
Eigen::Matrix3d MountError(std::mt19937_64& rng, double a_deg, double* angle_deg) {
  const double z = 2 * Uniform(rng) - 1, phi = 2 * kPi * Uniform(rng);
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  const Eigen::Vector3d axis(r * std::cos(phi), r * std::sin(phi), z);
  *angle_deg = a_deg * (0.5 + 0.5 * Uniform(rng));
  return Eigen::AngleAxisd(*angle_deg * kPi / 180, axis).toRotationMatrix();
}

std::string Field(const LuminaireSet& set, size_t k, const std::string& field) {
  return "orientations[" + std::to_string(k) + "] (" + set.orientations[k].name + "): " + field;
}

nlohmann::json MatrixJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}
nlohmann::json VectorJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// truth/orientations.json (schema 1, docs/formats.md §19).
void WriteTrueOrientations(const LuminaireSet& set, const std::vector<TruePose>& poses,
                           const SynthOrientationsOptions& o, const std::string& path) {
  nlohmann::json json;
  json["schema_version"] = kTrueOrientationsSchemaVersion;
  json["mount_error_deg"] = o.mount_error_deg;
  json["seed"] = o.seed;
  json["orientations"] = nlohmann::json::array();
  for (size_t k = 0; k < poses.size(); ++k) {
    const TruePose& p = poses[k];
    json["orientations"].push_back(
        {{"name", p.name},
         {"dataset", set.orientations[k].dataset},
         {"rotation", MatrixJson(p.rotation)},
         {"rotation_deg", VectorJson(RotationZyxDegreesOf(p.rotation))},
         {"nominal_rotation_deg", VectorJson(set.orientations[k].rotation_deg)},
         {"centre_mm", VectorJson(p.centre_mm)},
         {"error_deg", p.error_deg}});
  }
  WriteJsonAtomically(path, json);
}

// luminaire.json, truth/ and each orientation's dataset into `dir` (the staging folder, or the
// final one for a live capture).
void WriteLuminaireFolder(const SynthScene& scene, const SynthOptions& options,
                          const SynthOrientationsOptions& o, LuminaireSet set,
                          const std::vector<TruePose>& poses, const std::string& dir,
                          SynthOrientationsReport* report) {
  MakeDirectories(dir + "/truth");
  set.folder = dir;
  WriteLuminaireSet(set);
  WriteTrueOrientations(set, poses, o, dir + "/truth/orientations.json");
  WriteTruthLuminaire(scene.luminaire, dir + "/truth/luminaire.json");
  for (size_t k = 0; k < poses.size() && !StopRequested(); ++k) {
    SynthScene turned = scene;
    turned.luminaire = scene.luminaire.Turned(poses[k].rotation, poses[k].centre_mm);
    SynthOptions one = options;
    one.out_dir = set.DatasetFolder(k);
    one.force = true;  // a fresh folder (staging) or a live capture's redo
    LogInfo("orientation ", poses[k].name, " (", k + 1, "/", poses.size(), "): rotation_deg ",
            RotationZyxDegreesOf(poses[k].rotation).transpose(), ", mounting error ",
            poses[k].error_deg, " deg");
    report->orientations.push_back(RunSynth(turned, one));
  }
}

}  // namespace

LuminaireSet LoadOrientationsFile(const std::string& file) {
  const fs::path path(file);
  std::error_code ec;
  if (fs::is_directory(path, ec)) return LoadLuminaireSet(file);
  if (path.filename() == "luminaire.json")
    return LoadLuminaireSet(path.has_parent_path() ? path.parent_path().string() : ".");
  return LoadLuminaireSetFile(file, path.has_parent_path() ? path.parent_path().string() : ".");
}

void SynthOrientationsOptions::Check() const {
  if (orientations_file.empty())
    throw BadInput("--orientations: expected a file in luminaire.json's format, got nothing");
  if (!(mount_error_deg >= 0 && mount_error_deg <= kMaxMountErrorDeg))
    throw BadInput("--mount-error-deg: expected degrees in [0, " +
                   std::to_string(int(kMaxMountErrorDeg)) + "], got " +
                   std::to_string(mount_error_deg));
}

std::vector<TruePose> TruePoses(const LuminaireSet& set, double mount_error_deg, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<TruePose> poses;
  for (size_t k = 0; k < set.orientations.size(); ++k) {
    const Orientation& o = set.orientations[k];
    TruePose p;
    p.name = o.name;
    p.nominal = o.NominalRotation();
    p.centre_mm = o.centre_mm;
    p.rotation = p.nominal;
    if (k > 0 && mount_error_deg > 0)
      p.rotation = MountError(rng, mount_error_deg, &p.error_deg) * p.nominal;
    poses.push_back(p);
  }
  return poses;
}

void CheckBehindS(const Luminaire& luminaire, const LuminaireSet& set,
                  const std::vector<TruePose>& poses, const std::string& file) {
  if (!luminaire.ray_sources.empty()) luminaire.Turned(poses[0].rotation, poses[0].centre_mm);
  for (size_t k = 0; k < poses.size(); ++k) {
    try {
      luminaire.Turned(poses[k].rotation, poses[k].centre_mm);  // its refusal, named here
    } catch (const Error& e) {
      throw InputError(file, Field(set, k, "centre_mm"),
                       "a pose (rotation_deg, centre_mm) that keeps every emitter behind S",
                       e.what());
    }
  }
}

bool LuminaireFolderComplete(const std::string& dir) {
  try {
    if (!fs::exists(dir + "/truth/orientations.json") || !fs::exists(dir + "/truth/luminaire.json"))
      return false;
    const LuminaireSet set = LoadLuminaireSet(dir);
    for (size_t k = 0; k < set.orientations.size(); ++k)
      if (!DatasetComplete(set.DatasetFolder(k))) return false;
    return !set.orientations.empty();
  } catch (const Error&) {
    return false;
  }
}

SynthOrientationsReport RunSynthOrientations(const SynthScene& scene, const SynthOptions& options,
                                             const SynthOrientationsOptions& o) {
  options.Check();
  o.Check();
  SynthOrientationsReport report;
  const std::string& out = options.out_dir;
  const LuminaireSet set = LoadOrientationsFile(o.orientations_file);
  const std::vector<TruePose> poses = TruePoses(set, o.mount_error_deg, o.seed);
  CheckBehindS(scene.luminaire, set, poses, o.orientations_file);
  if (!options.force && !options.camera_folder && LuminaireFolderComplete(out)) {
    // Only the same plan is a finished job: another one is refused, not skipped.
    const LuminaireSet done = LoadLuminaireSet(out);
    bool same = done.orientations.size() == set.orientations.size();
    for (size_t k = 0; same && k < set.orientations.size(); ++k)
      same = done.orientations[k].name == set.orientations[k].name &&
             done.orientations[k].dataset == set.orientations[k].dataset &&
             done.orientations[k].rotation_deg.isApprox(set.orientations[k].rotation_deg) &&
             done.orientations[k].centre_mm.isApprox(set.orientations[k].centre_mm);
    if (!same)
      throw BadInput(LuminaireJsonPath(out) + ": orientations: expected those of " +
                     o.orientations_file +
                     " (the folder holds a capture of another plan), got others: use --force to "
                     "capture this plan over it, or another --out");
    LogInfo("a complete luminaire folder is already in ", out, " (use --force to redo it)");
    report.skipped = true;
    return report;
  }
  LogInfo(set.orientations.size(), " orientation(s) from ", o.orientations_file,
          ", mounting errors ",
          o.mount_error_deg > 0
              ? "in [" + Num(o.mount_error_deg / 2, 4) + ", " + Num(o.mount_error_deg, 4) + "] deg"
              : std::string("none"));
  if (options.interval_s >= 0) {  // live: readers follow the files where they will stay
    WriteLuminaireFolder(scene, options, o, set, poses, out, &report);
    return report;
  }
  // As RunSynth: staged beside `out`, swapped in when complete.
  if (!WriteFolderStaged(out, [&](const std::string& staging) {
        WriteLuminaireFolder(scene, options, o, set, poses, staging, &report);
        return !StopRequested();
      }))
    report.orientations.clear();
  return report;
}

}  // namespace lumislab
