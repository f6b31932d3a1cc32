#include "calibrate/cli_orientations.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/log.h"
#include "core/slab.h"

namespace lumislab {
namespace {

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// A number, or null where it is infinite (an unconstrained component).
nlohmann::json Sigma(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

std::string SigmaText(double v) { return std::isfinite(v) ? Num(v, 3) : std::string("free"); }

RegistrationInput ReadOrientation(const LuminaireSet& set, size_t k, const RegistrationOptions& o,
                                  int threads, std::string* units) {
  const Orientation& orientation = set.orientations[k];
  const Dataset dataset = Dataset::Load(set.DatasetFolder(k));
  const std::string slab_dir = dataset.Path("slab");
  if (!std::filesystem::is_regular_file(slab_dir + "/slab.json"))
    throw BadInput(slab_dir + "/slab.json: orientation " + orientation.name +
                   " has no slab (reconstruct its dataset first)");
  const SlabInfo info = SlabInfo::Load(slab_dir);
  // A partial slab lacks the light of its missing positions: its far field would be too low.
  if (!info.Complete())
    throw InputError(slab_dir + "/slab.json", "present",
                     "every position of the " + std::to_string(info.grid.nu) + " x " +
                         std::to_string(info.grid.nv) +
                         " grid (finish it with lumislab-reconstruct)",
                     std::to_string(info.present.size()) + " position(s)");
  // Intensities of different units cannot be compared (and the merge could not add them).
  if (units->empty()) *units = info.units;
  if (info.units != *units)
    throw InputError(slab_dir + "/slab.json", "units", "the first orientation's (" + *units + ")",
                     info.units);
  RegistrationInput in;
  in.name = orientation.name;
  in.nominal = orientation.NominalRotation();
  in.cone = ConeOfDataset(dataset);
  in.far_field = SampleFarFieldGrid(info, ReadSlabPositions(slab_dir, info, threads), in.cone,
                                    o.nodes_per_tan, threads);
  return in;
}

void PrintTable(const LuminaireSet& set, const Registration& r) {
  std::ostringstream table;
  table << "orientation  correction (deg, capture frame)      angle   sigma x / y / z (deg)\n";
  for (size_t k = 0; k < r.orientations.size(); ++k) {
    const RegisteredOrientation& o = r.orientations[k];
    char line[256];
    std::snprintf(line, sizeof line, "%-11s  %+9.4f %+9.4f %+9.4f  %7.4f  ",
                  set.orientations[k].name.c_str(), o.correction_deg.x(), o.correction_deg.y(),
                  o.correction_deg.z(), o.angle_deg);
    table << line
          << (o.gauge ? std::string("gauge (held at nominal)")
                      : SigmaText(o.sigma_deg.x()) + " / " + SigmaText(o.sigma_deg.y()) + " / " +
                            SigmaText(o.sigma_deg.z()))
          << "\n";
  }
  table << "pair         overlap (sr)  samples  rel. RMS before  after    ratio a/b\n";
  for (const RegisteredPair& p : r.pairs) {
    char line[256];
    std::snprintf(line, sizeof line, "%-5s %-5s  %12.4f  %7d  %15.4f  %7.4f  %9.4f\n",
                  set.orientations[size_t(p.a)].name.c_str(),
                  set.orientations[size_t(p.b)].name.c_str(), p.overlap_sr, p.samples, p.rms_before,
                  p.rms_after, p.ratio);
    table << line;
  }
  if (r.gain_profile_fitted) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "gain profile g(theta) = 1 %+.5f (1 - cos theta) %+.5f (1 - cos theta)^2 "
                  "(sigma %.5f, %.5f): g(20) = %.4f, g(40) = %.4f, g(%.0f) = %.4f\n",
                  r.gain_profile[0], r.gain_profile[1], r.gain_profile_sigma[0],
                  r.gain_profile_sigma[1], r.Gain(20), r.Gain(40), r.gain_profile_theta_max_deg,
                  r.Gain(r.gain_profile_theta_max_deg));
    table << line;
  }
  std::printf("%s", table.str().c_str());
}

}  // namespace

