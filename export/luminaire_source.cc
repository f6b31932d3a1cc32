#include "export/luminaire_source.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/checks.h"
#include "core/dataset.h"
#include "core/log.h"
#include "core/slab_light.h"
#include "export/complete_slab.h"

namespace lumislab {
namespace {

// A 1-sigma of registration.json: infinite where the overlaps do not constrain the component.
// "0.38 deg", or "unconstrained" for a direction the overlaps do not fix.
std::string Sigma(double sigma_deg) {
  return std::isfinite(sigma_deg) ? Num(sigma_deg, 2) + " deg" : std::string("unconstrained");
}

}  // namespace

MergedFarField MergedFarFieldChecked(const LuminaireSource& source,
                                     const std::vector<double>& c_deg,
                                     const std::vector<double>& gamma_deg,
                                     const FarFieldOptions& options) {
  MergedFarField merged = ComputeMergedFarField(source.slabs, c_deg, gamma_deg, options);
  for (const MergedFarField::PairScale& p : merged.pair_scales) {
    if (std::abs(p.ratio - 1) <= kMaxPairScaleDeviation) continue;
    std::ostringstream why;
    why << source.set.folder << ": orientations " << source.slabs[size_t(p.a)].name << " and "
        << source.slabs[size_t(p.b)].name
        << " disagree where both see the luminaire: " << source.slabs[size_t(p.b)].name << " / "
        << source.slabs[size_t(p.a)].name << " = " << p.ratio << " over " << p.directions
        << " grid directions (at most " << 100 * kMaxPairScaleDeviation
        << " % apart): check each one's calib/scale.json and slab, and the poses ("
        << RegisterCommand(source.set.folder) << ")";
    throw BadInput(why.str());
  }
  return merged;
}

std::string RegisterCommand(const std::string& folder) {
  return "lumislab-calibrate orientations --luminaire " + folder;
}

LuminaireSource LoadLuminaireSource(const std::string& folder, int threads,
                                    const std::string& stage) {
  LuminaireSource source;
  source.set = LoadLuminaireSet(folder);
  for (size_t k = 0; k < source.set.orientations.size(); ++k) {
    const Orientation& o = source.set.orientations[k];
    PosedSlab slab;
    slab.name = o.name;
    const std::string dataset = source.set.DatasetFolder(k);
    slab.slab_dir = ResolveSlabDir(dataset);
    slab.info = SlabInfo::Load(slab.slab_dir);
    RequireCompleteSlab(slab.info, slab.slab_dir);
    slab.positions = ReadSlabPositions(slab.slab_dir, slab.info, threads);
    CheckLog checks(DatasetOfSlab(slab.slab_dir), stage);
    CheckSlabLight(slab.info, slab.positions, slab.slab_dir, checks);
    checks.Save();
    slab.capture_from_luminaire = o.rotation;
    slab.centre_mm = o.centre_mm;
    slab.cone = ConeOfDataset(Dataset::Load(dataset));
    LogInfo("orientation ", o.name, ": ", slab.slab_dir, ", rotation (", o.rotation_deg.x(), ", ",
            o.rotation_deg.y(), ", ", o.rotation_deg.z(), ") deg",
            o.registered ? " registered" : " nominal", ", units ", slab.info.units);
    source.slabs.push_back(std::move(slab));
  }
  if (source.slabs.empty())
    throw InputError(LuminaireJsonPath(folder), "orientations", "at least one orientation", "none");
  source.units = CommonUnits(source.slabs);
  if (!source.set.orientations.front().registered && source.slabs.size() > 1)
    LogWarning(folder,
               ": not registered (no registration.json): the merge uses the nominal poses of "
               "luminaire.json, whose error (a degree or two for a hand remount) blurs the "
               "overlaps and turns the lobes; register it first: ",
               RegisterCommand(folder));
  return source;
}

std::string LuminaireSource::Orientations() const {
  std::string s = std::to_string(slabs.size()) + " orientation" + (slabs.size() == 1 ? "" : "s");
  s += " (" + slabs.front().name +
       (slabs.size() > 2    ? ", ..., "
        : slabs.size() == 2 ? ", "
                            : "") +
       (slabs.size() > 1 ? slabs.back().name : "") + "), ";
  const bool registered = set.orientations.front().registered;
  if (!registered) return s + "nominal poses (not registered)";
  double worst = 0, sigma = 0;
  std::string worst_name = set.orientations.front().name;
  for (const Orientation& o : set.orientations) {
    if (o.correction_deg.norm() > worst) worst = o.correction_deg.norm(), worst_name = o.name;
    sigma = std::max(sigma, o.sigma_deg.maxCoeff());
  }
  return s + "registered: corrections up to " + Num(worst, 3) + " deg (" + worst_name +
         "), 1-sigma up to " + Sigma(sigma);
}

std::vector<std::string> LuminaireSource::RegistrationRows() const {
  std::vector<std::string> rows;
  for (const Orientation& o : set.orientations) {
    std::string row = o.name + ": " + o.dataset + ", nominal rotation (" +
                      Num(o.rotation_deg.x(), 4) + ", " + Num(o.rotation_deg.y(), 4) + ", " +
                      Num(o.rotation_deg.z(), 4) + ") deg";
    if (o.registered)
      row += ", correction (" + Num(o.correction_deg.x(), 3) + ", " + Num(o.correction_deg.y(), 3) +
             ", " + Num(o.correction_deg.z(), 3) + ") deg +- (" + Sigma(o.sigma_deg.x()) + ", " +
             Sigma(o.sigma_deg.y()) + ", " + Sigma(o.sigma_deg.z()) + ") deg (1 sigma)";
    rows.push_back(row);
  }
  return rows;
}

std::string LuminaireFolderInfo(const std::string& folder, bool json) {
  const LuminaireSet set = LoadLuminaireSet(folder);
  nlohmann::json j;
  j["format"] = "lumislab luminaire folder";
  j["coverage_asked"] = set.coverage;
  j["registered"] = !set.orientations.empty() && set.orientations.front().registered;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<OrientationCone> cones;
  std::string text = folder + ": luminaire folder, " + std::to_string(set.orientations.size()) +
                     " orientations, coverage asked: " + set.coverage +
                     (j["registered"] ? ", registered" : ", not registered (nominal poses)") + "\n";
  for (size_t k = 0; k < set.orientations.size(); ++k) {
    const Orientation& o = set.orientations[k];
    nlohmann::json e;
    e["name"] = o.name;
    e["dataset"] = o.dataset;
    e["rotation_deg"] = {o.rotation_deg.x(), o.rotation_deg.y(), o.rotation_deg.z()};
    std::string line = "  " + o.name + ": " + o.dataset + ", rotation (" +
                       Num(o.rotation_deg.x(), 4) + ", " + Num(o.rotation_deg.y(), 4) + ", " +
                       Num(o.rotation_deg.z(), 4) + ") deg";
    if (o.registered) {
      e["correction_deg"] = {o.correction_deg.x(), o.correction_deg.y(), o.correction_deg.z()};
      for (int i = 0; i < 3; ++i)  // null: unconstrained, as registration.json writes it
        e["sigma_deg"].push_back(std::isfinite(o.sigma_deg[i]) ? nlohmann::json(o.sigma_deg[i])
                                                               : nlohmann::json());
      line += ", correction " + Num(o.correction_deg.norm(), 3) + " deg (1-sigma up to " +
              Sigma(o.sigma_deg.maxCoeff()) + ")";
    }
    const std::string dataset = set.DatasetFolder(k);
    const Dataset ds = Dataset::Load(dataset);
    cones.push_back(ConeOfDataset(ds));
    rotations.push_back(o.rotation);
    const std::string slab_dir = dataset + "/slab";
    if (std::filesystem::is_regular_file(slab_dir + "/slab.json")) {
      const SlabInfo info = SlabInfo::Load(slab_dir);
      // What slab.json lists, and whether each listed position's file is there.
      int missing = 0;
      for (const auto& [i, jj] : info.present)
        missing += !std::filesystem::is_regular_file(SlabPositionPath(slab_dir, i, jj));
      const std::string state = missing > 0 ? std::to_string(missing) + " position file(s) missing"
                                : info.Complete() ? "complete"
                                                  : "partial";
      e["slab"] = state;
      e["units"] = info.units;
      line += "; slab " + state + ", units " + info.units;
    } else {
      e["slab"] = "none";
      line += "; no slab yet";
    }
    j["orientations"].push_back(e);
    text += line + "\n";
  }
  const CoverageReport c = AnalyseCoverage(rotations, cones, set.coverage == "hemisphere");
  j["covered_fraction"] = c.covered_fraction;
  j["unseen_sr"] = c.unseen_sr;
  j["overlap_problem"] = c.overlap_problem;
  text += "  cones at these poses cover " + Num(100 * c.covered_fraction, 4) + " % of the " +
          set.coverage + " (" + Num(c.unseen_sr, 3) + " sr unseen); ";
  for (const PairOverlap& p : c.pairs) {
    j["pairs"].push_back({{"a", set.orientations[size_t(p.a)].name},
                          {"b", set.orientations[size_t(p.b)].name},
                          {"overlap_sr", p.overlap_sr}});
  }
  text +=
      std::to_string(c.pairs.size()) + " overlapping pairs; " +
      (c.overlap_problem.empty() ? "every orientation connected to the first" : c.overlap_problem) +
      "\n";
  return json ? j.dump(2) + "\n" : text;
}

size_t FrontOrientation(const LuminaireSet& set) {
  size_t best = 0;
  for (size_t k = 1; k < set.orientations.size(); ++k)
    if (set.orientations[k].rotation(2, 2) > set.orientations[best].rotation(2, 2)) best = k;
  return best;
}

FarFieldUncertainty LuminaireUncertainty(const LuminaireSource& source, int samples,
                                         const UncertaintyOptions& options) {
  FarFieldUncertainty worst;
  bool first = true;
  for (const PosedSlab& s : source.slabs) {
    FarFieldUncertainty u =
        EstimateFarFieldUncertainty(s.info, DatasetOfSlab(s.slab_dir), samples, options);
    if (first || u.FluxExpanded() > worst.FluxExpanded()) worst = std::move(u);
    first = false;
  }
  return worst;
}

std::string LuminaireSource::TruthDir() const {
  return (std::filesystem::path(set.folder) / "truth").string();
}

}  // namespace lumislab
