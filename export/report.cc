#include "export/report.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <limits>
#include <thread>

#include "core/atomic_file.h"
#include "core/checks.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/json.h"
#include "core/log.h"
#include "core/slab.h"
#include "core/slab_light.h"
#include "export/complete_slab.h"
#include "export/luminaire_source.h"
#include "export/plane_irradiance.h"
#include "lib/lightfield/far_field.h"
#include "lib/lightfield/far_field_light.h"
#include "lib/lightfield/light_colour.h"
#include "lib/photometry/colour.h"
#include "lib/synthetic/scene.h"

#ifndef LUMISLAB_VERSION
#define LUMISLAB_VERSION "unknown"
#endif

namespace lumislab {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kChromiumTimeoutS = 120;
constexpr double kMaxEfficacy = 683;  // lm/W: K_m, monochromatic 555 nm (SI candela definition)

// The colour section: the chromaticity and CCT of the slab's total light and of the far field
// per direction through the dataset's camera colour calibration (calib/colour.json,
// lib/lightfield/light_colour.h); not present without one. Directions: C every 45 degrees, gamma
// every 5 degrees within the measured cone, those whose luminance is at least 10 % of the peak's
// (dimmer ones carry the dual filter's ringing in their chromaticity); the table: gamma 0, 10, 20,
// 30 degrees within the measured cone in C 0, 90, 180, 270.
ReportColour MakeReportColour(const ReportData& r, const std::vector<SlabPosition>& positions,
                              int threads) {
  ReportColour c;
  const std::optional<ColourCalibration> calibration = ColourCalibration::LoadFor(r.dataset_dir);
  if (!calibration) return c;
  c.present = true;
  c.source = std::filesystem::path(calibration->file).lexically_relative(r.dataset_dir).string();
  const LightColour total = TotalLightColour(r.info, positions, *calibration);
  c.x = total.xy.x();
  c.y = total.xy.y();
  c.cct_k = total.cct.kelvin;
  c.duv = total.cct.duv;
  c.rows.push_back("Duv (total light): " + Num(total.cct.duv, 3));
  c.rows.push_back("camera RGB -> CIE XYZ: " + calibration->chart + " under " +
                   calibration->illuminant + ", fit Delta E*ab mean " +
                   Num(calibration->mean_delta_e, 3) + ", max " + Num(calibration->max_delta_e, 3));
  std::vector<double> cs, gammas;
  for (double cd = 0; cd < 360; cd += 45) cs.push_back(cd);
  for (double g = 0; g <= r.seen_cone_deg + 1e-9; g += 5) gammas.push_back(g);
  FarFieldOptions options;
  options.threads = threads;
  const FarFieldColour ff =
      ComputeFarFieldColour(r.info, positions, cs, gammas, *calibration, options);
  double peak_y = 0;
  for (size_t k = 0; k < ff.colour.size(); ++k)
    if (ff.seen[k]) peak_y = std::max(peak_y, ff.colour[k].xyz.y());
  double lo = kNan, hi = kNan;
  std::string lo_at, hi_at;
  int counted = 0;
  for (size_t ic = 0; ic < cs.size(); ++ic)
    for (size_t ig = 0; ig < gammas.size(); ++ig) {
      const LightColour& lc = ff.colour[ic * gammas.size() + ig];
      if (!ff.seen[ic * gammas.size() + ig] || !(lc.xyz.y() >= 0.1 * peak_y) ||
          !std::isfinite(lc.cct.kelvin))
        continue;
      const std::string at = "C " + Num(cs[ic], 3) + ", gamma " + Num(gammas[ig], 3);
      if (!(lc.cct.kelvin >= lo)) lo = lc.cct.kelvin, lo_at = at;
      if (!(lc.cct.kelvin <= hi)) hi = lc.cct.kelvin, hi_at = at;
      ++counted;
    }
  if (counted > 0)
    c.rows.push_back("CCT over " + std::to_string(counted) +
                     " directions (>= 10 % of the peak luminance, C every 45 deg, gamma every 5 "
                     "deg within the measured cone): " +
                     Num(lo, 4) + " K (" + lo_at + ") to " + Num(hi, 4) + " K (" + hi_at + ")");
  for (double g : {0.0, 10.0, 20.0, 30.0}) {
    if (g > r.seen_cone_deg) break;
    c.table_gamma.push_back(g);
    const size_t ig = size_t(std::lround(g / 5));
    for (size_t ic = 0; ic < cs.size(); ic += 2) {
      if (c.table_gamma.size() == 1) c.table_c.push_back(cs[ic]);
      const size_t k = ic * gammas.size() + ig;
      const LightColour& lc = ff.colour[k];
      c.cells.push_back(ff.seen[k] ? ReportColour::Cell{lc.xy.x(), lc.xy.y(), lc.cct.kelvin}
                                   : ReportColour::Cell{kNan, kNan, kNan});
    }
  }
  LogInfo("report: colour of the total light x ", Num(c.x, 4), " y ", Num(c.y, 4), ", CCT ",
          Num(c.cct_k, 4), " K (", c.source, ")");
  return c;
}

std::string FileTimeUtc(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto t = fs::last_write_time(path, ec);
  if (ec) return "";
  const auto system = std::chrono::time_point_cast<std::chrono::system_clock::duration>(
      t - fs::file_time_type::clock::now() + std::chrono::system_clock::now());
  const std::time_t tt = std::chrono::system_clock::to_time_t(system);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char text[40];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M UTC", &tm);
  return text;
}

std::vector<double> Range(double step, double last) {
  std::vector<double> v;
  const int n = int(std::lround(last / step));
  for (int k = 0; k <= n; ++k) v.push_back(k * step);
  return v;
}

// A luminaire folder's rows (first in the table): its orientations, their registration
// (registration.json: correction and 1-sigma per orientation) and the merged coverage; the rows
// after them are the front orientation's capture.
void AddLuminaireMetadata(const LuminaireSource& source, size_t front, const std::string& folder,
                          ReportData* r) {
  auto add = [&](const std::string& k, const std::string& v) { r->metadata.push_back({k, v}); };
  add("luminaire folder", folder + " (" + source.set.coverage + " asked)");
  add("orientations", source.Orientations());
  if (!source.set.orientations.front().registered)
    add("registration", "none: nominal poses; " + RegisterCommand(folder) + " refines them");
  const std::vector<std::string> rows = source.RegistrationRows();
  for (size_t k = 0; k < rows.size(); ++k) add("orientation " + std::to_string(k), rows[k]);
  add("merged coverage", Num(100 * r->seen_fraction, 4) + " % of the " + r->Domain() +
                             " seen by at least one orientation; the far field of each direction "
                             "is its orientations' blend (docs/method.md §4.12)");
  add("planes and colour",
      "orientation " + source.slabs[front].name + " (looking along gamma = 0); D from its S");
}

// Metadata rows from slab.json and whichever calibration files the dataset has.
void AddMetadata(ReportData* r) {
  auto add = [&](const std::string& k, const std::string& v) { r->metadata.push_back({k, v}); };
  const SlabInfo& i = r->info;
  add("slab", r->slab_dir);
  add("distance d (S to screen)", Num(i.distance_mm, 6) + " mm");
  add("grid", std::to_string(i.grid.nu) + " × " + std::to_string(i.grid.nv) + " positions, h " +
                  Num(i.grid.spacing_mm, 4) + " mm, K " +
                  std::to_string(std::max<int>(1, int(i.filter.dual_coefficients.size()) - 1)));
  add("slab window", Num(i.layout.window_w_mm, 5) + " × " + Num(i.layout.window_h_mm, 5) + " mm, " +
                         std::to_string(i.layout.res_x) + " × " + std::to_string(i.layout.res_y) +
                         " texels");
  add("units", i.units);
  const std::string slab_time = FileTimeUtc(r->slab_dir + "/slab.json");
  if (!slab_time.empty()) add("slab written", slab_time);
  if (r->dataset_dir.empty()) return;
  const std::string dataset_time = FileTimeUtc(r->dataset_dir + "/dataset.json");
  if (!dataset_time.empty()) add("dataset created", dataset_time);
  auto report_of = [&](const std::string& file, const std::string& label,
                       const std::vector<std::pair<std::string, std::string>>& fields) {
    const std::string path = r->dataset_dir + "/calib/" + file;
    if (!std::filesystem::is_regular_file(path)) return;
    const JsonDocument doc = JsonDocument::Load(path);
    const JsonView root = doc.root();
    std::string text;
    if (root.Has("report"))
      for (const auto& [field, unit] : fields)
        if (root["report"].Has(field))
          text += (text.empty() ? "" : ", ") + field + " " +
                  Num(root["report"][field].Number(), 4) + unit;
    add(label, "calib/" + file + (text.empty() ? "" : ": " + text));
  };
  report_of("screen.json", "screen calibration", {{"rms_px", " px"}, {"rms_mm", " mm"}});
  report_of("camera.json", "camera calibration", {{"rms_px", " px"}});
  report_of("dark.json", "dark frame", {});
  report_of("response.json", "response curve", {});
  report_of("flat.json", "flat field", {});
  const std::string scale = r->dataset_dir + "/calib/scale.json";
  if (std::filesystem::is_regular_file(scale)) {
    const JsonDocument doc = JsonDocument::Load(scale);
    add("scale calibration", "calib/scale.json: " + Num(doc.root()["scale"].Number(), 6) + " " +
                                 doc.root()["units"].String() + " per unit value");
  } else {
    add("scale calibration", "none (calib/scale.json absent)");
  }
}

// The plane at D: the slab's illuminance and, along y = 0, the far field's inverse square
// E = I(C, gamma) D / r^3 (10^6: mm^2 -> m^2), C = 0 for x > 0 and 180 for x < 0.
ReportPlane MakePlane(const ReportData& r, const std::vector<ImageF>& irradiance, double D,
                      const ReportOptions& o, int threads) {
  const PlaneIrradiance p =
      RenderPlaneIrradiance(r.info, irradiance, D, 0, o.plane_size, o.plane_samples, threads);
  if (!p.complete) throw Failure("stopped by a signal; " + o.out + " not written");
  ReportPlane plane;
  plane.note = CheckPlaneResolved(p, r.info, r.IlluminanceUnit(), "--distances-mm");
  plane.distance_mm = p.plane_z_mm;
  plane.extent_mm = p.extent_mm;
  plane.size = o.plane_size;
  const Eigen::Vector3d w = r.info.channel_weights;  // the slab's luminance (formats.md §6)
  for (int y = 0; y < plane.size; ++y)
    for (int x = 0; x < plane.size; ++x)
      plane.luminance.push_back(float(w[0] * p.irradiance.at(x, y, 0) +
                                      w[1] * p.irradiance.at(x, y, 1) +
                                      w[2] * p.irradiance.at(x, y, 2)));
  const int row = plane.size / 2;
  for (int x = 0; x < plane.size; ++x) {
    const double xm = (x + 0.5) / plane.size * plane.extent_mm - 0.5 * plane.extent_mm;
    const double rr = std::hypot(xm, D);
    const double gamma = std::atan2(std::abs(xm), D) * 180 / kPi;
    const double I = r.distribution.Intensity(xm >= 0 ? 0 : 180, gamma);
    plane.profile_x_mm.push_back(xm);
    plane.profile_slab.push_back(plane.luminance[row * plane.size + x]);
    plane.profile_far.push_back(gamma <= r.seen_cone_deg ? I * 1e6 * D / (rr * rr * rr) : kNan);
  }
  plane.centre_slab = plane.luminance[row * plane.size + plane.size / 2];
  plane.centre_far = r.distribution.Intensity(0, 0) * 1e6 / (D * D);
  return plane;
}

// Runs headless Chromium to print `html` to `pdf` (Chromium's own PDF writer; A4 from the
// page's CSS @page). LUMISLAB_CHROMIUM names another binary.
void PrintPdf(const std::string& html, const std::string& pdf) {
  const char* env = std::getenv("LUMISLAB_CHROMIUM");
  const std::string program = env && *env ? env : "chromium";
  std::vector<std::string> words = {program,
                                    "--headless",
                                    "--no-sandbox",
                                    "--disable-gpu",
                                    "--no-pdf-header-footer",
                                    "--print-to-pdf=" + pdf,
                                    "file://" + std::filesystem::absolute(html).string()};
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw Failure("cannot start " + program + " for --pdf");
  if (pid == 0) {
    setpgid(0, 0);
    const int null_fd = open("/dev/null", O_RDWR);
    if (null_fd >= 0) dup2(null_fd, 0), dup2(null_fd, 1), dup2(null_fd, 2);
    execvp(program.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  const auto start = std::chrono::steady_clock::now();
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() - start >
        std::chrono::duration<double>(kChromiumTimeoutS)) {
      kill(-pid, SIGKILL);
      waitpid(pid, &status, 0);
      throw Failure(program + " did not print " + pdf + " within " + Num(kChromiumTimeoutS, 3) +
                    " s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
    throw Failure("--pdf: cannot run " + program +
                  " (install Debian's chromium, or set LUMISLAB_CHROMIUM to a Chromium binary); " +
                  html + " is written");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !std::filesystem::exists(pdf))
    throw Failure(program + " failed to print " + html + " to " + pdf);
}

int RunReport(const ReportOptions& o, int threads) {
  LogInfo("parameters: slab=", o.slab, " out=", o.out, " pdf=", o.pdf,
          " input_watts=", o.input_watts, " distances_mm=", o.distances_mm.size(),
          " c_step=", o.c_step, " gamma_step=", o.gamma_step, " samples=", o.samples,
          " per_klm=", o.per_klm ? "yes" : "no", " force=", o.force ? "yes" : "no");
  if (std::filesystem::path(o.out).extension() != ".html")
    throw BadInput(o.out + ": --out must end in .html");
  if (!o.pdf.empty() && std::filesystem::path(o.pdf).extension() != ".pdf")
    throw BadInput(o.pdf + ": --pdf must end in .pdf");
  for (const std::string& path : {o.out, o.pdf}) {
    if (!path.empty()) CheckExportOutput(path, o.force);
  }
  const ReportData data = MakeReportData(o, threads);
  WriteTextAtomically(o.out, ReportHtml(data));
  std::printf("report: %s\n", o.out.c_str());
  if (!o.pdf.empty()) {
    PrintPdf(o.out, o.pdf);
    std::printf("report: %s\n", o.pdf.c_str());
  }
  return 0;
}

}  // namespace

std::string ReportData::IntensityUnit() const {
  if (!distribution.photometric) return "W/sr";
  return per_klm ? "cd/klm" : "cd";
}
std::string ReportData::FluxUnit() const { return distribution.photometric ? "lm" : "W"; }
std::string ReportData::IlluminanceUnit() const { return distribution.photometric ? "lx" : "W/m²"; }

ReportData MakeReportData(const ReportOptions& o, int threads) {
  if (!(o.c_step > 0 && o.c_step <= 90 &&
        std::abs(360 / o.c_step - std::round(360 / o.c_step)) < 1e-9))
    throw InputError("--c-step", "", "a step in (0, 90] degrees dividing 360", Num(o.c_step, 8));
  if (!(o.gamma_step > 0 && o.gamma_step <= 10 &&
        std::abs(90 / o.gamma_step - std::round(90 / o.gamma_step)) < 1e-9))
    throw InputError("--gamma-step", "", "a step in (0, 10] degrees dividing 90",
                     Num(o.gamma_step, 8));
  ReportData r;
  // A luminaire folder: the merged far field (gamma 0-180 for a sphere), the planes, colour and
  // capture metadata of its front orientation (FrontOrientation).
  std::optional<LuminaireSource> luminaire;
  size_t front = 0;
  if (IsLuminaireFolder(o.slab)) {
    luminaire = LoadLuminaireSource(o.slab, threads, "export report");
    front = FrontOrientation(luminaire->set);
    r.slab_dir = luminaire->slabs[front].slab_dir;
    if (luminaire->set.coverage == "sphere") r.gamma_span_deg = 180;
    r.measured = o.slab + " (luminaire folder: " + luminaire->Orientations() +
                 "; planes and colour from " + r.slab_dir + ")";
  } else {
    r.slab_dir = ResolveSlabDir(o.slab);
    r.measured = r.slab_dir;
  }
  r.dataset_dir = DatasetOfSlab(r.slab_dir);
  r.info = SlabInfo::Load(r.slab_dir);
  RequireCompleteSlab(r.info, r.slab_dir);
  r.per_klm = o.per_klm;
  r.generated_utc = NowUtc("%Y-%m-%d %H:%M UTC");
  r.software = std::string("lumislab-export ") + LUMISLAB_VERSION;
  CheckLog checks(luminaire ? "" : r.dataset_dir, "export report");
  std::vector<SlabPosition> positions = luminaire ? luminaire->slabs[front].positions
                                                  : ReadSlabPositions(r.slab_dir, r.info, threads);
  if (!luminaire) CheckSlabLight(r.info, positions, r.slab_dir, checks);

  IntensityDistribution& d = r.distribution;
  d.format = "lumislab far field";
  d.c_deg = Range(o.c_step, 360);
  d.gamma_deg = Range(o.gamma_step, r.gamma_span_deg);
  FarFieldOptions ff_options;
  ff_options.samples = o.samples;
  ff_options.threads = threads;
  FarField ff;
  if (luminaire) {
    ff = MergedFarFieldChecked(*luminaire, d.c_deg, d.gamma_deg, ff_options).ff;
  } else {
    ff = ComputeFarField(r.info, positions, d.c_deg, d.gamma_deg, ff_options);
    CheckFarFieldLight(ff, r.info, r.slab_dir, checks);
  }
  checks.Save();
  d.values = ff.values;
  for (double& v : d.values) v = std::max(v, 0.0);  // the fit's ringing: no negative intensity
  d.photometric = r.info.units == "lux";
  // A W/m^2 (or relative) slab gives W/sr and W: not a photometric report (issue 29 red team).
  r.title = !o.title.empty() ? o.title
            : d.photometric  ? "Photometric report"
                             : "Radiometric report";
  if (o.per_klm && !d.photometric)
    LogWarning("--per-klm: the slab is in ", r.info.units,
               " units, not lux: the diagrams stay in W/sr (cd/klm needs lm)");
  d.input_watts = o.input_watts;
  r.seen = ff.seen;
  r.summary = SummarisePhotometry(d, r.seen);
  // The seen flux alone already bounds the efficacy from below: above the luminous efficacy of
  // monochromatic 555 nm light (683 lm/W, the most any source can have) the power is wrong.
  if (d.photometric && o.input_watts > 0 && !(r.summary.total_flux / o.input_watts <= kMaxEfficacy))
    throw InputError(
        "--input-watts", "",
        "the luminaire's input power: at most " + Num(kMaxEfficacy, 4) +
            " lm/W (555 nm light) for the " + Num(r.summary.total_flux, 6) +
            " lm seen, i.e. >= " + Num(r.summary.total_flux / kMaxEfficacy, 6) + " W",
        Num(o.input_watts, 8) + " W (" + Num(r.summary.total_flux / o.input_watts, 6) + " lm/W)");
  r.seen_cone_deg = SeenConeDeg(d, r.seen);
  r.flux_in_cone = d.FluxWithin(r.seen_cone_deg);
  IntensityDistribution seen_sr = d;  // the zonal sum of 0/1: the seen solid angle
  for (size_t k = 0; k < seen_sr.values.size(); ++k) seen_sr.values[k] = r.seen[k] ? 1 : 0;
  r.seen_fraction = seen_sr.TotalFlux() / ((r.gamma_span_deg > 90 ? 4 : 2) * kPi);

  r.uncertainty =
      luminaire ? LuminaireUncertainty(*luminaire, o.samples, o.uncertainty)
                : EstimateFarFieldUncertainty(r.info, r.dataset_dir, o.samples, o.uncertainty);

  r.colour = MakeReportColour(r, positions, threads);
  std::vector<ImageF> irradiance;
  for (SlabPosition& p : positions) irradiance.push_back(std::move(p.irradiance));
  positions.clear();
  std::vector<double> distances = o.distances_mm;
  if (distances.empty())
    distances = {r.info.distance_mm, 2 * r.info.distance_mm, 4 * r.info.distance_mm};
  for (double D : distances) r.planes.push_back(MakePlane(r, irradiance, D, o, threads));
  if (luminaire) AddLuminaireMetadata(*luminaire, front, o.slab, &r);
  AddMetadata(&r);
  LogInfo("report: flux ", Num(r.summary.total_flux, 6), " ", r.FluxUnit(), ", seen to gamma ",
          Num(r.seen_cone_deg, 4), " deg (", Num(100 * r.seen_fraction, 3), " % of the ",
          r.gamma_span_deg > 90 ? "sphere" : "hemisphere", "), peak ", Num(r.summary.peak, 6), " ",
          r.IntensityUnit());
  return r;
}

ParsedCommand AddReportCommand(CLI::App& app, CommonOptions* common) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "the lab report of the slab: one self-contained, printable HTML file (summary, zonal "
      "lumens, polar / linear / iso-candela diagrams, illuminance on planes, the near-field "
      "advantage, candela table, uncertainty, metadata), and a PDF through headless Chromium");
  cmd->add_option("--slab", o->slab,
                  "dataset folder, its slab/, or a luminaire folder (the merged far field over "
                  "the sphere; the planes of the orientation looking along gamma = 0)")
      ->required();
  cmd->add_option("--out", o->out, "the report (.html)")->required();
  cmd->add_option("--pdf", o->pdf, "also print it to this PDF (needs chromium)");
  cmd->add_option("--input-watts", o->input_watts, "the luminaire's input power (W): efficacy")
      ->check(FiniteIn(0, 1e6));
  cmd->add_option("--distances-mm", o->distances_mm,
                  "planes for the illuminance pictures (mm, comma separated; default d, 2d, 4d)")
      ->delimiter(',')
      ->check(FiniteIn(kMinDistanceMm, kMaxDistanceMm));
  cmd->add_option("--c-step", o->c_step, "degrees between C planes of the far field")
      ->capture_default_str();
  cmd->add_option("--gamma-step", o->gamma_step,
                  "degrees between gamma angles (0-90; 0-180 for a luminaire folder measured "
                  "over the sphere)")
      ->capture_default_str();
  cmd->add_option("--samples", o->samples, "N x N quadrature points per position (far field)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  cmd->add_option("--plane-size", o->plane_size, "pixels per side of each plane picture")
      ->check(CLI::Range(16, 1024))
      ->capture_default_str();
  cmd->add_flag("--per-klm", o->per_klm, "diagrams and candela table in cd/klm (lux slabs)");
  AddUncertaintyOptions(cmd, &o->uncertainty);
  cmd->add_option("--title", o->title, "the report's title");
  cmd->add_flag("--force", o->force, "rewrite the outputs if they exist");
  AddCommonOptions(cmd, common);
  return [cmd, o](int threads) -> std::optional<int> {
    if (cmd->parsed()) return RunReport(*o, threads);
    return std::nullopt;
  };
}

}  // namespace lumislab
