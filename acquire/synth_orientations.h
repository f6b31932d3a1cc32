// lumislab-acquire synth --orientations: the synthetic capture of a luminaire from several
// orientations into a luminaire folder (docs/formats.md §19, "luminaire.json and synthetic
// orientations"): <lum>/luminaire.json (the nominal poses of the orientations file), one ordinary
// synthetic dataset per orientation of the scene's luminaire turned by its true pose, and
// <lum>/truth/ (the true poses, the luminaire in its own frame).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "acquire/synth.h"
#include "core/luminaire_set.h"

namespace lumislab {

constexpr int kTrueOrientationsSchemaVersion = 1;
constexpr double kMaxMountErrorDeg = 45;

struct SynthOrientationsOptions {
  std::string orientations_file;  // luminaire.json's format (lumislab-plan orientations --out)
  // > 0: every orientation but the first is turned further by a rotation of angle uniform in
  // [A/2, A] (degrees) about a uniformly random axis, drawn from `seed`.
  double mount_error_deg = 0;
  uint64_t seed = 1;

  void Check() const;  // BadInput naming the option
};

// The orientations of a file in luminaire.json's format (any name), a luminaire.json or a
// luminaire folder (LoadLuminaireSet's checks; messages name the file given).
LuminaireSet LoadOrientationsFile(const std::string& file);

// The true pose of one orientation: R_true = E R_nominal, E the mounting error (a turn in the
// capture frame, what registration.json's correction estimates), about the same centre.
struct TruePose {
  std::string name;
  Eigen::Matrix3d nominal = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // capture_from_luminaire
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();
  double error_deg = 0;  // the angle of E
};

// The true poses of `set`'s orientations: deterministic in (mount_error_deg, seed); the first
// orientation exact (it defines the luminaire frame).
std::vector<TruePose> TruePoses(const LuminaireSet& set, double mount_error_deg, uint64_t seed);

// BadInput "<file>: orientations[k] (name): centre_mm: expected ..., got <Luminaire::Turned's
// reason>" when a pose puts an emitter of `luminaire` on or in front of S (z >= 0 of the capture
// frame); Turned's own refusal of a luminaire with ray sources.
void CheckBehindS(const Luminaire& luminaire, const LuminaireSet& set,
                  const std::vector<TruePose>& poses, const std::string& file);

struct SynthOrientationsReport {
  bool skipped = false;                   // the folder already held a complete luminaire folder
  std::vector<SynthReport> orientations;  // per orientation, in the file's order
};

// The whole luminaire folder into options.out_dir: staged beside it and renamed when complete
// (a live --interval capture writes in place, luminaire.json first). Callable from tests.
SynthOrientationsReport RunSynthOrientations(const SynthScene& scene, const SynthOptions& options,
                                             const SynthOrientationsOptions& orientations);

// True when `dir` holds luminaire.json, truth/orientations.json, truth/luminaire.json and every
// orientation's complete dataset.
bool LuminaireFolderComplete(const std::string& dir);

}  // namespace lumislab
