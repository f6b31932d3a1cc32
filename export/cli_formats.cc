#include "export/cli_formats.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/log.h"
#include "core/slab.h"
#include "export/complete_slab.h"
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

// A dataset folder or its slab/: the folder holding slab.json.
std::string ResolveSlabDir(const std::string& path) {
  namespace fs = std::filesystem;
  if (fs::is_regular_file(path + "/slab.json")) return path;
  if (fs::is_regular_file(path + "/slab/slab.json")) return path + "/slab";
  throw BadInput(path + ": no slab.json there nor in " + path +
                 "/slab (--slab takes a dataset folder or its slab/)");
}

struct Slab {
  std::string dir;
  SlabInfo info;
  std::vector<SlabPosition> positions;
};

// The whole slab: a partial one would leave out the light of its missing positions. Its total
// light is checked into `checks` (a log of the dataset holding the slab, SlabChecks).
Slab LoadCompleteSlab(const std::string& path, int threads, CheckLog& checks) {
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
  return CheckLog(DatasetOfSlab(ResolveSlabDir(path)), stage);
}

// cd / lm for a slab scaled with a lux meter, W/sr / W otherwise (relative: a warning).
bool Photometric(const SlabInfo& info) {
  if (info.units == "relative")
    LogWarning(
        "the slab is in relative units (no radiometric scale): the values written are "
        "relative, labelled W/sr (W)");
  return info.units == "lux";
}

// The current time in UTC, through strftime's `format`.
std::string NowUtc(const char* format) {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, format, &tm);
  return text;
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
  std::vector<double> c_angles, gamma_angles;
  int samples = 4;
  std::vector<double> opening_mm;
  bool force = false;
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

