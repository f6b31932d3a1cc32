#include "study/study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/error.h"
#include "core/json.h"
#include "core/lab_model.h"
#include "core/log.h"
#include "core/slab_compare.h"
#include "core/stop_signal.h"
#include "lib/lightfield/reference_render.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/lightfield/tone_map.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"
#include "study/preview_sweep.h"
#include "study/stages.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// The knobs, in the order of the report.
const std::vector<std::string> kKnobs = {"spacing", "extent", "photo",    "k_max",  "resolution",
                                         "samples", "noise",  "brackets", "lambda", "preview"};

template <typename T>
std::vector<T> First(int n, std::vector<T> values) {
  values.resize(std::min(values.size(), size_t(n)));
  return values;
}

// One setting of the whole chain (the base, or the base with one knob moved).
struct Setting {
  double h_mm = 5;
  int nu = 9, nv = 7;
  double photo_scale = 1;
  int k_max = 1, resolution = 150, samples = 1, render_px = 96;
  double full_well_e = 0;     // > 0: a sensor_noise effect of this full well replaces the scene's
  std::vector<double> stops;  // not empty: a brackets effect of these stops replaces the scene's
  double lambda = -1;         // >= 0: reconstruct --lambda (else its default)
};

std::string StopsName(const std::vector<double>& stops) {
  std::string name;
  for (double s : stops) name += (name.empty() ? "" : "_") + Num(s);
  return name;
}

// Everything acquire and reconstruct see: points that agree on it share one dataset folder.
std::string DatasetName(const Setting& s) {
  return "h" + Num(s.h_mm) + "_" + std::to_string(s.nu) + "x" + std::to_string(s.nv) + "_p" +
         Num(s.photo_scale) + "_K" + std::to_string(s.k_max) + "_r" + std::to_string(s.resolution) +
         (s.full_well_e > 0 ? "_fw" + std::to_string(int(s.full_well_e)) : "") +
         (s.stops.empty() ? "" : "_ev" + StopsName(s.stops)) +
         (s.lambda >= 0 ? "_l" + Num(s.lambda) : "");
}
std::string Key(const Setting& s) {
  return DatasetName(s) + "_N" + std::to_string(s.samples) + "_px" + std::to_string(s.render_px);
}

struct StageTimes {
  double acquire_s = 0, calibrate_s = 0, reconstruct_s = 0;
  double preview_ms = 0;  // OSMesa frame of the crypt (PreviewFrameMs)
};

// The scene file of a setting: the study's scene with its grid, camera size, K changed.
std::string SceneText(const nlohmann::json& base, const Setting& s) {
  nlohmann::json scene = base;
  scene["setup"]["grid"]["nu"] = s.nu;
  scene["setup"]["grid"]["nv"] = s.nv;
  scene["setup"]["grid"]["spacing_mm"] = s.h_mm;
  scene["filter"]["k_max"] = s.k_max;
  // The same view at another pixel count: size and focal length scale together.
  const auto size = base["camera"]["size_px"];
  scene["camera"]["size_px"] = {int(std::lround(size[0].get<double>() * s.photo_scale)),
                                int(std::lround(size[1].get<double>() * s.photo_scale))};
  scene["camera"]["focal_px"] = base["camera"]["focal_px"].get<double>() * s.photo_scale;
  // The render is already at exposure x 2^stop: the sensor's noise on what was exposed first,
  // then the brackets' clip at 1 (a sensor clips the noisy signal; noise after the clip would
  // pull clipped pixels below 1, where the merge takes them for valid), then the scene's other
  // effects in their order.
  if (s.full_well_e > 0 || !s.stops.empty()) {
    nlohmann::json effects = nlohmann::json::array();
    if (s.full_well_e > 0)
      effects.push_back({{"type", "sensor_noise"}, {"full_well_e", s.full_well_e}, {"seed", 1}});
    if (!s.stops.empty()) effects.push_back({{"type", "brackets"}, {"stops", s.stops}});
    for (const auto& e : scene.value("effects", nlohmann::json::array())) {
      const std::string type = e.value("type", "");
      if ((type == "brackets" && !s.stops.empty()) || (type == "sensor_noise" && s.full_well_e > 0))
        continue;
      effects.push_back(e);
    }
    scene["effects"] = effects;
  }
  return scene.dump(2) + "\n";
}

std::vector<std::string> ReconstructArgs(const Setting& s, const std::string& ds, int threads) {
  std::vector<std::string> args = {"--dataset",    ds,
                                   "--resolution", std::to_string(s.resolution),
                                   "--threads",    std::to_string(threads)};
  if (s.lambda >= 0) args.insert(args.end(), {"--lambda", Num(s.lambda, 6)});
  return args;
}

