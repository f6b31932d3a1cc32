#include "export/cli_formats.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/log.h"
#include "core/slab.h"
#include "export/complete_slab.h"
#include "export/coverage.h"
#include "export/luminaire_source.h"
#include "export/report_uncertainty.h"
#include "lib/lightfield/far_field.h"
#include "lib/lightfield/far_field_light.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/file_info.h"
#include "lib/photometry/ies.h"
#include "lib/photometry/intensity_distribution.h"
#include "lib/photometry/tm25.h"

namespace lumislab {
namespace {

constexpr int kMetadataSchemaVersion = 1;
constexpr int64_t kMaxRays = 50000000;  // 1.4 GB of TM-25 rays

// ---- the slab -----------------------------------------------------------------------------

struct Slab {
  std::string dir;  // the slab folder; a luminaire folder's: the folder itself
  SlabInfo info;    // a luminaire folder: its first orientation's (units: every one's)
  std::vector<SlabPosition> positions;  // empty for a luminaire folder
  // A luminaire folder (docs/formats.md §19): every orientation's slab and pose, merged.
  std::shared_ptr<const LuminaireSource> luminaire;
};

// ---- a luminaire folder: the merged light field (lib/lightfield/merged_far_field.h) -------

// A luminaire folder's orientations, each slab complete (checked into its own dataset's
// checks.json under `stage`), in one unit.
Slab LoadLuminaireSlab(const std::string& folder, int threads, const std::string& stage) {
  Slab slab;
  slab.dir = folder;
  auto source = std::make_shared<LuminaireSource>(LoadLuminaireSource(folder, threads, stage));
  slab.info = source->slabs.front().info;
  LogInfo("luminaire ", folder, ": ", source->Orientations(),
          "; coverage asked: ", source->set.coverage, ", units ", source->units);
  slab.luminaire = source;
  return slab;
}

// The far field of the slab or, for a luminaire folder, the merged far field (luminaire frame);
// a single slab's light is checked into `checks` (a merged one's orientations were, each in its
// dataset, when loaded). `state_scales`: log the orientations' flux ratios over their overlaps
// (the grid's far field; not again for the cell check's fine one).
FarField SlabFarField(const Slab& slab, const std::vector<double>& c_deg,
                      const std::vector<double>& gamma_deg, const FarFieldOptions& options,
                      CheckLog& checks, bool state_scales = true) {
  if (!slab.luminaire) {
    FarField ff = ComputeFarField(slab.info, slab.positions, c_deg, gamma_deg, options);
    CheckFarFieldLight(ff, slab.info, slab.dir, checks);
    return ff;
  }
  MergedFarField merged = MergedFarFieldChecked(*slab.luminaire, c_deg, gamma_deg, options);
  for (const MergedFarField::PairScale& p : merged.pair_scales)
    if (state_scales)
      LogInfo("scale across orientations: ", slab.luminaire->slabs[size_t(p.b)].name, " / ",
              slab.luminaire->slabs[size_t(p.a)].name, " = ", Num(p.ratio, 4), " over the ",
              p.directions, " grid directions both weigh");
  return std::move(merged.ff);
}

// The coverage against the slab's model: a luminaire folder's truth/ (luminaire frame; without
// one, an isotropic emitter) or the dataset's (GridCoverage).
Coverage SlabCoverage(const IntensityDistribution& d, const FarField& ff, const Slab& slab) {
  return slab.luminaire ? GridCoverageWithTruth(d, ff, slab.info, slab.luminaire->TruthDir(), true)
                        : GridCoverage(d, ff, slab.info, slab.dir);
}

// The stated uncertainty of the slab; of a luminaire folder, the largest of its orientations'
// (by the flux term).
FarFieldUncertainty SlabUncertainty(const Slab& slab, int samples,
                                    const UncertaintyOptions& options) {
  return slab.luminaire
             ? LuminaireUncertainty(*slab.luminaire, samples, options)
             : EstimateFarFieldUncertainty(slab.info, DatasetOfSlab(slab.dir), samples, options);
}

bool Synthetic(const Slab& slab) {
  return slab.luminaire
             ? std::filesystem::is_regular_file(slab.luminaire->TruthDir() + "/luminaire.json")
             : SyntheticSlab(slab.dir);
}

// The gamma range a grid spans by default: 0-180 for a luminaire folder measured over the sphere,
// 0-90 (the hemisphere one slab can see) otherwise; `range` "sphere" or "hemisphere" asks for one.
double GammaSpan(const std::string& slab_path, const std::string& range) {
  if (range == "sphere") return 180;
  if (range == "hemisphere") return 90;
  return IsLuminaireFolder(slab_path) && LoadLuminaireSet(slab_path).coverage == "sphere" ? 180
                                                                                          : 90;
}

// The whole slab: a partial one would leave out the light of its missing positions. Its total
// light is checked into `checks` (a log of the dataset holding the slab, SlabChecks). A
// luminaire folder: LoadLuminaireSlab.
Slab LoadCompleteSlab(const std::string& path, int threads, CheckLog& checks,
                      const std::string& stage) {
  if (IsLuminaireFolder(path)) return LoadLuminaireSlab(path, threads, stage);
  Slab slab;
  slab.dir = ResolveSlabDir(path);
  slab.info = SlabInfo::Load(slab.dir);
  RequireCompleteSlab(slab.info, slab.dir);
  slab.positions = ReadSlabPositions(slab.dir, slab.info, threads);
  LogInfo("slab ", slab.dir, ": ", slab.info.grid.nu, " x ", slab.info.grid.nv, " positions, h ",
          slab.info.grid.spacing_mm, " mm, d ", slab.info.distance_mm, " mm, ",
          slab.info.layout.res_x, " x ", slab.info.layout.res_y, " texels, units ",
          slab.info.units);
  CheckSlabLight(slab.info, slab.positions, slab.dir, checks);
  return slab;
}

// The checks of `stage` on the slab at `path` (a dataset folder or its slab/), recorded in the
// dataset's checks.json when the slab is in one.
CheckLog SlabChecks(const std::string& path, const std::string& stage) {
  if (IsLuminaireFolder(path)) return CheckLog("", stage);  // each orientation's, when loaded
  return CheckLog(DatasetOfSlab(ResolveSlabDir(path)), stage);
}

// cd / lm for a slab scaled with a lux meter, W/sr / W otherwise (relative: a warning). A lux
// slab whose luminance is the Rec. 709 mix of camera RGB (no colour calibration) is a warning,
// not a refusal: the lux reading fixes the absolute level at the meter's position, so the
// mismatch of the camera's channels with V(lambda) matters only where the light's spectrum
// differs from the spectrum there (docs/method.md §3.7).
bool Photometric(const SlabInfo& info) {
  if (info.units == "relative")
    LogWarning(
        "the slab is in relative units (no radiometric scale): the values written are "
        "relative, labelled W/sr (W)");
  if (info.units == "lux" && !info.channel_weights_from_colour)
    LogWarning(
        "the luminance is the Rec. 709 mix of the camera's RGB, scaled to the lux meter's reading "
        "(calib/scale.json had no colour calibration): exact only when the light's spectrum is "
        "the same in every direction; lumislab-calibrate colour (a ColorChecker photo) gives the "
        "camera's own luminance, then calibrate scale and reconstruct again");
  return info.units == "lux";
}

// ---- keywords: flags over a metadata file -------------------------------------------------

struct Keywords {
  std::string metadata;  // JSON file
  // IES keyword -> value from a flag (empty: not given).
  std::map<std::string, std::string> flags;
};

// The metadata file (schema 1): optional strings test, testlab, issuedate, manufac, lumcat,
// luminaire, lamp, and `keywords`, an object of further IES keywords (upper case) to strings.
std::vector<std::pair<std::string, std::string>> ResolveKeywords(const Keywords& k) {
  static const std::pair<const char*, const char*> kFields[] = {
      {"test", "TEST"},       {"testlab", "TESTLAB"}, {"issuedate", "ISSUEDATE"},
      {"manufac", "MANUFAC"}, {"lumcat", "LUMCAT"},   {"luminaire", "LUMINAIRE"},
      {"lamp", "LAMP"}};
  std::vector<std::pair<std::string, std::string>> out;
  std::map<std::string, std::string> from_file;
  std::vector<std::pair<std::string, std::string>> extra;
  if (!k.metadata.empty()) {
    const JsonDocument doc = JsonDocument::Load(k.metadata);
    doc.CheckSchemaVersion(kMetadataSchemaVersion);
    const JsonView root = doc.root();
    for (const std::string& key : root.Keys()) {
      if (key == "schema_version") continue;
      if (key == "keywords") {
        for (const std::string& name : root[key].Keys()) {
          bool valid = !name.empty();
          for (char ch : name)
            valid = valid && (std::isupper(static_cast<unsigned char>(ch)) ||
                              std::isdigit(static_cast<unsigned char>(ch)) || ch == '_');
          if (!valid) root[key][name].Fail("a keyword name of A-Z, 0-9 and _");
          // What lumislab states itself (coverage, uncertainty, asymmetry, provenance) and the
          // keywords with their own members: a second line of one would contradict the first,
          // and `info` would read either.
          static const char* const kReserved[] = {
              "_COVERAGE", "_UNCERTAINTY", "_ASYMMETRY", "FILEGENINFO", "TEST", "TESTLAB",
              "ISSUEDATE", "MANUFAC",      "LUMCAT",     "LUMINAIRE",   "LAMP", "MORE"};
          for (const char* reserved : kReserved)
            if (name == reserved)
              root[key][name].Fail("a keyword lumislab does not write itself (" + name +
                                   (name[0] == '_' || name == "FILEGENINFO" || name == "MORE"
                                        ? " is lumislab's statement"
                                        : " has its own member or flag") +
                                   ")");
          extra.push_back({name, root[key][name].String()});
        }
        continue;
      }
      bool known = false;
      for (const auto& [field, keyword] : kFields)
        if (key == field) {
          from_file[keyword] = root[key].String();
          known = true;
        }
      if (!known)
        root[key].Fail(
            "a known member (test, testlab, issuedate, manufac, lumcat, luminaire, "
            "lamp, keywords)");
    }
  }
  for (const auto& [field, keyword] : kFields) {
    std::string value = from_file.count(keyword) ? from_file[keyword] : "";
    const auto flag = k.flags.find(keyword);
    if (flag != k.flags.end() && !flag->second.empty()) value = flag->second;
    if (keyword == std::string("ISSUEDATE") && value.empty()) value = NowUtc("%Y-%m-%d");
    if (!value.empty()) out.push_back({keyword, value});
  }
  out.insert(out.end(), extra.begin(), extra.end());
  return out;
}

void AddKeywordOptions(CLI::App* cmd, Keywords* k) {
  cmd->add_option("--test", k->flags["TEST"], "[TEST]: the test (report) number");
  cmd->add_option("--lab", k->flags["TESTLAB"], "[TESTLAB]: the laboratory");
  cmd->add_option("--issue-date", k->flags["ISSUEDATE"], "[ISSUEDATE] (default: today, UTC)");
  cmd->add_option("--manufacturer", k->flags["MANUFAC"], "[MANUFAC]: the luminaire's maker");
  cmd->add_option("--catalog", k->flags["LUMCAT"], "[LUMCAT]: the catalogue number");
  cmd->add_option("--luminaire", k->flags["LUMINAIRE"], "[LUMINAIRE]: its description");
  cmd->add_option("--lamp", k->flags["LAMP"], "[LAMP]: the lamp / light source");
  cmd->add_option("--metadata", k->metadata,
                  "JSON (schema_version 1) with test, testlab, issuedate, manufac, lumcat, "
                  "luminaire, lamp and keywords {NAME: text}; flags win over it");
}

// ---- ies / ldt ------------------------------------------------------------------------------

struct FarFieldCommand {
  std::string format;  // "ies" or "ldt"
  std::string slab, out;
  double c_step = 5, gamma_step = 2.5;
  std::string gamma_range;  // "", "hemisphere" or "sphere" (GammaSpan)
  std::vector<double> c_angles, gamma_angles;
  int samples = 4;
  std::vector<double> opening_mm;
  bool force = false;
  bool allow_partial = false;
  double max_asymmetry_pct = 5;
  bool accredited = false, lumen_scaled = false;
  double input_watts = 0;
  UncertaintyOptions uncertainty;
  Keywords keywords;
};

// The largest direction grid written: 721 C planes (0.5 degree steps over [0, 360]) and 361
// gamma angles (0.5 degrees over [0, 180]; --gamma-step spans [0, 90], so 0.25 degrees there). The
// photometric files in circulation, goniophotometer measurements included, use 1 to 5 degrees
// (EULUMDAT's usual 24 or 36 C planes, IES files of 73 x 37); 0.5 degrees is already finer than
// that, the far field's memory and time grow with the count of directions (a 0.01 degree grid is
// 324 million of them), and a grid finer than the slab resolves adds nothing but file size.
constexpr int kMaxCPlanes = 721;
constexpr int kMaxGammaAngles = 361;

std::vector<double> Steps(double step, double last, const std::string& option, int max_count) {
  if (!(step > 0) || !(step <= last) || std::abs(last / step - std::round(last / step)) > 1e-9)
    throw BadInput(option + ": expected a step in (0, " + Num(last, 6) + "] that divides " +
                   Num(last, 6) + ", got " + Num(step, 8));
  if (last / step + 1 > max_count + 1e-6)
    throw BadInput(option + ": expected a step that gives at most " + std::to_string(max_count) +
                   " angles over [0, " + Num(last, 6) + "] (at least " +
                   Num(last / (max_count - 1), 6) + " degrees), got " + Num(step, 8) + " (" +
                   Num(std::round(last / step) + 1, 12) + " angles)");
  std::vector<double> v;
  const int n = int(std::round(last / step));
  for (int k = 0; k <= n; ++k) v.push_back(k * step);
  return v;
}

// The requested C/gamma grid, checked (kMaxCPlanes, kMaxGammaAngles) before any work: a
// distribution of zeros the far field fills in.
IntensityDistribution DirectionGrid(const FarFieldCommand& c) {
  IntensityDistribution d;
  d.c_deg = c.c_angles.empty() ? Steps(c.c_step, 360, "--c-step", kMaxCPlanes) : c.c_angles;
  d.gamma_deg = c.gamma_angles.empty() ? Steps(c.gamma_step, GammaSpan(c.slab, c.gamma_range),
                                               "--gamma-step", kMaxGammaAngles)
                                       : c.gamma_angles;
  if (d.c_deg.size() > size_t(kMaxCPlanes))
    throw BadInput("--c-angles: expected at most " + std::to_string(kMaxCPlanes) +
                   " C planes, got " + std::to_string(d.c_deg.size()));
  if (d.gamma_deg.size() > size_t(kMaxGammaAngles))
    throw BadInput("--gamma-angles: expected at most " + std::to_string(kMaxGammaAngles) +
                   " gamma angles, got " + std::to_string(d.gamma_deg.size()));
  d.values.assign(d.c_deg.size() * d.gamma_deg.size(), 0.0);
  d.Check(c.c_angles.empty() && c.gamma_angles.empty() ? "--c-step/--gamma-step"
                                                       : "--c-angles/--gamma-angles");
  return d;
}

// IES and EULUMDAT hold candela: only a slab scaled with a lux meter has them. Checked on
// slab.json alone, before the positions are read.
void RequireLuxSlab(const std::string& path, const std::string& format) {
  if (IsLuminaireFolder(path)) {  // every orientation's
    const LuminaireSet set = LoadLuminaireSet(path);
    for (size_t k = 0; k < set.orientations.size(); ++k)
      RequireLuxSlab(set.DatasetFolder(k), format);
    return;
  }
  const std::string dir = ResolveSlabDir(path);
  const SlabInfo info = SlabInfo::Load(dir);
  if (info.units == "lux") return;
  const std::string dataset = DatasetOfSlab(dir).empty() ? "<dataset>" : DatasetOfSlab(dir);
  throw InputError(dir + "/slab.json", "units",
                   "lux (" + format +
                       " holds candela and lumen: calibrate the scale with a lux meter reading, "
                       "lumislab-calibrate scale --dataset " +
                       dataset +
                       " --position i,j --point-mm x,y --reading-p LX --reading-n LX --unit lux, "
                       "then lumislab-reconstruct --dataset " +
                       dataset + " --force; lumislab-export tm25 writes radiometric rays)",
                   info.units);
}

// The far field on the grid of `d`. A symmetric subset of the C range (--c-angles 0..90,
// 0..180, 90..270 or one plane) is computed at every mirror image of each plane, so that the
// subset carries the whole luminaire's light, and written as their mean; the asymmetry is the
// flux-weighted mean absolute deviation of the images from that mean, relative to it:
// sum over cells of dOmega mean_k |I_k - I_mean| / sum over cells of dOmega I_mean.
struct GridFarField {
  FarField ff;            // on d's grid: values (the images' mean) and seen (every image seen)
  double asymmetry = -1;  // -1: not a subset
  size_t images = 1;      // mirror images per plane
};

std::vector<double> MirrorImages(double c, CSymmetry symmetry) {
  std::vector<double> images;
  switch (symmetry) {
    case CSymmetry::kQuadrant:
      images = {c, 180 - c, 180 + c, 360 - c};
      break;
    case CSymmetry::kC0C180:
      images = {c, 360 - c};
      break;
    case CSymmetry::kC90C270:
      images = {c, 180 - c};
      break;
    case CSymmetry::kAxial:  // rotational symmetry: 24 planes 15 degrees apart
      for (int k = 0; k < 24; ++k) images.push_back(c + 15 * k);
      break;
    case CSymmetry::kNone:
      images = {c};
      break;
  }
  std::vector<double> distinct;  // in [0, 360), each once
  for (double x : images) {
    x = std::fmod(std::fmod(x, 360.0) + 360.0, 360.0);
    if (x > 360 - 1e-9) x = 0;
    bool seen = false;
    for (double y : distinct) seen = seen || std::abs(x - y) < 1e-9;
    if (!seen) distinct.push_back(x);
  }
  return distinct;
}

GridFarField ComputeGridFarField(const IntensityDistribution& d, const Slab& slab,
                                 const FarFieldOptions& options, CheckLog& checks) {
  GridFarField out;
  const CSymmetry symmetry = d.Symmetry();
  if (symmetry == CSymmetry::kNone) {
    out.ff = SlabFarField(slab, d.c_deg, d.gamma_deg, options, checks);
    return out;
  }
  std::vector<std::vector<double>> images(d.c_deg.size());
  std::vector<double> all;
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic) {
    images[ic] = MirrorImages(d.c_deg[ic], symmetry);
    all.insert(all.end(), images[ic].begin(), images[ic].end());
  }
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end(),
                        [](double a, double b) { return std::abs(a - b) < 1e-9; }),
            all.end());
  const FarField full = SlabFarField(slab, all, d.gamma_deg, options, checks);
  const size_t ng = d.gamma_deg.size();
  out.ff.c_deg = d.c_deg;
  out.ff.gamma_deg = d.gamma_deg;
  out.ff.values.assign(d.values.size(), 0.0);
  out.ff.seen.assign(d.values.size(), 1);
  IntensityDistribution deviation = d, mean = d;
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic) {
    std::vector<size_t> at;
    for (double x : images[ic])
      at.push_back(size_t(std::lower_bound(all.begin(), all.end(), x - 1e-9) - all.begin()));
    out.images = std::max(out.images, at.size());
    for (size_t ig = 0; ig < ng; ++ig) {
      double sum = 0;
      bool seen = true;
      for (size_t k : at) {
        sum += std::max(0.0, full.values[k * ng + ig]);
        seen = seen && full.seen[k * ng + ig];
      }
      const double m = sum / at.size();
      double dev = 0;
      for (size_t k : at) dev += std::abs(std::max(0.0, full.values[k * ng + ig]) - m);
      out.ff.values[ic * ng + ig] = m;
      out.ff.seen[ic * ng + ig] = seen;
      out.ff.unseen += !seen;
      mean.values[ic * ng + ig] = m;
      deviation.values[ic * ng + ig] = dev / at.size();
    }
  }
  const double flux = mean.TotalFlux();
  out.asymmetry = flux > 0 ? deviation.TotalFlux() / flux : 0;
  return out;
}