std::string RegistrationJson(const LuminaireSet& set, const Registration& r,
                             const RegistrationOptions& options) {
  nlohmann::json j;
  j["schema_version"] = kRegistrationSchemaVersion;
  j["gauge"] = set.orientations.front().name;
  j["max_relative_rms"] = options.max_relative_rms;
  j["residual_sigma"] = r.residual_sigma;
  j["residuals"] = r.residuals;
  j["converged"] = r.converged;
  if (r.gain_profile_fitted) {
    nlohmann::json g;
    g["model"] = "1 + p1 (1 - cos theta) + p2 (1 - cos theta)^2";
    g["p"] = {r.gain_profile[0], r.gain_profile[1]};
    g["sigma"] = {r.gain_profile_sigma[0], r.gain_profile_sigma[1]};
    g["theta_max_deg"] = r.gain_profile_theta_max_deg;
    j["gain_profile"] = g;
  }
  j["orientations"] = nlohmann::json::array();
  for (size_t k = 0; k < r.orientations.size(); ++k) {
    const RegisteredOrientation& o = r.orientations[k];
    nlohmann::json e;
    e["name"] = set.orientations[k].name;
    e["rotation_deg"] = Vec(RotationZyxDegreesOf(o.rotation));
    nlohmann::json rows = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) rows.push_back(Vec(o.rotation.row(i).transpose()));
    e["rotation_matrix"] = rows;
    e["correction_deg"] = Vec(o.correction_deg);
    e["angle_deg"] = o.angle_deg;
    e["sigma_deg"] = {Sigma(o.sigma_deg.x()), Sigma(o.sigma_deg.y()), Sigma(o.sigma_deg.z())};
    nlohmann::json axes = nlohmann::json::array();
    for (const Eigen::Vector3d& a : o.free_axes) axes.push_back(Vec(a));
    e["free_axes"] = axes;
    e["gauge"] = o.gauge;
    j["orientations"].push_back(e);
  }
  j["pairs"] = nlohmann::json::array();
  for (const RegisteredPair& p : r.pairs)
    j["pairs"].push_back({{"a", set.orientations[size_t(p.a)].name},
                          {"b", set.orientations[size_t(p.b)].name},
                          {"overlap_sr", p.overlap_sr},
                          {"samples", p.samples},
                          {"rms_before", p.rms_before},
                          {"rms_after", p.rms_after},
                          {"ratio", p.ratio}});
  return j.dump(2) + "\n";
}

void AddOrientationsCommand(CLI::App* app, CommonOptions* common, OrientationsCommand* c) {
  c->sub = app->add_subcommand(
      "orientations",
      "a luminaire folder (luminaire.json, one reconstructed dataset per orientation) -> "
      "<lum>/registration.json: the rotations of every orientation but the first refined so "
      "that the directions two orientations both see have the same intensity (Ceres), with "
      "their uncertainty; refuses (exit 2) a set whose overlaps are too small to register or "
      "disagree beyond noise after the fit, naming the pair");
  c->sub->add_option("--luminaire", c->luminaire, "the luminaire folder")->required();
  c->sub
      ->add_option("--max-relative-rms", c->options.max_relative_rms,
                   "refuse a pair whose relative RMS difference over its overlap stays above "
                   "this after the fit")
      ->capture_default_str();
  c->sub->add_flag("--gain-profile", c->options.fit_gain_profile,
                   "also fit a gain profile g(theta) = 1 + p1 (1 - cos theta) + p2 (1 - cos "
                   "theta)^2 of the angle from the capture axis, shared by every orientation "
                   "(needs three pairs or more; reported, not applied)");
  c->sub->add_flag("--force", c->force, "replace an existing registration.json");
  AddCommonOptions(c->sub, common);
}

int RunOrientationsCommand(OrientationsCommand* c, int threads) {
  c->options.threads = threads;
  c->options.Check();
  c->luminaire = TrimTrailingSlashes(c->luminaire);
  LogInfo("parameters: orientations luminaire=", c->luminaire,
          " max-relative-rms=", Num(c->options.max_relative_rms),
          " gain-profile=", c->options.fit_gain_profile ? "yes" : "no",
          " force=", c->force ? "yes" : "no");
  const LuminaireSet set = LoadLuminaireSet(c->luminaire);
  const std::string out = RegistrationJsonPath(c->luminaire);
  if (set.orientations.size() < 2)
    throw InputError(LuminaireJsonPath(c->luminaire), "orientations", "at least two to register",
                     std::to_string(set.orientations.size()));
  if (std::filesystem::exists(out) && !c->force)
    throw BadInput(out + ": exists; use --force to replace it");

  std::vector<RegistrationInput> inputs;
  std::vector<Eigen::Matrix3d> nominal;
  std::vector<OrientationCone> cones;
  std::vector<std::string> names;
  for (size_t k = 0; k < set.orientations.size(); ++k) {
    // The planner's reason first, before the slabs are read.
    const Dataset dataset = Dataset::Load(set.DatasetFolder(k));
    nominal.push_back(set.orientations[k].NominalRotation());
    cones.push_back(ConeOfDataset(dataset));
    names.push_back(set.orientations[k].name);
  }
  const CoverageReport coverage =
      AnalyseCoverage(nominal, cones, set.coverage == "hemisphere", 20000, names);
  if (!coverage.overlap_problem.empty())
    throw BadInput(LuminaireJsonPath(c->luminaire) +
                   ": the orientations cannot be registered: " + coverage.overlap_problem);
  std::string units;
  for (size_t k = 0; k < set.orientations.size(); ++k)
    inputs.push_back(ReadOrientation(set, k, c->options, threads, &units));

  const Registration registration = RegisterOrientations(inputs, coverage, c->options);
  PrintTable(set, registration);
  if (!registration.disagreement.empty()) {
    // A registration.json left from an earlier run would give the merge poses these slabs refute.
    if (std::filesystem::exists(out)) std::filesystem::remove(out);
    throw BadInput(c->luminaire + ": " + registration.disagreement);
  }
  RemoveOrphanedTemporaries(c->luminaire);
  WriteTextAtomically(out, RegistrationJson(set, registration, c->options));
  LogInfo("orientations: ", set.orientations.size(), " registered (gauge ",
          set.orientations.front().name, "), residual sigma ", Num(registration.residual_sigma),
          " over ", registration.residuals, " directions, ",
          registration.converged ? "converged" : "NOT converged", " -> ", out);
  return 0;
}

}  // namespace lumislab