// acquire synth -> calibrate screen -> reconstruct in work/<dataset>/, once: a finished dataset
// keeps its stage times in times.json (written last), and its photos are removed then unless
// --keep-photos. An interrupted one is continued by the stages' own resumption
// (docs/architecture.md §7.4). Then the preview's frame time on the crypt with this slab
// (`bench_size`, WxH).
StageTimes RunChain(const nlohmann::json& base_scene, const Setting& s, const std::string& work,
                    int threads, bool keep_photos, const std::string& bench_size) {
  const std::string dir = work + "/" + DatasetName(s);
  const std::string times_path = dir + "/times.json";
  if (fs::exists(times_path)) {
    const JsonDocument doc = JsonDocument::Load(times_path);
    return {doc.root()["acquire_s"].Number(), doc.root()["calibrate_s"].Number(),
            doc.root()["reconstruct_s"].Number(), doc.root()["preview_ms"].Number()};
  }
  MakeDirectories(dir);
  const std::string scene = dir + "/scene.json", ds = dir + "/ds", log = dir + "/log.txt";
  WriteTextAtomically(scene, SceneText(base_scene, s));
  const std::string t = std::to_string(threads), res = std::to_string(s.resolution);
  StageTimes times;
  times.acquire_s = RunStage(
      "lumislab-acquire",
      {"synth", "--scene", scene, "--out", ds, "--truth-resolution", res, "--threads", t}, log);
  times.calibrate_s =
      RunStage("lumislab-calibrate", {"screen", "--dataset", ds, "--threads", t}, log);
  times.reconstruct_s = RunStage("lumislab-reconstruct", ReconstructArgs(s, ds, threads), log);
  times.preview_ms = PreviewFrameMs(ds + "/slab", {"--scene", "crypt", "--size", bench_size},
                                    dir + "/preview_bench.txt", threads);
  if (!keep_photos) fs::remove_all(ds + "/photos");
  WriteJsonAtomically(times_path, {{"preview_ms", times.preview_ms},
                                   {"acquire_s", times.acquire_s},
                                   {"calibrate_s", times.calibrate_s},
                                   {"reconstruct_s", times.reconstruct_s}});
  return times;
}

double Sum(const ImageF& image) {
  double s = 0;
  for (float v : image.data) s += v;
  return s;
}

// Errors of one point: slab vs truth/, and the reference against the analytic image on the
// receiver plane at D = d, 2d, 4d (irradiance, every pixel of the plane's view).
void Measure(const SynthScene& scene, const Setting& s, const std::string& ds, int threads,
             StudyRow* row) {
  row->slab_rel_l2 = CompareSlabs(ds + "/slab", ds + "/truth").overall_relative_l2;
  const SlabInfo info = SlabInfo::Load(ds + "/slab");
  const std::vector<ImageF> irradiance = ReadSlabIrradiance(ds + "/slab", info, threads);
  std::vector<PointSource> sources;
  for (const Emitter& e : scene.luminaire.emitters)
    sources.push_back({e.position_mm, [e](const Eigen::Vector3d& w) { return e.Intensity(w); }});
  ReferenceOptions options;
  options.samples = s.samples;
  options.threads = threads;
  options.progress = false;
  row->render_s = 0;
  for (int k = 0; k < 3; ++k) {
    SceneRequest request;
    request.name = "plane";
    request.receiver_plane_mm = info.distance_mm * (1 << k);
    const ReferenceScene view(MakeSceneSetup(request, info), s.render_px, s.render_px);
    const ReferenceImage analytic = RenderPointSources(view, sources, options);
    const auto start = std::chrono::steady_clock::now();
    const ReferenceImage image = RenderReference(view, info, irradiance, options);
    row->render_s +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!image.complete || !analytic.complete) throw Failure("stopped by a signal");
    row->err[k] = CompareImages(image.irradiance, analytic.irradiance).relative_l2;
    const double flux = Sum(analytic.irradiance);
    row->flux[k] = flux > 0 ? Sum(image.irradiance) / flux : 0;
    // Only the pixels the grid covers: what is left there is the reconstruction's own error.
    double diff2 = 0, ref2 = 0, covered_flux = 0;
    const ImageF& a = analytic.irradiance;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) {
        const SurfacePoint p = view.Primary(x, y);
        if (!p.hit || !GridCovers(scene.luminaire, info, p.x)) continue;
        for (int c = 0; c < a.channels; ++c) {
          const double e = image.irradiance.at(x, y, c) - a.at(x, y, c);
          diff2 += e * e, ref2 += double(a.at(x, y, c)) * a.at(x, y, c);
          covered_flux += a.at(x, y, c);
        }
      }
    row->err_covered[k] = ref2 > 0 ? std::sqrt(diff2 / ref2) : -1;
    row->covered[k] = flux > 0 ? covered_flux / flux : 0;
  }
}