// A file's cells against a fine far field: its zonal flux sums each grid value over the cell
// around it (halfway to the neighbours), so a grid point the capture saw can stand for a cell
// reaching beyond the seen cone (a gamma grid of 0 and 180 has one cell over 0-90), and a grid
// too coarse for the light gives a flux unlike the light's.
struct CellCheck {
  Coverage fine;  // the coverage of C 0-355 (5 degrees) x the grid's gamma span (fine steps)
  double fine_step_deg = 0;
  double file_flux = 0, fine_flux = 0;  // zonal sums, unseen directions as 0
  double flux_deviation = 0;            // |file - fine| / fine
};
// On the demo's slab the file's flux on the default 5 x 2.5 degree grid is 0.73 % from the fine
// far field's, gamma 0-35 in 5 degree steps 0.21 %, 10-30 in 10 degree steps 1.1 %; gamma 0 and
// 180 is 692 % off, 0 and 90 132 %, 0, 45 and 90 27 %, 0 and 35 16 %.
constexpr double kMaxCellFluxDeviation = 0.03;
// A grid whose every point was seen but whose cells reach beyond the cone: the model's share of
// the flux there (gamma 0-35 in 5 degree steps on the demo: 0 %).
constexpr double kMaxCellUnseenShare = 0.001;

