#include "export/cli_plots.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/geometry.h"
#include "core/log.h"
#include "core/slab.h"
#include "export/complete_slab.h"
#include "export/luminaire_source.h"
#include "export/plane_irradiance.h"
#include "lib/lightfield/false_colour.h"
#include "lib/lightfield/far_field.h"
#include "lib/lightfield/far_field_light.h"
#include "lib/lightfield/polar_plot.h"
#include "lib/photo/photo_write.h"

namespace lumislab {
namespace {

struct IrradianceOptions {
  std::string slab_dir, out;
  double distance_mm = 0;
  double extent_mm = 0;  // 0: the window seen at D (window * D / d)
  int size = 512;
  int samples = 2;
  std::string range = "auto", scale = "linear";
  bool force = false;
};

struct PolarOptions {
  std::string slab_dir, out;
  double gamma_step_deg = 2.5;
  int samples = 4;
  int size = 600;
  std::string title;
  bool force = false;
};

std::string Extension(const std::string& path) {
  return std::filesystem::path(path).extension().string();
}

// A luminaire folder's plane z = D (luminaire frame) is the plane in front of the orientation
// that looks along the luminaire's gamma = 0 axis (its capture +z nearest the luminaire's +z):
// what that orientation's slab sees of it, at D + centre_z of its capture frame. The picture's
// extent (the window seen at D) lies within that orientation's cone, where its slab holds the
// light; a plane the pose tilts, or a centre off its axis, is warned about.
void PlaneOfLuminaireFolder(IrradianceOptions* o) {
  const LuminaireSet set = LoadLuminaireSet(o->slab_dir);
  const size_t best = FrontOrientation(set);
  const Orientation& front = set.orientations[best];
  const double tilt_deg = std::acos(std::clamp(front.rotation(2, 2), -1.0, 1.0)) * 180 / kPi;
  LogInfo("luminaire ", o->slab_dir, ": the plane z = ", o->distance_mm,
          " mm of the luminaire frame as orientation ", front.name, " sees it (its axis ",
          Num(tilt_deg, 3), " deg from gamma = 0), at ", o->distance_mm + front.centre_mm.z(),
          " mm from its S");
  if (tilt_deg > 0.5 || front.centre_mm.head<2>().norm() > 1)
    LogWarning("orientation ", front.name, " looks ", Num(tilt_deg, 3),
               " deg off the luminaire's gamma = 0 axis, its centre ",
               Num(front.centre_mm.head<2>().norm(), 3),
               " mm off its own axis: the picture is its plane, tilted and shifted that much");
  o->distance_mm += front.centre_mm.z();
  if (!(o->distance_mm >= kMinDistanceMm))
    throw InputError("--distance-mm", "",
                     "a plane beyond the front orientation's S (D + centre_z >= " +
                         Num(kMinDistanceMm, 3) + " mm)",
                     Num(o->distance_mm - front.centre_mm.z(), 6));
  o->slab_dir = ResolveSlabDir(set.DatasetFolder(best));
}

// The slab's irradiance on the plane z = D by the exact CPU reference (docs/method.md §4.5;
// nothing in the way, so no visibility rays), through the false colour of docs/method.md §4.9.
int RunIrradiance(IrradianceOptions o, int threads) {
  if (IsLuminaireFolder(o.slab_dir))
    PlaneOfLuminaireFolder(&o);
  else
    o.slab_dir = ResolveSlabDir(o.slab_dir);
  LogInfo("parameters: slab=", o.slab_dir, " distance_mm=", o.distance_mm,
          " extent_mm=", o.extent_mm, " size=", o.size, " samples=", o.samples, " range=", o.range,
          " scale=", o.scale, " out=", o.out);
  const std::string ext = Extension(o.out);
  if (ext != ".png" && ext != ".exr") throw BadInput(o.out + ": --out must end in .png or .exr");
  CheckExportOutput(o.out, o.force);
  if (o.extent_mm != 0 && !(o.extent_mm >= 1 && o.extent_mm <= kMaxDistanceMm))
    throw InputError("--extent-mm", "", "0 (default) or a length in [1, 1e5] mm",
                     std::to_string(o.extent_mm));
  FalseColourRequest request;
  request.log = o.scale == "log";
  ParseFalseColourRange(o.range, "--range", &request);
  const SlabInfo info = SlabInfo::Load(o.slab_dir);
  RequireCompleteSlab(info, o.slab_dir);
  std::vector<ImageF> irradiance;
  {
    std::vector<SlabPosition> positions = ReadSlabPositions(o.slab_dir, info, threads);
    CheckLog checks(DatasetOfSlab(o.slab_dir), "export irradiance");
    CheckSlabLight(info, positions, o.slab_dir, checks);
    checks.Save();
    for (SlabPosition& p : positions) irradiance.push_back(std::move(p.irradiance));
  }
  const PlaneIrradiance plane = RenderPlaneIrradiance(info, irradiance, o.distance_mm, o.extent_mm,
                                                      o.size, o.samples, threads);
  if (!plane.complete) throw Failure("stopped by a signal; " + o.out + " not written");
  const std::string unit = IrradianceUnitLabel(info.units);
  LogInfo("plane at ", plane.plane_z_mm, " mm: luminance min ", Num(plane.min_luminance, 6),
          " max ", Num(plane.max_luminance, 6), " ", unit, ", ", plane.negative_pixels,
          " pixel(s) below -", Num(100 * kPlaneNegativeTolerance, 2), " % of the maximum");
  CheckPlaneResolved(plane, info, unit, "--distance-mm");
  const ImageF& irradiance_image = plane.irradiance;
  if (ext == ".exr") {
    WriteExr(o.out, irradiance_image, {"R", "G", "B"});
  } else {
    const Rgb8Image picture = FalseColourPicture(
        irradiance_image, info.channel_weights, request, IrradianceUnitLabel(info.units),
        plane.extent_mm / o.size, "plane at " + FormatTick(plane.plane_z_mm, 1) + " mm");
    WriteRgb8File(o.out, picture.width, picture.height, picture.rgb);
  }
  LogInfo("irradiance on the plane at ", plane.plane_z_mm, " mm, ", plane.extent_mm, " mm wide, ",
          o.size, "x", o.size, " (", IrradianceUnitLabel(info.units), ") -> ", o.out);
  return 0;
}

int RunPolar(PolarOptions o, int threads) {
  if (!IsLuminaireFolder(o.slab_dir)) o.slab_dir = ResolveSlabDir(o.slab_dir);
  LogInfo("parameters: slab=", o.slab_dir, " gamma_step=", o.gamma_step_deg, " samples=", o.samples,
          " size=", o.size, " out=", o.out);
  const std::string ext = Extension(o.out);
  if (ext != ".svg" && ext != ".png") throw BadInput(o.out + ": --out must end in .svg or .png");
  CheckExportOutput(o.out, o.force);
  PolarPlotData data = PolarData(o.slab_dir, o.gamma_step_deg, o.samples, threads);
  if (!o.title.empty()) data.title = o.title;
  const PolarPlot plot = MakePolarPlot(data, o.size);
  if (ext == ".svg") {
    WriteTextAtomically(o.out, PolarPlotSvg(plot));
  } else {
    const Rgb8Image image = PolarPlotImage(plot);
    WriteRgb8File(o.out, image.width, image.height, image.rgb);
  }
  LogInfo("polar plot -> ", o.out);
  return 0;
}

}  // namespace

// The far field in the four half-planes, up to the largest gamma every one of them saw: of the
// slab (gamma 0-90), or of a luminaire folder the merged far field (gamma 0-180).
PolarPlotData PolarData(const std::string& slab_dir, double gamma_step_deg, int samples,
                        int threads) {
  const bool merged = IsLuminaireFolder(slab_dir);
  PolarOptions o;
  o.slab_dir = merged ? slab_dir : ResolveSlabDir(slab_dir);
  o.gamma_step_deg = gamma_step_deg;
  o.samples = samples;
  std::vector<double> gamma;
  const double span = merged ? 180 : 90;
  for (int k = 0; k * o.gamma_step_deg <= span + 1e-9; ++k) gamma.push_back(k * o.gamma_step_deg);
  FarFieldOptions options;
  options.samples = o.samples;
  options.threads = threads;
  const std::vector<double> planes = {0, 90, 180, 270};
  SlabInfo info;
  FarField far;
  if (merged) {
    const LuminaireSource source = LoadLuminaireSource(o.slab_dir, threads, "export polar");
    LogInfo("luminaire ", o.slab_dir, ": ", source.Orientations());
    info = source.slabs.front().info;
    far = MergedFarFieldChecked(source, planes, gamma, options).ff;
  } else {
    info = SlabInfo::Load(o.slab_dir);
    RequireCompleteSlab(info, o.slab_dir);
    const std::vector<SlabPosition> positions = ReadSlabPositions(o.slab_dir, info, threads);
    CheckLog checks(DatasetOfSlab(o.slab_dir), "export polar");
    CheckSlabLight(info, positions, o.slab_dir, checks);
    far = ComputeFarField(info, positions, planes, gamma, options);
    CheckFarFieldLight(far, info, o.slab_dir, checks);
    checks.Save();
  }
  size_t seen = 0;  // gamma[0 .. seen) seen in all four planes
  while (seen < gamma.size() && far.seen[seen] && far.seen[gamma.size() + seen] &&
         far.seen[2 * gamma.size() + seen] && far.seen[3 * gamma.size() + seen])
    ++seen;
  if (seen < 2)
    throw BadInput(o.slab_dir +
                   ": the slab(s) saw too few directions for a polar plot (gamma 0 to " +
                   std::to_string(seen == 0 ? 0.0 : gamma[seen - 1]) + " degrees)");
  PolarPlotData data;
  data.gamma_deg.assign(gamma.begin(), gamma.begin() + seen);
  std::vector<double>* curves[] = {&data.c0, &data.c90, &data.c180, &data.c270};
  int negative = 0;
  for (int c = 0; c < 4; ++c)
    for (size_t g = 0; g < seen; ++g) {
      const double v = far.values[c * gamma.size() + g];
      negative += v < 0;
      curves[c]->push_back(std::max(0.0, v));  // the signed dual's noise can dip below 0
    }
  if (negative > 0) LogWarning(negative, " negative intensities drawn as 0");
  data.unit = IntensityUnitLabel(info.units);
  data.title =
      std::string(merged ? "Merged far field (the orientations saw" : "Far field (the slab saw") +
      " \u03B3 = 0 to " + FormatTick(data.gamma_deg.back(), o.gamma_step_deg) + "\u00B0)";
  return data;
}

ParsedCommand AddPlotCommands(CLI::App& app, CommonOptions* common) {
  auto irradiance = std::make_shared<IrradianceOptions>();
  CLI::App* irr = app.add_subcommand(
      "irradiance",
      "the slab's irradiance (illuminance for a lux slab) on the plane z = D of the luminaire "
      "frame, by the exact CPU reference: .png false colour (viridis, colour bar in W/m² or lx, "
      "iso-lines at its ticks, a length scale) or .exr linear; +x right, +y up (the plane seen "
      "from behind it, looking back at the luminaire)");
  irr->add_option("--slab", irradiance->slab_dir,
                  "dataset folder, its slab/, or a luminaire folder (the plane z = D of the "
                  "luminaire frame as the orientation looking along gamma = 0 sees it)")
      ->required();
  irr->add_option("--distance-mm", irradiance->distance_mm, "D: the plane's distance from S (mm)")
      ->required()
      ->check(FiniteIn(kMinDistanceMm, kMaxDistanceMm));
  irr->add_option("--extent-mm", irradiance->extent_mm,
                  "the square's side on the plane (mm; default: the slab window seen at D)");
  irr->add_option("--size", irradiance->size, "pixels per side")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  irr->add_option("--samples", irradiance->samples, "N x N samples per basis support (1..64)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  irr->add_option("--range", irradiance->range,
                  "min:max of the colour bar in the slab's unit, or auto (0 .. the 99.5th "
                  "percentile rounded up; log: three decades below the top)")
      ->capture_default_str();
  irr->add_option("--scale", irradiance->scale, "linear | log")
      ->check(CLI::IsMember({"linear", "log"}))
      ->capture_default_str();
  irr->add_option("--out", irradiance->out, ".png (false colour) or .exr (linear)")->required();
  irr->add_flag("--force", irradiance->force, "rewrite the output if it exists");
  AddCommonOptions(irr, common);

  auto polar = std::make_shared<PolarOptions>();
  CLI::App* pol = app.add_subcommand(
      "polar",
      "the far-field polar diagram of the slab (intensity in cd or W/sr against gamma, planes "
      "C0-C180 and C90-C270, C0 (+x) and C90 (-y) on the right, up to the largest gamma the "
      "slab saw in all four)");
  pol->add_option("--slab", polar->slab_dir,
                  "dataset folder, its slab/, or a luminaire folder (the merged far field, gamma "
                  "0-180)")
      ->required();
  pol->add_option("--out", polar->out, ".svg or .png")->required();
  pol->add_option("--gamma-step", polar->gamma_step_deg, "degrees between the curves' points")
      ->check(FiniteIn(0.1, 45))
      ->capture_default_str();
  pol->add_option("--samples", polar->samples, "N x N samples per basis support (1..64)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  pol->add_option("--size", polar->size, "the diagram's width in pixels (SVG user units)")
      ->check(CLI::Range(200, 4096))
      ->capture_default_str();
  pol->add_option("--title", polar->title, "the title above the diagram");
  pol->add_flag("--force", polar->force, "rewrite the output if it exists");
  AddCommonOptions(pol, common);

  return [irr, pol, irradiance, polar](int threads) -> std::optional<int> {
    if (irr->parsed()) return RunIrradiance(*irradiance, threads);
    if (pol->parsed()) return RunPolar(*polar, threads);
    return std::nullopt;
  };
}

}  // namespace lumislab