// One sweep point: its knob, the value's label and the whole setting.
struct Point {
  std::string knob, value;
  Setting setting;
};

// The points of `knobs` around `base`, the first `values` of each knob's list. Spacing keeps the
// grid's extent (the positions cover the same part of S); extent keeps h and scales the span.
std::vector<Point> SweepPoints(const std::vector<std::string>& knobs, const Setting& base,
                               int values, bool quick, const SynthScene& scene) {
  std::vector<Point> points;
  const auto positions_for = [](int n0, double span_factor) {
    return std::max(1, int(std::lround((n0 - 1) * span_factor)) + 1);
  };
  for (const std::string& knob : knobs) {
    if (knob == "spacing")
      for (double f : First(values, std::vector<double>{2, 1, 0.5})) {
        Setting s = base;
        s.h_mm = base.h_mm * f;
        s.nu = positions_for(base.nu, 1 / f), s.nv = positions_for(base.nv, 1 / f);
        points.push_back({knob, Num(s.h_mm) + " mm", s});
      }
    if (knob == "extent")
      for (double f : First(values, std::vector<double>{0.5, 1, 1.5})) {
        Setting s = base;
        s.nu = positions_for(base.nu, f), s.nv = positions_for(base.nv, f);
        points.push_back({knob, "x" + Num(f), s});
      }
    if (knob == "photo")
      for (double f : First(values, quick ? std::vector<double>{1, 1.5, 2}
                                          : std::vector<double>{0.5, 0.75, 1})) {
        Setting s = base;
        s.photo_scale = base.photo_scale * f;
        points.push_back({knob, "x" + Num(s.photo_scale), s});
      }
    if (knob == "k_max")
      for (int k : First(values, std::vector<int>{1, 2, 3})) {
        Setting s = base;
        s.k_max = k;
        points.push_back({knob, std::to_string(k), s});
      }
    if (knob == "resolution")
      for (double f : First(values, std::vector<double>{0.5, 1, 2})) {
        Setting s = base;
        s.resolution = std::max(8, int(std::lround(base.resolution * f)));
        points.push_back({knob, std::to_string(s.resolution), s});
      }
    if (knob == "samples")
      for (int n : First(values, std::vector<int>{1, 2, 4})) {
        Setting s = base;
        s.samples = n;
        points.push_back({knob, std::to_string(n), s});
      }
    // Noise: the sensor's full well (electrons at value 1: shot noise of a photo at value x has
    // relative sigma 1/sqrt(x full_well)), read noise 3 e-; a shorter exposure is a smaller
    // effective full well.
    if (knob == "noise")
      for (double fw : First(values, std::vector<double>{20000, 2000, 200})) {
        Setting s = base;
        s.full_well_e = fw;
        points.push_back({knob, "full well " + std::to_string(int(fw)) + " e-", s});
      }
    // Brackets on the noisy camera of the noise knob's middle value: each added stop of +2
    // exposes 4x longer (clipped highlights are taken from the shorter ones), at the lab's cost
    // of one more exposure per slide.
    if (knob == "brackets")
      for (const auto& stops :
           First(values, std::vector<std::vector<double>>{{0}, {0, 2}, {0, 2, 4}})) {
        Setting s = base;
        s.full_well_e = 2000;
        // One exposure at stop 0 is what a scene without brackets takes: the noise knob's point.
        if (stops != std::vector<double>{0} || scene.Stops() != std::vector<double>{0})
          s.stops = stops;
        points.push_back(
            {knob, std::to_string(stops.size()) + " (ev " + StopsName(stops) + ")", s});
      }
    // Regularisation of the fit; reconstruct's default 1e-4 is the base itself.
    if (knob == "lambda")
      for (double l : First(values, std::vector<double>{1e-4, 1e-2, 1})) {
        Setting s = base;
        s.lambda = l == 1e-4 ? -1 : l;
        points.push_back({knob, Num(l) + (l == 1e-4 ? " (default)" : ""), s});
      }
  }
  return points;
}

}  // namespace