CellCheck CheckCells(const IntensityDistribution& d, const Slab& slab,
                     const FarFieldOptions& options) {
  CheckLog unrecorded("", "");  // the grid's far field was checked
  CellCheck out;
  IntensityDistribution fine;
  for (int k = 0; k < 72; ++k) fine.c_deg.push_back(5.0 * k);
  const double lo = d.gamma_deg.front(), hi = d.gamma_deg.back();
  const int n = hi > lo ? int(std::ceil((hi - lo) / 0.5)) : 0;
  out.fine_step_deg = n > 0 ? (hi - lo) / n : 0;
  for (int k = 0; k <= n; ++k) fine.gamma_deg.push_back(k == n ? hi : lo + k * out.fine_step_deg);
  const FarField ff =
      slab.luminaire
          ? SlabFarField(slab, fine.c_deg, fine.gamma_deg, options, unrecorded, false)
          : ComputeFarField(slab.info, slab.positions, fine.c_deg, fine.gamma_deg, options);
  fine.values = ff.values;
  for (double& v : fine.values) v = std::max(v, 0.0);
  out.fine = SlabCoverage(fine, ff, slab);
  out.file_flux = d.TotalFlux();
  out.fine_flux = fine.TotalFlux();
  out.flux_deviation = out.fine_flux > 0   ? std::abs(out.file_flux - out.fine_flux) / out.fine_flux
                       : out.file_flux > 0 ? 1.0
                                           : 0.0;
  return out;
}