// The far field of the slab on the requested grid, with the file's keywords: the distribution
// the writers take.
// The requested C/gamma grid, checked (kMaxCPlanes, kMaxGammaAngles) before any work: a
// distribution of zeros the far field fills in.
IntensityDistribution DirectionGrid(const FarFieldCommand& c) {
  IntensityDistribution d;
  d.c_deg = c.c_angles.empty() ? Steps(c.c_step, 360, "--c-step", kMaxCPlanes) : c.c_angles;
  d.gamma_deg = c.gamma_angles.empty() ? Steps(c.gamma_step, 90, "--gamma-step", kMaxGammaAngles)
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

IntensityDistribution SlabDistribution(const FarFieldCommand& c, const Slab& slab, int threads,
                                       CheckLog& checks) {
  IntensityDistribution d = DirectionGrid(c);
  FarFieldOptions options;
  options.samples = c.samples;
  options.threads = threads;
  const FarField ff = ComputeFarField(slab.info, slab.positions, d.c_deg, d.gamma_deg, options);
  CheckFarFieldLight(ff, slab.info, slab.dir, checks);
  d.values = ff.values;
  for (double& v : d.values) v = std::max(v, 0.0);  // ringing of the fit: no negative intensity
  d.photometric = Photometric(slab.info);
  const SamplingGrid& g = slab.info.grid;
  if (c.opening_mm.size() == 3) {
    d.opening = {c.opening_mm[0], c.opening_mm[1], c.opening_mm[2]};
  } else {  // the basis supports' extent on S: the largest opening the slab represents
    d.opening = {(g.nv + 1) * g.spacing_mm, (g.nu + 1) * g.spacing_mm, 0.0};
  }
  d.keywords = ResolveKeywords(c.keywords);
  std::ostringstream note;
  note << "lumislab-export " << c.format << " from the light slab " << slab.dir << " (" << g.nu
       << " x " << g.nv << " positions, h " << g.spacing_mm << " mm, d " << slab.info.distance_mm
       << " mm); directions the screen did not see are 0";
  d.keywords.push_back({"FILEGENINFO", note.str()});
  if (ff.unseen > 0)
    LogWarning(ff.unseen, " of ", ff.values.size(), " directions were not seen by the screen (",
               ff.behind, " of them behind S, gamma >= 90), written as 0");
  const char* unit = d.photometric ? " lm" : " W";
  LogInfo("far field: ", d.c_deg.size(), " C planes x ", d.gamma_deg.size(), " gamma angles, flux ",
          Num(d.TotalFlux(), 6), unit, " over the seen directions");
  return d;
}

int RunFarField(const FarFieldCommand& c, int threads) {
  LogInfo("parameters: slab=", c.slab, " out=", c.out, " c_step=", c.c_step,
          " gamma_step=", c.gamma_step, " c_angles=", c.c_angles.size(),
          " gamma_angles=", c.gamma_angles.size(), " samples=", c.samples,
          " metadata=", c.keywords.metadata, " force=", c.force ? "yes" : "no");
  CheckOutputPath(c.out);
  if (!c.force && std::filesystem::exists(c.out)) {
    LogInfo(c.out, " exists: skipped (--force rewrites it)");
    std::printf("%s: %s\n", c.format.c_str(), c.out.c_str());
    return 0;
  }
  DirectionGrid(c);  // refuses a bad grid before the slab is read
  CheckLog checks = SlabChecks(c.slab, "export " + c.format);
  const Slab slab = LoadCompleteSlab(c.slab, threads, checks);
  const IntensityDistribution d = SlabDistribution(c, slab, threads, checks);
  checks.Save();
  if (c.format == "ies")
    WriteIes(d, c.out);
  else
    WriteEulumdat(d, c.out);
  std::printf("%s: %s\n", c.format.c_str(), c.out.c_str());
  return 0;
}

CLI::App* AddFarFieldCommand(CLI::App& app, const std::string& format, FarFieldCommand* c,
                             CommonOptions* common) {
  c->format = format;
  CLI::App* cmd = app.add_subcommand(
      format, format == "ies" ? "the slab's far-field intensity as an IES LM-63-2019 file"
                              : "the slab's far-field intensity as an EULUMDAT file");
  cmd->add_option("--slab", c->slab, "dataset folder or its slab/")->required();
  cmd->add_option("--out", c->out, "file to write")->required();
  cmd->add_option("--c-step", c->c_step, "degrees between C planes, 0-360")->capture_default_str();
  cmd->add_option("--gamma-step", c->gamma_step, "degrees between gamma angles, 0-90")
      ->capture_default_str();
  cmd->add_option("--c-angles", c->c_angles, "explicit C planes (degrees, comma separated)")
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
  cmd->add_flag("--force", c->force, "rewrite the output if it exists");
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
};

int RunRays(const RayCommand& c, int threads) {
  LogInfo("parameters: slab=", c.slab, " out=", c.out, " rays=", c.rays, " seed=", c.seed,
          " force=", c.force ? "yes" : "no");
  CheckOutputPath(c.out);
  if (!c.force && std::filesystem::exists(c.out)) {
    LogInfo(c.out, " exists: skipped (--force rewrites it)");
    std::printf("tm25: %s\n", c.out.c_str());
    return 0;
  }
  CheckLog checks = SlabChecks(c.slab, "export tm25");
  const Slab slab = LoadCompleteSlab(c.slab, threads, checks);
  checks.Save();
  const SlabRays drawn = SampleSlabRays(slab.info, slab.positions, c.rays, c.seed, threads);
  Tm25RaySet set;
  set.photometric = Photometric(slab.info);
  const double nan = std::nan("");
  set.luminous_flux_lm = set.photometric ? drawn.total_flux : nan;
  set.radiant_flux_w = set.photometric ? nan : drawn.total_flux;
  set.creation_method = 1;  // measured
  set.date_time = NowUtc("%Y-%m-%dT%H:%M:%SZ");
  set.name = c.name;
  set.manufacturer = c.manufacturer;
  set.rayfile_creator = "lumislab-export tm25";
  set.equipment = "lumislab light slab: " + std::to_string(slab.info.grid.nu) + " x " +
                  std::to_string(slab.info.grid.nv) + " positions, h " +
                  Num(slab.info.grid.spacing_mm, 6) + " mm, d " + Num(slab.info.distance_mm, 6) +
                  " mm";
  set.additional_info = "rays drawn from the slab's light field, seed " + std::to_string(c.seed) +
                        "; origins on the sampling plane z = 0 (mm, luminaire frame)";
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
  cmd->add_option("--slab", c->slab, "dataset folder or its slab/")->required();
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
  cmd->add_flag("--force", c->force, "rewrite the output if it exists");
  AddCommonOptions(cmd, common);
  return cmd;
}

// ---- info -----------------------------------------------------------------------------------

struct InfoCommand {
  std::string file;
  bool json = false;
};

int RunInfo(const InfoCommand& c) {
  std::fputs(FormatPhotometricFileInfo(PhotometricFileInfo(c.file), c.json).c_str(), stdout);
  return 0;
}

CLI::App* AddInfoCommand(CLI::App& app, InfoCommand* c, CommonOptions* common) {
  CLI::App* cmd = app.add_subcommand(
      "info", "what an IES, EULUMDAT or TM-25 file holds: format, angle grid or rays, flux");
  cmd->add_option("file", c->file, "the file")->required();
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
