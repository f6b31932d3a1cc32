#include "calibrate/cli_radiometric.h"

#include <filesystem>
#include <sstream>

#include "calibrate/radiometric/calibration_checks.h"
#include "calibrate/radiometric/calibration_frames.h"
#include "calibrate/radiometric/flat_calibrator.h"
#include "core/atomic_file.h"
#include "core/checks.h"
#include "core/command_line.h"
#include "core/error.h"
#include "core/log.h"
#include "core/screen_calibration.h"
#include "lib/photometry/colour.h"

namespace lumislab {
namespace {

void AddCommon(CLI::App* sub, CommonOptions* common, RadiometricCommand* c, bool frames) {
  sub->add_option("--dataset", c->dataset_dir, "dataset folder (with dataset.json)")->required();
  if (frames) {
    sub->add_option("--frames", c->frames, "the frames (photo files, any format the decoder reads)")
        ->required()
        ->expected(1, -1);
    sub->add_option("--exposures", c->exposures,
                    "relative exposure of each frame, comma-separated (default: from EXIF)");
  }
  sub->add_flag("--force", c->force, "recalibrate even if the output exists");
  AddCommonOptions(sub, common);
}

std::pair<double, double> Pair(const std::string& text, const std::string& option) {
  std::stringstream in(text);
  double a, b;
  char comma;
  if (!(in >> a >> comma >> b) || comma != ',' || !in.eof() || !std::isfinite(a) ||
      !std::isfinite(b))
    throw BadInput(option + ": expected two numbers 'a,b', got '" + text + "'");
  return {a, b};
}

// calib/<name> of the dataset; false (and a log line) when it exists and --force is not given.
// Nothing is created yet: a step refused for bad input leaves the dataset as it was (MakeCalib
// creates calib/ once the result is there to write).
bool Prepare(const Dataset& dataset, const std::string& name, bool force, std::string* out) {
  *out = dataset.Path("calib/" + name);
  if (std::filesystem::exists(*out) && !force) {
    LogInfo(*out, " exists, skipping (use --force to recalibrate)");
    return false;
  }
  return true;
}

// calib/ of the dataset, created, without the temporaries of an interrupted run.
void MakeCalib(const Dataset& dataset) {
  MakeDirectories(dataset.Path("calib"));
  RemoveOrphanedTemporaries(dataset.Path("calib"));
}

ScreenCalibration LoadScreen(const Dataset& dataset, const char* step) {
  const std::string path = dataset.Path("calib/screen.json");
  if (!std::filesystem::exists(path))
    throw BadInput(path + ": missing; run lumislab-calibrate screen before " + step);
  return ScreenCalibration::Load(path);
}

// Which of calib/'s corrections a step decodes its photos with (one log line).
std::shared_ptr<const PhotoCorrections> Corrections(const Dataset& dataset, CorrectionSet which,
                                                    const char* step) {
  auto c = std::make_shared<PhotoCorrections>(LoadPhotoCorrections(dataset.Path("calib"), which));
  std::string what;
  if (c->response) what += " response curve (" + c->response->file + ")";
  if (c->dark) what += " dark map (" + c->dark->file + ")";
  if (c->flat) what += " flat field (" + c->flat->file + ")";
  LogInfo(step, ": decoding with", what.empty() ? " no radiometric calibration" : what);
  return c;
}

FrameOptions Frames(const RadiometricCommand& c, const char* what) {
  FrameOptions f;
  f.files = c.frames;
  if (!c.exposures.empty()) f.exposures = ParseExposureList(c.exposures);
  f.what = what;
  return f;
}

int RunDark(const RadiometricCommand& c, const Dataset& dataset) {
  c.dark_options.Check();
  std::string out;
  if (!Prepare(dataset, "dark.json", c.force, &out)) return 0;
  FrameOptions f = Frames(c, "dark frames");
  // The dark level is measured in the decoder's linear units: through the calibrated response
  // when there is one, never through an older dark or flat map.
  f.corrections = Corrections(dataset, {false, true, false}, "dark");
  const std::vector<CalibrationFrame> frames = DecodeCalibrationFrames(dataset, f);
  NoteSrgbCurve("dark", frames[0].photo);
  CheckLog checks(dataset.dir, "calibrate dark");
  CheckDarkFrames(frames, &checks);
  nlohmann::json report;
  const DarkMap map = CalibrateDark(frames, c.dark_options, &report);
  MakeCalib(dataset);
  SaveDarkMap(out, map, report);
  checks.Save();
  LogInfo("dark: ", c.frames.size(), " frame(s), ", report["exposures"].size(), " exposure(s) -> ",
          map.current.empty() ? "constant level" : "offset + current", "; mean level ",
          report["mean_black_level"].get<double>(), ", ", map.hot_count,
          " hot pixel(s) (threshold ", c.dark_options.hot_threshold, ") -> ", out);
  return 0;
}

int RunResponse(const RadiometricCommand& c, const Dataset& dataset) {
  c.response_options.Check();
  const std::vector<CalibrationFrame> frames =
      DecodeCalibrationFrames(dataset, Frames(c, "bracketed frames"));
  if (frames.size() < 2)
    throw BadInput("--frames: expected at least 2 bracketed frames, got " +
                   std::to_string(frames.size()));
  CheckLog checks(dataset.dir, "calibrate response");
  CheckExposureOrder(frames, &checks);
  std::string out;
  if (!frames[0].photo.EightBitCodes()) {
    // Linear data: nothing to recover, only to verify.
    if (!Prepare(dataset, "linearity.json", c.force, &out)) return 0;
    nlohmann::json report = CheckLinearity(frames);
    report["schema_version"] = kRadiometricCalibrationSchemaVersion;
    report["kind"] = "linearity";
    MakeCalib(dataset);
    WriteJsonAtomically(out, report);
    checks.Save();
    LogInfo("response: ", frames[0].photo.CodeBits(),
            "-bit frames are linear data: no curve recovered; value / exposure deviates from the "
            "middle exposure's by at most ",
            100 * report["max_deviation"].get<double>(), " % -> ", out);
    return 0;
  }
  if (!Prepare(dataset, "response.json", c.force, &out)) return 0;
  nlohmann::json report;
  const ResponseCurve curve = CalibrateResponse(frames, c.response_options, &report, &checks);
  CheckResponseFit(report, &checks);
  MakeCalib(dataset);
  SaveResponseCurve(out, curve, report);
  checks.Save();
  const nlohmann::json& dev = report["channel_deviation"];
  LogInfo("response: ", report["curves"].get<std::string>(), " from ",
          report["samples"][0].get<int>() + report["samples"][1].get<int>() +
              report["samples"][2].get<int>(),
          " sample pixels of ", frames.size(), " frames; channel data off the curve by at most ",
          dev[0].get<double>(), ", ", dev[1].get<double>(), ", ", dev[2].get<double>(),
          " (log, R G B); bracket consistency (RMS log ratio) ",
          report["consistency"]["rms_log_ratio"].get<double>(),
          " (sRGB curve: ", report["consistency_srgb_curve"]["rms_log_ratio"].get<double>(),
          ") -> ", out);
  return 0;
}

int RunFlat(const RadiometricCommand& c, const Dataset& dataset) {
  const ScreenCalibration screen = LoadScreen(dataset, "flat");
  std::string out;
  if (!Prepare(dataset, "flat.json", c.force, &out)) return 0;
  FrameOptions f = Frames(c, "flat frames");
  f.per_unit_exposure = true;
  f.corrections = Corrections(dataset, {true, true, false}, "flat");
  const std::vector<CalibrationFrame> frames = DecodeCalibrationFrames(dataset, f);
  NoteSrgbCurve("flat", frames[0].photo);
  nlohmann::json report;
  CheckLog checks(dataset.dir, "calibrate flat");
  const FlatMap map = CalibrateFlat(frames, dataset, screen, &report, c.flat_smooth_px, &checks);
  CheckFlat(report, &checks);
  MakeCalib(dataset);
  SaveFlatMap(out, map, report);
  checks.Save();
  LogInfo("flat: ", c.frames.size(), " frame(s); gain ", report["min_gain"].get<double>(), " .. ",
          report["max_gain"].get<double>(), " over ", report["screen_pixels"].get<long long>(),
          " screen pixels -> ", out);
  return 0;
}

int RunScale(const RadiometricCommand& c, const Dataset& dataset) {
  const ScreenCalibration screen = LoadScreen(dataset, "scale");
  ScaleReference reference;
  if (!c.reference_file.empty()) {
    reference = LoadScaleReference(c.reference_file);
  } else {
    if (c.position.empty() || c.point_mm.empty() || std::isnan(c.reading_p) ||
        std::isnan(c.reading_n))
      throw BadInput(
          "--reference: expected a reference file, or --position, --point-mm, --reading-p and "
          "--reading-n");
    reference.source = "command line";
    const auto [i, j] = Pair(c.position, "--position");
    if (i != std::floor(i) || j != std::floor(j))
      throw BadInput("--position: expected integers 'i,j', got '" + c.position + "'");
    reference.i = int(i), reference.j = int(j);
    const auto [x, y] = Pair(c.point_mm, "--point-mm");
    reference.point_mm = {x, y};
    reference.reading_p = c.reading_p;
    reference.reading_n = c.reading_n;
    reference.unit = CanonicalUnit(c.unit, "--unit");
  }
  reference.Check(dataset);
  std::string out;
  if (!Prepare(dataset, "scale.json", c.force, &out)) return 0;
  const auto corrections = Corrections(dataset, {}, "scale");
  // Luminance is the colour calibration's Y when the dataset has one (calib/colour.json), else
  // the Rec. 709 mix of camera RGB: exact only for a camera whose channels are Rec. 709's.
  ScaleOptions options = c.scale_options;
  if (const auto colour = ColourCalibration::LoadFor(dataset.dir)) {
    options.channel_weights = colour->LuminanceWeights();
    options.channel_weights_from_colour = true;
    LogInfo("scale: luminance weights ", options.channel_weights.x(), " ",
            options.channel_weights.y(), " ", options.channel_weights.z(), " (R G B) from ",
            colour->file);
  } else {
    LogInfo("scale: luminance weights of Rec. 709 (0.2126 0.7152 0.0722): no calib/colour.json",
            reference.unit == "lux"
                ? "; the lux reading is matched to the Rec. 709 mix of camera RGB, not to the "
                  "camera's luminance (lumislab-calibrate colour gives it)"
                : "");
  }
  nlohmann::json report;
  CheckLog checks(dataset.dir, "calibrate scale");
  const RadiometricScale scale =
      CalibrateScale(dataset, screen, reference, corrections, options, &report, &checks);
  CheckScale(report, scale.scale, &checks);
  MakeCalib(dataset);
  SaveRadiometricScale(out, scale, report);
  checks.Save();
  if (report.value("photos_through_srgb_curve", false))
    LogInfo(
        "scale: the photos' codes were linearised through the sRGB curve (no "
        "calib/response.json for them)");
  LogInfo("scale: ", scale.scale, " ", scale.units, " per unit (readings ", reference.reading_p,
          " - ", reference.reading_n, " over values ", report["value_p"].get<double>(), " - ",
          report["value_n"].get<double>(), ")",
          dataset.radiometric_scale
              ? "; dataset.json radiometry.scale_w_m2 " + std::to_string(*dataset.radiometric_scale)
              : std::string(),
          " -> ", out);
  return 0;
}

}  // namespace

void AddRadiometricCommands(CLI::App* app, CommonOptions* common, RadiometricCommand* c) {
  c->dark = app->add_subcommand(
      "dark",
      "dark frames (lens capped) -> calib/dark.json + dark.exr: per-pixel dark level (offset, "
      "and dark current when frames of 2+ exposures are given) and hot pixels, subtracted "
      "before everything else when photos are decoded");
  AddCommon(c->dark, common, c, true);
  c->dark
      ->add_option("--hot-threshold", c->dark_options.hot_threshold,
                   "hot pixel: dark level above the median's by more than this (linear, "
                   "fraction of full scale)")
      ->check(FiniteIn(1e-6, 1))
      ->capture_default_str();
  c->response = app->add_subcommand(
      "response",
      "bracketed frames of a still scene -> calib/response.json (8-bit frames: the camera "
      "response, a least-squares fit; used to linearise 8-bit photos) or calib/linearity.json "
      "(16-bit, float, RAW frames: a linearity check)");
  AddCommon(c->response, common, c, true);
  c->response
      ->add_option("--samples", c->response_options.samples,
                   "sample pixels per channel for the fit (smooth regions, 3 x 3 means)")
      ->capture_default_str();
  c->response->add_option("--lambda", c->response_options.lambda, "smoothness of the curve")
      ->capture_default_str();
  c->response->add_flag("--per-channel", c->response_options.per_channel,
                        "fit a curve per channel (default: one curve for R, G and B, as a JPEG "
                        "engine applies one tone curve; report.channel_deviation says whether "
                        "a channel's data disagree with it)");
  c->flat = app->add_subcommand(
      "flat",
      "frames of the screen under uniform irradiance -> calib/flat.json + flat.exr: per-pixel "
      "gain (vignetting x screen non-uniformity), mean 1 on the screen, divided out of every "
      "photo; needs calib/screen.json");
  AddCommon(c->flat, common, c, true);
  c->flat
      ->add_option("--smooth-px", c->flat_smooth_px,
                   "smooth the gain with a Gaussian of this sigma (pixels) over the screen "
                   "pixels: for noisy or JPEG frames (vignetting and screen gain vary slowly); "
                   "0: per pixel")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  c->scale = app->add_subcommand(
      "scale",
      "a radiometer / lux meter reading at a screen point for one position, T+ and T- -> "
      "calib/scale.json: irradiance per unit value, used instead of radiometry.scale_w_m2; "
      "needs calib/screen.json");
  AddCommon(c->scale, common, c, false);
  c->scale->add_option("--reference", c->reference_file,
                       "JSON {position: [i, j], point_mm: [x, y], reading_p, reading_n, unit}");
  c->scale->add_option("--position", c->position, "grid position 'i,j' of the reading");
  c->scale->add_option("--point-mm", c->point_mm, "screen point 'x,y' (lab mm) of the reading");
  c->scale->add_option("--reading-p", c->reading_p, "reading with slide T+ in")
      ->check(FiniteIn(-1e12, 1e12));
  c->scale->add_option("--reading-n", c->reading_n, "reading with slide T- in")
      ->check(FiniteIn(-1e12, 1e12));
  c->scale->add_option("--unit", c->unit, "W/m2 (radiometer) or lux (lux meter)")
      ->capture_default_str();
  c->scale
      ->add_option("--radius-px", c->scale_options.radius_px,
                   "the pixels within this distance of the point give a quadratic fit its value "
                   "there (about a meter's aperture; noise and JPEG error average out)")
      ->check(CLI::Range(2, 50))
      ->capture_default_str();
}

int RunRadiometricCommand(RadiometricCommand& c) {
  CLI::App* parsed = nullptr;
  for (CLI::App* sub : {c.dark, c.response, c.flat, c.scale})
    if (sub && sub->parsed()) parsed = sub;
  if (!parsed) return -1;
  c.dataset_dir = TrimTrailingSlashes(c.dataset_dir);
  std::ostringstream params;
  params << "dataset=" << c.dataset_dir << " frames=" << c.frames.size()
         << " exposures=" << (c.exposures.empty() ? "exif" : c.exposures)
         << " force=" << (c.force ? "yes" : "no");
  LogInfo("parameters: ", parsed->get_name(), " ", params.str());
  const Dataset dataset = Dataset::Load(c.dataset_dir);
  if (parsed == c.dark) return RunDark(c, dataset);
  if (parsed == c.response) return RunResponse(c, dataset);
  if (parsed == c.flat) return RunFlat(c, dataset);
  return RunScale(c, dataset);
}

}  // namespace lumislab