// The far field of the slab on the requested grid, with the file's keywords: the distribution
// the writers take. Refuses (exit 2) a grid the capture did not see where a model of the
// luminaire has light, unless --allow-partial, and a symmetric subset of a luminaire more
// asymmetric than --max-asymmetry.
IntensityDistribution SlabDistribution(const FarFieldCommand& c, const Slab& slab, int threads,
                                       CheckLog& checks, bool* simulation) {
  IntensityDistribution d = DirectionGrid(c);
  FarFieldOptions options;
  options.samples = c.samples;
  options.threads = threads;
  const GridFarField grid = ComputeGridFarField(d, slab, options, checks);
  d.values = grid.ff.values;
  for (double& v : d.values) v = std::max(v, 0.0);  // ringing of the fit: no negative intensity
  d.photometric = Photometric(slab.info);
  d.input_watts = c.input_watts;
  const SamplingGrid& g = slab.info.grid;
  if (c.opening_mm.size() == 3) {
    d.opening = {c.opening_mm[0], c.opening_mm[1], c.opening_mm[2]};
  } else {  // the basis supports' extent on S: the largest opening the slab represents
    d.opening = {(g.nv + 1) * g.spacing_mm, (g.nu + 1) * g.spacing_mm, 0.0};
  }
  const char* unit = d.photometric ? " lm" : " W";
  Coverage coverage = SlabCoverage(d, grid.ff, slab);
  if (coverage.unseen == coverage.directions)
    throw BadInput(c.out + ": the capture saw none of the grid's " +
                   std::to_string(coverage.directions) +
                   " directions: the file would hold only zeros (--gamma-angles within the seen "
                   "cone, gamma from 0)");
  const CellCheck cells = CheckCells(d, slab, options);
  LogInfo("far field: the grid's cells against a fine far field (C every 5 deg, gamma every ",
          Num(cells.fine_step_deg, 3), " deg): file flux ", Num(cells.file_flux, 6), unit,
          ", fine ", Num(cells.fine_flux, 6), unit, " (", Num(100 * cells.flux_deviation, 3),
          " %); the model's share in unseen directions within the cells ",
          Num(100 * cells.fine.model_unseen_share, 3), " %");
  if (cells.flux_deviation > kMaxCellFluxDeviation)
    throw BadInput(
        "--c-angles/--gamma-angles: the grid is too coarse for this light: the "
        "file's zonal flux " +
        Num(cells.file_flux, 6) + unit + " differs by " + Num(100 * cells.flux_deviation, 3) +
        " % from the far field's on a fine grid over the same angles, " + Num(cells.fine_flux, 6) +
        unit + " (at most " + Num(100 * kMaxCellFluxDeviation, 2) + " %): give finer angles");
  if (!coverage.Partial() && cells.fine.Partial() &&
      cells.fine.model_unseen_share > kMaxCellUnseenShare) {
    // Every grid point seen, but cells reach beyond the cone: state the fine grid's coverage.
    coverage.model_unseen_share = cells.fine.model_unseen_share;
    coverage.cells_beyond_cone = true;
    coverage.seen_gamma_max_deg = cells.fine.seen_gamma_max_deg;
    coverage.c_deg = cells.fine.c_deg;
  }
  // 683 lm/W is the most any light can give (monochromatic 555 nm): more from --input-watts is a
  // typo in the watts, not a luminaire. Partial coverage only lowers the file's flux.
  if (d.photometric && c.input_watts > 0 && d.TotalFlux() / c.input_watts > 683)
    throw BadInput("--input-watts: expected the luminaire's input power, got " +
                   Num(c.input_watts, 6) + " W, which would make its efficacy " +
                   Num(d.TotalFlux() / c.input_watts, 4) +
                   " lm/W (above 683 lm/W, the most "
                   "light can give)");
  *simulation = Synthetic(slab);
  LogInfo("far field: ", d.c_deg.size(), " C planes x ", d.gamma_deg.size(), " gamma angles, flux ",
          Num(d.TotalFlux(), 6), unit, " over the seen directions; ", coverage.SeenCone(), "; ",
          coverage.unseen, " of ", coverage.directions, " grid directions not seen; ",
          coverage.analytic ? "the analytic luminaire emits " : "a Lambertian model emits ",
          Num(coverage.model_flux, 6), unit, ", ", Num(100 * coverage.model_unseen_share, 3),
          " % of it in the unseen directions");
  if (coverage.Partial() && !c.allow_partial)
    throw BadInput(c.out +
                   ": the capture did not see every direction of the grid: " + coverage.Text() +
                   ". The file would carry 0 there (--allow-partial writes it with the coverage "
                   "stated; --gamma-angles can keep the grid within the seen cone)");
  d.keywords = ResolveKeywords(c.keywords);
  const std::string coverage_text =
      coverage.Partial() ? coverage.Text()
      : coverage.unseen > 0
          ? "complete where the model has light: " + std::to_string(coverage.unseen) +
                " grid directions not seen (written as 0), where " + coverage.model +
                " puts no flux"
          : "complete: every grid direction seen";
  if (c.format == "ies") {
    d.keywords.push_back({"_COVERAGE", coverage_text});
  } else if (coverage.Partial()) {
    // EULUMDAT has no keywords: the coverage goes into the measurement report field (line 8)
    // after the report number, where every reader shows it ("T-1; partial: ...").
    // The field holds 78 bytes: a coverage statement cut short would misstate it.
    constexpr size_t kLdtField = 78;
    bool found = false;
    for (auto& [key, value] : d.keywords)
      if (key == "TEST") {
        const std::string text = value + "; " + coverage.Short();
        if (text.size() > kLdtField)
          throw BadInput("--test: expected at most " +
                         std::to_string(kLdtField - 2 - coverage.Short().size()) +
                         " bytes for an EULUMDAT file with partial coverage (the measurement "
                         "report field holds " +
                         std::to_string(kLdtField) + " bytes and must keep '" + coverage.Short() +
                         "'), got " + std::to_string(value.size()));
        value = text;
        found = true;
      }
    if (!found) d.keywords.push_back({"TEST", coverage.Short()});
  }
  if (coverage.Partial()) LogWarning(c.out, ": written with partial coverage: ", coverage.Text());
  if (grid.asymmetry >= 0) {
    const std::string text = std::string(CSymmetryName(d.Symmetry())) +
                             " subset: each plane the mean of its " + std::to_string(grid.images) +
                             " mirror images; asymmetry " + Num(100 * grid.asymmetry, 3) +
                             " % (flux-weighted mean |I - mean| / mean over the images), at most " +
                             Num(c.max_asymmetry_pct, 4) + " % allowed";
    LogInfo("far field: ", text);
    if (100 * grid.asymmetry > c.max_asymmetry_pct)
      throw BadInput("--c-angles: expected a luminaire symmetric within " +
                     Num(c.max_asymmetry_pct, 4) + " % for the " + CSymmetryName(d.Symmetry()) +
                     " subset, got an asymmetry of " + Num(100 * grid.asymmetry, 3) +
                     " % (flux-weighted mean |I - mean| / mean over the mirror images; write "
                     "the full C range 0-360, or raise --max-asymmetry)");
    if (c.format == "ies") d.keywords.push_back({"_ASYMMETRY", text});
  }
  // The stated uncertainty (export/report_uncertainty.h, as the report states it): IES as
  // [_UNCERTAINTY]; EULUMDAT, without keywords, in the measurement report field (line 8) after
  // the report number and coverage when the field's 78 bytes hold it.
  const FarFieldUncertainty u = SlabUncertainty(slab, c.samples, c.uncertainty);
  std::string uncertainty_text = UncertaintyKeyword(u);
  if (slab.luminaire)
    uncertainty_text += "; the largest of the " + std::to_string(slab.luminaire->slabs.size()) +
                        " orientations' (the registration's and the blend's not included)";
  LogInfo("uncertainty: ", uncertainty_text);
  if (c.format == "ies") {
    d.keywords.push_back({"_UNCERTAINTY", uncertainty_text});
  } else {
    const std::string text = "U(k=2) flux " + Num(100 * u.FluxExpanded(), 2) + " %, peak " +
                             Num(100 * u.PeakExpanded(), 2) + " %";
    auto test = std::find_if(d.keywords.begin(), d.keywords.end(),
                             [](const auto& k) { return k.first == "TEST"; });
    if (test == d.keywords.end()) {
      d.keywords.push_back({"TEST", text});
    } else if (test->second.size() + 2 + text.size() <= 78) {
      test->second += "; " + text;
    } else {
      LogWarning(c.out, ": the uncertainty (", text,
                 ") does not fit the measurement report field after '", test->second,
                 "' (78 bytes): the EULUMDAT file leaves it out (the IES file and the report "
                 "carry it)");
    }
  }
  // Where the file comes from, without the folder's absolute path (a file is handed on).
  std::filesystem::path folder = std::filesystem::absolute(slab.dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();
  if (folder.filename() == "slab") folder = folder.parent_path();  // a dataset's slab/
  const std::string name = folder.filename().string();
  std::ostringstream note;
  if (slab.luminaire)
    note << "lumislab-export " << c.format << " from the merged light field of " << name << ": "
         << slab.luminaire->Orientations() << "; the first's slab " << g.nu << " x " << g.nv
         << " positions, h " << g.spacing_mm << " mm, d " << slab.info.distance_mm << " mm";
  else
    note << "lumislab-export " << c.format << " from the light slab of " << name << " (" << g.nu
         << " x " << g.nv << " positions, h " << g.spacing_mm << " mm, d " << slab.info.distance_mm
         << " mm)";
  d.keywords.push_back({"FILEGENINFO", note.str()});
  return d;
}

int RunFarField(const FarFieldCommand& c, int threads) {
  LogInfo("parameters: slab=", c.slab, " out=", c.out, " c_step=", c.c_step,
          " gamma_step=", c.gamma_step, " c_angles=", c.c_angles.size(),
          " gamma_angles=", c.gamma_angles.size(), " samples=", c.samples,
          " metadata=", c.keywords.metadata, " force=", c.force ? "yes" : "no",
          " allow_partial=", c.allow_partial ? "yes" : "no", " max_asymmetry=", c.max_asymmetry_pct,
          " accredited=", c.accredited ? "yes" : "no",
          " lumen_scaled=", c.lumen_scaled ? "yes" : "no", " input_watts=", c.input_watts);
  CheckExportOutput(c.out, c.force);
  DirectionGrid(c);              // refuses a bad grid before the slab is read, and bad keywords
  if (c.opening_mm.size() == 3)  // one shape IES and EULUMDAT both hold
    CheckPortableOpening({c.opening_mm[0], c.opening_mm[1], c.opening_mm[2]}, "--opening-mm", "");
  const auto keywords = ResolveKeywords(c.keywords);
  if (c.format == "ies") CheckIesRequiredKeywords(keywords, c.out);
  RequireLuxSlab(c.slab, c.format == "ies" ? "IES" : "EULUMDAT");
  CheckLog checks = SlabChecks(c.slab, "export " + c.format);
  const Slab slab = LoadCompleteSlab(c.slab, threads, checks, "export " + c.format);
  bool simulation = false;
  const IntensityDistribution d = SlabDistribution(c, slab, threads, checks, &simulation);
  checks.Save();
  if (c.format == "ies") {
    // The far field is computed from the slab on the requested grid, not measured at those
    // angles: LM-63-2019's "interpolated angle set". A synthetic dataset's slab is a computer
    // simulation, whatever the flags say.
    FileGenerationType type;
    type.simulation = simulation;
    type.accredited = c.accredited;
    type.interpolated = true;
    type.lumen_scaled = c.lumen_scaled;
    if (simulation && (c.accredited || c.lumen_scaled))
      LogWarning("a synthetic dataset: file generation type 1.00010 (computer simulation); ",
                 "--accredited and --lumen-scaled do not apply");
    IesWriteOptions options;
    options.file_generation_type = type.Code();
    LogInfo("file generation type ", options.file_generation_type, ": ",
            FileGenerationTypeName(options.file_generation_type));
    WriteIes(d, c.out, options);
  } else {
    WriteEulumdat(d, c.out);
  }
  std::printf("%s: %s\n", c.format.c_str(), c.out.c_str());
  return 0;
}

CLI::App* AddFarFieldCommand(CLI::App& app, const std::string& format, FarFieldCommand* c,
                             CommonOptions* common) {
  c->format = format;
  CLI::App* cmd = app.add_subcommand(
      format, format == "ies" ? "the slab's far-field intensity as an IES LM-63-2019 file (a "
                                "slab in lux: candela)"
                              : "the slab's far-field intensity as an EULUMDAT file (a slab in "
                                "lux: candela)");
  cmd->add_option("--slab", c->slab,
                  "dataset folder, its slab/, or a luminaire folder (the merged light field of "
                  "its orientations, docs/formats.md §19)")
      ->required();
  cmd->add_option("--out", c->out, "file to write")->required();
  cmd->add_option("--c-step", c->c_step, "degrees between C planes, 0-360")->capture_default_str();
  cmd->add_option("--gamma-step", c->gamma_step,
                  "degrees between gamma angles, 0-90 (0-180 with --gamma-range sphere)")
      ->capture_default_str();
  cmd->add_option("--gamma-range", c->gamma_range,
                  "hemisphere (gamma 0-90) or sphere (0-180) for --gamma-step (default: sphere "
                  "for a luminaire folder measured over the sphere, else hemisphere)")
      ->check(CLI::IsMember({"hemisphere", "sphere"}));
  cmd->add_option("--c-angles", c->c_angles,
                  "explicit C planes (degrees, comma separated); a symmetric range (0..90, "
                  "0..180, 90..270, one plane) is the mean of each plane's mirror images")
      ->delimiter(',');
  cmd->add_option("--gamma-angles", c->gamma_angles, "explicit gamma angles (degrees)")
      ->delimiter(',');
  cmd->add_option("--samples", c->samples, "N x N quadrature points per position on S")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  cmd->add_option("--opening-mm", c->opening_mm,
                  "luminous opening width,length,height in mm (default: the grid's extent)")
      ->check(FiniteIn(-1e6, 1e6))
      ->delimiter(',')
      ->expected(3);
  cmd->add_flag("--force", c->force, "rewrite the output if it exists (else exit 2)");
  cmd->add_flag("--allow-partial", c->allow_partial,
                "write a grid the capture did not wholly see (0 there), with the coverage "
                "stated in the file" +
                    std::string(format == "ies" ? " ([_COVERAGE])"
                                                : " (the measurement report field, line 8)"));
  cmd->add_option("--max-asymmetry", c->max_asymmetry_pct,
                  "a symmetric --c-angles subset: the largest asymmetry (percent, flux-weighted "
                  "mean |I - mean| / mean over the mirror images) written")
      ->check(FiniteIn(0, 100))
      ->capture_default_str();
  cmd->add_option("--input-watts", c->input_watts,
                  "the luminaire's input power, W (IES line 12, EULUMDAT's lamp wattage; gives "
                  "the efficacy)")
      ->check(FiniteIn(0, 1e7));
  if (format == "ies") {
    cmd->add_flag("--accredited", c->accredited,
                  "the lab is accredited for this test (file generation type 1.1xxxx)");
    cmd->add_flag("--lumen-scaled", c->lumen_scaled,
                  "the candela were scaled to another lumen rating (file generation type "
                  "1.xx1xx)");
  }
  AddUncertaintyOptions(cmd, &c->uncertainty);
  AddKeywordOptions(cmd, &c->keywords);
  AddCommonOptions(cmd, common);
  return cmd;
}

// ---- tm25 -----------------------------------------------------------------------------------

struct RayCommand {
  std::string slab, out;
  int64_t rays = 100000;
  uint64_t seed = 0;
  std::string name, manufacturer;
  bool force = false;
  bool allow_partial = false;
};

// What the rays cover: they leave S through the window, so only the cone the screen saw. The
// far field on a 5 x 2.5 degree grid over the hemisphere says which cone, and a model what
// share of the luminaire's flux falls outside it (GridCoverage).
Coverage RayCoverage(const Slab& slab, int threads, CheckLog& checks) {
  IntensityDistribution d;
  d.c_deg = Steps(5, 355, "C", kMaxCPlanes);
  d.gamma_deg = Steps(2.5, GammaSpan(slab.dir, ""), "gamma", kMaxGammaAngles);
  d.values.assign(d.c_deg.size() * d.gamma_deg.size(), 0.0);
  FarFieldOptions options;
  options.samples = 2;
  options.threads = threads;
  const FarField ff = SlabFarField(slab, d.c_deg, d.gamma_deg, options, checks);
  return SlabCoverage(d, ff, slab);
}

// A luminaire folder's rays (SampleMergedRays): every orientation's, turned into the luminaire
// frame and thinned by the blend, each ray with its slab's flux per ray.
int WriteMergedRays(const RayCommand& c, const Slab& slab, const Coverage& coverage,
                    const std::string& cone, int threads) {
  const LuminaireSource& lum = *slab.luminaire;
  const MergedRays merged = SampleMergedRays(lum.slabs, c.rays, c.seed, threads);
  Tm25RaySet set;
  set.photometric = Photometric(slab.info);
  const double nan = std::nan("");
  set.luminous_flux_lm = set.photometric ? merged.rays.total_flux : nan;
  set.radiant_flux_w = set.photometric ? nan : merged.rays.total_flux;
  set.date_time = NowUtc("%Y-%m-%dT%H:%M:%SZ");
  set.name = c.name;
  set.manufacturer = c.manufacturer;
  set.rayfile_creator = "lumislab-export tm25";
  set.equipment = "lumislab light slabs of a luminaire folder: " + lum.Orientations();
  set.additional_info =
      "rays drawn from each orientation's light field, seed " + std::to_string(c.seed) +
      ", turned into the luminaire frame and kept with the orientation's blend weight; origins "
      "on each orientation's sampling plane (mm, luminaire frame); coverage: " +
      (coverage.Partial() ? "partial: " : "complete: ") + cone;
  set.creation_method = Synthetic(slab) ? 0 : 1;
  set.rays.reserve(merged.rays.rays.size());
  for (size_t k = 0; k < merged.rays.rays.size(); ++k) {
    const SlabRay& r = merged.rays.rays[k];
    set.rays.push_back({float(r.origin_mm.x()), float(r.origin_mm.y()), float(r.origin_mm.z()),
                        float(r.direction.x()), float(r.direction.y()), float(r.direction.z()),
                        merged.ray_flux[k]});
  }
  const char* unit = set.photometric ? " lm" : " W";
  for (size_t k = 0; k < lum.slabs.size(); ++k)
    LogInfo("rays of ", lum.slabs[k].name, ": ", merged.drawn[k], " drawn of ",
            Num(merged.slab_flux[k], 6), unit, ", ", merged.kept[k], " kept (the blend keeps ",
            Num(100 * merged.kept_share[k], 3), " % of its flux)");
  LogInfo(merged.rays.rays.size(), " rays, total ", Num(merged.rays.total_flux, 6), unit);
  // Thinning by the blend keeps each ray with its weight: the kept sum estimates the blended
  // flux with a sampling error that few rays make large.
  double expected = 0;
  for (size_t k = 0; k < lum.slabs.size(); ++k)
    expected += merged.slab_flux[k] * merged.kept_share[k];
  const double off = expected > 0 ? merged.rays.total_flux / expected - 1 : 0;
  if (std::abs(off) > 0.01)
    LogWarning("the rays carry ", Num(100 * off, 3), " % of the blended flux (", Num(expected, 6),
               unit, "): the blend's thinning of ", c.rays,
               " rays leaves that sampling error; give more --rays");
  WriteTm25(set, c.out);
  std::printf("tm25: %s\n", c.out.c_str());
  return 0;
}

int RunRays(const RayCommand& c, int threads) {
  LogInfo("parameters: slab=", c.slab, " out=", c.out, " rays=", c.rays, " seed=", c.seed,
          " force=", c.force ? "yes" : "no", " allow_partial=", c.allow_partial ? "yes" : "no");
  CheckExportOutput(c.out, c.force);
  CheckLog checks = SlabChecks(c.slab, "export tm25");
  const Slab slab = LoadCompleteSlab(c.slab, threads, checks, "export tm25");
  const Coverage coverage = RayCoverage(slab, threads, checks);
  checks.Save();
  const std::string cone =
      (slab.luminaire ? "rays only in the directions some orientation saw: "
                      : "rays only in the cone the screen saw: ") +
      coverage.SeenCone() + " (5 x 2.5 degree grid); outside it " +
      (coverage.analytic ? "the analytic luminaire puts " : "the model puts ") +
      Num(100 * coverage.model_unseen_share, 3) + " % of its flux (" + coverage.model + ")";
  LogInfo("coverage: ", cone);
  if (coverage.Partial() && !c.allow_partial)
    throw BadInput(c.out + ": the rays would miss light the capture did not see: " + cone +
                   " (--allow-partial writes them with the cone stated in additional_info)");
  if (slab.luminaire) return WriteMergedRays(c, slab, coverage, cone, threads);
  const SlabRays drawn = SampleSlabRays(slab.info, slab.positions, c.rays, c.seed, threads);
  Tm25RaySet set;
  set.photometric = Photometric(slab.info);
  const double nan = std::nan("");
  set.luminous_flux_lm = set.photometric ? drawn.total_flux : nan;
  set.radiant_flux_w = set.photometric ? nan : drawn.total_flux;
  set.date_time = NowUtc("%Y-%m-%dT%H:%M:%SZ");
  set.name = c.name;
  set.manufacturer = c.manufacturer;
  set.rayfile_creator = "lumislab-export tm25";
  set.equipment = "lumislab light slab: " + std::to_string(slab.info.grid.nu) + " x " +
                  std::to_string(slab.info.grid.nv) + " positions, h " +
                  Num(slab.info.grid.spacing_mm, 6) + " mm, d " + Num(slab.info.distance_mm, 6) +
                  " mm";
  set.additional_info = "rays drawn from the slab's light field, seed " + std::to_string(c.seed) +
                        "; origins on the sampling plane z = 0 (mm, luminaire frame); coverage: " +
                        (coverage.Partial() ? "partial: " : "complete: ") + cone;
  set.creation_method = Synthetic(slab) ? 0 : 1;  // simulated (synthetic) or measured
  set.rays.reserve(drawn.rays.size());
  for (const SlabRay& r : drawn.rays)
    set.rays.push_back({float(r.origin_mm.x()), float(r.origin_mm.y()), float(r.origin_mm.z()),
                        float(r.direction.x()), float(r.direction.y()), float(r.direction.z()),
                        float(drawn.flux_per_ray)});
  const char* unit = set.photometric ? " lm" : " W";
  LogInfo(c.rays, " rays of ", Num(drawn.flux_per_ray, 6), unit, ", total ",
          Num(drawn.total_flux, 6), unit,
          "; the light field's negative part cancelled: ", Num(drawn.moved_flux, 4), unit,
          " within texels over ", Num(drawn.moved_mean_mm, 3), " mm on S on average (at most ",
          Num(drawn.moved_max_mm, 3), " mm; ", Num(drawn.uncentred_flux, 4), unit,
          " of it with the centroid not kept), ", Num(drawn.texel_moved_flux, 4), unit,
          " between texels over ", Num(drawn.texel_moved_mean_mm, 4), " mm on M on average");
  WriteTm25(set, c.out);
  std::printf("tm25: %s\n", c.out.c_str());
  return 0;
}

CLI::App* AddRayCommand(CLI::App& app, RayCommand* c, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand(
      "tm25", "rays drawn from the slab's light field as an ANSI/IES TM-25 ray file");
  cmd->add_option("--slab", c->slab,
                  "dataset folder, its slab/, or a luminaire folder (every orientation's rays, "
                  "turned into the luminaire frame and thinned by the blend)")
      ->required();
  cmd->add_option("--out", c->out, "ray file to write")->required();
  cmd->add_option("--rays", c->rays, "number of rays")
      ->check(CLI::Range(int64_t(1), kMaxRays))
      ->capture_default_str();
  // CLI11 converts "-1" to 2^64 - 1 for an unsigned option, silently: refused by name.
  cmd->add_option("--seed", c->seed, "random seed")
      ->check(CLI::Validator(
          [](const std::string& s) {
            return s.find('-') == std::string::npos ? std::string()
                                                    : "expected an integer >= 0, got " + s;
          },
          "INT >= 0"))
      ->capture_default_str();
  cmd->add_option("--name", c->name, "name of the light source (header)");
  cmd->add_option("--manufacturer", c->manufacturer, "its manufacturer (header)");
  cmd->add_flag("--force", c->force, "rewrite the output if it exists (else exit 2)");
  cmd->add_flag("--allow-partial", c->allow_partial,
                "write rays although the capture saw only a cone of the luminaire's light (the "
                "cone stated in additional_info)");
  AddCommonOptions(cmd, common);
  return cmd;
}

// ---- info -----------------------------------------------------------------------------------

struct InfoCommand {
  std::string file;
  bool json = false;
};

int RunInfo(const InfoCommand& c) {
  if (IsLuminaireFolder(c.file)) {
    std::fputs(LuminaireFolderInfo(c.file, c.json).c_str(), stdout);
    return 0;
  }
  // A luminaire folder's own luminaire.json names the folder (not an EULUMDAT file).
  const std::filesystem::path given(c.file);
  if (given.filename() == "luminaire.json") {
    const std::string folder = given.has_parent_path() ? given.parent_path().string() : ".";
    if (IsLuminaireFolder(folder)) {
      std::fputs(LuminaireFolderInfo(folder, c.json).c_str(), stdout);
      return 0;
    }
  }
  std::fputs(FormatPhotometricFileInfo(PhotometricFileInfo(c.file), c.json).c_str(), stdout);
  return 0;
}

CLI::App* AddInfoCommand(CLI::App& app, InfoCommand* c, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand(
      "info",
      "what an IES, EULUMDAT or TM-25 file holds: format, angle grid or rays, flux; of a "
      "luminaire folder: its orientations, registration and coverage");
  cmd->add_option("file", c->file, "the file, or a luminaire folder")->required();
  cmd->add_flag("--json", c->json, "print it as JSON (with a flux field)");
  AddCommonOptions(cmd, common);
  return cmd;
}

}  // namespace

ParsedCommand AddFormatCommands(CLI::App& app, CommonOptions* common) {
  // Owned by the returned function, which outlives the parse.
  auto info = std::make_shared<InfoCommand>();
  auto ies = std::make_shared<FarFieldCommand>();
  auto ldt = std::make_shared<FarFieldCommand>();
  auto tm25 = std::make_shared<RayCommand>();
  CLI::App* info_cmd = AddInfoCommand(app, info.get(), common);
  CLI::App* ies_cmd = AddFarFieldCommand(app, "ies", ies.get(), common);
  CLI::App* ldt_cmd = AddFarFieldCommand(app, "ldt", ldt.get(), common);
  CLI::App* tm25_cmd = AddRayCommand(app, tm25.get(), common);
  return [=](int threads) -> std::optional<int> {
    if (info_cmd->parsed()) return RunInfo(*info);
    if (ies_cmd->parsed()) return RunFarField(*ies, threads);
    if (ldt_cmd->parsed()) return RunFarField(*ldt, threads);
    if (tm25_cmd->parsed()) return RunRays(*tm25, threads);
    return std::nullopt;
  };
}

}  // namespace lumislab
