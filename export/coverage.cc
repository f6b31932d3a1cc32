#include "export/coverage.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/geometry.h"
#include "core/json.h"
#include "core/log.h"
#include "core/slab_light.h"
#include "lib/synthetic/scene.h"

namespace lumislab {
namespace {

std::string TruthDirOfSlab(const std::string& slab_dir) {
  namespace fs = std::filesystem;
  return (fs::absolute(slab_dir).lexically_normal().parent_path() / "truth").string();
}

// K (lm/W) of a synthetic dataset's lux meter: truth/reference.json's luminous_efficacy_lm_w
// (acquire synth --meter lux records it), else the scenes' default.
double TruthEfficacy(const std::string& truth_dir) {
  const std::string file = truth_dir + "/reference.json";
  if (std::filesystem::is_regular_file(file)) {
    const JsonDocument doc = JsonDocument::Load(file);
    if (doc.root().Has("luminous_efficacy_lm_w"))
      return doc.root()["luminous_efficacy_lm_w"].Number();
  }
  return DefaultLuminousEfficacy();
}

std::string Pct(double share) { return Num(100 * share, 3) + " %"; }

}  // namespace

bool SyntheticSlab(const std::string& slab_dir) {
  return std::filesystem::is_regular_file(TruthDirOfSlab(slab_dir) + "/luminaire.json");
}

Coverage GridCoverage(const IntensityDistribution& d, const FarField& ff, const SlabInfo& info,
                      const std::string& slab_dir) {
  return GridCoverageWithTruth(d, ff, info, TruthDirOfSlab(slab_dir));
}

Coverage GridCoverageWithTruth(const IntensityDistribution& d, const FarField& ff,
                               const SlabInfo& info, const std::string& truth_dir,
                               bool isotropic_model) {
  Coverage c;
  const size_t ng = d.gamma_deg.size();
  c.c_deg = d.c_deg;
  c.directions = d.values.size();
  for (uint8_t s : ff.seen) c.unseen += s == 0;
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic) {
    double max = -1;
    for (size_t ig = 0; ig < ng && ff.seen[ic * ng + ig]; ++ig) max = d.gamma_deg[ig];
    c.seen_gamma_max_deg.push_back(max);
  }
  // The model on the file's grid; its flux in the unseen directions over its flux on the grid.
  IntensityDistribution model = d;
  const bool lux = info.units == "lux";
  if (std::filesystem::is_regular_file(truth_dir + "/luminaire.json")) {
    const Luminaire luminaire = LoadLuminaire(truth_dir + "/luminaire.json");
    if (luminaire.ray_sources.empty()) {
      c.analytic = true;
      const double k = lux ? TruthEfficacy(truth_dir) : 1.0;  // lm = K x W
      for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
        for (size_t ig = 0; ig < ng; ++ig) {
          const Eigen::Vector3d w = TypeCDirection(d.c_deg[ic], d.gamma_deg[ig]);
          // cd: 683 integral of V I_lambda for an emitter with a spectrum, K x the Rec. 709
          // mix (the synthetic convention) without; W/sr: the slab's one channel.
          double value = 0;
          for (const Emitter& e : luminaire.emitters)
            value += !lux          ? info.channel_weights.dot(e.Intensity(w))
                     : e.cct_k > 0 ? e.LuminousIntensity(w)
                                   : k * Rec709Weights().dot(e.Intensity(w));
          model.values[ic * ng + ig] = value;
        }
      c.model = "the analytic luminaire of the synthetic dataset (truth/luminaire.json)";
    }
  }
  if (!c.analytic && isotropic_model) {
    for (double& v : model.values) v = 1;
    c.model =
        "a model, not a measurement: an isotropic emitter (I0 in every direction) matched to the "
        "seen flux";
  } else if (!c.analytic) {
    for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
      for (size_t ig = 0; ig < ng; ++ig)
        model.values[ic * ng + ig] = std::max(0.0, std::cos(d.gamma_deg[ig] * kPi / 180));
    c.model =
        "a model, not a measurement: a Lambertian emitter (I0 cos gamma) matched to the seen "
        "flux";
  }
  IntensityDistribution seen_part = model;
  for (size_t k = 0; k < seen_part.values.size(); ++k)
    if (!ff.seen[k]) seen_part.values[k] = 0;
  const double total = model.TotalFlux(), seen = seen_part.TotalFlux();
  c.model_unseen_share = total > 0 ? std::max(0.0, 1 - seen / total) : 0;
  if (c.analytic) {
    c.model_flux = total;
  } else {  // scaled so that its seen flux is the capture's
    IntensityDistribution file = d;
    file.values = ff.values;
    for (double& v : file.values) v = std::max(v, 0.0);
    c.model_flux = seen > 0 ? file.TotalFlux() * total / seen : 0;
  }
  return c;
}

std::string Coverage::SeenCone() const {
  double lo = 1e9, hi = -1;
  for (double g : seen_gamma_max_deg) lo = std::min(lo, g), hi = std::max(hi, g);
  std::string s = "gamma 0-" + Num(std::max(lo, 0.0), 4) + " deg seen in every C plane";
  if (hi > lo) {
    s += ", up to " + Num(hi, 4) + " in some (";
    // The planes at 0, 45, 90 ... that the grid has: the cone's shape without listing all.
    int listed = 0;
    for (size_t k = 0; k < c_deg.size(); ++k)
      if (std::abs(std::remainder(c_deg[k], 45.0)) < 1e-6 && listed < 8)
        s += std::string(listed++ ? ", " : "") + "C " + Num(c_deg[k], 4) + ": " +
             Num(seen_gamma_max_deg[k], 4);
    s += ")";
  }
  return s;
}

std::string Coverage::Text() const {
  if (cells_beyond_cone)
    return "partial: " + SeenCone() +
           "; every grid direction seen, but the grid's cells reach "
           "beyond that cone; " +
           (analytic ? "the analytic luminaire" : "the model") + " puts " +
           Pct(model_unseen_share) + " of its flux within them there (" + model + ")";
  return "partial: " + SeenCone() + "; " + std::to_string(unseen) + " of " +
         std::to_string(directions) + " grid directions (" + Pct(double(unseen) / directions) +
         ") not seen, written as 0; " + (analytic ? "the analytic luminaire" : "the model") +
         " puts " + Pct(model_unseen_share) + " of its flux there (" + model + ")";
}

std::string Coverage::Short() const {
  double lo = 1e9;
  for (double g : seen_gamma_max_deg) lo = std::min(lo, g);
  auto pct = [](double share) { return Num(100 * share, 3) + "%"; };
  return "partial g<=" + Num(std::max(lo, 0.0), 4) + ": unseen " +
         pct(double(unseen) / directions) + " dirs, " + pct(model_unseen_share) + " flux (" +
         (analytic ? "truth" : "Lambert") + ")";
}

}  // namespace lumislab