std::vector<StudyRow> RunStudySweep(const StudyOptions& o, int threads) {
  // Inputs first: the scene (exit 2 naming the file), the knobs, then --out.
  const SynthScene scene = LoadScene(o.scene);
  // The study measures against the analytic image of point emitters.
  RequirePointEmitters(scene.luminaire, scene.source, "the study's analytic receiver planes");
  const nlohmann::json base_scene =
      nlohmann::json::parse(o.scene == "default" ? DefaultSceneJson() : ReadTextFile(o.scene));
  std::vector<std::string> knobs;
  if (o.knobs == "all") {
    knobs = kKnobs;
  } else {
    std::istringstream in(o.knobs);
    for (std::string k; std::getline(in, k, ',');) {
      if (std::find(kKnobs.begin(), kKnobs.end(), k) == kKnobs.end())
        throw BadInput(
            "--knobs: expected a comma-separated subset of spacing, extent, photo, "
            "k_max, resolution, samples, noise, brackets, lambda, preview, got \"" +
            k + "\"");
      knobs.push_back(k);
    }
  }
  const std::string out = TrimTrailingSlashes(o.out);
  try {
    fs::create_directories(out);
    WriteTextAtomically(out + "/.write_probe", "");
    fs::remove(out + "/.write_probe");
  } catch (const std::exception& e) {
    throw BadInput("--out: cannot write into " + out + " (" + e.what() + ")");
  }
  RemoveOrphanedTemporaries(out);
  // What the rows depend on beyond their key: the scene and the lab model. A rerun into the same
  // --out must agree, or it would resume another study's rows and datasets.
  const nlohmann::json identity = {{"schema_version", 1},
                                   {"scene", base_scene},
                                   {"move_s", o.lab.move_s},
                                   {"exposure_s", o.lab.exposure_s},
                                   {"slides", o.lab.slides}};
  const std::string identity_path = out + "/study.json";
  if (fs::exists(identity_path)) {
    if (JsonDocument::Load(identity_path).raw() != identity)
      throw BadInput("--out: " + identity_path +
                     ": the folder holds a study of another scene or lab model (--move-s, "
                     "--exposure-s, --slides); use another --out");
  } else {
    WriteJsonAtomically(identity_path, identity);
  }

  const int preview_w = o.preview_width > 0 ? o.preview_width : (o.quick ? 120 : 240);
  const int preview_h = std::max(1, preview_w * 3 / 4);
  const std::string preview_size = std::to_string(preview_w) + "x" + std::to_string(preview_h);
  Setting base;
  base.h_mm = scene.grid.spacing_mm;
  base.nu = scene.grid.nu, base.nv = scene.grid.nv;
  base.photo_scale = o.photo_scale > 0 ? o.photo_scale : (o.quick ? 0.25 : 1.0);
  base.k_max = scene.k_max;
  base.resolution = o.resolution > 0 ? o.resolution : (o.quick ? 48 : 150);
  base.samples = o.samples;
  base.render_px = o.render_px > 0 ? o.render_px : (o.quick ? 40 : 96);

  const std::vector<Point> points = SweepPoints(knobs, base, o.values, o.quick, scene);

  const std::string csv = out + "/study.csv";
  std::vector<StudyRow> rows = fs::exists(csv) ? ReadStudyCsv(csv) : std::vector<StudyRow>{};
  const std::string header_note =
      "# lumislab-study: " + scene.source + "\n\nBase: h " + Num(base.h_mm) + " mm, " +
      std::to_string(base.nu) + "x" + std::to_string(base.nv) + " positions, photos " +
      Num(base.photo_scale) + " x the scene camera's, K " + std::to_string(base.k_max) + ", " +
      std::to_string(base.resolution) + " texels, N " + std::to_string(base.samples) +
      ", receiver plane " + std::to_string(base.render_px) + " px. Lab model: positions x (" +
      Num(o.lab.move_s) + " s move + " + std::to_string(o.lab.slides) + " slides x brackets x " +
      Num(o.lab.exposure_s) +
      " s). Screen calibration: `lumislab-calibrate screen` (the board "
      "photo). Photos through the scene's effects as given (the default scene has none: "
      "noise-free; the noise and brackets knobs add `sensor_noise` and `brackets` effects). "
      "Total time = lab model + reconstruct + reference render (three planes); acquire (sim) is "
      "the synthetic capture's own time, not counted; preview = the median OSMesa frame of the "
      "crypt (" +
      preview_size + ") with the point's slab.\n";
  const auto write_outputs = [&] {
    std::string text = StudyCsvHeader() + "\n";
    for (const StudyRow& r : rows) text += StudyCsvLine(r) + "\n";
    WriteTextAtomically(csv, text);
  };

  // SIGINT / SIGTERM: the stage in hand is told to stop, the study stops after it (exit 1);
  // study.csv holds the points completed before, and the same command continues.
  const StopSignalScope stop_scope;
  int skipped = 0;
  for (size_t p = 0; p < points.size(); ++p) {
    const Point& point = points[p];
    const std::string key = Key(point.setting);
    const auto done = std::find_if(rows.begin(), rows.end(), [&](const StudyRow& r) {
      return r.knob == point.knob && r.key == key;
    });
    if (done != rows.end()) {
      ++skipped;
      continue;
    }
    if (StopRequested()) throw Failure("stopped by a signal; run again to continue");
    LogInfo("point ", p + 1, "/", points.size(), ": ", point.knob, " = ", point.value);
    StudyRow row;
    const auto same =
        std::find_if(rows.begin(), rows.end(), [&](const StudyRow& r) { return r.key == key; });
    if (same != rows.end()) {
      row = *same;  // the same setting under another knob (the base): measured once
    } else {
      const Setting& s = point.setting;
      const StageTimes times =
          RunChain(base_scene, s, out + "/work", threads, o.keep_photos, preview_size);
      row.key = key;
      row.h_mm = s.h_mm, row.nu = s.nu, row.nv = s.nv;
      row.photo_w = int(std::lround(scene.camera.width * s.photo_scale));
      row.photo_h = int(std::lround(scene.camera.height * s.photo_scale));
      row.k_max = s.k_max, row.slab_res = s.resolution, row.samples = s.samples;
      row.render_px = s.render_px;
      row.acquire_s = times.acquire_s, row.calibrate_s = times.calibrate_s;
      row.reconstruct_s = times.reconstruct_s, row.preview_ms = times.preview_ms;
      row.full_well_e = s.full_well_e, row.lambda = s.lambda;
      LabModel lab = o.lab;
      lab.brackets = s.stops.empty() ? int(scene.Stops().size()) : int(s.stops.size());
      row.brackets = lab.brackets;
      Measure(scene, s, out + "/work/" + DatasetName(s) + "/ds", threads, &row);
      row.lab_s = lab.Seconds(row.positions());
      row.total_s = row.lab_s + row.reconstruct_s + row.render_s;
    }
    row.knob = point.knob, row.value = point.value;
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(row.err[k]) || !std::isfinite(row.flux[k]) ||
          !std::isfinite(row.err_covered[k]))
        throw Failure(point.knob + " = " + point.value + ": a non-finite error");
    rows.push_back(row);
    write_outputs();  // the row is in study.csv only once the point is complete
  }
  if (skipped > 0) LogInfo(skipped, " point(s) already in ", csv, ", skipped");

  // The preview's own knobs on the base dataset's slab (measured once it exists).
  std::vector<PreviewRow> preview_rows;
  const std::string preview_csv = out + "/preview.csv";
  if (fs::exists(preview_csv)) preview_rows = ReadPreviewCsv(preview_csv);
  if (std::find(knobs.begin(), knobs.end(), "preview") != knobs.end()) {
    PreviewSweepOptions po;
    const std::string base_dir = out + "/work/" + DatasetName(base);
    if (!fs::exists(base_dir + "/times.json"))
      RunChain(base_scene, base, out + "/work", threads, o.keep_photos, preview_size);
    po.slab = base_dir + "/ds/slab";
    po.work = out + "/work/preview";
    po.width = preview_w, po.height = preview_h;
    po.reference_samples = o.preview_samples;
    po.threads = threads;
    po.samples = First(o.values, po.samples);
    po.shadow_sizes = First(o.values, po.shadow_sizes);
    RunPreviewSweep(po, &preview_rows, [&] {
      std::string text = PreviewCsvHeader() + "\n";
      for (const PreviewRow& r : preview_rows) text += PreviewCsvLine(r) + "\n";
      WriteTextAtomically(preview_csv, text);
    });
  }

  std::string report = StudyReport(rows, kKnobs, header_note);
  if (!preview_rows.empty())
    report += "\n## The preview's own knobs (base slab, against the exact reference at N = " +
              std::to_string(o.preview_samples) + ")\n\n" + PreviewReport(preview_rows);
  WriteTextAtomically(out + "/report.md", report);
  WriteTextAtomically(out + "/study_d.svg", StudySvg(rows, kKnobs, 0));
  WriteTextAtomically(out + "/study_4d.svg", StudySvg(rows, kKnobs, 2));
  return rows;
}

}  // namespace lumislab
